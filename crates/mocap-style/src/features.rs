//! What the autoencoder sees, and how a motion is rebuilt from it.
//!
//! Every frame becomes one rotation per *slot*:
//!
//! - slot 0 is the pelvis's global rotation with its heading removed
//!   (`S = H^-1 R_pelvis`, with `H` the rotation about the up axis that turns
//!   a fixed horizontal axis onto the right-to-left hip direction). The tilt
//!   and roll of the pelvis are part of a style; its heading is part of the
//!   path, which comes from the source;
//! - the other slots are the local rotations of every joint below the pelvis
//!   that has rotation channels (end sites have none).
//!
//! A rotation `q` of slot `k` is fed as the exponential map
//! `v = log(r_k^-1 q)` (a rotation vector, [`quat_to_expmap`]) relative to a
//! reference rotation `r_k`, the mean rotation of the slot in the training
//! data. The reference changes nothing in the method (it is a fixed change of
//! the joint's local frame); it keeps every angle far from 180 degrees, where
//! the exponential map wraps around (Bandai's rig lays its bones along local
//! X, so its raw local rotations sit near 90 to 180 degrees). The vectors are
//! then standardised per channel with the training mean and deviation
//! ([`Normalization`]).
//!
//! The root (pelvis position and heading) is a [`RootTrack`] kept beside the
//! features: it is not style-converted.

use mocap_core::bodymap::{BodyMap, BodyPart};
use mocap_core::rotation::{expmap_to_quat, quat_to_expmap, slerp, Quat, Vec3};
use mocap_core::{forward_kinematics, Motion, Skeleton};
use serde::{Deserialize, Serialize};

use crate::{invalid, Result};

/// Numbers per slot (an exponential map).
pub const SLOT_DIM: usize = 3;

/// The joints of a rig that style transfer uses, found with the body map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigLayout {
    /// Every joint's name in skeleton order (recognises the rig).
    pub joint_names: Vec<String>,
    /// Every joint's parent.
    pub parents: Vec<Option<usize>>,
    /// The joint at the pelvis: it carries the root motion.
    pub pelvis: usize,
    pub left_hip: usize,
    pub right_hip: usize,
    pub head: usize,
    /// Ankle and toe joints of the left foot (toe when the rig has one).
    pub left_foot: Vec<usize>,
    pub right_foot: Vec<usize>,
    /// Joints whose local rotations are slots 1.. (skeleton order).
    pub joints: Vec<usize>,
}

impl RigLayout {
    /// Finds the layout of `skeleton` with [`BodyMap::detect`].
    pub fn from_skeleton(skeleton: &Skeleton) -> Result<RigLayout> {
        let map = BodyMap::detect(skeleton)?;
        let pelvis = map.require(BodyPart::Pelvis)?;
        if !skeleton.joint(pelvis).has_position_channels() {
            return Err(invalid(format!(
                "the pelvis joint `{}` has no position channels: style transfer moves the \
                 root through the pelvis, so it needs Xposition/Yposition/Zposition there",
                skeleton.joint(pelvis).name
            )));
        }
        if !skeleton.joint(pelvis).has_rotation_channels() {
            return Err(invalid(format!(
                "the pelvis joint `{}` has no rotation channels",
                skeleton.joint(pelvis).name
            )));
        }
        let below = skeleton.subtree(pelvis);
        let joints: Vec<usize> = below
            .iter()
            .copied()
            .filter(|&j| j != pelvis && skeleton.joint(j).has_rotation_channels())
            .collect();
        let foot = |ankle: BodyPart, toe: BodyPart| -> Result<Vec<usize>> {
            let mut v = vec![map.require(ankle)?];
            v.extend(map.joint(toe));
            Ok(v)
        };
        let mut joints_sorted = joints;
        joints_sorted.sort_unstable();
        Ok(RigLayout {
            joint_names: skeleton.joints().iter().map(|j| j.name.clone()).collect(),
            parents: skeleton.joints().iter().map(|j| j.parent).collect(),
            pelvis,
            left_hip: map.require(BodyPart::LeftHip)?,
            right_hip: map.require(BodyPart::RightHip)?,
            head: map.require(BodyPart::Head)?,
            left_foot: foot(BodyPart::LeftAnkle, BodyPart::LeftToe)?,
            right_foot: foot(BodyPart::RightAnkle, BodyPart::RightToe)?,
            joints: joints_sorted,
        })
    }

