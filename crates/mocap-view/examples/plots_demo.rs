//! Writes example plots to the folder given (default: current folder), to
//! look at: a rotation track, per-joint error bars, a confusion matrix.
use mocap_view::{
    plot_bars, plot_confusion, plot_lines, BarPlot, BarSeries, ConfusionPlot, LinePlot, Series,
};
fn main() {
    let dir = std::path::PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| ".".into()));
    let truth: Vec<f32> = (0..120).map(|i| 30.0 * (i as f32 * 0.08).sin()).collect();
    let noisy: Vec<f32> = truth
        .iter()
        .enumerate()
        .map(|(i, v)| v + ((i * 7919) % 13) as f32 - 6.0)
        .collect();
    let lines = LinePlot::new("example: a joint's rotation", "frame", "degrees")
        .with_series(Series::sampled("noisy", 0.0, 1.0, &noisy))
        .with_series(Series::sampled("truth", 0.0, 1.0, &truth));
    plot_lines(&dir.join("lines.png"), &lines).unwrap();
    let cats: Vec<String> = [
        "Hips",
        "Spine",
        "Chest",
        "Neck",
        "Head",
        "Shoulder_L",
        "UpperArm_L",
        "LowerArm_L",
        "Hand_L",
        "UpperLeg_L",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let bars = BarPlot {
        title: "example: per-joint error".into(),
        y_label: "mm".into(),
        categories: cats,
        series: vec![
            BarSeries {
                label: "a".into(),
                values: (0..10).map(|i| 10.0 + i as f32).collect(),
                errors: Some(vec![3.0; 10]),
            },
            BarSeries {
                label: "b".into(),
                values: (0..10).map(|i| 5.0 + 0.5 * i as f32).collect(),
                errors: Some(vec![1.0; 10]),
            },
        ],
        size: (900, 500),
    };
    plot_bars(&dir.join("bars.png"), &bars).unwrap();
    let conf = ConfusionPlot {
        title: "example: confusion".into(),
        labels: vec!["walk".into(), "run".into(), "bow".into()],
        counts: vec![
            vec![6.0, 2.0, 0.0],
            vec![1.0, 3.0, 0.0],
            vec![0.0, 0.0, 5.0],
        ],
        normalise_rows: true,
        size: (500, 500),
    };
    plot_confusion(&dir.join("confusion.png"), &conf).unwrap();
    plot_confusion(&dir.join("confusion.svg"), &conf).unwrap();
}
