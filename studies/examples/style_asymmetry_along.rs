//! Takes that walk straight and then turn (or turn and then walk straight),
//! restyled with the source's left-right asymmetry kept along time (the
//! default, `--asymmetry source`), kept as one offset for the whole clip
//! (`source-clip`) and not kept (`style`, the report's method):
//! does each part keep its own footwork? (bench/results/style.md, "Turns
//! kept along the take").
//!
//! ```text
//! cargo run --release -p mocap-studies --example style_asymmetry_along -- DIR \
//!     [--held-out last|first] [--model M]
//! ```
//!
//! `DIR` holds Bandai clips of one set (dataset-2). For every style with a
//! held-out straight walk and held-out turns, two takes are made by joining
//! held-out clips of that style end to end (`Motion::append`; the root jumps
//! at the join, which moves neither the joint rotations nor the feet
//! relative to the pelvis): the walk then the right turn, and the left turn
//! then the walk. Each is restyled with every held-out walk of the other
//! styles. The output is cut where the source's first clip ends (by the
//! time warp), and each part is measured against the same part of the
//! source:
//!
//! - feet offset: the mean sideways offset of the two ankles from the pelvis
//!   in the body frame (body heights), which tells turns from straight walks
//!   (turn_cues.sh); the table gives the mean |output - source| per part;
//! - content: the part classified by the evaluation's content classifier
//!   (trained on the set's clips that are not held out), right when it says
//!   the part's content.

use std::path::PathBuf;

use mocap_core::ops::trim;
use mocap_core::Motion;
use mocap_nn::device::DeviceChoice;
use mocap_style::{
    feet_sideways_offset, held_out, labelled_paths, list_bvh, load_clips, load_model,
    prepare_source, prepare_style, restyle_prepared, train_classifiers, Asymmetry, Clip,
    ClipFilter, ConvertOptions, EvalOptions, HeldOutTake, StageTimings,
};

fn feet_offset(motion: &Motion) -> f64 {
    feet_sideways_offset(motion).expect("pose values")
}

/// A source made of two clips, and where the first ends.
struct Joined<'a> {
    name: String,
    parts: [&'a Clip; 2],
    motion: Motion,
}

fn join<'a>(first: &'a Clip, second: &'a Clip) -> Joined<'a> {
    let mut motion = first.motion.clone();
    motion
        .append(&second.motion)
        .expect("clips of one skeleton");
    Joined {
        name: format!("{} + {}", first.name, second.name),
        parts: [first, second],
        motion,
    }
}

#[derive(Default, Clone, Copy)]
struct Tally {
    offset_error: [f64; 2],
    content_right: [usize; 2],
    outputs: usize,
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut option = |flag: &str| -> Option<String> {
        let i = args.iter().position(|a| a == flag)?;
        let value = args.get(i + 1).cloned().expect("a value after the flag");
        args.drain(i..i + 2);
        Some(value)
    };
    let which: HeldOutTake = option("--held-out")
        .map(|s| s.parse().expect("--held-out last|first"))
        .unwrap_or_default();
    let model_path = option("--model").map(PathBuf::from);
    let [dir] = args.as_slice() else {
        eprintln!("usage: style_asymmetry_along DIR [--held-out last|first] [--model M]");
        std::process::exit(2);
    };
    let files = labelled_paths(
        &list_bvh(&[PathBuf::from(dir)]).expect("a folder of clips"),
        &ClipFilter::default(),
    )
    .expect("labelled clips");
    let held = held_out(&files, which);
    let is_held =
        |p: &PathBuf| held.contains(&p.file_stem().unwrap().to_string_lossy().to_string());
    let (test, train): (Vec<_>, Vec<_>) = files.into_iter().partition(|(p, _)| is_held(p));
    let test = load_clips(&test).expect("held-out clips");
    let train = load_clips(&train).expect("training clips");
    eprintln!(
        "training the content classifier on {} clips...",
        train.len()
    );
    let (_, content) = train_classifiers(&train, &EvalOptions::default()).expect("classifiers");

    let of = |content: &str, style: &str| {
        test.iter()
            .find(|c| c.labels.content == content && c.labels.style == style)
    };
    let mut styles: Vec<&str> = test.iter().map(|c| c.labels.style.as_str()).collect();
    styles.sort();
    styles.dedup();
    let mut sources = Vec::new();
    for style in &styles {
        let (Some(walk), Some(right), Some(left)) = (
            of("walk", style),
            of("walk-turn-right", style),
            of("walk-turn-left", style),
        ) else {
            continue;
        };
        sources.push(join(walk, right));
        sources.push(join(left, walk));
    }
    let style_walks: Vec<&Clip> = test.iter().filter(|c| c.labels.content == "walk").collect();

