//! The Kinect v2 body layout: 25 joints, their kinematic tree, left/right
//! mirror pairs and the per-joint tracking state; and the Kinect joints of a
//! motion ([`truth_from_motion`]), the ground truth of the simulator.
//!
//! Joint indices are those of the Kinect for Windows SDK 2.0 `JointType`
//! enumeration, which is also the joint order of NTU RGB+D `.skeleton` files.
//!
//! Joint names and parents come from `mocap_core::bodymap::KINECT_V2_JOINTS`;
//! this module adds what fusion needs on top (indices by name, a
//! parent-before-child order, mirror pairs, tracking states).

use mocap_core::bodymap::{kinect_v2_joint, BodyMap, BodyPart, KINECT_V2_JOINTS};
use mocap_core::rotation::Vec3;
use mocap_core::{forward_kinematics, Error, Motion, Result};
use serde::{Deserialize, Serialize};

/// Number of joints in a Kinect v2 body.
pub const JOINT_COUNT: usize = 25;

/// Joint names in SDK order (from [`KINECT_V2_JOINTS`], the one copy of
/// the layout).
pub const JOINT_NAMES: [&str; JOINT_COUNT] = {
    let mut names = [""; JOINT_COUNT];
    let mut n = 0;
    while n < JOINT_COUNT {
        names[n] = KINECT_V2_JOINTS[n].0;
        n += 1;
    }
    names
};

/// Indices of the joints, for readable code.
pub mod joint {
    pub const SPINE_BASE: usize = 0;
    pub const SPINE_MID: usize = 1;
    pub const NECK: usize = 2;
    pub const HEAD: usize = 3;
    pub const SHOULDER_LEFT: usize = 4;
    pub const ELBOW_LEFT: usize = 5;
    pub const WRIST_LEFT: usize = 6;
    pub const HAND_LEFT: usize = 7;
    pub const SHOULDER_RIGHT: usize = 8;
    pub const ELBOW_RIGHT: usize = 9;
    pub const WRIST_RIGHT: usize = 10;
    pub const HAND_RIGHT: usize = 11;
    pub const HIP_LEFT: usize = 12;
    pub const KNEE_LEFT: usize = 13;
    pub const ANKLE_LEFT: usize = 14;
    pub const FOOT_LEFT: usize = 15;
    pub const HIP_RIGHT: usize = 16;
    pub const KNEE_RIGHT: usize = 17;
    pub const ANKLE_RIGHT: usize = 18;
    pub const FOOT_RIGHT: usize = 19;
    pub const SPINE_SHOULDER: usize = 20;
    pub const HAND_TIP_LEFT: usize = 21;
    pub const THUMB_LEFT: usize = 22;
    pub const HAND_TIP_RIGHT: usize = 23;
    pub const THUMB_RIGHT: usize = 24;
}

use joint::*;

/// Parent of each joint in the Kinect v2 bone list (SDK sample
/// `BodyBasics`, as [`KINECT_V2_JOINTS`]); `None` for the root, `SpineBase`.
pub const PARENTS: [Option<usize>; JOINT_COUNT] = {
    let mut parents = [None; JOINT_COUNT];
    let mut n = 0;
    while n < JOINT_COUNT {
        parents[n] = KINECT_V2_JOINTS[n].1;
        n += 1;
    }
    parents
};

/// The joints in an order where every parent comes before its children (the
/// SDK order does not: `SpineShoulder`, index 20, is the parent of `Neck`).
pub const TOPOLOGICAL_ORDER: [usize; JOINT_COUNT] = [
    SPINE_BASE,
    SPINE_MID,
    SPINE_SHOULDER,
    NECK,
    HEAD,
    SHOULDER_LEFT,
    ELBOW_LEFT,
    WRIST_LEFT,
    HAND_LEFT,
    HAND_TIP_LEFT,
    THUMB_LEFT,
    SHOULDER_RIGHT,
    ELBOW_RIGHT,
    WRIST_RIGHT,
    HAND_RIGHT,
    HAND_TIP_RIGHT,
    THUMB_RIGHT,
    HIP_LEFT,
    KNEE_LEFT,
    ANKLE_LEFT,
    FOOT_LEFT,
    HIP_RIGHT,
    KNEE_RIGHT,
    ANKLE_RIGHT,
    FOOT_RIGHT,
];

