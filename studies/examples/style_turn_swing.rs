//! Does a restyled turn keep the sideways swing of its feet within each
//! stride, or only where they are placed on average? (bench/results/style.md,
//! "Turns kept along the take".)
//!
//! ```text
//! cargo run --release -p mocap-studies --example style_turn_swing -- DIR STYLE_CLIP TURN...
//! ```
//!
//! For every clip, each ankle's sideways offset from the pelvis in the body
//! frame (mocap-search's pose values `left_ankle.x`, `right_ankle.x`, body
//! heights) is split in two: its mean over two of the clip's strides around
//! each frame (`mocap_style::windowed_mean`, the Hann window the asymmetry is
//! averaged over), which follows the clip as it walks in, turns and walks
//! out; and the rest, the swing within each stride. The table gives the
//! standard deviation of each part over the clip's frames, averaged over
//! clips, for the real straight walks and right turns of `DIR`, for the
//! `TURN` clips and for them restyled with `STYLE_CLIP` under each
//! asymmetry setting.

use std::path::PathBuf;

use mocap_core::io::read_motion;
use mocap_core::Motion;
use mocap_nn::device::DeviceChoice;
use mocap_search::{motion_features, VALUE_NAMES};
use mocap_style::{
    gait_period, labelled_paths, list_bvh, load_model, prepare_style, restyle, windowed_mean,
    Asymmetry, ClipFilter, ConvertOptions, RigLayout, StageTimings,
};

/// Where the left and the right ankle's sideways offsets from the pelvis
/// (body frame, body heights) are among mocap-search's per-frame pose values.
fn sideways_ankle_values() -> [usize; 2] {
    ["left_ankle.x", "right_ankle.x"].map(|name| {
        VALUE_NAMES
            .iter()
            .position(|n| *n == name)
            .expect("a pose value of mocap-search")
    })
}

/// (slow, swing) standard deviations of the left and right ankles' sideways
/// offsets; `None` for a clip without a gait.
fn slow_and_swing(motion: &Motion) -> Option<[[f64; 2]; 2]> {
    let rig = RigLayout::from_skeleton(motion.skeleton()).ok()?;
    let stride = gait_period(motion, &rig)?;
    let window = (2.0 * stride * motion.fps()).round() as usize;
    let features = motion_features(motion).expect("pose values");
    let ankles = sideways_ankle_values();
    let frames = features.values.len() / features.dim;
    let series: Vec<f64> = (0..frames)
        .flat_map(|f| ankles.map(|a| features.values[f * features.dim + a] as f64))
        .collect();
    let slow = windowed_mean(&series, 2, Some(window));
    let deviation = |x: &mut dyn Iterator<Item = f64>| {
        let x: Vec<f64> = x.collect();
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / x.len() as f64).sqrt()
    };
    let mut out = [[0.0; 2]; 2];
    for (k, row) in out.iter_mut().enumerate() {
        row[0] = deviation(&mut (0..frames).map(|f| slow[2 * f + k] as f64));
        row[1] = deviation(&mut (0..frames).map(|f| series[2 * f + k] - slow[2 * f + k] as f64));
    }
    Some(out)
}

/// One table row: the mean over `motions` of [`slow_and_swing`].
fn row(name: &str, motions: &[Motion]) {
    let all: Vec<_> = motions.iter().filter_map(slow_and_swing).collect();
    let n = all.len().max(1) as f64;
    let mean = |k: usize, part: usize| all.iter().map(|s| s[k][part]).sum::<f64>() / n;
    println!(
        "| {name} | {} | {:.4} / {:.4} | {:.4} / {:.4} |",
        all.len(),
        mean(0, 0),
        mean(1, 0),
        mean(0, 1),
        mean(1, 1)
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [dir, style, turns @ ..] = args.as_slice() else {
        eprintln!("usage: style_turn_swing DIR STYLE_CLIP TURN...");
        std::process::exit(2);
    };
    let read =
        |p: &str| read_motion(std::path::Path::new(p)).unwrap_or_else(|e| panic!("{p}: {e}"));
    let labelled = labelled_paths(
        &list_bvh(&[PathBuf::from(dir)]).expect("a folder of clips"),
        &ClipFilter::default(),
    )
    .expect("labelled clips");
    let of = |content: &str| -> Vec<Motion> {
        labelled
            .iter()
            .filter(|(_, l)| l.content == content)
            .map(|(p, _)| read(&p.to_string_lossy()))
            .collect()
    };
    let sources: Vec<Motion> = turns.iter().map(|p| read(p)).collect();
    let model = load_model(None, DeviceChoice::Cpu).expect("the shipped model");
    let mut t = StageTimings::default();
    let clip = prepare_style(&model, &read(style), "style", &mut t).expect("style clip");

    println!(
        "Sideways offset of the ankles from the pelvis (body heights), left / right: standard \
         deviation over a clip's frames of its mean over two strides (slow) and of the rest \
         (swing within a stride), averaged over clips.\n"
    );
    println!("| clips | n | slow, left / right | swing, left / right |");
    println!("| --- | --- | --- | --- |");
    row("real straight walks", &of("walk"));
    row("real right turns", &of("walk-turn-right"));
    row("the turns restyled (sources)", &sources);
    for asymmetry in Asymmetry::ALL {
        let options = ConvertOptions {
            asymmetry,
            ..ConvertOptions::default()
        };
        let outputs: Vec<Motion> = sources
            .iter()
            .map(|s| {
                restyle(
                    &model,
                    s,
                    &[(&clip, 1.0)],
                    &options,
                    StageTimings::default(),
                )
                .expect("restyle")
                .motion
            })
            .collect();
        row(
            &format!("outputs, asymmetry {}", asymmetry.name()),
            &outputs,
        );
    }
}
