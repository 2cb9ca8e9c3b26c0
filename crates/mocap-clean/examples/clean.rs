//! Cleans one BVH take; stands in for `mocap clean IN -o OUT`.
//!
//! cargo run --release -p mocap-clean --example clean -- IN.bvh OUT.bvh \
//!     [--model FILE.safetensors | --filter butterworth:2:6 | savitzky-golay:9:2 | median:9 | one-euro:1:0.05:1] \
//!     [--device cpu|cuda] [--hop N]

use std::path::PathBuf;

use mocap_clean::filters::Filter;
use mocap_clean::infer::{clean_file, CleanOptions, Method};

fn parse_filter(text: &str) -> Result<Filter, String> {
    let parts: Vec<&str> = text.split(':').collect();
    let num = |k: usize| -> Result<f32, String> {
        parts
            .get(k)
            .ok_or(format!("{text}: missing setting {k}"))?
            .parse::<f32>()
            .map_err(|e| e.to_string())
    };
    Ok(match parts[0] {
        "butterworth" => Filter::Butterworth {
            order: num(1)? as usize,
            cutoff_hz: num(2)?,
        },
        "savitzky-golay" => Filter::SavitzkyGolay {
            window: num(1)? as usize,
            polyorder: num(2)? as usize,
        },
        "median" => Filter::Median {
            window: num(1)? as usize,
        },
        "one-euro" => Filter::OneEuro {
            min_cutoff_hz: num(1)?,
            beta: num(2)?,
            d_cutoff_hz: num(3)?,
        },
        other => return Err(format!("unknown filter {other}")),
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        return Err(
            "usage: clean IN.bvh OUT.bvh [--model FILE | --filter SPEC] [--device D] [--hop N]"
                .into(),
        );
    }
    let mut options = CleanOptions {
        input: PathBuf::from(&args[0]),
        output: PathBuf::from(&args[1]),
        method: Method::DefaultModel,
        device: Default::default(),
        hop: None,
    };
    let mut i = 2;
    while i < args.len() {
        let value = args
            .get(i + 1)
            .ok_or(format!("{} needs a value", args[i]))?;
        match args[i].as_str() {
            "--model" => options.method = Method::Model(PathBuf::from(value)),
            "--filter" => options.method = Method::Filter(parse_filter(value)?),
            "--device" => options.device = value.parse()?,
            "--hop" => options.hop = Some(value.parse()?),
            other => return Err(format!("unknown option {other}").into()),
        }
        i += 2;
    }
    let report = clean_file(&options)?;
    println!("{}", serde_json::to_string_pretty(&report)?);
    Ok(())
}
