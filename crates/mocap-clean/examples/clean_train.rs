//! Trains a denoiser: the library call behind `mocap clean train`, with every option spelled out.
//!
//! cargo run --release -p mocap-clean --example clean_train -- \
//!     --data ../shared/data/bandai --out models/clean-default.safetensors \
//!     [--epochs 20] [--steps 40] [--batch 512] [--lr 1e-3] [--seed 1] \
//!     [--loss derivative|mse] [--representation rot6d|expmap|euler] [--rotations local|pelvis] [--base-filter SPEC | --base-wiener FILE] [--base-context FRAMES] [--base-input] \
//!     [--width 64] [--levels 2] [--blocks 1] [--window 16] [--large] \
//!     [--max-sigma 10] [--spike-probability 0.5] [--max-spikes 3] [--spike-sigma 16] \
//!     [--position-weight W] [--max-train-takes N] [--state DIR] [--resume] [--device cpu|cuda] [--json REPORT.json]

use std::path::PathBuf;

use mocap_clean::{train, DenoiserConfig, TrainOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut o = TrainOptions::default();
    let mut json = None;
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    let next = |i: &mut usize| -> Result<String, String> {
        *i += 1;
        args.get(*i)
            .cloned()
            .ok_or_else(|| format!("{} needs a value", args[*i - 1]))
    };
    while i < args.len() {
        match args[i].as_str() {
            "--data" => o.inputs.push(PathBuf::from(next(&mut i)?)),
            "--out" => o.out = PathBuf::from(next(&mut i)?),
            "--epochs" => o.epochs = next(&mut i)?.parse()?,
            "--steps" => o.steps_per_epoch = next(&mut i)?.parse()?,
            "--batch" => o.batch_size = next(&mut i)?.parse()?,
            "--lr" => o.learning_rate = next(&mut i)?.parse()?,
            "--seed" => o.seed = next(&mut i)?.parse()?,
            "--loss" => match next(&mut i)?.as_str() {
                "mse" => o.derivative_loss = false,
                "derivative" => o.derivative_loss = true,
                other => {
                    return Err(format!("--loss: expected mse or derivative, got {other}").into())
                }
            },
            "--representation" => o.representation = next(&mut i)?.parse()?,
            "--rotations" => o.frame = next(&mut i)?.parse()?,
            "--base-filter" => o.base_filter = Some(next(&mut i)?.parse()?),
            "--base-context" => o.base_context = next(&mut i)?.parse()?,
            "--base-wiener" => o.base_wiener = Some(PathBuf::from(next(&mut i)?)),
            "--base-input" => o.base_input = true,
            "--width" => o.network.width = next(&mut i)?.parse()?,
            "--levels" => o.network.levels = next(&mut i)?.parse()?,
            "--blocks" => o.network.blocks = next(&mut i)?.parse()?,
            "--window" => o.network.window = next(&mut i)?.parse()?,
            "--large" => o.network = DenoiserConfig::large(0),
            "--max-sigma" => {
                o.noise.random.as_mut().unwrap().max_sigma_deg = next(&mut i)?.parse()?
            }
            "--spike-probability" => o.noise.spike_probability = next(&mut i)?.parse()?,
            "--max-spikes" => {
                o.noise.spikes.as_mut().unwrap().max_spikes = next(&mut i)?.parse()?
            }
            "--spike-sigma" => {
                o.noise.spikes.as_mut().unwrap().duration_sigma_frames = next(&mut i)?.parse()?
            }
            "--position-weight" => o.position_weight = next(&mut i)?.parse()?,
            "--max-train-takes" => o.max_train_takes = Some(next(&mut i)?.parse()?),
            "--validation-windows" => o.validation_windows = next(&mut i)?.parse()?,
            "--state" => o.state_dir = Some(PathBuf::from(next(&mut i)?)),
            "--plot" => o.plot = Some(PathBuf::from(next(&mut i)?)),
            "--resume" => o.resume = true,
            "--device" => o.device = next(&mut i)?.parse()?,
            "--json" => json = Some(PathBuf::from(next(&mut i)?)),
            other => return Err(format!("unknown option {other}").into()),
        }
        i += 1;
    }
    if o.inputs.is_empty() {
        return Err("--data FOLDER is required".into());
    }
    let report = train(&o)?;
    let text = serde_json::to_string_pretty(&report)?;
    match json {
        Some(p) => mocap_core::io::atomic::write_bytes_atomically(&p, text.as_bytes())?,
        None => println!("{text}"),
    }
    eprintln!(
        "trained {} epochs, {:.0} samples/s, final validation MSE {:.6}; model {}",
        report.history.epochs.len(),
        report.samples_per_second,
        report
            .history
            .epochs
            .last()
            .map_or(f64::NAN, |e| e.valid_loss),
        report.model.display()
    );
    Ok(())
}