    /// Rotation slots per frame (pelvis + joints).
    pub fn slots(&self) -> usize {
        1 + self.joints.len()
    }

    /// Feature channels per frame.
    pub fn channels(&self) -> usize {
        SLOT_DIM * self.slots()
    }

    /// Checks that `skeleton` is this rig (same joint names and hierarchy,
    /// rotation channels on the same joints); `what` names the skeleton's
    /// file in the message. Bone lengths may differ (another performer).
    pub fn check_skeleton(&self, skeleton: &Skeleton, what: &str) -> Result<()> {
        let names: Vec<&str> = skeleton.joints().iter().map(|j| j.name.as_str()).collect();
        let parents: Vec<Option<usize>> = skeleton.joints().iter().map(|j| j.parent).collect();
        if names
            != self
                .joint_names
                .iter()
                .map(String::as_str)
                .collect::<Vec<_>>()
            || parents != self.parents
        {
            let ours: Vec<&str> = self.joint_names.iter().map(String::as_str).collect();
            let missing: Vec<&str> = ours
                .iter()
                .copied()
                .filter(|n| !names.contains(n))
                .collect();
            let extra: Vec<&str> = names
                .iter()
                .copied()
                .filter(|n| !ours.contains(n))
                .collect();
            return Err(invalid(format!(
                "{what}: another rig ({} joints{}{}{}); style transfer needs the same joint \
                 names and hierarchy ({} joints starting {}): play the clip on the model's rig \
                 first (`mocap convert CLIP --retarget-to A_CLIP_OF_THAT_RIG.bvh OUT.bvh`), or \
                 train a model on this rig with `mocap style train`",
                names.len(),
                if missing.is_empty() {
                    String::new()
                } else {
                    format!(", lacks {}", missing.join(", "))
                },
                if extra.is_empty() {
                    String::new()
                } else {
                    format!(", has {} not expected", extra.join(", "))
                },
                if missing.is_empty() && extra.is_empty() {
                    ", same names in another order or hierarchy"
                } else {
                    ""
                },
                ours.len(),
                ours.iter().take(4).copied().collect::<Vec<_>>().join(", "),
            )));
        }
        for &j in std::iter::once(&self.pelvis).chain(&self.joints) {
            if !skeleton.joint(j).has_rotation_channels() {
                return Err(invalid(format!(
                    "{what}: joint `{}` has no rotation channels, unlike the rig the model was \
                     trained on",
                    skeleton.joint(j).name
                )));
            }
        }
        Ok(())
    }

    /// Rest length of the legs, hip to ankle, averaged over both legs
    /// ([`Skeleton::chain_length`], file units): the scale of root heights
    /// and strides between performers.
    pub fn leg_length(&self, skeleton: &Skeleton) -> f32 {
        let leg = |ankle: usize, hip: usize| skeleton.chain_length(ankle, hip).unwrap_or(0.0);
        (leg(self.left_foot[0], self.left_hip) + leg(self.right_foot[0], self.right_hip)) / 2.0
    }
}

/// Root motion of a clip: the pelvis's global position and heading.
#[derive(Debug, Clone, PartialEq)]
pub struct RootTrack {
    /// Unit world up axis (the direction from the pelvis to the head).
    pub up: Vec3,
    /// Global pelvis position in every frame.
    pub position: Vec<Vec3>,
    /// Heading (rotation about `up`) in every frame.
    pub heading: Vec<Quat>,
}

impl RootTrack {
    /// Height of the pelvis above the origin along `up`, per frame.
    pub fn heights(&self) -> Vec<f32> {
        self.position.iter().map(|p| p.dot(self.up)).collect()
    }

