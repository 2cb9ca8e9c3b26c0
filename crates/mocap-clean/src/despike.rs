//! Finding and bridging spikes by hand-written rules: a classical stage, run alone or before a filter or denoiser.
//!
//! A spike of markerless capture (a wrong association with another person,
//! [`crate::noise::SpikeNoise`]) gives a joint and every joint below it the
//! rotations of another motion for a while. Inside the spike the motion is
//! smooth and plausible, so a denoiser that sees a short window cannot tell
//! it from the truth once the spike is longer than its window; what gives a
//! spike away is its two ends, where the whole subtree jumps at once.
//!
//! [`find_spikes`] looks for those jumps in the take as captured:
//!
//! 1. the jump of joint `k` at frame `t` is the angle between its mean
//!    rotation over the [`DespikeOptions::span`] frames before `t` and over
//!    the `span` frames from `t` on (with a span of 1: frames `t - 1` and
//!    `t`), divided by the upper quartile of that joint's jumps over the take
//!    (so fast joints and noisy takes are judged by their own scale). The
//!    rotation is the joint's global one by default
//!    ([`DespikeOptions::global`]): IK noise swings local rotations far more
//!    than global ones, a spike turns its subtree in both;
//! 2. the jump of a subtree is the median of its joints' jumps: a spike
//!    moves (nearly) all of them at once, a noisy joint alone does not;
//! 3. a joint whose own jump and whose subtree's jump both exceed
//!    [`DespikeOptions::threshold`], while no joint above it does, is at a
//!    *boundary* of a spike, where its subtree's jump is the largest within
//!    `span - 1` frames. A trunk joint (the pelvis and the spine: its
//!    subtree branches into several limbs) needs only its subtree's jump
//!    ([`DespikeOptions::trunk_by_subtree`]): a spike there swaps several
//!    limbs at once, while the trunk itself, upright in both motions, often
//!    hardly jumps; asking it for its own jump too passed such spikes down
//!    to single limbs, whose boundaries then rarely paired. The root
//!    never is a boundary, nor a joint with no rotating joint below it (its
//!    own jump is all there is to go by: a toe that rests and then moves
//!    would do);
//! 4. boundaries of the same joint are paired in time order, the first
//!    opening and the second closing a spike, when they lie at most
//!    [`DespikeOptions::max_frames`] apart (intermittent spikes give several
//!    pairs), and a spike inside a spike of a joint above it is bridged with
//!    that one; a boundary without a partner is left alone (taking it for a
//!    spike running to the nearer end of the take was measured worse:
//!    bench/results/clean.md).
//!
//! [`remove_spikes`] then replaces each found spike's subtree rotations by
//! the spherical interpolation (slerp) between the last frame before and the
//! first frame after it. Long spikes are bridged with a straight path, which
//! loses whatever the joint really did meanwhile, but it is much closer than
//! another person's motion.
//! `mocap clean apply --despike` does this before a filter or a denoiser runs,
//! which would smear each spike's jumps over the frames around it and take
//! part of it for noise (bench/results/clean.md).

use mocap_core::rotation::{angle_between, mean_of_close, slerp};
use mocap_core::{forward_kinematics, Motion, Skeleton};
use serde::{Deserialize, Serialize};

/// Settings of spike finding.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DespikeOptions {
    /// A subtree's median jump, in multiples of each joint's upper-quartile
    /// jump, above which a frame is a spike boundary.
    pub threshold: f32,
    /// Longest spike looked for, in frames.
    pub max_frames: usize,
    /// Frames averaged on each side of a boundary (at least 1).
    pub span: usize,
    /// Jumps of global rotations (forward kinematics) instead of local ones.
    /// Noise of IK on keypoints errs on the local rotations by several times
    /// its level (a joint swings to keep its child near the keypoint,
    /// [`crate::RandomNoise`]) but on the global ones by about its level, while a
    /// spike turns its whole subtree in both: spike boundaries stand out far
    /// better in global rotations (bench/results/clean.md).
    #[serde(default)]
    pub global: bool,
    /// Judge a trunk joint (one whose subtree branches into several limbs:
    /// the pelvis and the spine of a body) by its subtree's jump alone, not
    /// also by its own. A spike there swaps several limbs, which jump, but
    /// the trunk joint itself often turns little: both the take and the
    /// motion it was swapped with stand upright (docs/research/clean.md,
    /// "Finding spikes"). On by default; settings written without it
    /// read it as off, which is how they ran.
    #[serde(default)]
    pub trunk_by_subtree: bool,
}

