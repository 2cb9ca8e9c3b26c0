//! Evaluates style transfer on labelled clips: the library call behind
//! `mocap style eval`.
//!
//! ```text
//! cargo run --release -p mocap-style --example style_eval -- \
//!     [--model M.safetensors] [--sources walk,walk-turn-left] [--styles walk] \
//!     [--classifier-contents walk,walk-back] [--style-judge forest|conv-net] [--seed S] [--patch 32] [--asymmetry source|source-clip|style] [--foot-contacts] [--root feet] [--filmstrips DIR] \
//!     [--json report.json] [--markdown report.md] DIR...
//! ```

use std::path::PathBuf;

use mocap_style::{evaluate, EvalOptions};

fn main() {
    let mut options = EvalOptions::default();
    let mut json = None;
    let mut markdown = None;
    let mut args = std::env::args().skip(1);
    let list = |s: String| {
        s.split(',')
            .filter(|x| !x.is_empty())
            .map(String::from)
            .collect::<Vec<_>>()
    };
    while let Some(a) = args.next() {
        let mut value = || args.next().unwrap_or_else(|| panic!("{a} needs a value"));
        match a.as_str() {
            "--model" => options.model = Some(PathBuf::from(value())),
            "--held-out" => options.held_out_take = value().parse().expect("--held-out last|first"),
            "--sources" => options.source_contents = list(value()),
            "--styles" => options.style_contents = list(value()),
            "--classifier-contents" => options.classifier_filter.contents = list(value()),
            "--foot-contacts" => options.convert.foot_contacts = true,
            "--root" => options.convert.root = value().parse().expect("--root PATH"),
            "--asymmetry" => {
                options.convert.asymmetry = value()
                    .parse()
                    .expect("--asymmetry source|source-clip|style")
            }
            "--patch" => options.convert.patch = value().parse().expect("--patch N"),
            "--style-descriptor" => {
                options.style_descriptor = serde_json::from_value(serde_json::json!(value()))
                    .expect("intervals or statistics")
            }
            "--content-descriptor" => {
                options.content_descriptor = serde_json::from_value(serde_json::json!(value()))
                    .expect("intervals or statistics")
            }
            "--trees" => options.trees = value().parse().expect("--trees N"),
            "--style-judge" => options.set_style_judge(value().parse().expect("--style-judge")),
            "--seed" => options.seed = value().parse().expect("--seed N"),
            "--methods" => {
                options.methods = list(value())
                    .iter()
                    .map(|m| m.parse().expect("method name"))
                    .collect()
            }
            "--filmstrips" => options.filmstrips = Some(PathBuf::from(value())),
            "--json" => json = Some(PathBuf::from(value())),
            "--markdown" => markdown = Some(PathBuf::from(value())),
            _ => options.inputs.push(PathBuf::from(a)),
        }
    }
    let report = match evaluate(&options) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    let md = report.to_markdown();
    print!("{md}");
    eprintln!("{:.1} s", report.seconds);
    if let Some(p) = json {
        let text = serde_json::to_vec_pretty(&report).expect("serialisable");
        mocap_core::io::atomic::write_bytes_atomically(&p, &text).expect("write the JSON report");
    }
    if let Some(p) = markdown {
        mocap_core::io::atomic::write_bytes_atomically(&p, md.as_bytes())
            .expect("write the Markdown report");
    }
}