    /// Position and heading at a fractional frame (linear and slerp,
    /// clamped to the clip).
    pub fn sample(&self, t: f32) -> (Vec3, Quat) {
        let last = self.position.len() - 1;
        let t = t.clamp(0.0, last as f32);
        let i = (t.floor() as usize).min(last);
        let j = (i + 1).min(last);
        let a = t - i as f32;
        (
            self.position[i].lerp(self.position[j], a),
            slerp(self.heading[i], self.heading[j], a),
        )
    }
}

/// The world axis (signed unit X, Y or Z) closest to the mean direction from
/// pelvis to head over the clip.
pub fn up_axis(positions: &[Vec3], joint_count: usize, layout: &RigLayout) -> Vec3 {
    let frames = positions.len() / joint_count.max(1);
    let mut d = Vec3::ZERO;
    for f in 0..frames {
        d += positions[f * joint_count + layout.head] - positions[f * joint_count + layout.pelvis];
    }
    let a = d.abs();
    if a.x >= a.y && a.x >= a.z {
        Vec3::X * d.x.signum()
    } else if a.y >= a.z {
        Vec3::Y * d.y.signum()
    } else {
        Vec3::Z * d.z.signum()
    }
}

/// The gait period in seconds: the lag of the strongest autocorrelation of
/// the feet's heights between 0.4 and 2.5 s (the smallest lag within 90% of
/// the best, so that two strides are not taken for one). `None` when the
/// clip is too short or the feet do not move periodically (best
/// autocorrelation below 0.2).
pub fn gait_period(motion: &Motion, rig: &RigLayout) -> Option<f64> {
    let poses = forward_kinematics(motion);
    let up = up_axis(&poses.positions, poses.joint_count, rig);
    let fps = motion.fps();
    let n = poses.frame_count;
    let min_lag = (0.4 * fps).round() as usize;
    let max_lag = ((2.5 * fps).round() as usize).min(n.saturating_sub(n / 4));
    if max_lag <= min_lag + 2 {
        return None;
    }
    let signal = |joint: usize| -> Vec<f64> {
        let h: Vec<f64> = (0..n)
            .map(|f| poses.position(f, joint).dot(up) as f64)
            .collect();
        let mean = h.iter().sum::<f64>() / n as f64;
        h.into_iter().map(|x| x - mean).collect()
    };
    let feet = [signal(rig.left_foot[0]), signal(rig.right_foot[0])];
    // Normalised autocorrelation (mean over the overlap), summed over feet.
    let energy: f64 = feet
        .iter()
        .map(|s| s.iter().map(|x| x * x).sum::<f64>() / n as f64)
        .sum();
    if energy < 1e-9 {
        return None;
    }
    let r: Vec<f64> = (0..=max_lag)
        .map(|lag| {
            feet.iter()
                .map(|s| (0..n - lag).map(|t| s[t] * s[t + lag]).sum::<f64>() / (n - lag) as f64)
                .sum::<f64>()
                / energy
        })
        .collect();
    let peaks: Vec<usize> = (min_lag.max(1)..max_lag)
        .filter(|&l| r[l] >= r[l - 1] && r[l] >= r[l + 1])
        .collect();
    let best = peaks
        .iter()
        .map(|&l| r[l])
        .fold(f64::NEG_INFINITY, f64::max);
    if best < 0.2 {
        return None;
    }
    let lag = *peaks.iter().find(|&&l| r[l] >= 0.9 * best)?;
    // Parabolic interpolation of the peak for sub-frame precision.
    let (a, b, c) = (r[lag - 1], r[lag], r[lag + 1]);
    let denom = a - 2.0 * b + c;
    let offset = if denom.abs() > 1e-12 {
        0.5 * (a - c) / denom
    } else {
        0.0
    };
    Some((lag as f64 + offset.clamp(-0.5, 0.5)) / fps)
}

/// A fixed horizontal axis for heading angles: the first world axis that is
/// not the up axis.
fn horizontal_reference(up: Vec3) -> Vec3 {
    if up.x.abs() > 0.5 {
        Vec3::Y
    } else {
        Vec3::X
    }
}

