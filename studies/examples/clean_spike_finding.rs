//! Study: which spikes does rule-based spike finding miss, and where should
//! it look?
//!
//! On validation takes with random noise (sigma drawn in 0-10 degrees) and
//! 1-3 spikes, seeded as `spike_oracle` seeds its last row, spikes are looked
//! for either in the shipped model's output (local rotations, span 3) or in
//! the noisy input (as `mocap clean apply --despike` does), on local or global
//! rotations ([`DespikeOptions::global`]), with a grid of spans and
//! thresholds (and of the longest spike looked for, on global rotations in
//! the input); they are bridged in the input and the model runs on it. Printed: the mean
//! rotation error of each setting, two oracles (the true spikes bridged; the
//! model at the noise level estimated without spikes), the best fixed filter
//! of the evaluation's spike condition (Butterworth, 2 Hz), and, for finding
//! in the model's output and the default, every true spike sorted into found / found on a joint
//! above or below / missed (by why), weighted by the error it adds to the
//! input. `SPIKE_DETAILS=1` lists the missed spikes with their jumps.
//!
//! cargo run --release -p mocap-studies --example clean_spike_finding -- DATA [TAKES]

use mocap_studies::clean as support;

use std::time::Instant;

use mocap_clean::{
    bridge_spikes, filter_motion, find_spikes, normalised_jumps, rotation_error_deg, CleanModel,
    DespikeOptions, Filter, FoundSpike,
};
use mocap_core::rotation::angle_between;
use mocap_core::Motion;
use rayon::prelude::*;

struct TakeResult {
    frames: usize,
    /// Error times frames, per setting, then the two oracles.
    errors: Vec<f64>,
    /// Per sorted setting: the true spikes' (category, error mass in degrees
    /// x joint-frames), the found spikes matching none, the missed spikes.
    sorted: Vec<Sorting>,
    /// The noise level estimated without and with the spikes.
    levels: (f64, f64),
}

