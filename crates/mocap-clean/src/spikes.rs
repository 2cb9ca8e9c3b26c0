//! Learned spike finding (experimental): a network marks, for every joint
//! and frame, whether the joint's rotation belongs to another motion there;
//! the marked stretches are bridged.
//!
//! Why a second network: a spike ([`crate::noise::SpikeNoise`], a wrong
//! association with another person) is smooth and plausible inside, so a
//! denoiser trained to regress clean rotations leaves most of it (the
//! report's failure, measured in `bench/results/clean.md`), and trained on
//! spikes alone it stayed exactly at its input (measured: validation MSE flat
//! at the input's from the second epoch). Telling *whether* a stretch is
//! wrong is a classification, which the noise generator labels exactly: the
//! detector is the denoiser's network ([`crate::model`]) with one logit per
//! joint and frame instead of the global skip
//! ([`crate::model::Head::SpikeLogits`]), trained by the same loop
//! ([`crate::training::TrainOptions::spike_detector`]) with the binary
//! cross-entropy against [`spike_mask`]. It runs on the noisy rotations of a
//! whole take at once (the network is convolutional, so any length works).
//!
//! It learns slowly on this CPU: the network first answers each joint's base
//! rate for about 10 epochs (400 steps of 512 windows), then starts to mark
//! spikes (bench/results/clean.md has the curve and what the detector trained
//! there does). Giving it each frame's change as extra input did not shorten
//! that (validation cross-entropy 0.171 against 0.168 without, after 26
//! epochs), so it reads the rotations only. No detector ships.
//!
//! [`bridge_marked`] then replaces each marked stretch of a joint (at most
//! [`SpikeOptions::max_frames`] long) by the spherical interpolation between
//! the unmarked frames around it, as [`crate::despike`] does; a stretch at
//! the start or end of the take holds the nearest unmarked frame. A
//! denoiser may run afterwards (`mocap clean --spike-model FILE`): spikes
//! are taken out before the random noise is smoothed, because smoothing
//! spreads a spike's jumps over its neighbours.

use std::path::Path;

use burn::tensor::{Tensor, TensorData};
use mocap_core::rotation::{angle_between, slerp};
use mocap_core::Motion;
use mocap_nn::device::DeviceChoice;
use serde::{Deserialize, Serialize};

use crate::despike::FoundSpike;
use crate::features::FeatureLayout;
use crate::infer::CleanModel;
use crate::model::Head;
use crate::noise::Spike;
use crate::{CleanError, Result};

/// The smallest error (degrees) of a spiked joint that its mask marks.
///
/// A spike often gives a joint a rotation close to its own (a hand or a toe
/// that moves alike in both motions): such a joint is as good as clean, no
/// input tells it apart, and marking it taught the network only the share of
/// marked joints (measured: trained on every spiked joint, the detector
/// answered each joint's base rate everywhere). Errors below the random
/// noise's own (up to 10 degrees) are left to the denoiser.
pub const VISIBLE_SPIKE_DEG: f32 = 10.0;

/// The mask of `spikes` in `noisy` (a copy of `clean` with the spikes):
/// `1` where joint `joints[k]` lies in a spike's subtree during the spike
/// and its rotation is at least [`VISIBLE_SPIKE_DEG`] away from the clean
/// one, else `0`, frame by frame (`mask[f * joints.len() + k]`).
pub fn spike_mask(clean: &Motion, noisy: &Motion, joints: &[usize], spikes: &[Spike]) -> Vec<f32> {
    let frames = clean.frame_count();
    let skeleton = clean.skeleton();
    let mut mask = vec![0.0; frames * joints.len()];
    for s in spikes {
        let subtree = skeleton.subtree(s.joint);
        for (k, &j) in joints.iter().enumerate() {
            if !subtree.contains(&j) {
                continue;
            }
            for f in s.start..(s.start + s.frames).min(frames) {
                let error = angle_between(clean.local_rotation(f, j), noisy.local_rotation(f, j));
                if error.to_degrees() >= VISIBLE_SPIKE_DEG {
                    mask[f * joints.len() + k] = 1.0;
                }
            }
        }
    }
    mask
}

/// Settings of learned spike finding.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpikeOptions {
    /// A joint is marked at a frame when the detector's probability is at
    /// least this.
    pub threshold: f32,
    /// Longer marked stretches are left alone (a detector that marks a
    /// joint for seconds is not finding a spike).
    pub max_frames: usize,
}

impl Default for SpikeOptions {
    fn default() -> Self {
        SpikeOptions {
            threshold: 0.5,
            max_frames: 90,
        }
    }
}

