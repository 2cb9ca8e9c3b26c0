//! Report plots: PNG and SVG files with the data in them, and clear errors.

use std::path::Path;

use mocap_view::{
    plot_bars, plot_confusion, plot_lines, BarPlot, BarSeries, ConfusionPlot, LinePlot, Series,
    PALETTE,
};

fn pixels_near(path: &Path, colour: [u8; 3]) -> usize {
    let img = image::open(path).unwrap().to_rgb8();
    img.pixels()
        .filter(|p| (0..3).all(|k| (p.0[k] as i32 - colour[k] as i32).abs() < 12))
        .count()
}

/// A joint's rotation over time, noisy / cleaned / truth (as the denoising
/// report's figure), with a gap in the noisy track.
fn rotation_plot() -> LinePlot {
    let truth: Vec<f32> = (0..120).map(|i| 30.0 * (i as f32 * 0.08).sin()).collect();
    let mut noisy: Vec<f32> = truth
        .iter()
        .enumerate()
        .map(|(i, v)| v + if i % 7 == 0 { 12.0 } else { -3.0 })
        .collect();
    noisy[60] = f32::NAN;
    let cleaned: Vec<f32> = truth.iter().map(|v| v + 1.0).collect();
    LinePlot::new("LowerLeg_L x rotation", "frame", "degrees")
        .with_series(Series::sampled("noisy", 0.0, 1.0, &noisy))
        .with_series(Series::sampled("cleaned", 0.0, 1.0, &cleaned))
        .with_series(Series::sampled("truth", 0.0, 1.0, &truth))
}

#[test]
fn line_plot_png_and_svg() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("rotation.png");
    plot_lines(&png, &rotation_plot()).unwrap();
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (900, 500));
    for (i, colour) in PALETTE.iter().take(3).enumerate() {
        // A 120-sample curve two pixels wide: hundreds of its pixels.
        assert!(pixels_near(&png, *colour) > 300, "series {i}");
    }
    assert_eq!(pixels_near(&png, PALETTE[3]), 0, "no fourth series");

    let svg = dir.path().join("rotation.svg");
    plot_lines(&svg, &rotation_plot()).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg"));
    for label in [
        "LowerLeg_L x rotation",
        "noisy",
        "cleaned",
        "truth",
        "degrees",
    ] {
        assert!(text.contains(label), "{label}");
    }
}

#[test]
fn log_scale_leaves_out_what_it_cannot_draw() {
    let dir = tempfile::tempdir().unwrap();
    let mut plot = LinePlot::new("loss", "epoch", "loss");
    plot.log_y = true;
    plot.series.push(Series::new(
        "train",
        vec![(1.0, 1.0), (2.0, 0.1), (3.0, 0.0), (4.0, 0.01)],
    ));
    plot_lines(&dir.path().join("loss.png"), &plot).unwrap();

    plot.series = vec![Series::new("empty", vec![(1.0, 0.0), (2.0, -1.0)])];
    let e = plot_lines(&dir.path().join("none.png"), &plot)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no finite point"), "{e}");
    let e = plot_lines(&dir.path().join("x.jpg"), &rotation_plot())
        .unwrap_err()
        .to_string();
    assert!(e.contains(".png or .svg"), "{e}");
}

#[test]
fn per_joint_error_bars() {
    let dir = tempfile::tempdir().unwrap();
    let joints: Vec<String> = [
        "Hips",
        "Spine",
        "Chest",
        "Neck",
        "Head",
        "UpperArm_L",
        "LowerArm_L",
        "Hand_L",
        "UpperLeg_L",
        "LowerLeg_L",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let plot = BarPlot {
        title: "per-joint position error".into(),
        y_label: "mm".into(),
        categories: joints.clone(),
        series: vec![
            BarSeries {
                label: "noisy".into(),
                values: (0..10).map(|i| 20.0 + i as f32).collect(),
                errors: Some(vec![4.0; 10]),
            },
            BarSeries {
                label: "cleaned".into(),
                values: (0..10).map(|i| 8.0 + 0.5 * i as f32).collect(),
                errors: None,
            },
        ],
        size: (900, 500),
    };
    let png = dir.path().join("bars.png");
    plot_bars(&png, &plot).unwrap();
    assert!(pixels_near(&png, PALETTE[0]) > 1000);
    assert!(pixels_near(&png, PALETTE[1]) > 500);
    let svg = dir.path().join("bars.svg");
    plot_bars(&svg, &plot).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    for joint in &joints {
        assert!(text.contains(joint.as_str()), "{joint}");
    }

    let mut bad = plot.clone();
    bad.series[1].values.pop();
    let e = plot_bars(&dir.path().join("bad.png"), &bad)
        .unwrap_err()
        .to_string();
    assert!(e.contains("cleaned") && e.contains("9 values"), "{e}");
}

#[test]
fn confusion_matrix() {
    let dir = tempfile::tempdir().unwrap();
    let plot = ConfusionPlot {
        title: "search: true vs found".into(),
        labels: vec!["walk".into(), "run".into(), "bow".into()],
        counts: vec![
            vec![6.0, 2.0, 0.0],
            vec![1.0, 3.0, 0.0],
            vec![0.0, 0.0, 5.0],
        ],
        normalise_rows: true,
        size: (500, 500),
    };
    let svg = dir.path().join("confusion.svg");
    plot_confusion(&svg, &plot).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    // Row shares: walk 6/8, run 3/4.
    let cell = |v: &str| text.lines().any(|l| l.trim() == v);
    assert!(cell("0.75"), "the walk-walk cell");
    assert!(cell("0.25"), "the walk-run cell");
    assert!(cell("1.00"), "the bow-bow cell");
    let png = dir.path().join("confusion.png");
    plot_confusion(&png, &plot).unwrap();
    // The darkest cells (1.0) are dark blue.
    assert!(pixels_near(&png, [8, 48, 107]) > 1000);

    let mut bad = plot.clone();
    bad.counts[2].pop();
    assert!(plot_confusion(&png, &bad)
        .unwrap_err()
        .to_string()
        .contains("3 x 3"));
    bad = plot.clone();
    bad.counts[0][0] = -1.0;
    assert!(plot_confusion(&png, &bad)
        .unwrap_err()
        .to_string()
        .contains("negative"));
}
