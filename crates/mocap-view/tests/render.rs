//! Filmstrips and GIFs: the right frames, the figures on them in their
//! colours, side by side where asked, and clear errors.

use std::path::PathBuf;

use image::AnimationDecoder;
use mocap_core::rotation::Vec3;
use mocap_view::{render, FrameRange, Layout, RenderOptions, Scene, ViewMotion, PALETTE};

fn sample() -> PathBuf {
    mocap_testdata::sample_walk()
}

/// Pixels within 30 of `colour` on every channel, in the rectangle.
fn count_near(
    img: &image::RgbImage,
    colour: [u8; 3],
    x: std::ops::Range<u32>,
    y: std::ops::Range<u32>,
) -> usize {
    let mut n = 0;
    for yy in y {
        for xx in x.clone() {
            let p = img.get_pixel(xx, yy).0;
            if (0..3).all(|k| (p[k] as i32 - colour[k] as i32).abs() < 30) {
                n += 1;
            }
        }
    }
    n
}

/// Mean x of the pixels near `colour`.
fn mean_x(img: &image::RgbImage, colour: [u8; 3]) -> f32 {
    let (mut sum, mut n) = (0.0, 0.0);
    for (x, _, p) in img.enumerate_pixels() {
        if (0..3).all(|k| (p.0[k] as i32 - colour[k] as i32).abs() < 30) {
            sum += x as f32;
            n += 1.0;
        }
    }
    sum / n
}

#[test]
fn filmstrip_of_the_sample_shows_the_figure_in_every_panel() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("walk.png");
    let scene = Scene::from_files(&[sample()]).unwrap();
    let summary = render(&scene, &out, &RenderOptions::default()).unwrap();
    // 195 frames, about 8 panels: every 25th frame.
    assert_eq!(summary.frames, vec![0, 25, 50, 75, 100, 125, 150, 175]);
    let img = image::open(&out).unwrap().to_rgb8();
    assert_eq!((img.width(), img.height()), (summary.width, summary.height));
    assert_eq!(img.width(), 8 * 240);
    let colour = PALETTE[0];
    for k in 0..8 {
        let n = count_near(&img, colour, k * 240..(k + 1) * 240, 26..img.height());
        // A figure's bones and joints cover hundreds of pixels.
        assert!(n > 300, "panel {k}: {n} pixels of the motion's colour");
    }
}

#[test]
fn rows_show_each_motion_on_its_own_row_at_the_same_moments() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rows.png");
    let proud = mocap_testdata::sample("dataset-1_walk_proud_001.bvh");
    let scene = Scene::from_files(&[sample(), proud]).unwrap();
    let options = RenderOptions {
        layout: Layout::Rows,
        columns: 4,
        ..RenderOptions::default()
    };
    let summary = render(&scene, &out, &options).unwrap();
    // Four moments over the shorter take, on the first take's clock.
    assert_eq!(summary.frames.len(), 4);
    assert_eq!(summary.frames[0], 0);
    assert_eq!((summary.width, summary.height), (4 * 240, 26 + 2 * 320));
    let img = image::open(&out).unwrap().to_rgb8();
    for (row, colour) in PALETTE.iter().take(2).enumerate() {
        let rows = 26 + row as u32 * 320..26 + (row as u32 + 1) * 320;
        for k in 0..4 {
            let n = count_near(&img, *colour, k * 240..(k + 1) * 240, rows.clone());
            assert!(n > 300, "row {row}, panel {k}: {n} pixels of its colour");
        }
        // The other motion's colour is not on this row.
        let other = PALETTE[1 - row];
        assert!(count_near(&img, other, 0..img.width(), rows.clone()) < 50);
    }
}

#[test]
fn frames_and_every_pick_the_panels() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Scene::from_files(&[sample()]).unwrap();
    let options = RenderOptions {
        frames: Some(FrameRange::new(10..21)),
        every: Some(5),
        ..RenderOptions::default()
    };
    let summary = render(&scene, &dir.path().join("a.png"), &options).unwrap();
    assert_eq!(summary.frames, vec![10, 15, 20]);
    assert_eq!(summary.width, 3 * 240);

    let parse = |t: &str| t.parse::<FrameRange>();
    assert_eq!(parse("10..").unwrap().resolve(195), 10..195);
    assert_eq!(parse("..5").unwrap().resolve(195), 0..5);
    assert_eq!(parse("3..7").unwrap(), FrameRange::new(3..7));
    // An open end runs to the end of the take.
    let options = RenderOptions {
        frames: Some(parse("190..").unwrap()),
        every: Some(2),
        ..RenderOptions::default()
    };
    let summary = render(&scene, &dir.path().join("b.png"), &options).unwrap();
    assert_eq!(summary.frames, vec![190, 192, 194]);
    for bad in ["10", "a..b", "5..5", "9..3"] {
        let e = parse(bad).unwrap_err().to_string();
        assert!(e.contains(bad), "{e}");
    }
}

