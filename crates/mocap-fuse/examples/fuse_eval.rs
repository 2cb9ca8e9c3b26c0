//! The evaluation of `mocap fuse eval` on BVH takes, as an example of this
//! crate alone (it builds in a fraction of the time the whole CLI takes):
//!
//! ```text
//! cargo run --release -p mocap-fuse --example fuse_eval -- [--sensors 2,3,4] [--seeds 1,2,3]
//!     [--calib truth|body] [--limits SKELETON.asf] [--json OUT.json] [--md OUT.md] BVH_OR_FOLDER...
//! ```

use std::path::PathBuf;

use mocap_fuse::eval::{evaluate, report_markdown, CalibrationSource, EvalOptions};

fn list<T: std::str::FromStr>(s: &str) -> Vec<T> {
    s.split(',').filter_map(|x| x.trim().parse().ok()).collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut options = EvalOptions::default();
    let (mut json, mut md) = (None, None);
    let mut i = 0;
    while i < args.len() {
        let next = || args.get(i + 1).cloned().ok_or("missing value");
        match args[i].as_str() {
            "--sensors" => options.sensor_counts = list(&next()?),
            "--seeds" => options.seeds = list(&next()?),
            "--calib" => {
                options.calibration = match next()?.as_str() {
                    "truth" => CalibrationSource::Truth,
                    "body" => CalibrationSource::Body,
                    other => return Err(format!("--calib truth|body, not {other}").into()),
                }
            }
            "--limits" => {
                let skeleton = mocap_core::io::asf_amc::read_asf(next()?)?
                    .to_skeleton(mocap_core::io::asf_amc::LengthUnit::Centimetres)?;
                options.limit_ranges = Some(mocap_fuse::body::ranges_from_limits(&skeleton)?);
            }
            "--json" => json = Some(PathBuf::from(next()?)),
            "--md" => md = Some(PathBuf::from(next()?)),
            a => {
                options.inputs.push(PathBuf::from(a));
                i += 1;
                continue;
            }
        }
        i += 2;
    }
    let command = format!("fuse_eval {}", args.join(" "));
    let report = evaluate(&options)?;
    let text = report_markdown(&report, &command);
    println!("{text}");
    if let Some(p) = json {
        std::fs::write(p, serde_json::to_string_pretty(&report)?)?;
    }
    if let Some(p) = md {
        std::fs::write(p, text)?;
    }
    Ok(())
}