/// The heading: rotation about `up` turning the fixed horizontal axis onto
/// the horizontal part of `lateral` (the right-to-left hip vector).
fn heading_of(lateral: Vec3, up: Vec3, previous: Option<Quat>) -> Quat {
    let h = lateral - up * lateral.dot(up);
    if h.length_squared() < 1e-12 {
        // Hips exactly above one another: keep the previous heading.
        return previous.unwrap_or(Quat::IDENTITY);
    }
    let h = h.normalize();
    let r = horizontal_reference(up);
    let angle = up.dot(r.cross(h)).atan2(r.dot(h));
    let q = Quat::from_axis_angle(up, angle);
    // Keep quaternion signs continuous along time (for slerp).
    match previous {
        Some(p) if p.dot(q) < 0.0 => -q,
        _ => q,
    }
}

/// A clip split into rotation slots (frame after frame, `layout.slots()` per
/// frame) and its root track.
pub fn decompose(motion: &Motion, layout: &RigLayout) -> (Vec<Quat>, RootTrack) {
    let poses = forward_kinematics(motion);
    let n = poses.joint_count;
    let up = up_axis(&poses.positions, n, layout);
    let frames = motion.frame_count();
    let mut rotations = Vec::with_capacity(frames * layout.slots());
    let mut position = Vec::with_capacity(frames);
    let mut heading: Vec<Quat> = Vec::with_capacity(frames);
    for f in 0..frames {
        let lateral = poses.position(f, layout.left_hip) - poses.position(f, layout.right_hip);
        let h = heading_of(lateral, up, heading.last().copied());
        heading.push(h);
        position.push(poses.position(f, layout.pelvis));
        rotations.push(h.inverse() * poses.rotation(f, layout.pelvis));
        for &j in &layout.joints {
            rotations.push(motion.local_rotation(f, j));
        }
    }
    (
        rotations,
        RootTrack {
            up,
            position,
            heading,
        },
    )
}

/// Reference rotations and per-channel statistics of the training data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Normalization {
    /// Reference rotation `r_k` of every slot, as `[x, y, z, w]`.
    pub reference: Vec<[f32; 4]>,
    /// Mean of every channel of `log(r_k^-1 q)`.
    pub mean: Vec<f32>,
    /// Standard deviation of every channel (floored, see [`Normalization::fit`]).
    pub std: Vec<f32>,
}

/// Smallest standard deviation used to divide a channel (radians): a joint
/// that barely moves in the training data (toes) must not blow up.
const MIN_STD: f32 = 0.02;

impl Normalization {
    /// Fits the reference rotations (the normalised sum of each slot's
    /// quaternions, signs aligned to the first) and channel statistics on
    /// clips of slot rotations.
    pub fn fit(clips: &[&[Quat]], slots: usize) -> Result<Normalization> {
        let total: usize = clips.iter().map(|c| c.len() / slots).sum();
        if total == 0 {
            return Err(invalid("no frames to fit the feature statistics on"));
        }
        let mut sums = vec![glam::Vec4::ZERO; slots];
        let mut firsts: Vec<Option<Quat>> = vec![None; slots];
        for clip in clips {
            for (i, q) in clip.iter().enumerate() {
                let k = i % slots;
                let first = *firsts[k].get_or_insert(*q);
                let q = if first.dot(*q) < 0.0 { -*q } else { *q };
                sums[k] += glam::Vec4::from(q);
            }
        }
        let reference: Vec<[f32; 4]> = sums
            .iter()
            .map(|s| {
                let q = Quat::from_vec4(*s);
                let q = if q.length_squared() > 1e-12 {
                    q.normalize()
                } else {
                    Quat::IDENTITY
                };
                q.to_array()
            })
            .collect();
        let channels = slots * SLOT_DIM;
        let mut norm = Normalization {
            reference,
            mean: vec![0.0; channels],
            std: vec![1.0; channels],
        };
        let mut sum = vec![0.0f64; channels];
        let mut sum2 = vec![0.0f64; channels];
        for clip in clips {
            let v = norm.exp_maps(clip);
            for (i, x) in v.iter().enumerate() {
                sum[i % channels] += *x as f64;
                sum2[i % channels] += (*x as f64) * (*x as f64);
            }
        }
        for c in 0..channels {
            let m = sum[c] / total as f64;
            let var = (sum2[c] / total as f64 - m * m).max(0.0);
            norm.mean[c] = m as f32;
            norm.std[c] = (var.sqrt() as f32).max(MIN_STD);
        }
        Ok(norm)
    }

