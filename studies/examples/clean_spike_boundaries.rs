//! Study: which statistic tells a spike's boundary from the rest of a noisy
//! take best?
//!
//! Same takes and noise as `spike_finding` (sigma drawn in 0-10 degrees, 1-3
//! spikes). Two tables of recall at 1% and 0.1% false positives:
//!
//! - per subtree (first table): for every joint that can be a spike's and
//!   every frame, a score of its subtree's step there: the median of its
//!   joints' normalised jumps ([`normalised_jumps`], local or global
//!   rotations, capped by the joint's own jump as `find_spikes` requires, or
//!   not), or the mean distance its points (joints and end sites below it,
//!   relative to it) move between the frames before and after, raw or over
//!   the take's upper quartile. Positives: the boundaries of a true spike at
//!   its joint (turning some joint by >= 20 degrees); negatives: frames more
//!   than 6 frames from every boundary of a spike on that joint, or above or
//!   below it;
//! - per joint (second table): the step of each joint's local rotation on
//!   the noisy input, the shipped model's output or its Wiener filter's
//!   output: the mean step of `find_spikes` over its quartile, or the step
//!   between lines fitted on each side (over the take's median, or raw).
//!
//! cargo run --release -p mocap-studies --example clean_spike_boundaries -- DATA [TAKES]

use mocap_studies::clean as support;

use mocap_clean::{normalised_jumps, CleanModel, FeatureLayout, Representation};
use mocap_core::rotation::{angle_between, expmap_to_quat, quat_to_expmap};
use mocap_core::rotation::{Quat, Vec3};
use mocap_core::{forward_kinematics, Motion};
use rayon::prelude::*;

/// The value at the boundary (position 0) of the least-squares line through
/// `ys` at positions `xs`.
fn intercept(xs: &[f32], ys: &[Vec3]) -> Vec3 {
    let n = xs.len() as f32;
    let mx = xs.iter().sum::<f32>() / n;
    let my = ys.iter().copied().sum::<Vec3>() / n;
    let sxx: f32 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    if sxx == 0.0 {
        return my;
    }
    let sxy: Vec3 = xs.iter().zip(ys).map(|(x, y)| *y * (x - mx)).sum();
    my - sxy / sxx * mx
}

/// The step at the boundary before frame `t`: the angle between the lines
/// fitted to the `w` frames on each side, both taken to the boundary.
fn linear_step(motion: &Motion, k: usize, t: usize, w: usize) -> f32 {
    let side = |frames: std::ops::Range<usize>, reference: Quat| {
        let xs: Vec<f32> = frames
            .clone()
            .map(|f| f as f32 - (t as f32 - 0.5))
            .collect();
        let ys: Vec<Vec3> = frames
            .map(|f| quat_to_expmap(reference.inverse() * motion.local_rotation(f, k)))
            .collect();
        reference * expmap_to_quat(intercept(&xs, &ys))
    };
    let left = side(t - w..t, motion.local_rotation(t - 1, k));
    let right = side(t..t + w, motion.local_rotation(t, k));
    angle_between(left, right).to_degrees()
}

