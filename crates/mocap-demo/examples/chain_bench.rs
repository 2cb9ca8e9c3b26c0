//! The demo's chain (fuse → clean → feet → search → style) on held-out
//! Bandai takes: each stage's error against the take itself and its time.
//!
//! `cargo run --release -p mocap-demo --example chain_bench -- DIR [MAX_TAKES]`
//! (`bench/chain.sh` writes `bench/results/chain.md` with it).
//!
//! The takes are those of `DIR` (Bandai dataset-1: not in the search
//! library, which is dataset-2) in the shipped denoiser's test split
//! (`mocap_clean::Split::Test`: never seen in its training), so neither the
//! denoiser nor the search has seen them. The style model was trained on
//! Bandai walks of both datasets; its numbers here are times only.
//! Markdown on standard output.

use std::path::PathBuf;

use mocap_clean::{list_bvh, paths_in_split, Split, SplitFractions};
use mocap_demo::{run_demo, DemoOptions, DemoReport, StageStatus};

/// What one take gave, `None` where a stage did not run.
struct Row {
    take: String,
    seconds: f64,
    values: Vec<Option<f64>>,
    predicted: String,
}

/// The columns: (stage, number, heading).
const COLUMNS: &[(&str, &str, &str)] = &[
    ("fuse", "mpjpe_mm", "fused joints, Kinect layout (mm)"),
    ("clean", "position_error_fused_mm", "fused on rig (mm)"),
    ("clean", "position_error_filtered_mm", "Butterworth (mm)"),
    ("clean", "position_error_cleaned_mm", "denoiser (mm)"),
    ("clean", "jitter_sample", "jitter: take"),
    ("clean", "jitter_fused", "fused"),
    ("clean", "jitter_filtered", "Butterworth"),
    ("clean", "jitter_cleaned", "denoiser"),
    ("feet", "sliding_sample_cm_s", "sliding (cm/s): take"),
    ("feet", "sliding_before_cm_s", "before feet"),
    ("feet", "sliding_after_cm_s", "after feet"),
    ("feet", "jitter_after", "jitter after feet"),
    (
        "style",
        "source_reconstruction_deg",
        "style model's error on the take (deg)",
    ),
];

/// Stage times (s).
const STAGES: &[&str] = &["fuse", "clean", "feet", "search", "style"];

fn value(report: &DemoReport, stage: &str, name: &str) -> Option<f64> {
    report
        .stage(stage)
        .filter(|s| s.status == StageStatus::Ran)
        .and_then(|s| s.value(name))
}

/// A value of column `c`: times to the hundredth of a second, the rest to
/// one decimal.
fn cell(c: usize, v: f64) -> String {
    if c >= COLUMNS.len() {
        format!("{v:.2}")
    } else {
        format!("{v:.1}")
    }
}

fn mean(c: usize, values: impl Iterator<Item = Option<f64>>) -> String {
    let (sum, n) = values
        .flatten()
        .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 {
        "-".into()
    } else {
        cell(c, sum / n as f64)
    }
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let dir = PathBuf::from(args.next().ok_or_else(|| {
        anyhow::anyhow!("usage: chain_bench DIR [MAX_TAKES] (a folder of Bandai takes)")
    })?);
    let max_takes: usize = args.next().map_or(Ok(usize::MAX), |a| a.parse())?;
    let takes = paths_in_split(&list_bvh(&[dir])?, Split::Test, &SplitFractions::default());
    let work = tempfile::tempdir()?;
    let mut rows = Vec::new();
    for (i, take) in takes.iter().take(max_takes).enumerate() {
        let name = take
            .file_stem()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        eprintln!("[{}/{}] {name}", i + 1, takes.len().min(max_takes));
        let options = DemoOptions {
            out: work.path().join(&name),
            sample: take.clone(),
            pictures: false,
            ..DemoOptions::default()
        };
        let report = run_demo(&options)?;
        for stage in &report.stages {
            if stage.status != StageStatus::Ran {
                eprintln!(
                    "  {}: {} ({})",
                    stage.name,
                    stage.status.label(),
                    stage.message.as_deref().unwrap_or("")
                );
            }
        }
        let mut values: Vec<Option<f64>> = COLUMNS
            .iter()
            .map(|(stage, number, _)| value(&report, stage, number))
            .collect();
        values.extend(
            STAGES
                .iter()
                .map(|s| report.stage(s).map(|stage| stage.seconds)),
        );
        values.push(value(&report, "fuse", "send_seconds"));
        values.push(value(&report, "clean", "clean_seconds"));
        let predicted = report
            .stage("search")
            .and_then(|s| s.facts.iter().find(|(k, _)| k == "predicted"))
            .map_or_else(|| "-".to_string(), |(_, v)| v.clone());
        let seconds = mocap_core::io::bvh::read_bvh(take)?.duration();
        rows.push(Row {
            take: name,
            seconds,
            values,
            predicted,
        });
    }

    let headings: Vec<String> = COLUMNS
        .iter()
        .map(|(_, _, h)| h.to_string())
        .chain(STAGES.iter().map(|s| format!("{s} (s)")))
        .chain([
            "of fuse: UDP replay (s)".to_string(),
            "of clean: the network (s)".to_string(),
        ])
        .collect();
    println!(
        "| take | length (s) | {} | search says |",
        headings.join(" | ")
    );
    println!("|{}", " --- |".repeat(headings.len() + 3));
    for row in &rows {
        let cells: Vec<String> = row
            .values
            .iter()
            .enumerate()
            .map(|(c, v)| v.map_or("-".into(), |v| cell(c, v)))
            .collect();
        println!(
            "| {} | {:.1} | {} | {} |",
            row.take,
            row.seconds,
            cells.join(" | "),
            row.predicted
        );
    }
    let means: Vec<String> = (0..headings.len())
        .map(|c| mean(c, rows.iter().map(|r| r.values[c])))
        .collect();
    println!(
        "| **mean of {} takes** | {} | {} | |",
        rows.len(),
        mean(0, rows.iter().map(|r| Some(r.seconds))),
        means.join(" | ")
    );
    Ok(())
}
