//! Synthetic noise of markerless capture, added to clean motion to make
//! training pairs and evaluation inputs.
//!
//! ## Random noise ([`RandomNoise`])
//!
//! Small per-frame errors of 2D pose estimation. Each joint gets its own
//! random rotation error `d_j` (a rotation vector drawn from
//! `N(0, sigma^2 / 3 I)`, so the RMS error angle is `sigma`); `sigma` is drawn
//! per sample, uniformly in `[0, max_sigma]`.
//!
//! Applied naively to the local rotations (`q_j' = q_j d_j`), the error of a
//! joint rotates every joint below it: the position error adds up from the
//! root to the hands and feet. This is not what a keypoint detector does: it
//! errs on each keypoint independently. So the default is
//! *chain-corrected*: with global rotations `G` and positions `x`, in
//! parent-before-child order,
//!
//! 1. the joint's global rotation is perturbed by its own error only,
//!    `A_j = G_j d_j` (not by its ancestors');
//! 2. `A_j` is then swung (shortest-arc rotation) so that its bone to its
//!    main child `c` (the child with the longest offset) points from the
//!    joint's *noisy* position `x_j'` to `x_c + e_c`, where
//!    `e_c = (A_j - G_j) t_c` is the displacement that `d_j` alone gives the
//!    child. The drift inherited from the ancestors is thereby cancelled;
//! 3. local rotations are `q_j' = A_p'^-1 A_j'` (root: `A_root'`).
//!
//! The position error of every joint is therefore that of a single bone
//! turned by about `sigma`, whatever its depth in the chain (measured in the
//! tests: it grows with depth for the naive noise and stays flat here).
//!
//! The price is in the *local* rotations: a joint whose bone to its main
//! child is short (Hips, Shoulder) must swing far to cancel a drift of a few
//! centimetres, so its local rotation error is several times `sigma`
//! (measured on a Bandai take at `sigma` = 5 degrees: about 20 degrees at
//! Hips, Shoulder and UpperLeg, 8-13 at the limbs' distal joints), while
//! the positions err by only a few centimetres. This is also what IK on
//! noisy keypoints produces: wrong rotations that still put the joints near
//! the observed points.
//!
//! Joints above the pelvis get no error (see
//! [`RandomNoise::perturb_above_pelvis`]): some rigs put helper joints there
//! (Bandai Namco's `joint_Root`, on the floor, 94 cm below `Hips`), which no
//! keypoint detector sees. An error on such a joint turns the whole body
//! about a point on the floor: the pelvis moves by `sigma` times the
//! helper's 94 cm "bone" (8 cm at 5 degrees, three times the error of a
//! body bone), and every joint below must swing to cancel it. Measured on
//! `dataset-1_walk_tired_002` at `sigma` = 5 degrees, with that error the
//! noisy local rotations err by 38 degrees at `Hips` and 53 at `UpperLeg`
//! (the other joints 9-37); without it, see `bench/results/clean.md`.
//!
//! ## Spike noise ([`SpikeNoise`])
//!
//! A wrong association with another person: a random joint and every joint
//! below it take the rotations of a different motion for a duration drawn
//! from a half-normal distribution (`|N(0, duration_sigma^2)|` frames, at
//! least one), with one to `max_spikes` simultaneous spikes.
//!
//! Root translation is never changed.

use mocap_core::forward_kinematics;
use mocap_core::retarget::Retargeting;
use mocap_core::rotation::{expmap_to_quat, Quat, Vec3};
use mocap_core::Motion;
use mocap_core::Skeleton;
use rand::{Rng, RngExt};
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use crate::{CleanError, Result};

/// Random per-frame noise (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RandomNoise {
    /// Largest standard deviation of the per-joint error angle, in degrees
    /// (report: 10). Each sample draws its own in `[0, max_sigma_deg]`.
    pub max_sigma_deg: f32,
    /// Correct the accumulation along the chain (default true).
    pub chain_corrected: bool,
    /// Also perturb the joints above the pelvis
    /// ([`mocap_core::Skeleton::first_branching_joint`]), such as a helper
    /// root on the floor. Off by default (see the module docs); models
    /// trained before this option existed were trained with it on, hence
    /// the serde default.
    #[serde(default = "perturbed_above_pelvis_before")]
    pub perturb_above_pelvis: bool,
}

