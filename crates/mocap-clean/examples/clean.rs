//! Cleans one BVH take: the library call behind `mocap clean apply IN -o OUT`.
//!
//! cargo run --release -p mocap-clean --example clean -- IN.bvh OUT.bvh \
//!     [--model FILE.safetensors | --filter butterworth:2:6 | savitzky-golay:9:2 | median:9 | one-euro:1:0.05:1] \
//!     [--device cpu|cuda] [--hop N]

use std::path::PathBuf;

use mocap_clean::{clean_file, CleanOptions, Filter, Method};

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
        despike: None,
        root_filter: None,
        feet: None,
    };
    let mut i = 2;
    while i < args.len() {
        let value = args
            .get(i + 1)
            .ok_or(format!("{} needs a value", args[i]))?;
        match args[i].as_str() {
            "--model" => options.method = Method::Model(PathBuf::from(value)),
            "--filter" => options.method = Method::Filter(value.parse::<Filter>()?),
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
