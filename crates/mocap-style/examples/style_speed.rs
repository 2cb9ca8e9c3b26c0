//! Time to restyle a 10-second clip, and the share of each stage.
//!
//! ```text
//! cargo run --release -p mocap-style --example style_speed -- SOURCE STYLE_CLIP [--model M] [--runs 20] [--patches 32,48]
//! ```
//!
//! The source is cut (or its frames used) to its first 10 seconds; each run
//! prepares and encodes the style clip and its mirror, then restyles, as
//! `mocap style apply` does (file reading and writing excluded). Prints the
//! median of every stage over the runs, for elastic and fixed patches, the
//! three roots, and without the source's asymmetry (which encodes the
//! source's mirror too). `--patches` repeats the elastic and fixed rows
//! for other patch lengths (default: the default length only).

use std::path::PathBuf;

use mocap_core::io::bvh::read_bvh;
use mocap_core::ops::trim;
use mocap_nn::device::DeviceChoice;
use mocap_style::{
    load_model, prepare_style, restyle, source_reconstruction_deg, Asymmetry, ConvertOptions,
    Method, RootPath, StageTimings,
};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut paths = Vec::new();
    let mut model_path = None;
    let mut runs = 20;
    let mut patches = vec![ConvertOptions::default().patch];
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--model" => model_path = args.next().map(PathBuf::from),
            "--runs" => runs = args.next().expect("--runs N").parse()?,
            "--patches" => {
                patches = args
                    .next()
                    .expect("--patches P1,P2")
                    .split(',')
                    .map(str::parse)
                    .collect::<Result<_, _>>()?
            }
            _ => paths.push(PathBuf::from(a)),
        }
    }
    let [source, style] = &paths[..] else {
        return Err(
            "usage: style_speed SOURCE STYLE_CLIP [--model M] [--runs N] [--patches P1,P2]".into(),
        );
    };
    let model = load_model(model_path.as_deref(), DeviceChoice::Cpu)?;
    let source = read_bvh(source)?;
    let frames = ((10.0 * source.fps()).round() as usize).min(source.frame_count());
    let source = trim(&source, 0..frames)?;
    let style_motion = read_bvh(style)?;
    println!(
        "source: {} frames ({:.2} s at {:.0} fps); style clip: {} frames; {} runs; threads: {}",
        source.frame_count(),
        source.duration(),
        source.fps(),
        style_motion.frame_count(),
        runs,
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    println!(
        "| method | total (ms) | prepare | encode | match | decode | compose | output frames |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
    let default_patch = ConvertOptions::default().patch;
    // Every setting at the default patch length, then elastic and fixed
    // patches at each other length asked for.
    let mut settings = vec![
        (
            Method::ElasticPatches,
            RootPath::FeetAlongSource,
            Asymmetry::Source,
        ),
        (
            Method::FixedPatches,
            RootPath::FeetAlongSource,
            Asymmetry::Source,
        ),
        (Method::ElasticPatches, RootPath::Source, Asymmetry::Source),
        (Method::ElasticPatches, RootPath::Feet, Asymmetry::Source),
        (
            Method::ElasticPatches,
            RootPath::FeetAlongSource,
            Asymmetry::SourceClip,
        ),
        (
            Method::ElasticPatches,
            RootPath::FeetAlongSource,
            Asymmetry::Style,
        ),
    ]
    .into_iter()
    .map(|(method, root, asymmetry)| (method, root, asymmetry, default_patch))
    .collect::<Vec<_>>();
    for &patch in patches.iter().filter(|&&p| p != default_patch) {
        for method in [Method::ElasticPatches, Method::FixedPatches] {
            settings.push((method, RootPath::FeetAlongSource, Asymmetry::Source, patch));
        }
    }
    for (method, root, asymmetry, patch) in settings {
        let mut all: Vec<StageTimings> = Vec::new();
        let mut out_frames = 0;
        for _ in 0..runs + 1 {
            let mut t = StageTimings::default();
            let clip = prepare_style(&model, &style_motion, "style", &mut t)?;
            let options = ConvertOptions {
                method,
                root,
                asymmetry,
                patch,
                ..ConvertOptions::default()
            };
            let r = restyle(&model, &source, &[(&clip, 1.0)], &options, t)?;
            out_frames = r.motion.frame_count();
            all.push(r.timings);
        }
        all.remove(0); // warm-up
        let ms = |f: &dyn Fn(&StageTimings) -> f64| 1000.0 * median(all.iter().map(f).collect());
        let total = ms(&|t| t.total());
        let share = |v: f64| format!("{v:.1} ms ({:.0}%)", 100.0 * v / total);
        println!(
            "| {}, P {patch}, root {}, asymmetry {} | {:.1} | {} | {} | {} | {} | {} | {} |",
            method.name(),
            root.name(),
            asymmetry.name(),
            total,
            share(ms(&|t| t.prepare)),
            share(ms(&|t| t.encode)),
            share(ms(&|t| t.matching)),
            share(ms(&|t| t.decode)),
            share(ms(&|t| t.compose)),
            out_frames
        );
    }
    // `mocap style apply` also checks, once per source, how well the model
    // reproduces it (not part of `restyle`).
    let mut check = Vec::new();
    for _ in 0..runs + 1 {
        let t = std::time::Instant::now();
        source_reconstruction_deg(&model, &source)?;
        check.push(1000.0 * t.elapsed().as_secs_f64());
    }
    check.remove(0); // warm-up
    println!(
        "\n`style apply` adds the source check (source_reconstruction_deg): {:.1} ms",
        median(check)
    );
    Ok(())
}