/// What noise headers written before `perturb_above_pelvis` existed mean.
fn perturbed_above_pelvis_before() -> bool {
    true
}

impl Default for RandomNoise {
    fn default() -> Self {
        RandomNoise {
            max_sigma_deg: 10.0,
            chain_corrected: true,
            perturb_above_pelvis: false,
        }
    }
}

/// Spike noise: subtrees swapped with another motion (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpikeNoise {
    /// At most this many simultaneous spikes (report: 3).
    pub max_spikes: usize,
    /// Standard deviation of the spike duration in frames (report: 16).
    pub duration_sigma_frames: f32,
    /// Whether the root can be picked (then the whole pose is swapped).
    pub include_root: bool,
}

impl Default for SpikeNoise {
    fn default() -> Self {
        SpikeNoise {
            max_spikes: 3,
            duration_sigma_frames: 16.0,
            include_root: false,
        }
    }
}

/// One spike that was added: `joint` and its subtree, frames
/// `start..start + frames`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Spike {
    pub joint: usize,
    pub start: usize,
    pub frames: usize,
}

/// The noise of a training or evaluation sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NoiseConfig {
    pub random: Option<RandomNoise>,
    pub spikes: Option<SpikeNoise>,
    /// Probability that a sample gets spikes (when `spikes` is set).
    pub spike_probability: f32,
}

impl Default for NoiseConfig {
    /// Both kinds: random noise on every sample, spikes on half of them.
    fn default() -> Self {
        NoiseConfig {
            random: Some(RandomNoise::default()),
            spikes: Some(SpikeNoise::default()),
            spike_probability: 0.5,
        }
    }
}

/// A random rotation whose angle has RMS `sigma` radians.
fn random_rotation<R: Rng + ?Sized>(rng: &mut R, sigma: f32) -> Quat {
    if sigma <= 0.0 {
        return Quat::IDENTITY;
    }
    let normal = Normal::new(0.0f32, sigma / 3f32.sqrt()).expect("finite sigma");
    expmap_to_quat(Vec3::new(
        normal.sample(rng),
        normal.sample(rng),
        normal.sample(rng),
    ))
}

/// Adds random noise with a standard deviation drawn in
/// `[0, max_sigma_deg]`; returns the noisy motion and the drawn sigma.
pub fn add_random_noise<R: Rng + ?Sized>(
    motion: &Motion,
    params: &RandomNoise,
    rng: &mut R,
) -> (Motion, f32) {
    let sigma_deg = rng.random::<f32>() * params.max_sigma_deg.max(0.0);
    (
        add_random_noise_sigma(motion, sigma_deg, params, rng),
        sigma_deg,
    )
}