impl Default for DespikeOptions {
    /// Tuned on the 120 validation takes of the Bandai data with random
    /// noise and spikes, the spikes bridged before the shipped model
    /// (`mocap clean eval --despike`, bench/results/clean.md); the same
    /// settings are tuned for spike finding alone.
    fn default() -> Self {
        DespikeOptions {
            threshold: 3.0,
            max_frames: 90,
            span: 1,
            global: true,
            trunk_by_subtree: true,
        }
    }
}

/// A spike that was found: `joint` and its subtree, frames
/// `start..start + frames`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct FoundSpike {
    pub joint: usize,
    pub start: usize,
    pub frames: usize,
}

/// A spike the noise put in, as a found one would be (for bridging the true
/// spikes, an oracle, and for matching found spikes against them).
impl From<crate::noise::Spike> for FoundSpike {
    fn from(spike: crate::noise::Spike) -> Self {
        FoundSpike {
            joint: spike.joint,
            start: spike.start,
            frames: spike.frames,
        }
    }
}

/// The spikes of `motion` (see the module docs), in order of joint, then
/// start.
pub fn find_spikes(motion: &Motion, options: &DespikeOptions) -> Vec<FoundSpike> {
    let skeleton = motion.skeleton();
    let frames = motion.frame_count();
    let n = skeleton.joint_count();
    let span = options.span.max(1);
    if frames < 2 * span + 1 {
        return Vec::new();
    }
    // Boundaries at frames `first..=last` (both sides have `span` frames).
    let (first, last) = (span, frames - span);
    let jump = normalised_jumps(motion, span, options.global);
    let subtrees = rotating_subtrees(skeleton);
    // Trunk joints: some joint in the subtree has two or more children
    // with rotating joints below them (a joint without channels between
    // counts as the branch it leads to).
    let branching: Vec<bool> = (0..n)
        .map(|k| {
            skeleton
                .children(k)
                .filter(|&c| !subtrees[c].is_empty())
                .count()
                >= 2
        })
        .collect();
    let trunk: Vec<bool> = (0..n)
        .map(|j| skeleton.subtree(j).into_iter().any(|k| branching[k]))
        .collect();
    // Candidate boundaries per joint (frame, subtree jump), in time order.
    let mut candidates: Vec<Vec<(usize, f32)>> = vec![Vec::new(); n];
    let mut values = Vec::new();
    let mut jumps = vec![false; n];
    let mut scores = vec![0.0f32; n];
    let mut ancestor_jumps = vec![false; n];
    for t in first..=last {
        for j in 0..n {
            // A root is never a spike (its subtree is the whole body, and
            // the root carries the translation).
            let own_counts = !(options.trunk_by_subtree && trunk[j]);
            if skeleton.joint(j).parent.is_none()
                || subtrees[j].len() < 2
                || (own_counts && jump[t * n + j] <= options.threshold)
            {
                jumps[j] = false;
                continue;
            }
            values.clear();
            values.extend(subtrees[j].iter().map(|&k| jump[t * n + k]));
            values.sort_by(f32::total_cmp);
            scores[j] = values[values.len() / 2];
            jumps[j] = scores[j] > options.threshold;
        }
        // Only the topmost jumping joint of a branch is the spike's (joints
        // without rotation channels in between do not count).
        for j in 0..n {
            ancestor_jumps[j] = skeleton
                .joint(j)
                .parent
                .is_some_and(|p| jumps[p] || ancestor_jumps[p]);
            if jumps[j] && !ancestor_jumps[j] {
                candidates[j].push((t, scores[j]));
            }
        }
    }
    // A step seen through averaged windows rises and falls over
    // `2 span - 1` frames: keep its peak.
    let mut boundaries: Vec<Vec<usize>> = candidates
        .iter()
        .map(|list| {
            list.iter()
                .enumerate()
                .filter(|&(i, &(t, score))| {
                    list.iter().enumerate().all(|(i2, &(t2, score2))| {
                        i2 == i
                            || t.abs_diff(t2) >= span
                            || score2 < score
                            || (score2 == score && i < i2)
                    })
                })
                .map(|(_, &(t, _))| t)
                .collect()
        })
        .collect();
    // Near a joint's boundary, a joint below it may peak a frame earlier or
    // later: that is the same spike (parents come before children).
    for j in 0..n {
        let mut above = skeleton.joint(j).parent;
        while let Some(a) = above {
            let (before, from_j) = boundaries.split_at_mut(j);
            let ancestor = &before[a];
            from_j[0].retain(|&t| ancestor.iter().all(|&ta| t.abs_diff(ta) >= span));
            above = skeleton.joint(a).parent;
        }
    }
    pair_boundaries(&subtrees, &boundaries, options.max_frames)
}