#[test]
fn bad_requests_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Scene::from_files(&[sample()]).unwrap();
    let render_with = |name: &str, options: RenderOptions| {
        render(&scene, &dir.path().join(name), &options)
            .unwrap_err()
            .to_string()
    };
    assert!(render_with("a.jpg", RenderOptions::default()).contains(".png (filmstrip) or .gif"));
    let e = render_with(
        "a.png",
        RenderOptions {
            frames: Some(FrameRange::new(100..300)),
            ..RenderOptions::default()
        },
    );
    assert!(e.contains("100..300") && e.contains("0..195"), "{e}");
    let e = render_with(
        "a.png",
        RenderOptions {
            every: Some(0),
            ..RenderOptions::default()
        },
    );
    assert!(e.contains("--every"), "{e}");
    let e = render_with(
        "a.png",
        RenderOptions {
            every: Some(1),
            ..RenderOptions::default()
        },
    );
    assert!(
        e.contains("195 frames") && e.contains("raise --every"),
        "{e}"
    );
    assert!(
        !dir.path().join("a.png").exists(),
        "nothing written on error"
    );
}

#[test]
fn gif_has_the_frames_at_the_takes_speed() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("walk.gif");
    let scene = Scene::from_files(&[sample()]).unwrap();
    let options = RenderOptions {
        frames: Some(FrameRange::new(0..30)),
        panel_size: Some((160, 120)),
        ..RenderOptions::default()
    };
    let summary = render(&scene, &out, &options).unwrap();
    assert_eq!(summary.frames.len(), 30);
    let decoder = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
        std::fs::File::open(&out).unwrap(),
    ))
    .unwrap();
    let frames = decoder.into_frames().collect_frames().unwrap();
    assert_eq!(frames.len(), 30);
    // 30 frames at 30 fps last one second; GIF delays are in hundredths.
    let total_ms: u32 = frames
        .iter()
        .map(|f| {
            let (n, d) = f.delay().numer_denom_ms();
            n / d
        })
        .sum();
    assert!((990..=1010).contains(&total_ms), "{total_ms} ms");
    // The figure moves: the first and last pictures differ.
    assert_ne!(frames[0].buffer(), frames[29].buffer());
    let first = image::DynamicImage::ImageRgba8(frames[0].buffer().clone()).to_rgb8();
    assert!(count_near(&first, PALETTE[0], 0..160, 0..120) > 50);
}

#[test]
fn side_by_side_puts_the_second_motion_to_the_right() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("side.png");
    let scene = Scene::from_files(&[sample(), sample()]).unwrap();
    let options = RenderOptions {
        frames: Some(FrameRange::new(0..1)),
        layout: Layout::SideBySide,
        panel_size: Some((480, 320)),
        ..RenderOptions::default()
    };
    render(&scene, &out, &options).unwrap();
    let img = image::open(&out).unwrap().to_rgb8();
    let (a, b) = (PALETTE[0], PALETTE[1]);
    // Below the legend, where both swatches sit.
    let body = image::imageops::crop_imm(&img, 0, 26, img.width(), img.height() - 26).to_image();
    assert!(count_near(&body, a, 0..480, 0..294) > 200);
    assert!(count_near(&body, b, 0..480, 0..294) > 200);
    assert!(
        mean_x(&body, b) > mean_x(&body, a) + 60.0,
        "{} vs {}",
        mean_x(&body, a),
        mean_x(&body, b)
    );
}

#[test]
fn confidence_colours_the_joints() {
    // A two-joint "arm" held still, seen with no confidence at all: drawn
    // red, not in the motion's colour.
    let positions = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.4, 1.5, 0.0),
    ]
    .repeat(3);
    let names = vec!["hip".into(), "shoulder".into(), "hand".into()];
    let motion = ViewMotion::from_positions(
        "fused",
        names,
        vec![None, Some(0), Some(1)],
        0.1,
        positions,
        Some(1.0),
    )
    .unwrap()
    .with_confidence(vec![0.0; 9])
    .unwrap();
    let scene = Scene::new(vec![motion]);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c.png");
    let options = RenderOptions {
        panel_size: Some((200, 200)),
        ..RenderOptions::default()
    };
    render(&scene, &out, &options).unwrap();
    let img = image::open(&out).unwrap().to_rgb8();
    let body = image::imageops::crop_imm(&img, 0, 26, img.width(), 200).to_image();
    let red = mocap_view::confidence_colour(0.0);
    assert!(red[0] > 180 && red[1] < 60 && red[2] < 60, "{red:?}");
    assert!(count_near(&body, red, 0..body.width(), 0..200) > 100);
    assert_eq!(count_near(&body, PALETTE[0], 0..body.width(), 0..200), 0);
    let green = mocap_view::confidence_colour(1.0);
    assert!(green[1] > 150 && green[0] < 60, "{green:?}");
}
