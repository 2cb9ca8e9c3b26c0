//! Study: of what spike finding loses against the oracle, how much is the
//! wrong joint, how much the wrong frames, how much the spikes never found,
//! and which joints' spikes are missed?
//!
//! On validation takes with the spike studies' noise (random noise drawn in
//! 0-10 degrees, 1-3 spikes; `support::spiked_take`), the finder's spikes
//! are bridged in the input and the shipped model runs, as
//! `mocap clean apply --despike` does, for the own-jump finder (every
//! joint judged by its own jump as well as its subtree's) and the default
//! (trunk joints judged by their subtree's jump alone,
//! [`DespikeOptions::trunk_by_subtree`]). Beside each, every found spike that
//! overlaps a true spike of a related joint by half its frames is corrected:
//! its joint set to the true one (frames kept), or its joint and frames
//! both; spikes matching none are kept or dropped. The true spikes bridged
//! are the oracle. Also: bridges anchored on the mean of 4 frames on each
//! side instead of one, and the default finder at other thresholds.
//! Printed: the mean rotation error of each, where found spikes sit against
//! the true ones, and the missed spikes' error by joint.
//!
//! cargo run --release -p mocap-studies --example clean_spike_attribution -- DATA [TAKES]

use mocap_studies::clean as support;

use std::collections::BTreeMap;
use std::time::Instant;

use mocap_clean::{
    bridge_spikes, find_spikes, rotation_error_deg, CleanModel, DespikeOptions, FoundSpike,
};
use mocap_core::rotation::{angle_between, mean_of_close, slerp};
use mocap_core::{Motion, Skeleton};
use rayon::prelude::*;

/// Where a found spike lies against the true spikes: 0 at the true joint,
/// 1 at a joint above it, 2 below it, 3 matching none; and which.
fn relation(
    skeleton: &Skeleton,
    found: &FoundSpike,
    truth: &[FoundSpike],
) -> (usize, Option<usize>) {
    for (i, s) in truth.iter().enumerate() {
        if support::overlap(found, s) < 0.5 {
            continue;
        }
        if found.joint == s.joint {
            return (0, Some(i));
        }
        if skeleton.subtree(found.joint).contains(&s.joint) {
            return (1, Some(i));
        }
        if skeleton.subtree(s.joint).contains(&found.joint) {
            return (2, Some(i));
        }
    }
    (3, None)
}

/// [`bridge_spikes`] with each end anchored on the mean of up to `k`
/// frames beside the spike, placed at their middle frame (so steady motion
/// is not pulled back by the averaging).
fn bridge_anchored(motion: &Motion, spikes: &[FoundSpike], k: usize) -> Motion {
    let mut out = motion.clone();
    let skeleton = motion.skeleton();
    let frames = motion.frame_count();
    for s in spikes {
        let end = (s.start + s.frames).min(frames);
        let before = s.start.saturating_sub(k)..s.start;
        let after = end..(end + k).min(frames);
        if s.start >= end || (before.is_empty() && after.is_empty()) {
            continue;
        }
        let middle = |r: &std::ops::Range<usize>| (r.start + r.end - 1) as f32 / 2.0;
        for j in skeleton.subtree(s.joint) {
            if !skeleton.joint(j).has_rotation_channels() {
                continue;
            }
            let anchor = |r: &std::ops::Range<usize>| {
                (!r.is_empty())
                    .then(|| mean_of_close(r.clone().map(|f| motion.local_rotation(f, j))))
            };
            let (a, b) = (anchor(&before), anchor(&after));
            for f in s.start..end {
                let q = match (a, b) {
                    (Some(a), Some(b)) => {
                        let (ta, tb) = (middle(&before), middle(&after));
                        slerp(a, b, (f as f32 - ta) / (tb - ta))
                    }
                    (Some(q), None) | (None, Some(q)) => q,
                    (None, None) => unreachable!("checked above"),
                };
                out.set_local_rotation(f, j, q);
            }
        }
    }
    out
}

/// One take's results: frames; the errors (x frames) shared by the
/// finders (see `main`); each finder's.
type TakeResult = (usize, Vec<f64>, Vec<FinderResult>);