/// Adds random noise of standard deviation `sigma_deg` degrees, corrected as
/// `params` says (its `max_sigma_deg` is not used).
pub fn add_random_noise_sigma<R: Rng + ?Sized>(
    motion: &Motion,
    sigma_deg: f32,
    params: &RandomNoise,
    rng: &mut R,
) -> Motion {
    let sigma = sigma_deg.to_radians();
    let skeleton = motion.skeleton();
    let n = skeleton.joint_count();
    let rotates: Vec<bool> = skeleton
        .joints()
        .iter()
        .map(|j| j.channels.iter().any(|c| c.is_rotation()))
        .collect();
    // Whether each joint gets its own error: not the joints above the pelvis
    // unless asked (they come first: parents precede children).
    let mut perturbed = rotates.clone();
    if !params.perturb_above_pelvis {
        let pelvis = skeleton.first_branching_joint();
        let mut above = skeleton.joint(pelvis).parent;
        while let Some(j) = above {
            perturbed[j] = false;
            above = skeleton.joint(j).parent;
        }
    }
    let mut out = motion.clone();
    if !params.chain_corrected {
        for f in 0..motion.frame_count() {
            for j in (0..n).filter(|&j| perturbed[j]) {
                let q = motion.local_rotation(f, j) * random_rotation(rng, sigma);
                out.set_local_rotation(f, j, q);
            }
        }
        return out;
    }
    // The main child of each joint: the child with the longest offset.
    let main_child: Vec<Option<usize>> = (0..n)
        .map(|j| {
            skeleton
                .children(j)
                .max_by(|&a, &b| {
                    skeleton
                        .joint(a)
                        .offset
                        .length()
                        .total_cmp(&skeleton.joint(b).offset.length())
                })
                .filter(|&c| skeleton.joint(c).offset.length() > 1e-6)
        })
        .collect();
    let poses = forward_kinematics(motion);
    let mut noisy_rot = vec![Quat::IDENTITY; n];
    let mut noisy_pos = vec![Vec3::ZERO; n];
    for f in 0..motion.frame_count() {
        for j in 0..n {
            let g = poses.rotation(f, j);
            let x = poses.position(f, j);
            let parent = skeleton.joint(j).parent;
            let xj = match parent {
                Some(p) => noisy_pos[p] + noisy_rot[p] * motion.local_translation(f, j),
                None => x,
            };
            let mut a = if perturbed[j] {
                g * random_rotation(rng, sigma)
            } else if rotates[j] {
                // A helper above the pelvis keeps its rotation; its children
                // are then where they should be and nothing swings.
                g
            } else {
                // A joint without rotation channels follows its parent.
                match parent {
                    Some(p) => noisy_rot[p] * motion.local_rotation(f, j),
                    None => g,
                }
            };
            if let (true, Some(c)) = (rotates[j], main_child[j]) {
                let t = motion.local_translation(f, c);
                let own_error = a * t - g * t;
                let target = poses.position(f, c) + own_error - xj;
                let current = a * t;
                if target.length() > 1e-6 && current.length() > 1e-6 {
                    a = Quat::from_rotation_arc(current.normalize(), target.normalize()) * a;
                }
            }
            noisy_rot[j] = a.normalize();
            noisy_pos[j] = xj;
        }
        for j in (0..n).filter(|&j| rotates[j]) {
            let local = match skeleton.joint(j).parent {
                Some(p) => noisy_rot[p].conjugate() * noisy_rot[j],
                None => noisy_rot[j],
            };
            out.set_local_rotation(f, j, local.normalize());
        }
    }
    out
}

/// Adds one to `max_spikes` spikes taken from `donors` (motions on the same
/// skeleton, at least as long as `motion`; one is picked per spike).
pub fn add_spike_noise<R: Rng + ?Sized>(
    motion: &Motion,
    donors: &[&Motion],
    params: &SpikeNoise,
    rng: &mut R,
) -> Result<(Motion, Vec<Spike>)> {
    let count = if params.max_spikes == 0 {
        0
    } else {
        rng.random_range(1..=params.max_spikes)
    };
    let frames = motion.frame_count();
    let mut spikes = Vec::with_capacity(count);
    let duration = Normal::new(0.0f32, params.duration_sigma_frames.max(0.0))
        .map_err(|e| CleanError::Invalid(format!("spike duration: {e}")))?;
    for _ in 0..count {
        let len = (duration.sample(rng).abs().ceil() as usize).max(1);
        let start = rng.random_range(0..frames.max(1));
        spikes.push(Spike {
            joint: 0,
            start,
            frames: len.min(frames - start),
        });
    }
    add_spikes(motion, donors, params, &mut spikes, rng)
}