    let model = load_model(model_path.as_deref(), DeviceChoice::Cpu).expect("model");
    let mut prepared = Vec::new();
    for clip in &style_walks {
        let mut t = StageTimings::default();
        prepared.push(prepare_style(&model, &clip.motion, &clip.name, &mut t).expect("style clip"));
    }

    let settings = [Asymmetry::Source, Asymmetry::SourceClip, Asymmetry::Style];
    let mut tallies = [Tally::default(); 3];
    let mut source_tally = Tally::default();
    let mut windows = Vec::new();
    for source in &sources {
        let split = source.parts[0].motion.frame_count();
        let source_parts = [
            trim(&source.motion, 0..split).unwrap(),
            trim(&source.motion, split..source.motion.frame_count()).unwrap(),
        ];
        let wanted = source_parts.each_ref().map(feet_offset);
        for (k, part) in source_parts.iter().enumerate() {
            let right = content.predict(part).unwrap() == source.parts[k].labels.content;
            source_tally.content_right[k] += right as usize;
        }
        source_tally.outputs += 1;
        let prepared_source = settings.map(|a| prepare_source(&model, &source.motion, a).unwrap());
        for (clip, style) in style_walks.iter().zip(&prepared) {
            if clip.labels.style == source.parts[0].labels.style {
                continue;
            }
            for ((tally, &asymmetry), prepared) in
                tallies.iter_mut().zip(&settings).zip(&prepared_source)
            {
                let options = ConvertOptions {
                    asymmetry,
                    ..ConvertOptions::default()
                };
                let t = StageTimings::default();
                let out = restyle_prepared(&model, prepared, &[(style, 1.0)], &options, t)
                    .expect("restyle");
                if asymmetry == Asymmetry::Source {
                    windows.push(out.asymmetry_window_s);
                }
                // Output frames from the source's first clip, then the rest.
                let cut = out
                    .conversion
                    .source_time
                    .iter()
                    .position(|&u| u >= split as f32)
                    .unwrap_or(out.motion.frame_count());
                let parts = [
                    trim(&out.motion, 0..cut).unwrap(),
                    trim(&out.motion, cut..out.motion.frame_count()).unwrap(),
                ];
                for (k, part) in parts.iter().enumerate() {
                    tally.offset_error[k] += (feet_offset(part) - wanted[k]).abs();
                    let right = content.predict(part).unwrap() == source.parts[k].labels.content;
                    tally.content_right[k] += right as usize;
                }
                tally.outputs += 1;
            }
        }
        eprintln!("{} restyled", source.name);
    }

    let found: Vec<f64> = windows.iter().flatten().copied().collect();
    println!(
        "{} joined takes of {} (held-out take: {}), each restyled with the held-out walks of the \
         other styles: {} outputs per setting. Asymmetry window (`source`): two strides, {:.2}-{:.2} s \
         ({} of {} outputs; the others one offset per clip).\n",
        sources.len(),
        dir,
        if which == HeldOutTake::Last { "last" } else { "first" },
        tallies[0].outputs,
        found.iter().copied().fold(f64::INFINITY, f64::min),
        found.iter().copied().fold(0.0, f64::max),
        found.len(),
        windows.len(),
    );
    println!(
        "| asymmetry | feet offset error, first clip | feet offset error, second clip | \
         content right, first clip | content right, second clip |"
    );
    println!("| --- | --- | --- | --- | --- |");
    let pct = |n: usize, of: usize| 100.0 * n as f64 / of.max(1) as f64;
    for (tally, asymmetry) in tallies.iter().zip(&settings) {
        println!(
            "| {} | {:.4} | {:.4} | {:.1}% | {:.1}% |",
            asymmetry.name(),
            tally.offset_error[0] / tally.outputs as f64,
            tally.offset_error[1] / tally.outputs as f64,
            pct(tally.content_right[0], tally.outputs),
            pct(tally.content_right[1], tally.outputs),
        );
    }
    println!(
        "| (the sources' parts) | 0 | 0 | {:.1}% | {:.1}% |",
        pct(source_tally.content_right[0], source_tally.outputs),
        pct(source_tally.content_right[1], source_tally.outputs),
    );
}