    pub fn slots(&self) -> usize {
        self.reference.len()
    }

    pub fn channels(&self) -> usize {
        self.mean.len()
    }

    fn exp_maps(&self, rotations: &[Quat]) -> Vec<f32> {
        let slots = self.slots();
        let mut out = Vec::with_capacity(rotations.len() * SLOT_DIM);
        for (i, q) in rotations.iter().enumerate() {
            let r = Quat::from_array(self.reference[i % slots]);
            out.extend_from_slice(&quat_to_expmap(r.inverse() * *q).to_array());
        }
        out
    }

    /// Standardised features, frame after frame (`channels()` per frame).
    pub fn features(&self, rotations: &[Quat]) -> Vec<f32> {
        let channels = self.channels();
        let mut v = self.exp_maps(rotations);
        for (i, x) in v.iter_mut().enumerate() {
            let c = i % channels;
            *x = (*x - self.mean[c]) / self.std[c];
        }
        v
    }

    /// Slot rotations of standardised features (the inverse of
    /// [`Normalization::features`]).
    pub fn rotations(&self, features: &[f32]) -> Vec<Quat> {
        let channels = self.channels();
        let slots = self.slots();
        features
            .chunks_exact(SLOT_DIM)
            .enumerate()
            .map(|(k, v)| {
                let c = (k * SLOT_DIM) % channels;
                let e = Vec3::new(
                    v[0] * self.std[c] + self.mean[c],
                    v[1] * self.std[c + 1] + self.mean[c + 1],
                    v[2] * self.std[c + 2] + self.mean[c + 2],
                );
                Quat::from_array(self.reference[k % slots]) * expmap_to_quat(e)
            })
            .collect()
    }
}

/// The motion sampled at fractional frames `times` (slerp of local
/// rotations, linear position channels; clamped to the clip), with the same
/// skeleton and frame time.
pub fn sample_frames(motion: &Motion, times: &[f32]) -> Result<Motion> {
    let skeleton = motion.skeleton();
    if motion.frame_count() == 0 {
        return Err(invalid("cannot sample a motion without frames"));
    }
    let last = motion.frame_count() - 1;
    let mut values = Vec::with_capacity(times.len() * skeleton.channel_count());
    let mut between = Vec::new();
    for (k, &t) in times.iter().enumerate() {
        let t = t.clamp(0.0, last as f32);
        let i = (t.floor() as usize).min(last);
        let a = t - i as f32;
        values.extend_from_slice(motion.frame(i));
        if a > 1e-4 && i < last {
            between.push((k, i, a));
        }
    }
    let mut out = Motion::new(skeleton.clone(), motion.frame_time(), times.len(), values)?;
    for (k, i, a) in between {
        for (j, joint) in skeleton.joints().iter().enumerate() {
            if joint.has_rotation_channels() {
                let q = slerp(
                    motion.local_rotation(i, j),
                    motion.local_rotation(i + 1, j),
                    a,
                );
                out.set_local_rotation(k, j, q);
            }
            if joint.has_position_channels() {
                let p = motion
                    .local_translation(i, j)
                    .lerp(motion.local_translation(i + 1, j), a);
                out.set_local_translation(k, j, p);
            }
        }
    }
    Ok(out)
}