/// The mirror joint of each joint (left <-> right; the spine maps to itself).
pub const MIRROR: [usize; JOINT_COUNT] = [
    SPINE_BASE,
    SPINE_MID,
    NECK,
    HEAD,
    SHOULDER_RIGHT,
    ELBOW_RIGHT,
    WRIST_RIGHT,
    HAND_RIGHT,
    SHOULDER_LEFT,
    ELBOW_LEFT,
    WRIST_LEFT,
    HAND_LEFT,
    HIP_RIGHT,
    KNEE_RIGHT,
    ANKLE_RIGHT,
    FOOT_RIGHT,
    HIP_LEFT,
    KNEE_LEFT,
    ANKLE_LEFT,
    FOOT_LEFT,
    SPINE_SHOULDER,
    HAND_TIP_RIGHT,
    THUMB_RIGHT,
    HAND_TIP_LEFT,
    THUMB_LEFT,
];

/// The joint index of a Kinect v2 joint name (as in [`JOINT_NAMES`]).
pub fn joint_index(name: &str) -> Option<usize> {
    JOINT_NAMES.iter().position(|n| *n == name)
}

/// How well the sensor sees a joint (SDK `TrackingState`, NTU column 12).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum TrackingState {
    /// Not seen; the position is meaningless.
    NotTracked = 0,
    /// Not seen directly; the position is the tracker's guess (occluded).
    Inferred = 1,
    /// Seen.
    Tracked = 2,
}

impl TrackingState {
    /// The state of a numeric code 0, 1 or 2.
    pub fn from_code(code: i64) -> Option<TrackingState> {
        match code {
            0 => Some(TrackingState::NotTracked),
            1 => Some(TrackingState::Inferred),
            2 => Some(TrackingState::Tracked),
            _ => None,
        }
    }

    /// The numeric code 0, 1 or 2.
    pub fn code(self) -> u8 {
        self as u8
    }
}

/// The ground truth: Kinect joints in world space (metres, y up) per frame.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundTruth {
    pub fps: f64,
    pub frames: Vec<[Vec3; JOINT_COUNT]>,
}

impl GroundTruth {
    /// The pose at time `t` (seconds), linearly interpolated; clamped to the
    /// take.
    pub fn at(&self, t: f64) -> [Vec3; JOINT_COUNT] {
        let x = (t * self.fps).max(0.0);
        let i = (x.floor() as usize).min(self.frames.len() - 1);
        let j = (i + 1).min(self.frames.len() - 1);
        let a = (x - i as f64).clamp(0.0, 1.0) as f32;
        std::array::from_fn(|n| self.frames[i][n].lerp(self.frames[j][n], a))
    }

    pub fn duration(&self) -> f64 {
        (self.frames.len().saturating_sub(1)) as f64 / self.fps
    }
}

/// Length units per metre of a motion, from the standing height of its
/// first frame (head above the lower ankle): centimetres (Bandai), metres,
/// or inches.
pub fn guess_units_per_metre(height_in_units: f32) -> f32 {
    if height_in_units > 60.0 && height_in_units < 260.0 {
        100.0
    } else if height_in_units > 25.0 && height_in_units <= 60.0 {
        // Some exporters write inches (a 1.7 m person is 67 in), others
        // a tenth of a metre... inches is the common case.
        39.37
    } else {
        1.0
    }
}