/// A trained spike detector (see the module docs).
#[derive(Debug)]
pub struct SpikeDetector {
    model: CleanModel,
}

impl SpikeDetector {
    /// Loads a detector written by `mocap clean train --spike-detector`.
    pub fn load(path: &Path, device: DeviceChoice) -> Result<SpikeDetector> {
        Self::checked(CleanModel::load(path, device)?)
    }

    /// Loads checkpoint bytes; `origin` names them in errors.
    pub fn from_bytes(
        bytes: Vec<u8>,
        origin: &Path,
        device: DeviceChoice,
    ) -> Result<SpikeDetector> {
        Self::checked(CleanModel::from_bytes(bytes, origin, device)?)
    }

    fn checked(model: CleanModel) -> Result<SpikeDetector> {
        match model.description.network.head {
            Head::SpikeLogits { .. } => Ok(SpikeDetector { model }),
            Head::Correction => Err(CleanError::Invalid(format!(
                "{} is a denoiser, not a spike detector (train one with `mocap clean train \
                 --spike-detector`)",
                model.source.display()
            ))),
        }
    }

    /// Where it was loaded from.
    pub fn source(&self) -> &Path {
        &self.model.source
    }

    /// The probability that each joint with rotation channels is in a spike
    /// at each frame: `p[f * joints + k]`, `k` in the order of the rig's
    /// rotating joints. The network runs on the whole take at once, padded
    /// by repeating its first and last frames by half a training window.
    pub fn probabilities(&self, motion: &Motion) -> Result<Vec<f32>> {
        self.probabilities_on(motion, &self.model.layout_for(motion)?)
    }

    /// [`Self::probabilities`] with the rig's features already checked.
    fn probabilities_on(&self, motion: &Motion, layout: &FeatureLayout) -> Result<Vec<f32>> {
        let (network, device) = self.model.network();
        let config = &self.model.description.network;
        let (c, joints) = (layout.channels(), layout.joints.len());
        let frames = motion.frame_count();
        if frames == 0 {
            return Ok(Vec::new());
        }
        let mut features = layout.encode(motion);
        layout.recenter(&mut features);
        let front = config.window / 2;
        let unit = 1usize << config.levels;
        let padded = (frames + 2 * front).div_ceil(unit) * unit;
        // Channels first, as the network takes them.
        let mut x = vec![0.0f32; c * padded];
        for i in 0..padded {
            let f = i.saturating_sub(front).min(frames - 1);
            for ch in 0..c {
                x[ch * padded + i] = features[f * c + ch];
            }
        }
        let input = Tensor::<3>::from_data(TensorData::new(x, [1, c, padded]), device);
        let logits: Vec<f32> = network
            .forward(input)
            .into_data()
            .try_to_vec()
            .map_err(|e| CleanError::Invalid(format!("reading the detector's output: {e:?}")))?;
        let mut p = vec![0.0; frames * joints];
        for f in 0..frames {
            for k in 0..joints {
                let z = logits[k * padded + front + f];
                p[f * joints + k] = 1.0 / (1.0 + (-z).exp());
            }
        }
        Ok(p)
    }

    /// Finds spikes in `motion` and bridges them ([`bridge_marked`]).
    pub fn remove_spikes(
        &self,
        motion: &Motion,
        options: &SpikeOptions,
    ) -> Result<(Motion, Vec<FoundSpike>)> {
        let layout = self.model.layout_for(motion)?;
        let p = self.probabilities_on(motion, &layout)?;
        let joints = layout.joints;
        Ok(bridge_marked(motion, &joints, &p, options))
    }
}

