//! How well the style autoencoder reproduces each clip with no style
//! ([`mocap_style::source_reconstruction_deg`]), by set and content:
//! the measurement behind [`mocap_style::UNFAMILIAR_SOURCE_DEG`].
//!
//! ```text
//! cargo run --release -p mocap-studies --example style_familiarity -- [--model M.safetensors] \
//!     [--trained-on walk,walk-back,...] DIR...
//! ```
//!
//! Prints a Markdown table: per (set, content), the clips, whether the
//! shipped model trained on that content, and the median, 90th percentile
//! and largest reconstruction error (degrees).

use std::collections::BTreeMap;
use std::path::PathBuf;

use mocap_nn::device::DeviceChoice;
use mocap_style::{
    labelled_paths, list_bvh, load_model, source_reconstruction_deg, ClipFilter, WALKING_CONTENTS,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut model_path = None;
    let mut inputs = Vec::new();
    // The shipped model's training contents (bench/style/run.sh).
    let mut trained_on: Vec<String> = WALKING_CONTENTS.map(String::from).to_vec();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--model" => model_path = Some(PathBuf::from(args.next().ok_or("--model FILE")?)),
            "--trained-on" => {
                let list = args.next().ok_or("--trained-on CONTENT,...")?;
                trained_on = list.split(',').map(String::from).collect();
            }
            _ => inputs.push(PathBuf::from(a)),
        }
    }
    let model = load_model(model_path.as_deref(), DeviceChoice::Cpu)?;
    let files = labelled_paths(&list_bvh(&inputs)?, &ClipFilter::default())?;
    let mut groups: BTreeMap<(String, String), Vec<f32>> = BTreeMap::new();
    for (path, labels) in &files {
        let motion = mocap_core::io::bvh::read_bvh(path)?;
        let error = source_reconstruction_deg(&model, &motion)?;
        groups
            .entry((labels.set.clone(), labels.content.clone()))
            .or_default()
            .push(error);
    }
    // Every clip's error, by whether the model trained on its content.
    let (mut known, mut unknown) = (Vec::new(), Vec::new());
    for ((_, content), errors) in &groups {
        if trained_on.contains(content) {
            known.extend(errors);
        } else {
            unknown.extend(errors);
        }
    }
    println!("| set | content | trained on | clips | median (deg) | 90th percentile | largest |");
    println!("| --- | --- | --- | ---: | ---: | ---: | ---: |");
    for ((set, content), mut errors) in groups {
        errors.sort_by(f32::total_cmp);
        let at = |q: f32| errors[((errors.len() - 1) as f32 * q).round() as usize];
        println!(
            "| {set} | {content} | {} | {} | {:.2} | {:.2} | {:.2} |",
            if trained_on.contains(&content) {
                "yes"
            } else {
                "no"
            },
            errors.len(),
            at(0.5),
            at(0.9),
            errors[errors.len() - 1],
        );
    }
    let share =
        |v: &[f32], t: f32| v.iter().filter(|&&e| e > t).count() as f64 / v.len().max(1) as f64;
    println!();
    println!(
        "| threshold (deg) | clips of trained contents above ({}) | other clips above ({}) |",
        known.len(),
        unknown.len()
    );
    println!("| ---: | ---: | ---: |");
    for t in [5.0, 6.0, 7.0, 8.0, 9.0, 10.0] {
        println!(
            "| {t:.0} | {:.1}% | {:.1}% |",
            100.0 * share(&known, t),
            100.0 * share(&unknown, t)
        );
    }
    Ok(())
}