struct Sorting {
    spikes: Vec<(&'static str, f64)>,
    false_found: usize,
    details: Vec<String>,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = support::parse()?;
    let model = CleanModel::load_default(Default::default())?;
    let takes = args.validation_takes()?;
    // (label, where spikes are looked for: 0 the model's output, 1 the
    // noisy input; options). Spikes up to 90 frames long, then the longest
    // spike varied.
    let mut settings: Vec<(String, usize, Option<DespikeOptions>)> =
        vec![("no spike finding".to_string(), 0, None)];
    for (signal, place) in [(0, "model output"), (1, "input")] {
        for global in [false, true] {
            for span in [1, 2, 3] {
                for threshold in [2.0f32, 2.5, 3.0, 4.0, 5.0] {
                    settings.push((
                        format!(
                            "{place}, {} rotations, span {span}, threshold {threshold}",
                            if global { "global" } else { "local" },
                        ),
                        signal,
                        Some(DespikeOptions {
                            span,
                            threshold,
                            global,
                            max_frames: 90,
                            trunk_by_subtree: false,
                        }),
                    ));
                }
            }
        }
    }
    // The longest spike looked for, on the best of the above.
    for max_frames in [24, 30, 45, 60] {
        for threshold in [2.5f32, 3.0] {
            settings.push((
                format!(
                    "input, global rotations, span 1, threshold {threshold}, longest spike {max_frames} frames"
                ),
                1,
                Some(DespikeOptions {
                    span: 1,
                    threshold,
                    global: true,
                    max_frames,
                    trunk_by_subtree: false,
                }),
            ));
        }
    }
    // The spikes of these two are sorted: finding in the model's output and
    // the default.
    let sorted = [
        (
            "model output, local rotations, span 3, threshold 3",
            0,
            DespikeOptions {
                span: 3,
                threshold: 3.0,
                global: false,
                max_frames: 90,
                trunk_by_subtree: false,
            },
        ),
        (
            "input, default settings (--despike)",
            1,
            DespikeOptions::default(),
        ),
    ];
    let started = Instant::now();
    let results: Vec<TakeResult> = (0..takes.len())
        .into_par_iter()
        .map(|i| {
            let support::SpikedTake {
                noisy,
                spiked,
                spikes,
            } = support::spiked_take(&takes, i, None);
            let clean = &takes[i].motion;
            let n = clean.frame_count();
            let (cleaned, spiked_level) = model.clean_reporting(&spiked, None).expect("clean");
            let (_, noisy_level) = model.clean_reporting(&noisy, None).expect("clean");
            let looked_at = |signal: usize| [&cleaned, &spiked][signal];
            let mut errors: Vec<f64> = settings
                .iter()
                .map(|(_, signal, options)| {
                    let out = match options {
                        None => cleaned.clone(),
                        Some(o) => {
                            let found = find_spikes(looked_at(*signal), o);
                            model
                                .clean(&bridge_spikes(&spiked, &found), None)
                                .expect("clean")
                        }
                    };
                    rotation_error_deg(clean, &out) * n as f64
                })
                .collect();
            let truth: Vec<FoundSpike> = spikes.iter().map(|&s| FoundSpike::from(s)).collect();
            let oracle = model
                .clean(&bridge_spikes(&spiked, &truth), None)
                .expect("clean");
            errors.push(rotation_error_deg(clean, &oracle) * n as f64);
            let at_noisy_level = model
                .clean_at_level(&spiked, None, noisy_level)
                .expect("clean")
                .0;
            errors.push(rotation_error_deg(clean, &at_noisy_level) * n as f64);
            // The reference of the target: the best fixed filter on
            // the evaluation's spike condition.
            let butterworth = filter_motion(
                &spiked,
                &Filter::Butterworth {
                    order: 2,
                    cutoff_hz: 2.0,
                },
            )
            .expect("filter");
            errors.push(rotation_error_deg(clean, &butterworth) * n as f64);
            let sorted = sorted
                .iter()
                .map(|(_, signal, options)| {
                    sort_spikes(
                        i,
                        clean,
                        &noisy,
                        looked_at(*signal),
                        &spiked,
                        &truth,
                        options,
                    )
                })
                .collect();
            TakeResult {
                frames: n,
                errors,
                sorted,
                levels: (noisy_level.unwrap_or(0.0), spiked_level.unwrap_or(0.0)),
            }
        })
        .collect();
    let frames: usize = results.iter().map(|r| r.frames).sum();
    println!(
        "{} validation takes, {frames} frames, sigma drawn in 0-10, 1-3 spikes; spikes found (where the setting \
         says) bridged in the input, then the shipped model. Mean rotation error (degrees).\n",
        takes.len()
    );
    println!("| setting | error |\n| --- | ---: |");
    let mean =
        |column: usize| results.iter().map(|r| r.errors[column]).sum::<f64>() / frames as f64;
    for (s, (label, _, _)) in settings.iter().enumerate() {
        println!("| {label} | {:.3} |", mean(s));
    }
    println!(
        "| oracle: true spikes bridged | {:.3} |",
        mean(settings.len())
    );
    println!(
        "| oracle: no spike finding, the model at the level estimated without spikes | {:.3} |",
        mean(settings.len() + 1)
    );
    println!(
        "| reference: butterworth 2 Hz (2nd order), no spike finding | {:.3} |",
        mean(settings.len() + 2)
    );
    let lift: Vec<f64> = results.iter().map(|r| r.levels.1 - r.levels.0).collect();
    println!(
        "\nNoise level estimated with spikes minus without: mean {:.2} deg, largest {:.2} deg",
        lift.iter().sum::<f64>() / lift.len() as f64,
        lift.iter().cloned().fold(f64::MIN, f64::max)
    );
    for (k, (label, _, options)) in sorted.iter().enumerate() {
        println!(
            "\nTrue spikes, {label} ({options:?}); error mass = degrees summed over the spike's joints and \
             frames (noisy against spiked).\n"
        );
        println!("| category | spikes | share of error mass |\n| --- | ---: | ---: |");
        let all: Vec<(&str, f64)> = results
            .iter()
            .flat_map(|r| r.sorted[k].spikes.clone())
            .collect();
        let total: f64 = all.iter().map(|s| s.1).sum();
        let mut categories: Vec<&str> = all.iter().map(|s| s.0).collect();
        categories.sort();
        categories.dedup();
        for c in categories {
            let count = all.iter().filter(|s| s.0 == c).count();
            let mass: f64 = all.iter().filter(|s| s.0 == c).map(|s| s.1).sum();
            println!("| {c} | {count} | {:.1}% |", 100.0 * mass / total);
        }
        let false_found: usize = results.iter().map(|r| r.sorted[k].false_found).sum();
        println!("\nFound spikes matching no true spike: {false_found}");
        if std::env::var_os("SPIKE_DETAILS").is_some() {
            println!("\nMissed (other), normalised jumps of the subtree's joints:\n");
            for r in &results {
                for d in &r.sorted[k].details {
                    println!("- {d}");
                }
            }
        }
    }
    println!("\n{:.0} s", started.elapsed().as_secs_f64());
    Ok(())
}

/// Sorts the true spikes of take `take` by what spike finding with
/// `options` on `looked_at` made of them.
fn sort_spikes(
    take: usize,
    clean: &Motion,
    noisy: &Motion,
    looked_at: &Motion,
    spiked: &Motion,
    truth: &[FoundSpike],
    options: &DespikeOptions,
) -> Sorting {
    let skeleton = clean.skeleton();
    let n = clean.frame_count();
    let found = find_spikes(looked_at, options);
    let related =
        |a: usize, b: usize| skeleton.subtree(a).contains(&b) || skeleton.subtree(b).contains(&a);
    let mut matched = vec![false; found.len()];
    let jump = normalised_jumps(looked_at, options.span, options.global);
    let joint_count = skeleton.joint_count();
    let mut details = Vec::new();
    let spikes = truth
        .iter()
        .map(|s| {
            let joints: Vec<usize> = skeleton
                .subtree(s.joint)
                .into_iter()
                .filter(|&k| skeleton.joint(k).has_rotation_channels())
                .collect();
            let mut mass = 0.0f64;
            let mut biggest = 0.0f32;
            for f in s.start..s.start + s.frames {
                for &k in &joints {
                    let e = angle_between(noisy.local_rotation(f, k), spiked.local_rotation(f, k))
                        .to_degrees();
                    mass += e as f64;
                    biggest = biggest.max(e);
                }
            }
            let mut category = "";
            for (m, f) in found.iter().enumerate() {
                if support::overlap(f, s) >= 0.5 {
                    if f.joint == s.joint {
                        matched[m] = true;
                        category = "found";
                        break;
                    } else if related(f.joint, s.joint) {
                        matched[m] = true;
                        category = "found on a joint above or below";
                    }
                }
            }
            if category.is_empty() {
                category = if joints.len() < 2 {
                    "missed: leaf joint"
                } else if s.start + s.frames >= n {
                    "missed: runs into the end"
                } else if biggest < 10.0 {
                    "missed: under 10 degrees"
                } else if s.frames <= 2 {
                    "missed: 1-2 frames"
                } else {
                    "missed: other"
                };
            }
            if category == "missed: other" {
                let at = |t: usize| {
                    joints
                        .iter()
                        .map(|&k| format!("{:.1}", jump[t.min(n - 1) * joint_count + k]))
                        .collect::<Vec<_>>()
                        .join(" ")
                };
                details.push(format!(
                    "take {take} ({n} frames) {}@{}+{} max {biggest:.0} deg; jumps at start [{}] at end [{}]",
                    skeleton.joint(s.joint).name,
                    s.start,
                    s.frames,
                    at(s.start),
                    at(s.start + s.frames)
                ));
            }
            (category, mass)
        })
        .collect();
    Sorting {
        spikes,
        false_found: matched.iter().filter(|&&m| !m).count(),
        details,
    }
}