/// Writes slot rotations and the pelvis path into `base` (a motion of the
/// layout's rig with as many frames): the pelvis gets global rotation
/// `heading * slot 0` and global position `pelvis`, the other joints their
/// local rotations. Joints above the pelvis keep `base`'s values.
pub fn compose(
    mut base: Motion,
    layout: &RigLayout,
    rotations: &[Quat],
    pelvis: &[Vec3],
    heading: &[Quat],
) -> Result<Motion> {
    let frames = base.frame_count();
    if rotations.len() != frames * layout.slots()
        || pelvis.len() != frames
        || heading.len() != frames
    {
        return Err(invalid(format!(
            "internal: {frames} frames but {} rotations, {} pelvis positions, {} headings",
            rotations.len(),
            pelvis.len(),
            heading.len()
        )));
    }
    let parent = base.skeleton().joint(layout.pelvis).parent;
    let parent_poses = parent.map(|_| forward_kinematics(&base));
    for f in 0..frames {
        let (rp, xp) = match (parent, &parent_poses) {
            (Some(p), Some(poses)) => (poses.rotation(f, p), poses.position(f, p)),
            _ => (Quat::IDENTITY, Vec3::ZERO),
        };
        let slots = &rotations[f * layout.slots()..(f + 1) * layout.slots()];
        let global = heading[f] * slots[0];
        base.set_local_rotation(f, layout.pelvis, rp.inverse() * global);
        base.set_local_translation(f, layout.pelvis, rp.inverse() * (pelvis[f] - xp));
        for (&j, &q) in layout.joints.iter().zip(&slots[1..]) {
            base.set_local_rotation(f, j, q);
        }
    }
    Ok(base)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::test_support::bandai_walk;

    /// decompose then compose gives back the clip (same FK positions).
    #[test]
    fn decompose_compose_round_trip() {
        let Some(motion) = bandai_walk("dataset-1_walk_proud_001.bvh") else {
            return;
        };
        let layout = RigLayout::from_skeleton(motion.skeleton()).unwrap();
        assert_eq!(layout.pelvis, motion.skeleton().find("Hips").unwrap());
        assert_eq!(layout.slots(), 21);
        let (rotations, root) = decompose(&motion, &layout);
        assert_eq!(root.up, Vec3::Y);
        let norm = Normalization::fit(&[&rotations], layout.slots()).unwrap();
        let features = norm.features(&rotations);
        // Relative to the mean rotation, no angle is near the wrap-around.
        let max = features
            .chunks(3)
            .zip((0..).map(|k| k % layout.slots()))
            .map(|(v, _)| v.iter().map(|x| x.abs()).fold(0.0, f32::max))
            .fold(0.0, f32::max);
        assert!(max < 20.0, "standardised feature up to {max}");
        let back = norm.rotations(&features);
        let rebuilt = compose(
            Motion::rest(
                motion.skeleton().clone(),
                motion.frame_time(),
                motion.frame_count(),
            )
            .unwrap(),
            &layout,
            &back,
            &root.position,
            &root.heading,
        )
        .unwrap();
        let a = forward_kinematics(&motion);
        let b = forward_kinematics(&rebuilt);
        let worst = a
            .positions
            .iter()
            .zip(&b.positions)
            .map(|(p, q)| (*p - *q).length())
            .fold(0.0, f32::max);
        assert!(worst < 0.05, "joint moved by {worst} cm");
    }

    #[test]
    fn sampling_on_frames_copies_them() {
        let Some(motion) = bandai_walk("dataset-1_walk_proud_001.bvh") else {
            return;
        };
        let times: Vec<f32> = (0..10).map(|k| (2 * k) as f32).collect();
        let s = sample_frames(&motion, &times).unwrap();
        assert_eq!(s.frame(3), motion.frame(6));
        let half = sample_frames(&motion, &[10.5]).unwrap();
        let q = half.local_rotation(0, 3);
        let expected = slerp(
            motion.local_rotation(10, 3),
            motion.local_rotation(11, 3),
            0.5,
        );
        assert!(mocap_core::rotation::angle_between(q, expected) < 1e-3);
    }

    #[test]
    fn another_rig_is_refused_with_its_differences() {
        let Some(motion) = bandai_walk("dataset-1_walk_proud_001.bvh") else {
            return;
        };
        let layout = RigLayout::from_skeleton(motion.skeleton()).unwrap();
        let mut joints = motion.skeleton().clone().into_joints();
        joints[3].name = "Spine2".into();
        let other = Skeleton::new(joints).unwrap();
        let err = layout
            .check_skeleton(&other, "style.bvh")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("style.bvh") && err.contains("lacks Chest") && err.contains("Spine2"),
            "{err}"
        );
    }
}
