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
