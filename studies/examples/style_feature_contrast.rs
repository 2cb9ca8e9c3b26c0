//! Which of mocap-search's per-frame pose values tell two contents apart, and
//! where some other clips (restyled outputs, say) sit between them: used to
//! see why restyled turns are read as straight walks (bench/results/style.md,
//! "Both folds").
//!
//! ```text
//! cargo run --release -p mocap-studies --example style_feature_contrast -- \
//!     DIR CONTENT_A CONTENT_B FILE... [--top 12]
//! ```
//!
//! Every clip of `DIR` whose labels say `CONTENT_A` or `CONTENT_B` gives the
//! mean and the deviation over its frames of each of the judges' pose values
//! (`mocap_style::clip_pose_statistics`). A
//! value's separation is the difference of the two contents' averages over
//! their clips, in units of the pooled spread between clips; the values that
//! separate most are printed with the average of `FILE...` placed on the
//! scale from `CONTENT_B` (0) to `CONTENT_A` (1).

use std::path::{Path, PathBuf};

use mocap_core::io::read_motion;
use mocap_search::VALUE_NAMES;
use mocap_style::{clip_pose_statistics, labelled_paths, list_bvh, ClipFilter};

/// Per clip: the mean, then the deviation, of every pose value over its frames.
fn clip_statistics(path: &Path) -> Vec<f64> {
    let motion = read_motion(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    clip_pose_statistics(&motion)
        .expect("pose values")
        .into_iter()
        .map(f64::from)
        .collect()
}

/// Average and spread over clips of statistic `k`.
fn average(clips: &[Vec<f64>], k: usize) -> (f64, f64) {
    let n = clips.len() as f64;
    let mean = clips.iter().map(|c| c[k]).sum::<f64>() / n;
    let spread = (clips.iter().map(|c| (c[k] - mean).powi(2)).sum::<f64>() / n).sqrt();
    (mean, spread)
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut top = 12;
    if let Some(i) = args.iter().position(|a| a == "--top") {
        top = args[i + 1].parse().expect("--top N");
        args.drain(i..i + 2);
    }
    let [dir, a, b, files @ ..] = args.as_slice() else {
        eprintln!("usage: style_feature_contrast DIR CONTENT_A CONTENT_B FILE... [--top N]");
        std::process::exit(2);
    };
    let labelled = labelled_paths(
        &list_bvh(&[PathBuf::from(dir)]).expect("a folder of clips"),
        &ClipFilter::default(),
    )
    .expect("labelled clips");
    let of = |content: &str| -> Vec<Vec<f64>> {
        labelled
            .iter()
            .filter(|(_, l)| l.content == content)
            .map(|(p, _)| clip_statistics(p))
            .collect()
    };
    let (clips_a, clips_b) = (of(a), of(b));
    let others: Vec<Vec<f64>> = files
        .iter()
        .map(|f| clip_statistics(Path::new(f)))
        .collect();
    assert!(
        !clips_a.is_empty() && !clips_b.is_empty() && !others.is_empty(),
        "no clips"
    );
    // Means first, then deviations, of the pose values.
    let pose_values = clips_a[0].len() / 2;
    let mut rows: Vec<(f64, String)> = (0..2 * pose_values)
        .map(|k| {
            let (mean_a, spread_a) = average(&clips_a, k);
            let (mean_b, spread_b) = average(&clips_b, k);
            let (mean_o, _) = average(&others, k);
            let pooled = ((spread_a.powi(2) + spread_b.powi(2)) / 2.0).sqrt().max(1e-12);
            let separation = (mean_a - mean_b) / pooled;
            let place = (mean_o - mean_b) / (mean_a - mean_b);
            let what = if k < pose_values { "mean" } else { "deviation" };
            let name = VALUE_NAMES[k % pose_values];
            (
                separation.abs(),
                format!(
                    "| {name} | {what} | {separation:+.2} | {mean_a:.3} | {mean_b:.3} | {mean_o:.3} | {place:+.2} |"
                ),
            )
        })
        .collect();
    rows.sort_by(|x, y| y.0.total_cmp(&x.0));
    println!(
        "{a}: {} clips, {b}: {} clips, files: {}\n",
        clips_a.len(),
        clips_b.len(),
        others.len()
    );
    println!(
        "| value | over frames | separation | {a} | {b} | files | files on {b} (0) to {a} (1) |"
    );
    println!("| --- | --- | ---: | ---: | ---: | ---: | ---: |");
    for (_, row) in rows.iter().take(top) {
        println!("{row}");
    }
}