/// Adds spikes of given starts and lengths (their joints are drawn); the
/// evaluation uses it to place spikes of chosen lengths.
pub fn add_spikes<R: Rng + ?Sized>(
    motion: &Motion,
    donors: &[&Motion],
    params: &SpikeNoise,
    spikes: &mut [Spike],
    rng: &mut R,
) -> Result<(Motion, Vec<Spike>)> {
    let skeleton = motion.skeleton();
    let frames = motion.frame_count();
    for d in donors {
        if d.skeleton().joint_count() != skeleton.joint_count() || d.frame_count() < frames {
            return Err(CleanError::Invalid(format!(
                "a spike donor must have the same skeleton ({} joints) and at least {frames} frames; got {} joints, {} frames",
                skeleton.joint_count(),
                d.skeleton().joint_count(),
                d.frame_count()
            )));
        }
    }
    if donors.is_empty() {
        return Err(CleanError::Invalid(
            "spike noise needs at least one donor motion".into(),
        ));
    }
    let candidates: Vec<usize> = (0..skeleton.joint_count())
        .filter(|&j| params.include_root || skeleton.joint(j).parent.is_some())
        .filter(|&j| skeleton.joint(j).channels.iter().any(|c| c.is_rotation()))
        .collect();
    if candidates.is_empty() {
        return Err(CleanError::Invalid("no joint can take a spike".into()));
    }
    let mut out = motion.clone();
    for spike in spikes.iter_mut() {
        spike.joint = candidates[rng.random_range(0..candidates.len())];
        let donor = donors[rng.random_range(0..donors.len())];
        let subtree = skeleton.subtree(spike.joint);
        let end = (spike.start + spike.frames).min(frames);
        for f in spike.start..end {
            for &j in &subtree {
                out.set_local_rotation(f, j, donor.local_rotation(f, j));
            }
        }
        // Frames after the spike keep continuous Euler tracks: rewrite the
        // next frame's rotations through set_local_rotation as well.
        if end < frames {
            for &j in &subtree {
                out.set_local_rotation(end, j, motion.local_rotation(end, j));
            }
        }
    }
    Ok((out, spikes.to_vec()))
}

/// Applies `config` to `motion`: random noise, then (with the configured
/// probability) spikes from `donors`.
pub fn add_noise<R: Rng + ?Sized>(
    motion: &Motion,
    donors: &[&Motion],
    config: &NoiseConfig,
    rng: &mut R,
) -> Result<Motion> {
    let noisy = match &config.random {
        Some(r) => add_random_noise(motion, r, rng).0,
        None => motion.clone(),
    };
    if let Some(s) = &config.spikes {
        if rng.random::<f32>() < config.spike_probability {
            return Ok(add_spike_noise(&noisy, donors, s, rng)?.0);
        }
    }
    Ok(noisy)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::synthetic_motion;
    use rand::rngs::ChaCha8Rng;
    use rand::SeedableRng;

    /// Mean position error of each joint, over frames.
    fn position_errors(a: &Motion, b: &Motion) -> Vec<f32> {
        let (pa, pb) = (forward_kinematics(a), forward_kinematics(b));
        let n = a.skeleton().joint_count();
        (0..n)
            .map(|j| {
                (0..a.frame_count())
                    .map(|f| (pa.position(f, j) - pb.position(f, j)).length())
                    .sum::<f32>()
                    / a.frame_count() as f32
            })
            .collect()
    }

    #[test]
    fn chain_correction_keeps_the_error_flat_along_the_chain() {
        // A straight chain of equal bones: naive noise grows with depth.
        let motion = synthetic_motion(400, 11);
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        // A chain has no pelvis (no branch): perturb every joint.
        let corrected_params = RandomNoise {
            perturb_above_pelvis: true,
            ..Default::default()
        };
        let naive_params = RandomNoise {
            chain_corrected: false,
            ..corrected_params
        };
        let naive = add_random_noise_sigma(&motion, 5.0, &naive_params, &mut rng);
        let corrected = add_random_noise_sigma(&motion, 5.0, &corrected_params, &mut rng);
        let en = position_errors(&motion, &naive);
        let ec = position_errors(&motion, &corrected);
        let last = en.len() - 1;
        // Naive: the chain end errs far more than the first bone.
        assert!(en[last] > 3.0 * en[1], "naive {en:?}");
        // Corrected: about the same error at every depth.
        assert!(ec[last] < 1.6 * ec[1], "corrected {ec:?}");
        assert!(ec[last] < 0.5 * en[last]);
        // The per-bone error is about sigma * bone length (10 units, 5 deg).
        let expected = 10.0 * 5f32.to_radians();
        assert!(ec[1] > 0.4 * expected && ec[1] < 2.0 * expected, "{ec:?}");
        // Root translation untouched.
        for f in 0..motion.frame_count() {
            assert_eq!(motion.root_translation(f), corrected.root_translation(f));
        }
    }

    #[test]
    fn joints_above_the_pelvis_keep_their_rotation_unless_asked() {
        let motion = crate::test_support::branching_motion(50);
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let noisy = add_random_noise_sigma(&motion, 8.0, &RandomNoise::default(), &mut rng);
        let moved = |noisy: &Motion, j: usize| {
            (0..motion.frame_count())
                .map(|f| {
                    mocap_core::rotation::angle_between(
                        motion.local_rotation(f, j),
                        noisy.local_rotation(f, j),
                    )
                })
                .fold(0.0f32, f32::max)
        };
        // Joint 0 (the helper root) is above the pelvis (joint 1).
        assert!(moved(&noisy, 0) < 1e-5);
        assert!(moved(&noisy, 1) > 1f32.to_radians());
        let everywhere = RandomNoise {
            perturb_above_pelvis: true,
            ..Default::default()
        };
        let noisy = add_random_noise_sigma(&motion, 8.0, &everywhere, &mut rng);
        assert!(moved(&noisy, 0) > 1f32.to_radians());
    }

    #[test]
    fn spikes_swap_a_subtree_for_a_while() {
        let motion = synthetic_motion(60, 6);
        let donor = crate::test_support::synthetic_motion_phase(60, 6, 2.0);
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let params = SpikeNoise {
            max_spikes: 1,
            duration_sigma_frames: 10.0,
            include_root: false,
        };
        let (noisy, spikes) = add_spike_noise(&motion, &[&donor], &params, &mut rng).unwrap();
        assert_eq!(spikes.len(), 1);
        let s = spikes[0];
        let subtree = motion.skeleton().subtree(s.joint);
        for f in 0..motion.frame_count() {
            for j in 0..motion.skeleton().joint_count() {
                let inside = f >= s.start && f < s.start + s.frames && subtree.contains(&j);
                let want = if inside {
                    donor.local_rotation(f, j)
                } else {
                    motion.local_rotation(f, j)
                };
                let angle = mocap_core::rotation::angle_between(noisy.local_rotation(f, j), want);
                assert!(angle < 1e-3, "frame {f} joint {j} inside {inside}");
            }
        }
    }
}

