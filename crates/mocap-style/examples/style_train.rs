//! Trains the style autoencoder: the library call behind `mocap style train`.
//!
//! ```text
//! cargo run --release -p mocap-style --example style_train -- \
//!     [--epochs 30] [--steps 100] [--contents walk,walk-back] [--seed 1] [--foot-loss W] \
//!     -o models/style-default.safetensors DIR...
//! ```

use std::path::PathBuf;

use mocap_style::{train, TrainOptions};

fn main() {
    let mut options = TrainOptions::default();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().unwrap_or_else(|| panic!("{a} needs a value"));
        match a.as_str() {
            "-o" | "--output" => options.out = PathBuf::from(value()),
            "--epochs" => options.epochs = value().parse().expect("--epochs N"),
            "--steps" => options.steps_per_epoch = value().parse().expect("--steps N"),
            "--seed" => options.seed = value().parse().expect("--seed N"),
            "--lr" => options.learning_rate = value().parse().expect("--lr X"),
            "--contents" => {
                options.filter.contents = value().split(',').map(String::from).collect()
            }
            "--no-hold-out" => options.hold_out = false,
            "--held-out" => options.held_out_take = value().parse().expect("--held-out last|first"),
            "--resume" => options.resume = true,
            "--foot-loss" => options.foot_loss_weight = value().parse().expect("--foot-loss W"),
            _ => options.inputs.push(PathBuf::from(a)),
        }
    }
    match train(&options) {
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
