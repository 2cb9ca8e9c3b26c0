//! Evaluates methods on held-out takes: the library call behind `mocap clean eval`.
//!
//! cargo run --release -p mocap-clean --example clean_eval -- --data ../shared/data/bandai \
//!     [--model LABEL=FILE (LABEL without "=")]... [--no-default-model] [--no-filters] [--all-takes] \
//!     [--max-takes N] [--tune-takes N] [--spike-lengths 2,4,8,16,32,64] [--seed S] [--max-sigma DEG] [--noise-above-pelvis] [--despike] \
//!     [--json OUT.json] [--markdown OUT.md]

use std::path::PathBuf;

use mocap_clean::{evaluate, EvalOptions, ModelEntry};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut o = EvalOptions::default();
    let (mut json, mut markdown) = (None, None);
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    while i < args.len() {
        let value = || {
            args.get(i + 1)
                .cloned()
                .ok_or(format!("{} needs a value", args[i]))
        };
        let mut takes_value = true;
        match args[i].as_str() {
            "--data" => o.inputs.push(PathBuf::from(value()?)),
            "--model" => {
                let v = value()?;
                let (label, path) = v.split_once('=').unwrap_or((v.as_str(), v.as_str()));
                o.models.push(ModelEntry {
                    label: label.into(),
                    path: Some(PathBuf::from(path)),
                });
            }
            "--max-takes" => o.max_takes = Some(value()?.parse()?),
            "--tune-takes" => o.tune_takes = value()?.parse()?,
            "--seed" => o.seed = value()?.parse()?,
            "--max-sigma" => o.random.max_sigma_deg = value()?.parse()?,
            "--device" => o.device = value()?.parse()?,
            "--spike-lengths" => {
                o.spike_lengths = value()?
                    .split(',')
                    .filter(|s| !s.is_empty())
                    .map(str::parse)
                    .collect::<Result<_, _>>()?
            }
            "--json" => json = Some(PathBuf::from(value()?)),
            "--markdown" => markdown = Some(PathBuf::from(value()?)),
            flag => {
                takes_value = false;
                match flag {
                    "--no-default-model" => o.models.retain(|m| m.path.is_some()),
                    "--no-filters" => o.filters = false,
                    "--all-takes" => o.test_split_only = false,
                    "--noise-above-pelvis" => o.random.perturb_above_pelvis = true,
                    "--despike" => o.despike = true,
                    other => return Err(format!("unknown option {other}").into()),
                }
            }
        }
        i += if takes_value { 2 } else { 1 };
    }
    if o.inputs.is_empty() {
        return Err("--data FOLDER is required".into());
    }
    let report = evaluate(&o)?;
    if let Some(p) = json {
        mocap_core::io::atomic::write_bytes_atomically(
            &p,
            serde_json::to_string_pretty(&report)?.as_bytes(),
        )?;
    }
    let md = report.to_markdown();
    if let Some(p) = markdown {
        mocap_core::io::atomic::write_bytes_atomically(&p, md.as_bytes())?;
    }
    println!("{md}");
    Ok(())
}
