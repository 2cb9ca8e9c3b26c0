//! Inference and training speed of a denoiser (a benchmark, not a test).
//!
//! cargo run --release -p mocap-clean --example clean_speed -- --data ../shared/data/bandai \
//!     [--model FILE (a network or a Wiener filter)] [--base-wiener FILE] [--device cpu|cuda] [--frames 1800] [--repeats 5] [--train-steps 5] [--batch 512]
//!     [--level-estimate segment-median|pooled]
//!
//! `--base-wiener`: the Wiener filter file a model on a Wiener base was trained with (its training
//! speed needs it; the model file carries only what cleaning needs).
//!
//! Inference: a clip of `frames` frames (takes of the data set joined end to
//! end), cleaned `repeats` times; frames per second of `CleanModel::clean`
//! (feature conversion, windows, network, blending and writing the rotations
//! back all included; file reading excluded).
//! Training: samples per second of `train_steps` optimiser steps of the
//! model's configuration (noise generation and its base filter included).

use std::path::PathBuf;
use std::time::Instant;

use mocap_clean::{list_bvh, train, CleanModel, LevelEstimate, ModelFile, TrainOptions};
use mocap_core::io::bvh::read_bvh;
use mocap_core::Motion;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mut data, mut model_path, mut device) = (None, None, mocap_nn::device::DeviceChoice::Cpu);
    let (mut frames, mut repeats, mut train_steps, mut batch) =
        (1800usize, 5usize, 5usize, 512usize);
    let mut base_wiener = None;
    let mut level_estimate = LevelEstimate::default();
    let mut i = 0;
    while i < args.len() {
        let v = args
            .get(i + 1)
            .cloned()
            .ok_or(format!("{} needs a value", args[i]))?;
        match args[i].as_str() {
            "--data" => data = Some(PathBuf::from(v)),
            "--model" => model_path = Some(PathBuf::from(v)),
            "--base-wiener" => base_wiener = Some(PathBuf::from(v)),
            "--device" => device = v.parse()?,
            "--frames" => frames = v.parse()?,
            "--repeats" => repeats = v.parse()?,
            "--train-steps" => train_steps = v.parse()?,
            "--batch" => batch = v.parse()?,
            "--level-estimate" => {
                level_estimate = match v.as_str() {
                    "segment-median" => LevelEstimate::SegmentMedian,
                    "pooled" => LevelEstimate::Pooled,
                    _ => {
                        return Err(format!("--level-estimate {v}: segment-median or pooled").into())
                    }
                }
            }
            other => return Err(format!("unknown option {other}").into()),
        }
        i += 2;
    }
    let data = data.ok_or("--data FOLDER is required")?;
    // What a user waits for before the first frame: reading the model and
    // building its filter's bases.
    let start = Instant::now();
    let mut model = match &model_path {
        Some(p) => ModelFile::load(p, device)?,
        None => ModelFile::Network(Box::new(CleanModel::load_default(device)?)),
    };
    match &mut model {
        ModelFile::Network(m) => m.set_level_estimate(level_estimate),
        ModelFile::Wiener(w) => w.set_level_estimate(level_estimate),
    }
    let load_seconds = start.elapsed().as_secs_f64();
    // A long clip: takes joined end to end on the first take's skeleton.
    let paths = list_bvh(std::slice::from_ref(&data))?;
    let first = read_bvh(&paths[0])?;
    let c = first.skeleton().channel_count();
    let mut values = Vec::with_capacity(frames * c);
    for p in &paths {
        if values.len() >= frames * c {
            break;
        }
        let m = read_bvh(p)?;
        if m.skeleton().channel_count() == c {
            values.extend_from_slice(m.values());
        }
    }
    values.truncate(frames * c);
    let clip = Motion::new(
        first.skeleton().clone(),
        first.frame_time(),
        values.len() / c,
        values,
    )?;
    let start = Instant::now();
    model.clean(&clip, None)?; // warm-up
    println!(
        "load: {load_seconds:.3} s; first clean (a mixture builds its chosen component's bases): {:.3} s",
        start.elapsed().as_secs_f64()
    );
    let start = Instant::now();
    for _ in 0..repeats {
        model.clean(&clip, None)?;
    }
    let seconds = start.elapsed().as_secs_f64() / repeats as f64;
    let fps = clip.frame_count() as f64 / seconds;
    let what = match &model {
        ModelFile::Network(m) => format!("{} parameters, device {device}", m.parameter_count()),
        ModelFile::Wiener(_) => "Wiener filter".into(),
    };
    println!(
        "inference: {} frames in {:.4} s = {:.0} frames/s = {:.0}x real time at {:.0} fps ({what})",
        clip.frame_count(),
        seconds,
        fps,
        fps / clip.fps(),
        clip.fps(),
    );
    // A Wiener filter is fitted, not trained: no training speed.
    let ModelFile::Network(model) = model else {
        return Ok(());
    };
    if train_steps > 0 && model.description.base_wiener.is_some() && base_wiener.is_none() {
        return Err(
            "the model corrects a Wiener filter: give its file with --base-wiener to time training"
                .into(),
        );
    }
    if train_steps > 0 {
        let dir = tempfile_dir()?;
        let options = TrainOptions {
            inputs: vec![data],
            out: dir.join("speed.safetensors"),
            network: model.description.network,
            representation: model.description.representation,
            frame: model.description.frame,
            base_filter: model.description.base_filter,
            base_context: model.description.base_context,
            base_wiener: base_wiener.clone(),
            base_input: model.description.base_input(),
            epochs: 1,
            steps_per_epoch: train_steps,
            batch_size: batch,
            validation_windows: batch,
            device,
            ..TrainOptions::default()
        };
        let report = train(&options)?;
        println!(
            "training: {:.0} samples/s ({} steps of batch {batch}, noise generation included, device {device})",
            report.samples_per_second, train_steps
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
    Ok(())
}

fn tempfile_dir() -> std::io::Result<PathBuf> {
    let dir = std::env::temp_dir().join(format!("mocap-clean-speed-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}
