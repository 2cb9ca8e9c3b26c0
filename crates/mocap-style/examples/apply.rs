//! Restyles a clip: the library call behind `mocap style apply`.
//!
//! ```text
//! cargo run --release -p mocap-style --example apply -- SOURCE --style STYLE_CLIP -o out.bvh \
//!     [--model M.safetensors] [--strength 0.7] [--method fixed-patches] \
//!     [--fade-in 2] [--blend OTHER_STYLE_CLIP:0.5] [--patch 32]
//! ```

use std::path::PathBuf;

use mocap_style::{apply, parse_blend, ApplyOptions};

fn main() {
    let mut options = ApplyOptions::new("", "", "out.bvh");
    let mut args = std::env::args().skip(1);
    let result = (|| -> mocap_style::Result<_> {
        while let Some(a) = args.next() {
            let mut value = || args.next().unwrap_or_else(|| panic!("{a} needs a value"));
            match a.as_str() {
                "-o" | "--output" => options.out = PathBuf::from(value()),
                "--style" => options.style = PathBuf::from(value()),
                "--model" => options.model = Some(PathBuf::from(value())),
                "--strength" => options.strength = value().parse().expect("--strength X"),
                "--method" => options.method = value().parse()?,
                "--fade-in" => {
                    options.fade_in_seconds = value()
                        .trim_end_matches('s')
                        .parse()
                        .expect("--fade-in SECONDS")
                }
                "--blend" => options.blend = Some(parse_blend(&value())?),
                "--patch" => options.patch = value().parse().expect("--patch N"),
                _ => options.source = PathBuf::from(a),
            }
        }
        apply(&options)
    })();
    match result {
        Ok(report) => println!(
            "{}",
            serde_json::to_string_pretty(&report).expect("serialisable")
        ),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