/// Per joint, `stat[t * n + k]` divided by the median over the take's
/// boundaries (a robust noise scale), at least 0.5 degrees.
fn median_normalised(stat: &mut [f32], n: usize, first: usize, last: usize) {
    for k in 0..n {
        let mut values: Vec<f32> = (first..=last).map(|t| stat[t * n + k]).collect();
        values.sort_by(f32::total_cmp);
        let scale = values[values.len() / 2].max(0.5);
        for t in first..=last {
            stat[t * n + k] /= scale;
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = support::parse()?;
    let model = CleanModel::load_default(Default::default())?;
    let wiener = model
        .base_wiener()
        .expect("the shipped model has a Wiener base");
    let takes = args.validation_takes()?;
    subtree_level(&takes, &model);
    // (statistic name) -> (positives, negatives)
    let names: Vec<String> = {
        let mut v = Vec::new();
        for signal in ["input", "model", "wiener"] {
            for span in [1, 2, 3, 4] {
                v.push(format!(
                    "{signal}: mean step, span {span}, / upper quartile"
                ));
            }
            for w in [2, 3, 4, 6] {
                v.push(format!("{signal}: line step, {w} frames, / median"));
                v.push(format!("{signal}: line step, {w} frames, raw degrees"));
            }
        }
        v
    };
    let per_take: Vec<Vec<(Vec<f32>, Vec<f32>)>> = (0..takes.len())
        .into_par_iter()
        .map(|i| {
            let support::SpikedTake {
                noisy,
                spiked,
                spikes,
            } = support::spiked_take(&takes, i, None);
            let clean = &takes[i].motion;
            let n_frames = clean.frame_count();
            let cleaned = model.clean(&spiked, None).expect("clean");
            let layout = FeatureLayout::new(clean.skeleton(), Representation::Rot6d).expect("rig");
            let mut features = layout.encode(&spiked);
            wiener.filter_features(&mut features, None);
            let mut filtered = spiked.clone();
            layout.decode_into(&features, &mut filtered);

            let skeleton = clean.skeleton();
            let n = skeleton.joint_count();
            let joints: Vec<usize> = (0..n)
                .filter(|&k| {
                    skeleton.joint(k).parent.is_some() && skeleton.joint(k).has_rotation_channels()
                })
                .collect();
            // Positive boundaries (t, k) and frames near any boundary of k.
            let mut positive = vec![false; n_frames * n];
            let mut near = vec![false; n_frames * n];
            for s in &spikes {
                for k in skeleton.subtree(s.joint) {
                    for b in [s.start, s.start + s.frames] {
                        if b == 0 || b >= n_frames {
                            continue;
                        }
                        // Inside frame next to the boundary.
                        let inside = if b == s.start { b } else { b - 1 };
                        let turn = angle_between(
                            noisy.local_rotation(inside, k),
                            spiked.local_rotation(inside, k),
                        )
                        .to_degrees();
                        if turn >= 20.0 {
                            positive[b * n + k] = true;
                        }
                        for t in b.saturating_sub(6)..(b + 7).min(n_frames) {
                            near[t * n + k] = true;
                        }
                    }
                }
            }
            let mut out = Vec::new();
            for signal in [&spiked, &cleaned, &filtered] {
                for span in [1, 2, 3, 4] {
                    out.push((normalised_jumps(signal, span, false), span));
                }
                for w in [2usize, 3, 4, 6] {
                    let mut stat = vec![0.0f32; n_frames * n];
                    if n_frames > 2 * w {
                        for &k in &joints {
                            for t in w..=n_frames - w {
                                stat[t * n + k] = linear_step(signal, k, t, w);
                            }
                        }
                    }
                    let raw = stat.clone();
                    if n_frames > 2 * w {
                        median_normalised(&mut stat, n, w, n_frames - w);
                    }
                    out.push((stat, w));
                    out.push((raw, w));
                }
            }
            out.into_iter()
                .map(|(stat, margin)| {
                    split_scores(&stat, n, n_frames, margin, &joints, &positive, &near)
                })
                .collect()
        })
        .collect();
    println!(
        "{} validation takes, sigma drawn in 0-10, 1-3 spikes. Recall of spike boundaries (a subtree joint turned \
         by >= 20 degrees) at a false-positive rate per joint and frame.\n",
        takes.len()
    );
    print_recall(&names, &per_take);
    Ok(())
}

/// The points a spike on joint `j` moves: every joint below `j` and every
/// end site of `j` and the joints below it, relative to `j`'s position, per
/// frame (frames x points).
fn subtree_points(motion: &Motion, j: usize) -> Vec<Vec<Vec3>> {
    let poses = forward_kinematics(motion);
    let skeleton = motion.skeleton();
    let below = skeleton.subtree(j);
    (0..motion.frame_count())
        .map(|f| {
            let origin = poses.position(f, j);
            let mut points = Vec::new();
            for &k in &below {
                if k != j {
                    points.push(poses.position(f, k) - origin);
                }
                for &offset in &skeleton.joint(k).end_sites {
                    points.push(poses.position(f, k) + poses.rotation(f, k) * offset - origin);
                }
            }
            points
        })
        .collect()
}

/// Step of the subtree's points at the boundary before `t`: the mean over
/// points of the distance between their means over `span` frames before and
/// from `t` on.
fn point_step(points: &[Vec<Vec3>], t: usize, span: usize) -> f32 {
    let m = points[0].len();
    if m == 0 {
        return 0.0;
    }
    (0..m)
        .map(|q| {
            let before: Vec3 = (t - span..t).map(|f| points[f][q]).sum::<Vec3>() / span as f32;
            let after: Vec3 = (t..t + span).map(|f| points[f][q]).sum::<Vec3>() / span as f32;
            before.distance(after)
        })
        .sum::<f32>()
        / m as f32
}

/// Subtree-level: positives are (boundary, spike joint) of true spikes that
/// turn some joint of the subtree by >= 20 degrees; negatives are (t, j) more
/// than 6 frames from any boundary of a spike on j, a joint above or below.
fn subtree_level(takes: &[mocap_clean::Take], model: &CleanModel) {
    let names = [
        "rotations (model output, span 3): subtree median of normalised jumps",
        "rotations (input, span 2): subtree median of normalised jumps",
        "global rotations (input, span 1): subtree median of normalised jumps",
        "global rotations (input, span 2): subtree median of normalised jumps",
        "global rotations (input, span 1): subtree mean of normalised jumps",
        "global rotations (input, span 1): subtree median, not min with own",
        "positions (input, span 1): / upper quartile",
        "positions (input, span 2): / upper quartile",
        "positions (input, span 3): / upper quartile",
        "positions (model output, span 1): / upper quartile",
        "positions (model output, span 2): / upper quartile",
        "positions (model output, span 3): / upper quartile",
        "positions (input, span 2): raw",
        "positions (model output, span 2): raw",
    ];
    let per_take: Vec<Vec<(Vec<f32>, Vec<f32>)>> = (0..takes.len())
        .into_par_iter()
        .map(|i| {
            let support::SpikedTake {
                noisy,
                spiked,
                spikes,
            } = support::spiked_take(takes, i, None);
            let clean = &takes[i].motion;
            let n_frames = clean.frame_count();
            let cleaned = model.clean(&spiked, None).expect("clean");
            let skeleton = clean.skeleton();
            let n = skeleton.joint_count();
            let candidates: Vec<usize> = (0..n)
                .filter(|&j| {
                    skeleton.joint(j).parent.is_some()
                        && skeleton.joint(j).has_rotation_channels()
                        && skeleton
                            .subtree(j)
                            .iter()
                            .filter(|&&k| skeleton.joint(k).has_rotation_channels())
                            .count()
                            >= 2
                })
                .collect();
            let related = |a: usize, b: usize| {
                skeleton.subtree(a).contains(&b) || skeleton.subtree(b).contains(&a)
            };
            let mut positive = vec![false; n_frames * n];
            let mut near = vec![false; n_frames * n];
            for s in &spikes {
                for b in [s.start, s.start + s.frames] {
                    if b == 0 || b >= n_frames {
                        continue;
                    }
                    let inside = if b == s.start { b } else { b - 1 };
                    let turn = skeleton
                        .subtree(s.joint)
                        .into_iter()
                        .map(|k| {
                            angle_between(
                                noisy.local_rotation(inside, k),
                                spiked.local_rotation(inside, k),
                            )
                            .to_degrees()
                        })
                        .fold(0.0f32, f32::max);
                    if turn >= 20.0 {
                        positive[b * n + s.joint] = true;
                    }
                    for &j in &candidates {
                        if related(j, s.joint) {
                            for t in b.saturating_sub(6)..(b + 7).min(n_frames) {
                                near[t * n + j] = true;
                            }
                        }
                    }
                }
            }
            let margin = 3;
            let mut stats: Vec<Vec<f32>> = Vec::new();
            // Rotations: subtree median of normalised jumps.
            for (signal, span, global, how) in [
                (&cleaned, 3usize, false, 0),
                (&spiked, 2, false, 0),
                (&spiked, 1, true, 0),
                (&spiked, 2, true, 0),
                (&spiked, 1, true, 1),
                (&spiked, 1, true, 2),
            ] {
                let jump = normalised_jumps(signal, span, global);
                let mut stat = vec![0.0f32; n_frames * n];
                for &j in &candidates {
                    let sub: Vec<usize> = skeleton
                        .subtree(j)
                        .into_iter()
                        .filter(|&k| skeleton.joint(k).has_rotation_channels())
                        .collect();
                    for t in 0..n_frames {
                        let mut v: Vec<f32> = sub.iter().map(|&k| jump[t * n + k]).collect();
                        v.sort_by(f32::total_cmp);
                        let median = v[v.len() / 2];
                        let mean = v.iter().sum::<f32>() / v.len() as f32;
                        stat[t * n + j] = match how {
                            0 => median.min(jump[t * n + j]),
                            1 => mean.min(jump[t * n + j]),
                            _ => median,
                        };
                    }
                }
                stats.push(stat);
            }
            let mut raws = Vec::new();
            for signal in [&spiked, &cleaned] {
                for span in [1usize, 2, 3] {
                    let mut stat = vec![0.0f32; n_frames * n];
                    let mut raw = vec![0.0f32; n_frames * n];
                    for &j in &candidates {
                        let points = subtree_points(signal, j);
                        if n_frames < 2 * span + 1 {
                            continue;
                        }
                        let mut values = Vec::new();
                        for t in span..=n_frames - span {
                            let v = point_step(&points, t, span);
                            raw[t * n + j] = v;
                            values.push(v);
                        }
                        values.sort_by(f32::total_cmp);
                        let scale = values[values.len() * 3 / 4].max(1e-3);
                        for t in span..=n_frames - span {
                            stat[t * n + j] = raw[t * n + j] / scale;
                        }
                    }
                    stats.push(stat);
                    if span == 2 {
                        raws.push(raw);
                    }
                }
            }
            stats.extend(raws);
            stats
                .into_iter()
                .map(|stat| split_scores(&stat, n, n_frames, margin, &candidates, &positive, &near))
                .collect()
        })
        .collect();
    println!("Subtree level: recall of spike boundaries at a false-positive rate per candidate joint and frame.\n");
    print_recall(&names, &per_take);
    println!();
}

/// The scores of `stat` (frames x `n` joints) at `joints`, frames `margin`
/// from either end: (at positive boundaries, away from every boundary).
fn split_scores(
    stat: &[f32],
    n: usize,
    n_frames: usize,
    margin: usize,
    joints: &[usize],
    positive: &[bool],
    near: &[bool],
) -> (Vec<f32>, Vec<f32>) {
    let (mut pos, mut neg) = (Vec::new(), Vec::new());
    if n_frames < 2 * margin + 1 {
        return (pos, neg);
    }
    for t in margin..=n_frames - margin {
        for &k in joints {
            let v = stat[t * n + k];
            if positive[t * n + k] {
                pos.push(v);
            } else if !near[t * n + k] {
                neg.push(v);
            }
        }
    }
    (pos, neg)
}

/// The recall table: per statistic, the share of positives above the
/// negatives' 99th and 99.9th percentiles.
fn print_recall<S: std::fmt::Display>(names: &[S], per_take: &[Vec<(Vec<f32>, Vec<f32>)>]) {
    println!(
        "| statistic | positives | recall at 1% | recall at 0.1% |\n| --- | ---: | ---: | ---: |"
    );
    for (s, name) in names.iter().enumerate() {
        let pos: Vec<f32> = per_take.iter().flat_map(|t| t[s].0.clone()).collect();
        let mut neg: Vec<f32> = per_take.iter().flat_map(|t| t[s].1.clone()).collect();
        neg.sort_by(f32::total_cmp);
        let at = |q: f64| {
            let cut = neg[((neg.len() as f64) * q) as usize];
            pos.iter().filter(|&&v| v > cut).count() as f64 / pos.len() as f64
        };
        println!(
            "| {name} | {} | {:.3} | {:.3} |",
            pos.len(),
            at(0.99),
            at(0.999)
        );
    }
}
