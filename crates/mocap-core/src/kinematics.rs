//! Forward kinematics: global joint positions and rotations for every frame.
//!
//! For joint `j` with parent `p`, local rotation `q_j` and local translation
//! `t_j` (offset or position channels):
//!
//! ```text
//! R_j = R_p * q_j
//! x_j = x_p + R_p * t_j
//! ```
//!
//! and a root has `R_j = q_j`, `x_j = t_j`.

use std::ops::Range;

use crate::motion::{local_rotation_of, local_translation_of, Motion};
use crate::rotation::{Quat, Vec3};

/// Global joint positions and rotations, frame after frame
/// (`frame * joint_count + joint`).
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalPoses {
    pub joint_count: usize,
    pub frame_count: usize,
    pub positions: Vec<Vec3>,
    pub rotations: Vec<Quat>,
}

impl GlobalPoses {
    pub fn position(&self, frame: usize, joint: usize) -> Vec3 {
        self.positions[frame * self.joint_count + joint]
    }

    pub fn rotation(&self, frame: usize, joint: usize) -> Quat {
        self.rotations[frame * self.joint_count + joint]
    }

    /// The positions of all joints in one frame.
    pub fn frame_positions(&self, frame: usize) -> &[Vec3] {
        &self.positions[frame * self.joint_count..(frame + 1) * self.joint_count]
    }

    /// Smallest and largest coordinates over all joints and frames, or `None`
    /// for a motion without frames.
    pub fn bounding_box(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
        )
    }

    /// The rotations of all joints in one frame.
    pub fn frame_rotations(&self, frame: usize) -> &[Quat] {
        &self.rotations[frame * self.joint_count..(frame + 1) * self.joint_count]
    }
}

/// Global poses of every frame of `motion`.
pub fn forward_kinematics(motion: &Motion) -> GlobalPoses {
    forward_kinematics_range(motion, 0..motion.frame_count())
}

/// Global poses of the frames `frames` of `motion`, the first of them at
/// index 0 of the result: the same numbers as [`forward_kinematics`] gives
/// those frames, for going through a long take a piece at a time
/// ([`FRAMES_AT_A_TIME`]).
pub fn forward_kinematics_range(motion: &Motion, frames: Range<usize>) -> GlobalPoses {
    let skeleton = motion.skeleton();
    let n = skeleton.joint_count();
    let count = frames.len();
    let mut positions = Vec::with_capacity(n * count);
    let mut rotations = Vec::with_capacity(n * count);
    let joints = skeleton.joints();
    let spans: Vec<(usize, usize)> = (0..n)
        .map(|j| {
            let start = skeleton.channel_start(j);
            (start, start + joints[j].channels.len())
        })
        .collect();
    for f in frames {
        let frame = motion.frame(f);
        let base = positions.len();
        for (joint, &(start, end)) in joints.iter().zip(&spans) {
            let values = &frame[start..end];
            let local = local_rotation_of(&joint.channels, values);
            let translation = local_translation_of(joint, values);
            let (rotation, position) = match joint.parent {
                Some(p) => {
                    let (rp, xp) = (rotations[base + p], positions[base + p]);
                    (rp * local, xp + rp * translation)
                }
                None => (local, translation),
            };
            rotations.push(rotation);
            positions.push(position);
        }
    }
    GlobalPoses {
        joint_count: n,
        frame_count: count,
        positions,
        rotations,
    }
}

/// Frames whose poses are computed at a time by what goes through a whole
/// take ([`bounding_box`], the positions writers): their memory does not
/// grow with the take.
pub const FRAMES_AT_A_TIME: usize = 1024;

/// The pieces of `FRAMES_AT_A_TIME` frames of a take of `frames` frames.
pub fn frame_pieces(frames: usize) -> impl Iterator<Item = Range<usize>> {
    (0..frames)
        .step_by(FRAMES_AT_A_TIME)
        .map(move |start| start..(start + FRAMES_AT_A_TIME).min(frames))
}

/// Smallest and largest global joint coordinates over all joints and
/// frames of `motion` ([`GlobalPoses::bounding_box`] of its
/// [`forward_kinematics`]), `None` for a motion without frames; the poses
/// are computed a piece at a time.
pub fn bounding_box(motion: &Motion) -> Option<(Vec3, Vec3)> {
    let mut bounds: Option<(Vec3, Vec3)> = None;
    for piece in frame_pieces(motion.frame_count()) {
        let poses = forward_kinematics_range(motion, piece);
        let Some(&first) = poses.positions.first() else {
            continue;
        };
        let start = bounds.unwrap_or((first, first));
        bounds = Some(
            poses
                .positions
                .iter()
                .fold(start, |(lo, hi), &p| (lo.min(p), hi.max(p))),
        );
    }
    bounds
}

/// Global positions of the end sites of every joint in one frame, as
/// `(joint, position)` pairs in skeleton order.
pub fn end_site_positions(
    motion: &Motion,
    poses: &GlobalPoses,
    frame: usize,
) -> Vec<(usize, Vec3)> {
    let mut out = Vec::new();
    for (j, joint) in motion.skeleton().joints().iter().enumerate() {
        for &offset in &joint.end_sites {
            out.push((
                j,
                poses.position(frame, j) + poses.rotation(frame, j) * offset,
            ));
        }
    }
    out
}

