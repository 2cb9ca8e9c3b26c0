//! Runs the search evaluation end to end, as `mocap search eval` does, and
//! prints the Markdown report (or JSON with `--json`).
//!
//! ```text
//! cargo run --release -p mocap-studies --example search_eval -- \
//!     --labels-from-name bandai-content --folds 5 ../shared/data/bandai/dataset-2
//! ```
//!
//! Options: `--labels-from-name PATTERN` or `--labels FILE`; `--folds K`
//! (default 5) or `--by-performer` or `--test DIR` (the positional folders
//! are then the training clips); `--trees T`, `--candidates K`,
//! `--min-entropy E`, `--frames N`, `--seed S`; `--min-clips-for-average M`
//! (the second macro average, over classes with at least M clips; default
//! 10); `--no-baselines`,
//! `--no-unseen`, `--no-takes`; `--name NAME` (the data's name in the
//! report); `--json`; `--output FILE` writes the report there too (atomically).

use std::path::PathBuf;
use std::process::ExitCode;

use mocap_search::{evaluate_files, EvalConfig, LabelFile, LabelRule, NamePattern, SplitRule};

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut dirs = Vec::new();
    let mut test_dirs = Vec::new();
    let mut rule: Option<(LabelRule, String)> = None;
    let mut config = EvalConfig {
        progress: true,
        ..EvalConfig::default()
    };
    let mut json = false;
    let mut name: Option<String> = None;
    let mut out: Option<PathBuf> = None;
    let value = |args: &mut dyn Iterator<Item = String>, flag: &str| {
        args.next().ok_or_else(|| format!("{flag} needs a value"))
    };
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--labels-from-name" => {
                let p = value(&mut args, &arg)?;
                rule = Some((LabelRule::FromName(NamePattern::parse(&p)?), p));
            }
            "--labels" => {
                let p = value(&mut args, &arg)?;
                rule = Some((LabelRule::FromFile(LabelFile::read(p.as_ref())?), p));
            }
            "--folds" => {
                config.split = SplitRule::Folds {
                    k: value(&mut args, &arg)?.parse()?,
                }
            }
            "--by-performer" => config.split = SplitRule::ByPerformer,
            "--test" => test_dirs.push(PathBuf::from(value(&mut args, &arg)?)),
            "--trees" => config.index.forest.trees = value(&mut args, &arg)?.parse()?,
            "--candidates" => {
                config.index.forest.tree.candidates_per_node =
                    Some(value(&mut args, &arg)?.parse()?)
            }
            "--min-entropy" => {
                config.index.forest.tree.min_entropy = value(&mut args, &arg)?.parse()?
            }
            "--frames" => config.index.frames = value(&mut args, &arg)?.parse()?,
            "--seed" => config.seed = value(&mut args, &arg)?.parse()?,
            "--min-clips-for-average" => {
                config.min_clips_for_average = value(&mut args, &arg)?.parse()?
            }
            "--no-bootstrap" => config.index.forest.bootstrap = false,
            "--no-baselines" => config.baselines = false,
            "--no-unseen" => config.unseen_classes = false,
            "--no-takes" => config.takes = false,
            "--name" => name = Some(value(&mut args, &arg)?),
            "--json" => json = true,
            "--output" => out = Some(PathBuf::from(value(&mut args, &arg)?)),
            flag if flag.starts_with("--") => return Err(format!("unknown option {flag}").into()),
            dir => dirs.push(PathBuf::from(dir)),
        }
    }
    let (rule, rule_name) = rule.ok_or("give --labels-from-name PATTERN or --labels FILE")?;
    if dirs.is_empty() {
        return Err("give at least one folder of clips".into());
    }
    let report = evaluate_files(
        &dirs,
        &test_dirs,
        &rule,
        &rule_name,
        name.as_deref(),
        &config,
    )?;
    let text = if json {
        serde_json::to_string_pretty(&report)?
    } else {
        report.to_markdown()
    };
    println!("{text}");
    if let Some(path) = out {
        mocap_core::io::atomic::write_bytes_atomically(&path, text.as_bytes())?;
    }
    Ok(())
}