/// Bridges every stretch where joint `joints[k]` has `probabilities[f *
/// joints.len() + k]` at or above the threshold (see the module docs).
/// Returns the bridged motion and the stretches of the joints whose parent
/// was not marked where the stretch starts (the tops of the spiked
/// subtrees).
pub fn bridge_marked(
    motion: &Motion,
    joints: &[usize],
    probabilities: &[f32],
    options: &SpikeOptions,
) -> (Motion, Vec<FoundSpike>) {
    let frames = motion.frame_count();
    let n = joints.len();
    let skeleton = motion.skeleton();
    let marked = |f: usize, k: usize| probabilities[f * n + k] >= options.threshold;
    // The nearest rotating ancestor of each joint, as a column of the mask.
    let column_of = |j: usize| joints.iter().position(|&x| x == j);
    let parent_column: Vec<Option<usize>> = joints
        .iter()
        .map(|&j| {
            let mut a = skeleton.joint(j).parent;
            while let Some(p) = a {
                if let Some(k) = column_of(p) {
                    return Some(k);
                }
                a = skeleton.joint(p).parent;
            }
            None
        })
        .collect();
    let mut out = motion.clone();
    let mut found = Vec::new();
    for (k, &joint) in joints.iter().enumerate() {
        let mut f = 0;
        while f < frames {
            if !marked(f, k) {
                f += 1;
                continue;
            }
            let start = f;
            while f < frames && marked(f, k) {
                f += 1;
            }
            let end = f;
            if end - start > options.max_frames {
                continue;
            }
            let before = start
                .checked_sub(1)
                .map(|b| motion.local_rotation(b, joint));
            let after = (end < frames).then(|| motion.local_rotation(end, joint));
            for g in start..end {
                let q = match (before, after) {
                    (Some(a), Some(b)) => {
                        slerp(a, b, (g + 1 - start) as f32 / (end + 1 - start) as f32)
                    }
                    (Some(a), None) => a,
                    (None, Some(b)) => b,
                    (None, None) => continue,
                };
                out.set_local_rotation(g, joint, q);
            }
            if parent_column[k].is_none_or(|p| !marked(start, p)) {
                found.push(FoundSpike {
                    joint,
                    start,
                    frames: end - start,
                });
            }
        }
    }
    found.sort_by_key(|s| (s.start, s.joint));
    (out, found)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::synthetic_motion;
    use mocap_core::rotation::angle_between;

    #[test]
    fn the_mask_covers_the_visibly_wrong_joints_of_the_spike() {
        let clean = synthetic_motion(10, 4);
        let skeleton = clean.skeleton().clone();
        let joints: Vec<usize> = (0..skeleton.joint_count()).collect();
        let spike = Spike {
            joint: 2,
            start: 3,
            frames: 20,
        };
        // Joint 2 turned by 30 degrees in the spike, the joints below by 5.
        let mut noisy = clean.clone();
        let subtree = skeleton.subtree(2);
        for f in 3..10 {
            for &j in &subtree {
                let angle = if j == 2 { 30f32 } else { 5.0 };
                let q = clean.local_rotation(f, j)
                    * mocap_core::rotation::Quat::from_rotation_x(angle.to_radians());
                noisy.set_local_rotation(f, j, q);
            }
        }
        let mask = spike_mask(&clean, &noisy, &joints, &[spike]);
        for f in 0..10 {
            for (k, &j) in joints.iter().enumerate() {
                let expected = j == 2 && f >= 3;
                assert_eq!(
                    mask[f * joints.len() + k] == 1.0,
                    expected,
                    "frame {f} joint {j}"
                );
            }
        }
    }

    #[test]
    fn marked_stretches_are_bridged_and_the_rest_kept() {
        let motion = synthetic_motion(30, 4);
        let skeleton = motion.skeleton();
        let joints: Vec<usize> = (0..skeleton.joint_count())
            .filter(|&j| skeleton.joint(j).has_rotation_channels())
            .collect();
        // Joint column 1 marked on frames 10..15, column 0 at the start.
        let mut p = vec![0.0; 30 * joints.len()];
        for f in 10..15 {
            p[f * joints.len() + 1] = 0.9;
        }
        for f in 0..3 {
            p[f * joints.len()] = 0.7;
        }
        let (out, found) = bridge_marked(&motion, &joints, &p, &SpikeOptions::default());
        let j = joints[1];
        let (a, b) = (motion.local_rotation(9, j), motion.local_rotation(15, j));
        for f in 10..15 {
            let w = (f - 9) as f32 / 6.0;
            assert!(angle_between(out.local_rotation(f, j), slerp(a, b, w)) < 1e-3);
        }
        // A stretch at the start holds the first unmarked frame.
        for f in 0..3 {
            let held = motion.local_rotation(3, joints[0]);
            assert!(angle_between(out.local_rotation(f, joints[0]), held) < 1e-3);
        }
        // Everything else is untouched.
        for f in 0..30 {
            for (k, &jj) in joints.iter().enumerate() {
                if (k == 1 && (10..15).contains(&f)) || (k == 0 && f < 3) {
                    continue;
                }
                assert_eq!(out.local_rotation(f, jj), motion.local_rotation(f, jj));
            }
        }
        assert_eq!(found.len(), 2, "{found:?}");
        // Too long a stretch is left alone.
        let strict = SpikeOptions {
            max_frames: 4,
            ..SpikeOptions::default()
        };
        let (out, _) = bridge_marked(&motion, &joints, &p, &strict);
        assert_eq!(out.local_rotation(12, j), motion.local_rotation(12, j));
    }
}