/// Each joint's subtree (itself and every joint below it), keeping only
/// the joints with rotation channels: the joints a spike of it turns.
pub fn rotating_subtrees(skeleton: &Skeleton) -> Vec<Vec<usize>> {
    (0..skeleton.joint_count())
        .map(|j| {
            skeleton
                .subtree(j)
                .into_iter()
                .filter(|&k| skeleton.joint(k).has_rotation_channels())
                .collect()
        })
        .collect()
}

/// Step 4 of [`find_spikes`]: each joint's boundaries (`boundaries[joint]`,
/// frames in time order) paired in time order into spikes at most
/// `max_frames` long, a boundary without a partner left alone, and a spike
/// inside a spike of a joint above it dropped (it is bridged with that
/// one; `subtrees` from [`rotating_subtrees`], which tells what is above
/// what). Public for studies that find boundaries another way.
pub fn pair_boundaries(
    subtrees: &[Vec<usize>],
    boundaries: &[Vec<usize>],
    max_frames: usize,
) -> Vec<FoundSpike> {
    let mut spikes = Vec::new();
    for (joint, times) in boundaries.iter().enumerate() {
        let mut i = 0;
        while i + 1 < times.len() {
            let (start, end) = (times[i], times[i + 1]);
            if end - start <= max_frames {
                spikes.push(FoundSpike {
                    joint,
                    start,
                    frames: end - start,
                });
                i += 2;
            } else {
                i += 1;
            }
        }
    }
    let inside_above = |s: &FoundSpike| {
        spikes.iter().any(|a| {
            a.joint != s.joint
                && subtrees[a.joint].contains(&s.joint)
                && a.start <= s.start
                && s.start + s.frames <= a.start + a.frames
        })
    };
    spikes
        .iter()
        .filter(|s| !inside_above(s))
        .copied()
        .collect()
}

/// Step 1 of [`find_spikes`]: `jump[t * joints + k]`, the angle (degrees)
/// between joint `k`'s mean rotation (global with `global`, from forward
/// kinematics, else local) over the `span` frames before
/// frame `t` and over the `span` frames from `t` on, divided by the upper
/// quartile of that joint's jumps over the take (at least one degree); zero
/// where a side has fewer than `span` frames and for joints without rotation
/// channels.
pub fn normalised_jumps(motion: &Motion, span: usize, global: bool) -> Vec<f32> {
    let skeleton = motion.skeleton();
    let frames = motion.frame_count();
    let n = skeleton.joint_count();
    let span = span.max(1);
    let mut jump = vec![0.0f32; frames * n];
    if frames < 2 * span + 1 {
        return jump;
    }
    let (first, last) = (span, frames - span);
    let poses = global.then(|| forward_kinematics(motion));
    let rotation = |f: usize, k: usize| match &poses {
        Some(poses) => poses.rotation(f, k),
        None => motion.local_rotation(f, k),
    };
    for k in (0..n).filter(|&k| skeleton.joint(k).has_rotation_channels()) {
        let mut angles: Vec<f32> = (first..=last)
            .map(|t| {
                let before = mean_of_close((t - span..t).map(|f| rotation(f, k)));
                let after = mean_of_close((t..t + span).map(|f| rotation(f, k)));
                angle_between(before, after).to_degrees()
            })
            .collect();
        for (i, a) in angles.iter().enumerate() {
            jump[(first + i) * n + k] = *a;
        }
        // The scale: the upper quartile of the joint's jumps (at least one
        // degree). Not the median: joints that rest most of the time (toes
        // in a walk) would make every step look like a spike.
        angles.sort_by(f32::total_cmp);
        let scale = angles[angles.len() * 3 / 4].max(1.0);
        for t in first..=last {
            jump[t * n + k] /= scale;
        }
    }
    jump
}

