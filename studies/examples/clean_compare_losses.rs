//! The report's comparison: several training runs (seeds) with plain MSE and
//! with the derivative loss, validation curves overlaid in one PNG, and the
//! area under the first epochs' validation curve.
//!
//! cargo run --release -p mocap-studies --example clean_compare_losses -- \
//!     --data ../shared/data/bandai --out-dir bench/clean/compare \
//!     [--seeds 1,2,3] [--epochs 8] [--steps 20] [--batch 512] [--auc-epochs 3] [--max-train-takes N]
//!     [--replot]   (only redraw validation_curves.png from summary.json)

use std::path::PathBuf;

use mocap_clean::{train, TrainOptions};
use mocap_nn::plot::{plot_curves, PlotOptions, Series};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut base = TrainOptions::default();
    let mut out_dir = PathBuf::from("bench/clean/compare");
    let mut seeds: Vec<u64> = vec![1, 2, 3];
    let mut auc_epochs = 3;
    let mut replot = false;
    let mut i = 0;
    while i < args.len() {
        if args[i] == "--replot" {
            replot = true;
            i += 1;
            continue;
        }
        let v = args
            .get(i + 1)
            .cloned()
            .ok_or(format!("{} needs a value", args[i]))?;
        match args[i].as_str() {
            "--data" => base.inputs.push(PathBuf::from(v)),
            "--out-dir" => out_dir = PathBuf::from(v),
            "--seeds" => seeds = v.split(',').map(str::parse).collect::<Result<_, _>>()?,
            "--epochs" => base.epochs = v.parse()?,
            "--steps" => base.steps_per_epoch = v.parse()?,
            "--batch" => base.batch_size = v.parse()?,
            "--auc-epochs" => auc_epochs = v.parse()?,
            "--max-train-takes" => base.max_train_takes = Some(v.parse()?),
            "--window" => base.network.window = v.parse()?,
            other => return Err(format!("unknown option {other}").into()),
        }
        i += 2;
    }
    std::fs::create_dir_all(&out_dir)?;
    if replot {
        // Redraw the overlay from a finished comparison's summary.json.
        let summary: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out_dir.join("summary.json"))?)?;
        let series: Vec<Series> = summary["runs"]
            .as_array()
            .ok_or("summary.json without runs")?
            .iter()
            .map(|r| {
                let points = r["valid_mse"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .enumerate()
                    .map(|(i, v)| ((i + 1) as f32, v.as_f64().unwrap_or(f64::NAN) as f32))
                    .collect();
                Series::new(
                    format!("{} seed {}", r["loss"].as_str().unwrap_or("?"), r["seed"]),
                    points,
                )
            })
            .collect();
        plot(&out_dir, &series)?;
        return Ok(());
    }
    let mut series = Vec::new();
    let mut rows = Vec::new();
    for derivative in [false, true] {
        let name = if derivative { "derivative" } else { "mse" };
        for &seed in &seeds {
            let mut o = base.clone();
            o.derivative_loss = derivative;
            o.seed = seed;
            o.out = out_dir.join(format!("{name}-seed{seed}.safetensors"));
            o.state_dir = Some(out_dir.join(format!("{name}-seed{seed}.state")));
            let report = train(&o)?;
            let points = report
                .history
                .epochs
                .iter()
                .map(|e| ((e.epoch + 1) as f32, e.valid_loss as f32))
                .collect();
            series.push(Series::new(format!("{name} seed {seed}"), points));
            rows.push(serde_json::json!({
                "loss": name,
                "seed": seed,
                "valid_mse": report.history.epochs.iter().map(|e| e.valid_loss).collect::<Vec<_>>(),
                "auc_first_epochs": report.history.valid_area(auc_epochs),
                "final_valid_mse": report.history.epochs.last().map(|e| e.valid_loss),
                "samples_per_second": report.samples_per_second,
            }));
            eprintln!(
                "{name} seed {seed}: {:?}",
                report
                    .history
                    .epochs
                    .iter()
                    .map(|e| e.valid_loss)
                    .collect::<Vec<_>>()
            );
        }
    }
    plot(&out_dir, &series)?;
    let summary = serde_json::json!({ "auc_epochs": auc_epochs, "runs": rows });
    let text = serde_json::to_string_pretty(&summary)?;
    mocap_core::io::atomic::write_bytes_atomically(&out_dir.join("summary.json"), text.as_bytes())?;
    println!("{text}");
    Ok(())
}

fn plot(out_dir: &std::path::Path, series: &[Series]) -> Result<(), Box<dyn std::error::Error>> {
    plot_curves(
        &out_dir.join("validation_curves.png"),
        series,
        &PlotOptions {
            y_label: "validation MSE (6D features)".into(),
            ..PlotOptions::new("Validation loss: plain MSE vs derivative loss")
        },
    )?;
    Ok(())
}