/// Two-bone inverse kinematics: the world-space turns of the hip (about
/// the hip) and of the knee (about the knee, applied before the hip's) that
/// bring the ankle `a` of the chain hip `h` - knee `k` - ankle `a` as close
/// to `target` as the bone lengths allow. The knee bends in the plane it
/// already bends in. `None` for a straight or degenerate leg.
///
/// Applied to a leg: the hip's new global rotation is `turn_hip * R_hip`,
/// the knee's `turn_hip * turn_knee * R_knee`; the bones keep their lengths.
pub fn two_bone_ik(h: Vec3, k: Vec3, a: Vec3, target: Vec3) -> Option<(Quat, Quat)> {
    let thigh = (k - h).length();
    let shin = (a - k).length();
    if thigh < 1e-6 || shin < 1e-6 {
        return None;
    }
    let reach = (target - h)
        .length()
        .clamp((thigh - shin).abs() + 1e-4, thigh + shin - 1e-4);
    let axis = (k - h).cross(a - k);
    if axis.length() < 1e-6 * thigh * shin {
        return None;
    }
    let axis = axis.normalize();
    // Interior knee angle now and the one that gives the wanted reach.
    let interior = (h - k)
        .normalize()
        .dot((a - k).normalize())
        .clamp(-1.0, 1.0)
        .acos();
    let wanted = ((thigh * thigh + shin * shin - reach * reach) / (2.0 * thigh * shin))
        .clamp(-1.0, 1.0)
        .acos();
    // Turning the shin about `axis` changes the interior angle by the turn
    // in one direction: take the sign that reaches `reach`.
    let delta = wanted - interior;
    let candidates = [
        Quat::from_axis_angle(axis, delta),
        Quat::from_axis_angle(axis, -delta),
    ];
    let turn_knee = candidates
        .into_iter()
        .min_by(|p, q| {
            let dp = ((k + *p * (a - k)) - h).length() - reach;
            let dq = ((k + *q * (a - k)) - h).length() - reach;
            dp.abs().total_cmp(&dq.abs())
        })
        .expect("two candidates");
    let moved = k + turn_knee * (a - k);
    let from = (moved - h).normalize();
    let to = (target - h).normalize();
    let turn_hip = Quat::from_rotation_arc(from, to);
    Some((turn_hip, turn_knee))
}

/// The largest `s` in [0, 1] with `|ankle + s shift| <= reach`, for an
/// ankle (relative to the hip) within `reach` (a leg reaches at most its
/// length): the root of the quadratic `|ankle + s shift|^2 = reach^2` on
/// the far side. How much of a wanted `shift` of the ankle a leg can follow.
pub fn within_reach(ankle: Vec3, shift: Vec3, reach: f32) -> f32 {
    let a = shift.dot(shift);
    if a <= 0.0 {
        return 0.0;
    }
    let b = 2.0 * ankle.dot(shift);
    let c = ankle.dot(ankle) - reach * reach;
    ((-b + (b * b - 4.0 * a * c).max(0.0).sqrt()) / (2.0 * a)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shift_is_shortened_to_the_reach_along_its_direction() {
        let ankle = Vec3::new(10.0, -80.0, 0.0);
        let shift = Vec3::new(60.0, 0.0, 5.0);
        let s = within_reach(ankle, shift, 85.0);
        assert!(s > 0.0 && s < 1.0, "{s}");
        assert!(((ankle + shift * s).length() - 85.0).abs() < 1e-3);
        // Already within reach: the whole shift.
        assert_eq!(within_reach(ankle, shift * 0.01, 85.0), 1.0);
        assert_eq!(within_reach(ankle, Vec3::ZERO, 85.0), 0.0);
    }

    #[test]
    fn two_bone_reaches_a_reachable_target() {
        let h = Vec3::new(0.0, 90.0, 0.0);
        let k = Vec3::new(0.0, 48.0, 8.0);
        let a = Vec3::new(0.0, 8.0, 0.0);
        for target in [
            Vec3::new(5.0, 8.0, 10.0),
            Vec3::new(-6.0, 10.0, -12.0),
            Vec3::new(0.0, 20.0, 3.0),
        ] {
            let (turn_hip, turn_knee) = two_bone_ik(h, k, a, target).expect("bent leg");
            let new_knee = h + turn_hip * (k - h);
            let new_ankle = new_knee + turn_hip * turn_knee * (a - k);
            assert!(
                (new_ankle - target).length() < 1e-2,
                "{new_ankle:?} vs {target:?}"
            );
            // Bone lengths are kept.
            assert!(((new_knee - h).length() - (k - h).length()).abs() < 1e-3);
            assert!(((new_ankle - new_knee).length() - (a - k).length()).abs() < 1e-3);
        }
        // Out of reach: the leg stretches towards it.
        let (turn_hip, turn_knee) = two_bone_ik(h, k, a, Vec3::new(0.0, -200.0, 0.0)).unwrap();
        let new_ankle = h + turn_hip * (k - h) + turn_hip * turn_knee * (a - k);
        assert!(new_ankle.y < a.y);
    }
}