/// `motion` with every found spike bridged by slerp (see the module docs),
/// and the spikes.
pub fn remove_spikes(motion: &Motion, options: &DespikeOptions) -> (Motion, Vec<FoundSpike>) {
    let spikes = find_spikes(motion, options);
    (bridge_spikes(motion, &spikes), spikes)
}

/// `motion` with the rotations of each spike's joint and subtree replaced,
/// over its frames, by slerp from the frame before it to the frame after
/// it; a spike at an end of the take holds the one frame next to it, and
/// one covering the whole take is left as it is.
pub fn bridge_spikes(motion: &Motion, spikes: &[FoundSpike]) -> Motion {
    let mut out = motion.clone();
    let skeleton = motion.skeleton();
    let frames = motion.frame_count();
    for s in spikes {
        let end = (s.start + s.frames).min(frames);
        let before = s.start.checked_sub(1);
        let after = (end < frames).then_some(end);
        if s.start >= end || (before.is_none() && after.is_none()) {
            continue;
        }
        for k in skeleton.subtree(s.joint) {
            if !skeleton.joint(k).has_rotation_channels() {
                continue;
            }
            let rotation = |f: Option<usize>| f.map(|f| out.local_rotation(f, k));
            let (a, b) = (rotation(before), rotation(after));
            for f in s.start..end {
                let q = match (a, b) {
                    (Some(a), Some(b)) => {
                        let (first, last) = (s.start - 1, end);
                        slerp(a, b, (f - first) as f32 / (last - first) as f32)
                    }
                    (Some(q), None) | (None, Some(q)) => q,
                    (None, None) => unreachable!("checked above"),
                };
                out.set_local_rotation(f, k, q);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::{add_spikes, Spike, SpikeNoise};
    use crate::test_support::{branching_motion, synthetic_motion_phase};
    use mocap_core::rotation::Quat;
    use rand::SeedableRng;

    /// The branching test body with spikes from a shifted copy.
    fn spiked(spikes: &mut [Spike]) -> (Motion, Motion, Vec<Spike>) {
        let clean = branching_motion(200);
        let mut donor = branching_motion(200);
        let shifted = synthetic_motion_phase(200, 2, 1.5);
        // The donor: the same body moving differently (every rotation
        // turned by a slowly varying amount).
        for f in 0..200 {
            for j in [1, 2, 3, 5, 6] {
                let extra = shifted.local_rotation(f, 1);
                let q = donor.local_rotation(f, j) * extra * extra;
                donor.set_local_rotation(f, j, q);
            }
        }
        let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(2);
        let (noisy, spikes) =
            add_spikes(&clean, &[&donor], &SpikeNoise::default(), spikes, &mut rng).unwrap();
        (clean, noisy, spikes)
    }

    #[test]
    fn spikes_at_the_ends_of_a_take_hold_the_frame_next_to_them() {
        let motion = synthetic_motion_phase(20, 3, 0.4);
        let spike = |start, frames| FoundSpike {
            joint: 1,
            start,
            frames,
        };
        let bridged = bridge_spikes(&motion, &[spike(0, 4), spike(17, 3)]);
        for f in 0..20 {
            for j in 0..3 {
                let expected = match (j, f) {
                    (0, _) => motion.local_rotation(f, 0),
                    (_, 0..4) => motion.local_rotation(4, j),
                    (_, 17..) => motion.local_rotation(16, j),
                    _ => motion.local_rotation(f, j),
                };
                assert!(
                    bridged.local_rotation(f, j).abs_diff_eq(expected, 1e-6),
                    "{f} {j}"
                );
            }
        }
        // Inside, the bridge runs from the frame before to the frame after.
        let inside = bridge_spikes(&motion, &[spike(5, 4)]);
        let (a, b) = (motion.local_rotation(4, 2), motion.local_rotation(9, 2));
        assert!(inside
            .local_rotation(7, 2)
            .abs_diff_eq(slerp(a, b, 0.6), 1e-6));
        // A spike over the whole take has nothing to bridge from.
        assert_eq!(
            bridge_spikes(&motion, &[spike(0, 20)]).values(),
            motion.values()
        );
    }

    #[test]
    fn a_spike_is_found_at_its_joint_and_bridged() {
        let (clean, noisy, spikes) = spiked(&mut [Spike {
            joint: 0,
            start: 60,
            frames: 40,
        }]);
        let options = DespikeOptions::default();
        let (repaired, found) = remove_spikes(&noisy, &options);
        assert_eq!(
            found,
            vec![FoundSpike {
                joint: spikes[0].joint,
                start: 60,
                frames: 40
            }]
        );
        let error = |m: &Motion| -> f32 {
            (60..100)
                .flat_map(|f| {
                    clean
                        .skeleton()
                        .subtree(spikes[0].joint)
                        .into_iter()
                        .map(move |k| (f, k))
                })
                .filter(|&(_, k)| clean.skeleton().joint(k).has_rotation_channels())
                .map(|(f, k)| angle_between(clean.local_rotation(f, k), m.local_rotation(f, k)))
                .sum()
        };
        assert!(
            error(&repaired) < 0.5 * error(&noisy),
            "{} vs {}",
            error(&repaired),
            error(&noisy)
        );
        // Nothing outside the spike changed.
        for f in (0..60).chain(100..200) {
            assert_eq!(repaired.frame(f), noisy.frame(f));
        }
    }

    #[test]
    fn a_spike_under_ik_noise_is_found_in_global_rotations() {
        use crate::noise::{add_random_noise_sigma, RandomNoise};
        let clean = branching_motion(200);
        let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(5);
        let noisy = add_random_noise_sigma(&clean, 5.0, &RandomNoise::default(), &mut rng);
        let mut donor = branching_motion(200);
        let turn = Quat::from_rotation_x(70f32.to_radians());
        for f in 0..200 {
            for j in [5, 6] {
                let q = donor.local_rotation(f, j) * turn;
                donor.set_local_rotation(f, j, q);
            }
        }
        let params = SpikeNoise::default();
        let mut spike = [Spike {
            joint: 5,
            start: 80,
            frames: 40,
        }];
        // `add_spikes` draws the joint: draw until it is the leg.
        let (spiked, spikes) = (0..)
            .map(|_| add_spikes(&noisy, &[&donor], &params, &mut spike, &mut rng).unwrap())
            .find(|(_, s)| s[0].joint == 5)
            .unwrap();
        let found = find_spikes(&spiked, &DespikeOptions::default());
        assert!(
            found.iter().any(|f| f.joint == spikes[0].joint
                && f.start.abs_diff(80) <= 1
                && (f.start + f.frames).abs_diff(120) <= 1),
            "{found:?}"
        );
        // Why global rotations: the noise swings the local rotations (each
        // joint keeps its child near the keypoint), so the spike's jumps
        // stand out less there.
        let n = spiked.skeleton().joint_count();
        let (global, local) = (
            normalised_jumps(&spiked, 1, true),
            normalised_jumps(&spiked, 1, false),
        );
        for t in [80, 120] {
            for k in [5, 6] {
                assert!(global[t * n + k] > local[t * n + k], "{t} {k}");
            }
        }
    }

    #[test]
    fn a_trunk_spike_is_found_at_the_trunk_joint_though_it_hardly_turns() {
        // A spike of the pelvis: the motion swapped in stands as upright (its
        // pelvis turned by one degree), but its spine and leg turn otherwise.
        let clean = branching_motion(200);
        let mut spiked = clean.clone();
        let limb = Quat::from_rotation_x(60f32.to_radians());
        let pelvis = Quat::from_rotation_x(1f32.to_radians());
        for f in 80..120 {
            for (j, turn) in [(1, pelvis), (2, limb), (3, limb), (5, limb), (6, limb)] {
                spiked.set_local_rotation(f, j, clean.local_rotation(f, j) * turn);
            }
        }
        let trunk = DespikeOptions::default();
        assert!(trunk.trunk_by_subtree);
        assert_eq!(
            find_spikes(&spiked, &trunk),
            vec![FoundSpike {
                joint: 1,
                start: 80,
                frames: 40
            }]
        );
        // Judged by its own jump as well, the pelvis is passed over and the
        // spike is found below it, at the spine and the leg.
        let own_too = DespikeOptions {
            trunk_by_subtree: false,
            ..trunk
        };
        let found: Vec<usize> = find_spikes(&spiked, &own_too)
            .iter()
            .map(|s| s.joint)
            .collect();
        assert_eq!(found, vec![2, 5]);
    }

    #[test]
    fn smooth_motion_has_no_spikes() {
        let clean = branching_motion(300);
        assert!(find_spikes(&clean, &DespikeOptions::default()).is_empty());
    }
}
