//! Accuracy of the evaluation's classifiers on real clips (no restyling):
//! held-out clips and, with `--cv`, cross-validation on the training clips.
//! Used to choose the classifiers on real clips, never on outputs.
//!
//! ```text
//! cargo run --release -p mocap-studies --example style_classifiers -- [--cv | --cv-style | --cv-content] \
//!     [--classifier-contents walk,walk-back] [--style-descriptor gait] \
//!     [--content-descriptor intervals-gait] [--style-window 2] [--content-window 2] \
//!     [--style-model forest|nearest-mean|discriminant|conv-net] [--style-judge forest|conv-net|both] [--shrinkage 0.5] [--content-model M] [--seed S] [--mirror] [--candidates N] [--trees 100] \
//!     [--net-epochs 30] [--net-width 64] [--net-kernel 7] [--net-dropout 0.3] [--net-lr 0.001] [--net-velocities] DIR...
//! ```

use std::path::PathBuf;

use mocap_studies::style::{check_classifiers, CrossValidate};
use mocap_style::EvalOptions;

fn main() {
    let mut options = EvalOptions::default();
    let mut cv = CrossValidate::default();
    let mut args = std::env::args().skip(1);
    fn descriptor<T: serde::de::DeserializeOwned>(s: String) -> T {
        serde_json::from_value(serde_json::json!(s)).expect("a descriptor or model name")
    }
    while let Some(a) = args.next() {
        let mut value = || args.next().unwrap_or_else(|| panic!("{a} needs a value"));
        match a.as_str() {
            "--cv" => {
                cv.style = true;
                cv.content = true
            }
            "--cv-style" => cv.style = true,
            "--cv-content" => cv.content = true,
            "--candidates" => options.candidates = Some(value().parse().expect("N")),
            "--classifier-contents" => {
                options.classifier_filter.contents = value().split(',').map(String::from).collect()
            }
            "--style-descriptor" => options.style_descriptor = descriptor(value()),
            "--content-descriptor" => options.content_descriptor = descriptor(value()),
            "--style-window" => options.style_windows.length = value().parse().expect("seconds"),
            "--content-window" => {
                options.content_windows.length = value().parse().expect("seconds")
            }
            "--style-model" => options.style_model = descriptor(value()),
            "--style-judge" => options.set_style_judge(value().parse().expect("--style-judge")),
            "--content-model" => options.content_model = descriptor(value()),
            "--shrinkage" => options.shrinkage = value().parse().expect("shrinkage"),
            "--seed" => options.seed = value().parse().expect("seed"),
            "--held-out" => options.held_out_take = value().parse().expect("--held-out last|first"),
            "--style-hop" => options.style_windows.hop = value().parse().expect("seconds"),
            "--mirror" => options.style_mirror_training = true,
            "--trees" => options.trees = value().parse().expect("--trees N"),
            "--net-epochs" => options.net.epochs = value().parse().expect("--net-epochs N"),
            "--net-width" => options.net.width = value().parse().expect("--net-width N"),
            "--net-kernel" => options.net.kernel = value().parse().expect("--net-kernel N"),
            "--net-dropout" => options.net.dropout = value().parse().expect("--net-dropout P"),
            "--net-velocities" => options.net.velocities = true,
            "--net-lr" => options.net.learning_rate = value().parse().expect("--net-lr L"),
            _ => options.inputs.push(PathBuf::from(a)),
        }
    }
    let started = std::time::Instant::now();
    match check_classifiers(&options, cv) {
        Ok(checks) => {
            println!(
                "{}",
                serde_json::to_string_pretty(&checks).expect("serialisable")
            );
            eprintln!("{:.1} s", started.elapsed().as_secs_f64());
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
