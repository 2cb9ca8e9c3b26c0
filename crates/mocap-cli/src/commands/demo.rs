//! `mocap demo`: the whole pipeline on bundled data, with an HTML report
//! (mocap-demo).

use std::io::IsTerminal;
use std::path::PathBuf;

use mocap_demo::{run_demo_with, DemoOptions, StageStatus};

use super::GlobalOptions;

#[derive(clap::Args)]
pub struct Args {
    /// The report folder (index.html, report.json, BVH outputs, pictures).
    #[arg(long, short, default_value = "mocap-demo-report")]
    output: PathBuf,
    /// Print the report as JSON on standard output.
    #[arg(long)]
    json: bool,
    /// The take to start from (default: the bundled Bandai walk).
    #[arg(long)]
    sample: Option<PathBuf>,
    /// The style example clip (default: the bundled proud walk).
    #[arg(long)]
    style_clip: Option<PathBuf>,
    /// The denoiser model (default: models/clean-default.safetensors).
    #[arg(long)]
    clean_model: Option<PathBuf>,
    /// The style model (default: models/style-default.safetensors).
    #[arg(long)]
    style_model: Option<PathBuf>,
    /// The search library index (default: models/search-bandai-content.idx).
    #[arg(long)]
    search_index: Option<PathBuf>,
    /// Simulated sensors.
    #[arg(long, default_value_t = 3)]
    sensors: usize,
    /// Seed of the simulated capture.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Skip filmstrips and plots.
    #[arg(long)]
    no_pictures: bool,
}

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    let defaults = DemoOptions::default();
    if args.sensors == 0 {
        anyhow::bail!("--sensors must be at least 1");
    }
    let demo = DemoOptions {
        out: args.output,
        sample: args.sample.unwrap_or(defaults.sample),
        style_clip: args.style_clip.unwrap_or(defaults.style_clip),
        clean_model: args.clean_model.unwrap_or(defaults.clean_model),
        style_model: args.style_model.unwrap_or(defaults.style_model),
        search_index: args.search_index.unwrap_or(defaults.search_index),
        sensors: args.sensors,
        seed: args.seed,
        pictures: !args.no_pictures,
        ..defaults
    };
    // Progress lines on standard error, only for a person watching.
    let show = !options.quiet && std::io::stderr().is_terminal();
    let mut progress = |line: &str| {
        if show {
            eprintln!("{line}");
        }
    };
    let report = run_demo_with(&demo, &mut progress)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        for s in &report.stages {
            match &s.message {
                Some(m) if s.status != StageStatus::Ran => {
                    println!("{:<8} {}: {m}", s.name, s.status.label())
                }
                _ => println!("{:<8} {} in {:.1} s", s.name, s.status.label(), s.seconds),
            }
        }
        println!(
            "Report: {} ({:.1} s)",
            report.index_html.display(),
            report.seconds
        );
    }
    Ok(())
}
