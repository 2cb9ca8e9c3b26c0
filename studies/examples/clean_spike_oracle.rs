//! Study: how far could spikes be taken out if we knew where they are?
//!
//! An upper bound for spike finding, on validation takes with random noise of
//! fixed sigma plus 1-3 spikes (the evaluation's spike noise): the spikes'
//! joints and frames are taken from the noise generator (an oracle), and
//! each spiked subtree is either
//!
//! - bridged (slerp from the frame before the spike to the frame after it,
//!   what `mocap clean apply --despike` does with the spikes it finds), then the
//!   learned Wiener filter runs; or
//! - bridged, then marked missing for the Wiener filter, which estimates it
//!   from the rest of the body in every segment the spike touches
//!   (`WienerFilter::filter_features_missing`, (3)); or
//! - both: the bridged take's filtered output outside the spikes and the
//!   estimate from the rest of the body over the spikes' frames.
//!
//! A last row draws each take's sigma uniformly in [0, 10] degrees, as the
//! evaluation's spike condition does (`mocap clean eval`).
//!
//! The same with the shipped model (the network reading and correcting that
//! filter) in place of the filter: reading the spikes, after bridging the
//! true ones, and on the takes without spikes.
//!
//! Last, not an oracle: spike finding on local rotations in the shipped
//! model's output, bridged in that output, or in the input before the model
//! runs again; and as `mocap clean apply --despike` runs it (on global
//! rotations, in the input, before the model, or before the Butterworth
//! filter).
//!
//! Against: the noisy input, the best fixed Butterworth on the evaluation's
//! spike condition (2nd order, 2 Hz), the Wiener filter reading the spikes
//! as they are, and the Wiener filter on the same take without spikes (what
//! perfect spike removal would give). Mean rotation error over all joints
//! and frames (degrees).
//!
//! cargo run --release -p mocap-studies --example clean_spike_oracle -- DATA [TAKES] [SIGMAS] [WIENER_FILE]

use mocap_studies::clean as support;

use std::time::Instant;

use mocap_clean::{
    bridge_spikes, filter_motion, remove_spikes, rotation_error_deg, CleanModel, DespikeOptions,
    FeatureLayout, Filter, FoundSpike, Representation, WienerFilter,
};
use mocap_core::Motion;
use rayon::prelude::*;