/// One finder's results on one take.
#[derive(Default)]
struct FinderResult {
    /// Error x frames: found, joint corrected, joint and frames corrected,
    /// false ones dropped too, found with anchors of 4 frames.
    errors: Vec<f64>,
    /// Found spikes at the true joint, above it, below it, matching none.
    places: [usize; 4],
    /// Missed spikes: joint name -> (count, error mass in degrees x
    /// joint-frames, noisy against spiked).
    missed: BTreeMap<String, (usize, f64)>,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = support::parse()?;
    let model = CleanModel::load_default(Default::default())?;
    let takes = args.validation_takes()?;
    let finders = [
        (
            "own jump too",
            DespikeOptions {
                trunk_by_subtree: false,
                ..DespikeOptions::default()
            },
        ),
        ("default (trunk by subtree)", DespikeOptions::default()),
    ];
    let thresholds = [2.5f32, 2.75, 3.25, 3.5];
    let started = Instant::now();
    let results: Vec<TakeResult> = (0..takes.len())
        .into_par_iter()
        .map(|i| {
            let support::SpikedTake {
                spiked,
                spikes,
                noisy,
            } = support::spiked_take(&takes, i, None);
            let clean = &takes[i].motion;
            let skeleton = clean.skeleton();
            let n = clean.frame_count();
            let error_of = |m: &Motion| {
                rotation_error_deg(clean, &model.clean(m, None).expect("clean")) * n as f64
            };
            let error = |list: &[FoundSpike]| error_of(&bridge_spikes(&spiked, list));
            let truth: Vec<FoundSpike> = spikes.iter().map(|&s| FoundSpike::from(s)).collect();
            // No finding, the oracle, the oracle anchored, no spikes at all,
            // then the default finder at other thresholds.
            let mut shared = vec![
                error_of(&spiked),
                error(&truth),
                error_of(&bridge_anchored(&spiked, &truth, 4)),
                error_of(&noisy),
            ];
            for &threshold in &thresholds {
                let options = DespikeOptions {
                    threshold,
                    ..DespikeOptions::default()
                };
                shared.push(error(&find_spikes(&spiked, &options)));
            }
            let per_finder = finders
                .iter()
                .map(|(_, options)| {
                    let found = find_spikes(&spiked, options);
                    let mut result = FinderResult::default();
                    let (mut joint_fixed, mut both_fixed, mut true_only) =
                        (Vec::new(), Vec::new(), Vec::new());
                    for f in &found {
                        let (place, matched) = relation(skeleton, f, &truth);
                        result.places[place] += 1;
                        match matched {
                            Some(m) => {
                                joint_fixed.push(FoundSpike {
                                    joint: truth[m].joint,
                                    ..*f
                                });
                                both_fixed.push(truth[m]);
                                true_only.push(truth[m]);
                            }
                            None => {
                                joint_fixed.push(*f);
                                both_fixed.push(*f);
                            }
                        }
                    }
                    result.errors = vec![
                        error(&found),
                        error(&joint_fixed),
                        error(&both_fixed),
                        error(&true_only),
                        error_of(&bridge_anchored(&spiked, &found, 4)),
                    ];
                    for s in &truth {
                        if found
                            .iter()
                            .any(|f| relation(skeleton, f, std::slice::from_ref(s)).0 < 3)
                        {
                            continue;
                        }
                        let mut mass = 0.0f64;
                        for k in skeleton.subtree(s.joint) {
                            if !skeleton.joint(k).has_rotation_channels() {
                                continue;
                            }
                            for f in s.start..s.start + s.frames {
                                mass += angle_between(
                                    noisy.local_rotation(f, k),
                                    spiked.local_rotation(f, k),
                                )
                                .to_degrees() as f64;
                            }
                        }
                        let entry = result
                            .missed
                            .entry(skeleton.joint(s.joint).name.clone())
                            .or_default();
                        entry.0 += 1;
                        entry.1 += mass;
                    }
                    result
                })
                .collect();
            (n, shared, per_finder)
        })
        .collect();
    let frames: usize = results.iter().map(|r| r.0).sum();
    let mean = |e: &dyn Fn(&TakeResult) -> f64| results.iter().map(e).sum::<f64>() / frames as f64;
    println!(
        "{} validation takes, {frames} frames, sigma drawn in 0-10, 1-3 spikes; spikes bridged in the input, \
         then the shipped model. Mean rotation error (degrees).\n",
        takes.len()
    );
    println!("| spikes bridged | error |\n| --- | ---: |");
    println!("| none (no spike finding) | {:.3} |", mean(&|r| r.1[0]));
    let rows = [
        "found",
        "found, joint corrected",
        "found, joint and frames corrected",
        "found, joint and frames corrected, false ones dropped",
        "found, bridges anchored on 4 frames each side",
    ];
    for (f, (name, _)) in finders.iter().enumerate() {
        for (k, row) in rows.iter().enumerate() {
            println!("| {name}: {row} | {:.3} |", mean(&|r| r.2[f].errors[k]));
        }
    }
    for (k, threshold) in thresholds.iter().enumerate() {
        println!(
            "| default finder at threshold {threshold} | {:.3} |",
            mean(&|r| r.1[4 + k])
        );
    }
    println!("| oracle: true spikes | {:.3} |", mean(&|r| r.1[1]));
    println!(
        "| oracle, bridges anchored on 4 frames each side | {:.3} |",
        mean(&|r| r.1[2])
    );
    println!(
        "| no spikes (random noise alone) | {:.3} |",
        mean(&|r| r.1[3])
    );
    for (f, (name, _)) in finders.iter().enumerate() {
        let mut places = [0usize; 4];
        let mut missed: BTreeMap<String, (usize, f64)> = BTreeMap::new();
        for r in &results {
            for (k, p) in r.2[f].places.iter().enumerate() {
                places[k] += p;
            }
            for (joint, (count, mass)) in &r.2[f].missed {
                let entry = missed.entry(joint.clone()).or_default();
                entry.0 += count;
                entry.1 += mass;
            }
        }
        println!(
            "\n{name}: found spikes {} at the true joint, {} at a joint above it, {} below it, {} matching no \
             true spike. Missed spikes by joint (error mass: degrees summed over the spike's joints and frames, \
             noisy against spiked; the largest first):\n",
            places[0], places[1], places[2], places[3]
        );
        let total: f64 = missed.values().map(|m| m.1).sum();
        let mut list: Vec<_> = missed.into_iter().collect();
        list.sort_by(|a, b| b.1 .1.total_cmp(&a.1 .1));
        println!("| joint | spikes | error mass |\n| --- | ---: | ---: |");
        for (joint, (count, mass)) in list {
            println!("| {joint} | {count} | {mass:.0} |");
        }
        println!("| all | | {total:.0} |");
    }
    println!("\n{:.0} s", started.elapsed().as_secs_f64());
    Ok(())
}
