//! Study: how much do the evaluation's spike figures depend on its one noise
//! draw, and does the default spike finder beat the own-jump finder (trunk
//! joints judged by their own jump too) over several draws?
//!
//! On the test takes, the evaluation's spike conditions
//! ([`mocap_clean::noisy_take`]) are drawn again with other seeds
//! (the evaluation's own is 7). For each draw: spikes found (the default
//! finder, trunk joints judged by their subtree alone; and the own-jump
//! finder, every joint by its own jump too) and bridged, then the
//! shipped model; the two Butterworth references of the target (the
//! best fixed one on this condition, 2 Hz, and the per-take cross-validated
//! one); the true spikes bridged, then the model (the oracle); and on spikes
//! alone, the two finders with and without the model, and the best tuned
//! filter of the evaluation on that condition (a running median of 3 frames).
//! Mean rotation error in degrees, frame-weighted.
//!
//! cargo run --release -p mocap-studies --example clean_spike_draws -- DATA [SEEDS]

use mocap_studies::clean as support;

use mocap_clean::{
    bridge_spikes, filter_motion, find_spikes, noisy_take, rotation_error_deg, CleanModel,
    DespikeOptions, Filter, FoundSpike,
};

/// Columns: spikes on random noise (finder + model: default, own-jump;
/// Butterworth 2 Hz, cross-validated Butterworth), spikes alone (finder
/// alone: default, own-jump; finder + model: default, own-jump),
/// the oracle on spikes on random noise, the median of 3 frames on spikes
/// alone.
const COLUMNS: usize = 10;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let draws = support::test_draws()?;
    let (takes, frames) = (&draws.takes, draws.frames);
    let model = CleanModel::load_default(Default::default())?;
    let finders = [
        DespikeOptions::default(),
        DespikeOptions {
            trunk_by_subtree: false,
            ..DespikeOptions::default()
        },
    ];
    println!(
        "{} test takes, {frames} frames; the evaluation's noise (seed 7) and other draws. Mean rotation error \
         (degrees); ratio = cross-validated Butterworth / spikes found then the model.\n",
        takes.len()
    );
    println!(
        "| seed | spikes: default finder + model | own-jump finder + model | Butterworth 2 Hz | \
         cross-validated Butterworth | ratio (default, own-jump) | spikes alone: default finder | \
         own-jump finder | default finder + model | own-jump finder + model | oracle: true spikes \
         bridged, then the model | ratio (oracle) | spikes alone: median of 3 | ratio to it (default finder, \
         own-jump) |"
    );
    println!(
        "| ---: | ---: | ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |"
    );
    support::over_draws(
        &draws,
        COLUMNS,
        |options, i| {
            let clean = &takes[i].motion;
            let weight = clean.frame_count() as f64;
            let error = |m: &mocap_core::Motion| rotation_error_deg(clean, m) * weight;
            let found_then_model = |spiked: &mocap_core::Motion, finder: &DespikeOptions| {
                let bridged = bridge_spikes(spiked, &find_spikes(spiked, finder));
                let cleaned = model.clean(&bridged, None).expect("clean");
                (error(&bridged), error(&cleaned))
            };
            let mut row = [0.0f64; COLUMNS];
            let (spiked, spikes) = noisy_take(takes, i, 1, options).expect("noise");
            row[0] = found_then_model(&spiked, &finders[0]).1;
            row[1] = found_then_model(&spiked, &finders[1]).1;
            let filtered = |f: Filter| error(&filter_motion(&spiked, &f).expect("filter"));
            row[2] = filtered(Filter::Butterworth {
                order: 2,
                cutoff_hz: 2.0,
            });
            row[3] = filtered(Filter::ButterworthGcv { order: 2 });
            let truth: Vec<FoundSpike> = spikes.iter().map(|&s| FoundSpike::from(s)).collect();
            row[8] = error(
                &model
                    .clean(&bridge_spikes(&spiked, &truth), None)
                    .expect("clean"),
            );
            let alone = noisy_take(takes, i, 2, options).expect("noise").0;
            row[9] = error(&filter_motion(&alone, &Filter::Median { window: 3 }).expect("filter"));
            (row[4], row[6]) = found_then_model(&alone, &finders[0]);
            (row[5], row[7]) = found_then_model(&alone, &finders[1]);
            row.to_vec()
        },
        print_row,
        "mean",
    );
    Ok(())
}

fn print_row(label: &str, m: &[f64]) {
    println!(
        "| {label} | {:.3} | {:.3} | {:.3} | {:.3} | {:.2}x, {:.2}x | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.2}x | {:.3} | {:.2}x, {:.2}x |",
        m[0],
        m[1],
        m[2],
        m[3],
        m[3] / m[0],
        m[3] / m[1],
        m[4],
        m[5],
        m[6],
        m[7],
        m[8],
        m[3] / m[8],
        m[9],
        m[9] / m[4],
        m[9] / m[5]
    );
}