/// The methods, in table order.
const METHODS: [&str; 14] = [
    "noisy input",
    "butterworth 2 Hz",
    "Wiener filter",
    "oracle: bridge, Wiener",
    "oracle: bridge, Wiener told the spikes are missing",
    "oracle: bridge, Wiener; spike frames from the rest of the body",
    "Wiener filter, same take without spikes",
    "shipped model",
    "oracle: bridge, shipped model",
    "shipped model, same take without spikes",
    "shipped model, spikes found in its output (local rotations) bridged there",
    "shipped model, spikes found in its output (local rotations) bridged in the input, shipped model again",
    "spikes found in the input (global rotations, --despike) bridged, then the shipped model",
    "spikes found in the input (global rotations, --despike) bridged, then butterworth 2 Hz",
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = support::parse()?;
    let wiener_path = args
        .rest
        .first()
        .map_or("models/clean-wiener.safetensors", String::as_str);
    let wiener = WienerFilter::load(std::path::Path::new(wiener_path))?;
    let model = CleanModel::load_default(Default::default())?;
    let takes = args.validation_takes()?;
    let frames: usize = takes.iter().map(|t| t.motion.frame_count()).sum();
    println!(
        "{} validation takes, {frames} frames; random noise of the given sigma, then 1-3 spikes (sd 16 frames) \
         from other takes; Wiener filter {wiener_path}; mean rotation error (degrees), frame-weighted.\n",
        takes.len()
    );
    print!("| sigma (deg) |");
    for m in METHODS {
        print!(" {m} |");
    }
    println!("\n| ---: |{}", " ---: |".repeat(METHODS.len()));
    let started = Instant::now();
    // Fixed levels, then (None) a level drawn per take in [0, 10].
    let levels: Vec<Option<f32>> = args.sigmas.iter().map(|&s| Some(s)).chain([None]).collect();
    for &level in &levels {
        let per_take: Vec<[f64; METHODS.len()]> = (0..takes.len())
            .into_par_iter()
            .map(|i| {
                let support::SpikedTake {
                    noisy,
                    spiked,
                    spikes,
                } = support::spiked_take(&takes, i, level);
                let clean = &takes[i].motion;
                let n = clean.frame_count();
                let found: Vec<FoundSpike> = spikes.iter().map(|&s| FoundSpike::from(s)).collect();
                let bridged = bridge_spikes(&spiked, &found);
                let layout =
                    FeatureLayout::new(clean.skeleton(), Representation::Rot6d).expect("rig");
                let c = layout.channels();
                // Channels of every spiked joint and its subtree, over the
                // spike's frames.
                let mut missing = vec![false; n * c];
                for s in &spikes {
                    for k in clean.skeleton().subtree(s.joint) {
                        let Some(slot) = layout.joints.iter().position(|&j| j == k) else {
                            continue;
                        };
                        for f in s.start..(s.start + s.frames).min(n) {
                            for ch in slot * 6..slot * 6 + 6 {
                                missing[f * c + ch] = true;
                            }
                        }
                    }
                }
                let run = |motion: &Motion, told: bool| -> Vec<f32> {
                    let mut features = layout.encode(motion);
                    wiener.filter_features_missing(
                        &mut features,
                        None,
                        told.then_some(&missing[..]),
                    );
                    features
                };
                let decoded = |features: &[f32]| {
                    let mut out = clean.clone();
                    layout.decode_into(features, &mut out);
                    out
                };
                let bridged_filtered = run(&bridged, false);
                let bridged_told = run(&bridged, true);
                let combined: Vec<f32> = bridged_filtered
                    .iter()
                    .zip(&bridged_told)
                    .zip(&missing)
                    .map(|((&a, &b), &gone)| if gone { b } else { a })
                    .collect();
                // Not an oracle: spike finding on the model's output
                // (local rotations), its spikes bridged in that
                // output, or in the input before cleaning it again.
                let on_output = DespikeOptions {
                    threshold: 3.0,
                    span: 3,
                    global: false,
                    max_frames: 90,
                    trunk_by_subtree: false,
                };
                let (found_bridged_after, found_after) =
                    remove_spikes(&model.clean(&spiked, None).expect("clean"), &on_output);
                let (despiked, _) = remove_spikes(&spiked, &DespikeOptions::default());
                let outputs = [
                    spiked.clone(),
                    filter_motion(
                        &spiked,
                        &Filter::Butterworth {
                            order: 2,
                            cutoff_hz: 2.0,
                        },
                    )
                    .expect("filter"),
                    decoded(&run(&spiked, false)),
                    decoded(&bridged_filtered),
                    decoded(&bridged_told),
                    decoded(&combined),
                    decoded(&run(&noisy, false)),
                    model.clean(&spiked, None).expect("clean"),
                    model.clean(&bridged, None).expect("clean"),
                    model.clean(&noisy, None).expect("clean"),
                    found_bridged_after,
                    model
                        .clean(&bridge_spikes(&spiked, &found_after), None)
                        .expect("clean"),
                    model.clean(&despiked, None).expect("clean"),
                    filter_motion(
                        &despiked,
                        &Filter::Butterworth {
                            order: 2,
                            cutoff_hz: 2.0,
                        },
                    )
                    .expect("filter"),
                ];
                outputs.map(|out| rotation_error_deg(clean, &out) * n as f64)
            })
            .collect();
        match level {
            Some(sigma) => print!("| {sigma} |"),
            None => print!("| drawn in 0-10 |"),
        }
        for m in 0..METHODS.len() {
            let sum: f64 = per_take.iter().map(|e| e[m]).sum();
            print!(" {:.3} |", sum / frames as f64);
        }
        println!();
    }
    println!("\n{:.0} s", started.elapsed().as_secs_f64());
    Ok(())
}