/// The Kinect v2 joints of a motion: joints located with
/// [`BodyMap::detect`]; the hands, hand tips and thumbs (which rigs like
/// Bandai's lack) are placed along the forearm beyond the wrist (8 cm, 16 cm,
/// and 5 cm plus 3 cm sideways), the feet 12 cm ahead of the ankle when the
/// rig has no toe. Positions are converted to metres.
pub fn truth_from_motion(motion: &Motion, units_per_metre: Option<f32>) -> Result<GroundTruth> {
    let skeleton = motion.skeleton();
    let map = BodyMap::detect(skeleton)?;
    let poses = forward_kinematics(motion);
    let joint_of = |n: usize| -> Option<usize> {
        BodyPart::ALL
            .iter()
            .find(|&&p| kinect_v2_joint(p) == Some(n))
            .and_then(|&p| map.joint(p))
    };
    let mapped: Vec<Option<usize>> = (0..JOINT_COUNT).map(joint_of).collect();
    for n in [
        SPINE_BASE,
        HEAD,
        SHOULDER_LEFT,
        ELBOW_LEFT,
        WRIST_LEFT,
        SHOULDER_RIGHT,
        ELBOW_RIGHT,
        WRIST_RIGHT,
        HIP_LEFT,
        KNEE_LEFT,
        ANKLE_LEFT,
        HIP_RIGHT,
        KNEE_RIGHT,
        ANKLE_RIGHT,
    ] {
        if mapped[n].is_none() {
            return Err(Error::Invalid(format!(
                "the skeleton has no joint for Kinect's {}",
                JOINT_NAMES[n]
            )));
        }
    }
    let units = match units_per_metre {
        Some(u) => u,
        None => {
            let head = poses.position(0, mapped[HEAD].unwrap());
            let ankle = poses
                .position(0, mapped[ANKLE_LEFT].unwrap())
                .y
                .min(poses.position(0, mapped[ANKLE_RIGHT].unwrap()).y);
            guess_units_per_metre(head.y - ankle)
        }
    };
    let mut frames = Vec::with_capacity(motion.frame_count());
    for f in 0..motion.frame_count() {
        let at = |j: usize| poses.position(f, j) / units;
        let mut p = [Vec3::ZERO; JOINT_COUNT];
        for n in 0..JOINT_COUNT {
            if let Some(j) = mapped[n] {
                p[n] = at(j);
            }
        }
        // Joints some rigs lack: midpoints and points beyond the wrist.
        if mapped[SPINE_MID].is_none() {
            p[SPINE_MID] = p[SPINE_BASE].lerp(p[SPINE_SHOULDER], 0.5);
        }
        if mapped[SPINE_SHOULDER].is_none() {
            p[SPINE_SHOULDER] = p[SHOULDER_LEFT].lerp(p[SHOULDER_RIGHT], 0.5);
        }
        if mapped[NECK].is_none() {
            p[NECK] = p[SPINE_SHOULDER].lerp(p[HEAD], 0.4);
        }
        for (elbow, wrist, hand, tip, thumb) in [
            (ELBOW_LEFT, WRIST_LEFT, HAND_LEFT, HAND_TIP_LEFT, THUMB_LEFT),
            (
                ELBOW_RIGHT,
                WRIST_RIGHT,
                HAND_RIGHT,
                HAND_TIP_RIGHT,
                THUMB_RIGHT,
            ),
        ] {
            let along = (p[wrist] - p[elbow]).normalize_or(Vec3::NEG_Y);
            let side = along.cross(Vec3::Y).normalize_or(Vec3::X);
            if mapped[hand].is_none() {
                p[hand] = p[wrist] + along * 0.08;
            }
            p[tip] = p[wrist] + along * 0.16;
            p[thumb] = p[wrist] + along * 0.05 + side * 0.03;
        }
        for (knee, ankle, foot, hip_here, hip_other) in [
            (KNEE_LEFT, ANKLE_LEFT, FOOT_LEFT, HIP_LEFT, HIP_RIGHT),
            (KNEE_RIGHT, ANKLE_RIGHT, FOOT_RIGHT, HIP_RIGHT, HIP_LEFT),
        ] {
            if mapped[foot].is_none() {
                let forward = (p[hip_other] - p[hip_here])
                    .cross(Vec3::Y)
                    .normalize_or(Vec3::Z);
                let _ = knee;
                p[foot] = p[ankle] + forward * 0.12 - Vec3::Y * 0.05;
            }
        }
        frames.push(p);
    }
    Ok(GroundTruth {
        fps: motion.fps(),
        frames,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topological_order_puts_parents_first_and_covers_every_joint() {
        let mut seen = [false; JOINT_COUNT];
        for &j in &TOPOLOGICAL_ORDER {
            if let Some(p) = PARENTS[j] {
                assert!(seen[p], "{} before its parent", JOINT_NAMES[j]);
            }
            assert!(!seen[j]);
            seen[j] = true;
        }
        assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn mirror_is_an_involution_that_swaps_sides() {
        for j in 0..JOINT_COUNT {
            assert_eq!(MIRROR[MIRROR[j]], j);
            let name = JOINT_NAMES[j];
            let other = JOINT_NAMES[MIRROR[j]];
            if name.ends_with("Left") {
                assert_eq!(other, name.replace("Left", "Right"));
            } else if !name.ends_with("Right") {
                assert_eq!(other, name);
            }
        }
    }

    #[test]
    fn parents_of_mirror_joints_are_mirrors() {
        for j in 0..JOINT_COUNT {
            assert_eq!(PARENTS[MIRROR[j]], PARENTS[j].map(|p| MIRROR[p]));
        }
    }
}