/// Noise as other rigs make it, for a model that cleans their takes through
/// its own rig (`crate::rig`): a take of another rig has its noise on that
/// rig's joints, about that rig's bones (the chain correction makes most of
/// a joint's error a turn about its bone), and the model sees it played by
/// its own rig. Each sample is played by one of the rigs or by its own, at
/// random; the noise is put on there and both the clean and the noisy
/// sample are played back, so that the model learns to give the clean one
/// as its rig plays it.
#[derive(Debug, Clone, Default)]
pub(crate) struct NoiseRigs {
    /// Each rig: from the model's rig to it, and back.
    rigs: Vec<(Retargeting, Retargeting)>,
}

impl NoiseRigs {
    /// The retargetings between `own` (the model's rig) and each of
    /// `others`, whose body parts must be found.
    pub(crate) fn new(own: &Skeleton, others: &[Skeleton]) -> Result<NoiseRigs> {
        let rigs = others
            .iter()
            .map(|other| {
                Ok((
                    Retargeting::detect(own, other)?,
                    Retargeting::detect(other, own)?,
                ))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(NoiseRigs { rigs })
    }

    /// `clean` (of the model's rig) and a noisy copy as [`add_noise`] makes
    /// it, both through a rig drawn at random (one of the others, or none:
    /// then `clean` itself): (clean, noisy).
    pub(crate) fn add_noise<R: Rng + ?Sized>(
        &self,
        clean: &Motion,
        donors: &[&Motion],
        config: &NoiseConfig,
        rng: &mut R,
    ) -> Result<(Motion, Motion)> {
        let k = rng.random_range(0..=self.rigs.len());
        let Some((there, back)) = k.checked_sub(1).map(|k| &self.rigs[k]) else {
            let noisy = add_noise(clean, donors, config, rng)?;
            return Ok((clean.clone(), noisy));
        };
        let played = there.apply(clean)?;
        let donors = donors
            .iter()
            .map(|d| there.apply(d))
            .collect::<mocap_core::Result<Vec<_>>>()?;
        let donor_refs: Vec<&Motion> = donors.iter().collect();
        let noisy = add_noise(&played, &donor_refs, config, rng)?;
        Ok((back.apply(&played)?, back.apply(&noisy)?))
    }
}
