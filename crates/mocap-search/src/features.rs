//! Relative pose features: 76 numbers per frame that describe the pose in a
//! body-centred frame, independent of where the performer stands, which way
//! they face and how tall they are.
//!
//! **Body-centred frame.** Origin at the pelvis; up is the world up axis
//! (+Y, the BVH and ASF/AMC convention); the lateral axis `x` points to the
//! performer's left: the sum of the left-minus-right hip and
//! left-minus-right shoulder vectors, projected on the floor; forward is
//! `z = x × up`. A position `p` becomes `(x·(p - pelvis), up·(p - pelvis),
//! z·(p - pelvis)) / h`.
//!
//! **Body height `h`.** The report takes `max(J_y) - min(J_y)` of the upright
//! rest pose. Rest poses are not upright in every rig (Bandai's joints have
//! rotated local frames, so its zero pose lies on its side), so `h` is the
//! height the same joints span when standing straight: the length of the
//! bone chain from the head down to the pelvis plus the mean length of the
//! chains from the pelvis down to each ankle, measured on the first frame.
//!
//! **The 76 values** (positions and distances divided by `h`, velocities per
//! second, angles in radians), numbered as in [`VALUE_NAMES`]:
//!
//! | values | what |
//! | --- | --- |
//! | 0-26 | head, left/right wrist, elbow, knee and ankle in the body frame (x, y, z each) |
//! | 27 | pelvis height above the floor (the lowest ankle of the clip) |
//! | 28-37 | distances: wrist-wrist, ankle-ankle, knee-knee, elbow-elbow, each wrist to the head, each wrist to the other shoulder, each wrist to its own hip |
//! | 38-41 | flexion of the left/right elbow and knee (angle between the two bones) |
//! | 42-44 | body tilt: angle between the body axis (pelvis to neck) and the body frame's up, forward and lateral axes |
//! | 45-48 | pelvis velocity in the body frame (x, y, z) and turning speed about up (left turns positive) |
//! | 49-52 | speed of each wrist and ankle relative to the body frame |
//! | 53-55 | height of each wrist above the head, height of the left ankle above the right one |
//! | 56-61 | velocity of each wrist relative to the body frame (x, y, z each) |
//! | 62-67 | direction of each forearm (unit vector from elbow to wrist) in the body frame |
//! | 68-73 | each wrist relative to its own shoulder in the body frame |
//! | 74-75 | acceleration magnitude of each wrist relative to the body frame |
//!
//! The velocities (45-52) carry what a single pose cannot: walking forward,
//! backward, sideways or in a turn differ mostly in how the pelvis moves.
//!
//! Values 56-75 (feature version 2) serve the arm gestures of Bandai
//! dataset-1 (bye, byebye, guide, bow), which the first 56 values confuse
//! most: the direction a wrist moves (a wave goes side to side, a guiding
//! gesture out and back), where the forearm points, the hand's position
//! measured from its own shoulder rather than the pelvis (so a bent or
//! leaning trunk moves it less) and how jerky the hand moves (a wave
//! reverses direction several times a second). On dataset-1 content,
//! 5-fold by take, mean over fold seeds 1-20 (`bench/search/seeds.sh`), the
//! macro F over the 10 classes with 15 or more clips is 0.851 with them and
//! 0.840 without, over all 13 classes 0.714 and 0.700 (dataset-1 styles
//! 0.544 and 0.525; dataset-2 0.99+ either way; see
//! `bench/results/search.md`). Signed ankle velocities, the horizontal
//! pelvis speed and the ankles' heights above the floor give nothing beyond
//! the spread between seeds, so they are not included.

use mocap_core::bodymap::{BodyMap, BodyPart};
use mocap_core::kinematics::{forward_kinematics_range, frame_pieces};
use mocap_core::rotation::Vec3;
use mocap_core::Motion;

use crate::error::{Result, SearchError};
use crate::intervals::FeatureSequence;

/// Number of values per frame.
pub const VALUE_COUNT: usize = 76;

/// Version of the feature definition, stored in every index: change it when
/// the values above change, so that old index files are reported stale.
pub(crate) const FEATURE_VERSION: u32 = 2;

/// Names of the 76 values, in order.
pub const VALUE_NAMES: [&str; VALUE_COUNT] = [
    "head.x",
    "head.y",
    "head.z",
    "left_wrist.x",
    "left_wrist.y",
    "left_wrist.z",
    "right_wrist.x",
    "right_wrist.y",
    "right_wrist.z",
    "left_elbow.x",
    "left_elbow.y",
    "left_elbow.z",
    "right_elbow.x",
    "right_elbow.y",
    "right_elbow.z",
    "left_knee.x",
    "left_knee.y",
    "left_knee.z",
    "right_knee.x",
    "right_knee.y",
    "right_knee.z",
    "left_ankle.x",
    "left_ankle.y",
    "left_ankle.z",
    "right_ankle.x",
    "right_ankle.y",
    "right_ankle.z",
    "pelvis_height",
    "wrist_wrist",
    "ankle_ankle",
    "knee_knee",
    "elbow_elbow",
    "left_wrist_head",
    "right_wrist_head",
    "left_wrist_right_shoulder",
    "right_wrist_left_shoulder",
    "left_wrist_left_hip",
    "right_wrist_right_hip",
    "left_elbow_flexion",
    "right_elbow_flexion",
    "left_knee_flexion",
    "right_knee_flexion",
    "tilt_up",
    "tilt_forward",
    "tilt_lateral",
    "pelvis_velocity.x",
    "pelvis_velocity.y",
    "pelvis_velocity.z",
    "turn_speed",
    "left_wrist_speed",
    "right_wrist_speed",
    "left_ankle_speed",
    "right_ankle_speed",
    "left_wrist_above_head",
    "right_wrist_above_head",
    "left_ankle_above_right",
    "left_wrist_velocity.x",
    "left_wrist_velocity.y",
    "left_wrist_velocity.z",
    "right_wrist_velocity.x",
    "right_wrist_velocity.y",
    "right_wrist_velocity.z",
    "left_forearm.x",
    "left_forearm.y",
    "left_forearm.z",
    "right_forearm.x",
    "right_forearm.y",
    "right_forearm.z",
    "left_wrist_from_shoulder.x",
    "left_wrist_from_shoulder.y",
    "left_wrist_from_shoulder.z",
    "right_wrist_from_shoulder.x",
    "right_wrist_from_shoulder.y",
    "right_wrist_from_shoulder.z",
    "left_wrist_acceleration",
    "right_wrist_acceleration",
];

/// World up axis (BVH and ASF/AMC are Y-up).
const UP: Vec3 = Vec3::Y;

/// The joints the features are made of, as joint indices of one skeleton.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct KeyJoints {
    pub pelvis: usize,
    pub neck: usize,
    pub head: usize,
    /// Left then right for each of the following.
    pub shoulder: [usize; 2],
    pub elbow: [usize; 2],
    pub wrist: [usize; 2],
    pub hip: [usize; 2],
    pub knee: [usize; 2],
    pub ankle: [usize; 2],
}

impl KeyJoints {
    /// Finds the key joints of a skeleton with the core body map; the error
    /// names the body parts the rig lacks.
    pub fn detect(skeleton: &mocap_core::Skeleton) -> Result<KeyJoints> {
        let map = BodyMap::detect(skeleton)?;
        let part = |p: BodyPart| -> Result<usize> { Ok(map.require(p)?) };
        let pair = |l: BodyPart, r: BodyPart| -> Result<[usize; 2]> { Ok([part(l)?, part(r)?]) };
        let head = part(BodyPart::Head)?;
        // Not every rig has a neck joint (the body map does not require
        // one): the chest or the head's parent stands in for the top of the
        // body axis.
        let neck = map
            .joint(BodyPart::Neck)
            .or(map.joint(BodyPart::Chest))
            .or(skeleton.joint(head).parent)
            .unwrap_or(head);
        Ok(KeyJoints {
            pelvis: part(BodyPart::Pelvis)?,
            neck,
            head,
            shoulder: pair(BodyPart::LeftShoulder, BodyPart::RightShoulder)?,
            elbow: pair(BodyPart::LeftElbow, BodyPart::RightElbow)?,
            wrist: pair(BodyPart::LeftWrist, BodyPart::RightWrist)?,
            hip: pair(BodyPart::LeftHip, BodyPart::RightHip)?,
            knee: pair(BodyPart::LeftKnee, BodyPart::RightKnee)?,
            ankle: pair(BodyPart::LeftAnkle, BodyPart::RightAnkle)?,
        })
    }
}

/// The per-frame features of a motion, at its own frame rate.
pub fn motion_features(motion: &Motion) -> Result<FeatureSequence> {
    let joints = KeyJoints::detect(motion.skeleton())?;
    // Positions only, a piece of the take at a time: the full global poses
    // (rotations too) of a long take would take twice the memory.
    let joint_count = motion.skeleton().joint_count();
    let mut positions = Vec::with_capacity(joint_count * motion.frame_count());
    for piece in frame_pieces(motion.frame_count()) {
        positions.extend(forward_kinematics_range(motion, piece).positions);
    }
    let poses = Positions::new(&positions, joint_count);
    pose_features(&poses, &joints, &motion.skeleton().parents(), motion.fps())
}

/// The global joint positions of every frame of a take (what the features
/// are made of), `joint_count` to a frame.
pub(crate) struct Positions<'a> {
    joint_count: usize,
    frame_count: usize,
    positions: &'a [Vec3],
}

impl<'a> Positions<'a> {
    pub(crate) fn new(positions: &'a [Vec3], joint_count: usize) -> Positions<'a> {
        Positions {
            joint_count,
            frame_count: positions.len() / joint_count.max(1),
            positions,
        }
    }

    fn position(&self, frame: usize, joint: usize) -> Vec3 {
        self.positions[frame * self.joint_count + joint]
    }
}

/// Body height `h` (see the module docs) from the first frame.
pub(crate) fn body_height(poses: &Positions, joints: &KeyJoints, parents: &[Option<usize>]) -> f32 {
    // Length of the bone chain from `from` up to its ancestor `to`.
    let chain = |from: usize, to: usize| -> f32 {
        let mut length = 0.0;
        let mut at = from;
        while at != to {
            let Some(parent) = parents[at] else { break };
            length += poses.position(0, at).distance(poses.position(0, parent));
            at = parent;
        }
        length
    };
    let legs =
        (chain(joints.ankle[0], joints.pelvis) + chain(joints.ankle[1], joints.pelvis)) / 2.0;
    chain(joints.head, joints.pelvis) + legs
}

/// Angle in radians between two vectors (0 when either is zero).
fn angle(a: Vec3, b: Vec3) -> f32 {
    let n = a.length() * b.length();
    if n < 1e-12 {
        return 0.0;
    }
    (a.dot(b) / n).clamp(-1.0, 1.0).acos()
}

/// The unit lateral (left) axis of every frame's body-centred frame. Where
/// hips and shoulders give no horizontal direction (lying down), the
/// previous frame's axis is kept.
fn lateral_axes(poses: &Positions, j: &KeyJoints) -> Vec<Vec3> {
    let mut axes = Vec::with_capacity(poses.frame_count);
    let mut last = Vec3::X;
    for f in 0..poses.frame_count {
        let p = |joint: usize| poses.position(f, joint);
        let across = (p(j.hip[0]) - p(j.hip[1])) + (p(j.shoulder[0]) - p(j.shoulder[1]));
        let flat = across - UP * across.dot(UP);
        if flat.length() > 1e-6 {
            last = flat.normalize();
        }
        axes.push(last);
    }
    axes
}

/// Signed angle in radians turning `a` into `b` about the up axis
/// (counter-clockwise seen from above, i.e. a left turn, is positive).
fn turn_angle(a: Vec3, b: Vec3) -> f32 {
    a.cross(b).dot(UP).atan2(a.dot(b))
}

/// The frames before and after `f` for a central difference, and the time
/// between them in frames (one-sided at the ends of the clip).
fn neighbours(f: usize, frames: usize) -> (usize, usize, f32) {
    let before = f.saturating_sub(1);
    let after = (f + 1).min(frames - 1);
    (before, after, (after - before).max(1) as f32)
}

/// Three frames centred as near `f` as the clip allows, for a second
/// difference `x[a] - 2 x[b] + x[c]` over one frame; `None` for clips of
/// fewer than 3 frames.
fn second_difference_frames(f: usize, frames: usize) -> Option<(usize, usize, usize)> {
    if frames < 3 {
        return None;
    }
    let b = f.clamp(1, frames - 2);
    Some((b - 1, b, b + 1))
}

/// The 76 values of every frame of `poses` (see the module docs).
/// `parents` gives each joint's parent (for the body height) and `fps`
/// turns frame differences into velocities per second.
pub(crate) fn pose_features(
    poses: &Positions,
    j: &KeyJoints,
    parents: &[Option<usize>],
    fps: f64,
) -> Result<FeatureSequence> {
    let frames = poses.frame_count;
    if frames == 0 {
        return Err(SearchError::Invalid("the motion has no frames".into()));
    }
    let h = body_height(poses, j, parents);
    if !(h.is_finite() && h > 1e-6) {
        return Err(SearchError::Invalid(format!(
            "the body height from head to ankles is {h}; the skeleton's key joints coincide"
        )));
    }
    let fps = fps as f32;
    let lateral = lateral_axes(poses, j);
    let floor = (0..frames)
        .flat_map(|f| j.ankle.map(|a| poses.position(f, a).dot(UP)))
        .fold(f32::INFINITY, f32::min);
    // Body-frame coordinates of joint `joint` in frame `f`, over h.
    let body = |f: usize, joint: usize| -> Vec3 {
        let x = lateral[f];
        let z = x.cross(UP);
        let d = (poses.position(f, joint) - poses.position(f, j.pelvis)) / h;
        Vec3::new(d.dot(x), d.dot(UP), d.dot(z))
    };
    let mut values = Vec::with_capacity(frames * VALUE_COUNT);
    for f in 0..frames {
        let start = values.len();
        let p = |joint: usize| poses.position(f, joint);
        let dist = |a: usize, b: usize| p(a).distance(p(b)) / h;
        // 0-26: key joints in the body frame.
        for joint in [
            j.head, j.wrist[0], j.wrist[1], j.elbow[0], j.elbow[1], j.knee[0], j.knee[1],
            j.ankle[0], j.ankle[1],
        ] {
            values.extend_from_slice(&body(f, joint).to_array());
        }
        // 27: pelvis above the floor.
        values.push((p(j.pelvis).dot(UP) - floor) / h);
        // 28-37: distances between joints.
        values.extend_from_slice(&[
            dist(j.wrist[0], j.wrist[1]),
            dist(j.ankle[0], j.ankle[1]),
            dist(j.knee[0], j.knee[1]),
            dist(j.elbow[0], j.elbow[1]),
            dist(j.wrist[0], j.head),
            dist(j.wrist[1], j.head),
            dist(j.wrist[0], j.shoulder[1]),
            dist(j.wrist[1], j.shoulder[0]),
            dist(j.wrist[0], j.hip[0]),
            dist(j.wrist[1], j.hip[1]),
        ]);
        // 38-41: flexion of elbows and knees (0 = straight).
        let flexion = |a: usize, b: usize, c: usize| angle(p(b) - p(a), p(c) - p(b));
        values.extend_from_slice(&[
            flexion(j.shoulder[0], j.elbow[0], j.wrist[0]),
            flexion(j.shoulder[1], j.elbow[1], j.wrist[1]),
            flexion(j.hip[0], j.knee[0], j.ankle[0]),
            flexion(j.hip[1], j.knee[1], j.ankle[1]),
        ]);
        // 42-44: body tilt against the body frame's axes.
        let (x, z) = (lateral[f], lateral[f].cross(UP));
        let axis = p(j.neck) - p(j.pelvis);
        values.extend_from_slice(&[angle(axis, UP), angle(axis, z), angle(axis, x)]);
        // 45-48: pelvis velocity in this frame's body frame, turning speed.
        let (before, after, span) = neighbours(f, frames);
        let rate = fps / span;
        let v = (poses.position(after, j.pelvis) - poses.position(before, j.pelvis)) * rate / h;
        values.extend_from_slice(&[v.dot(x), v.dot(UP), v.dot(z)]);
        values.push(turn_angle(lateral[before], lateral[after]) * rate);
        // 49-52: limb speeds relative to the body.
        for joint in [j.wrist[0], j.wrist[1], j.ankle[0], j.ankle[1]] {
            values.push((body(after, joint) - body(before, joint)).length() * rate);
        }
        // 53-55: heights.
        let height = |joint: usize| p(joint).dot(UP) / h;
        values.extend_from_slice(&[
            height(j.wrist[0]) - height(j.head),
            height(j.wrist[1]) - height(j.head),
            height(j.ankle[0]) - height(j.ankle[1]),
        ]);
        // 56-61: wrist velocities relative to the body frame.
        for w in j.wrist {
            let d = (body(after, w) - body(before, w)) * rate;
            values.extend_from_slice(&d.to_array());
        }
        // 62-67: forearm directions.
        for k in 0..2 {
            let d = (body(f, j.wrist[k]) - body(f, j.elbow[k])).normalize_or_zero();
            values.extend_from_slice(&d.to_array());
        }
        // 68-73: wrists from their own shoulders.
        for k in 0..2 {
            values.extend_from_slice(&(body(f, j.wrist[k]) - body(f, j.shoulder[k])).to_array());
        }
        // 74-75: wrist acceleration, a second difference over one frame
        // (frame time 1/fps, so times fps²).
        for w in j.wrist {
            let a = match second_difference_frames(f, frames) {
                Some((a, b, c)) => {
                    (body(a, w) - body(b, w) * 2.0 + body(c, w)).length() * fps * fps
                }
                None => 0.0,
            };
            values.push(a);
        }
        debug_assert_eq!(values.len() - start, VALUE_COUNT);
        if let Some(k) = values[start..].iter().position(|v| !v.is_finite()) {
            return Err(SearchError::Invalid(format!(
                "frame {f}: feature `{}` is not a finite number (joint positions are NaN or infinite)",
                VALUE_NAMES[k]
            )));
        }
    }
    Ok(FeatureSequence {
        dim: VALUE_COUNT,
        values,
    })
}

#[cfg(test)]
mod tests {
    use mocap_core::rotation::{Quat, Vec3};
    use mocap_core::{forward_kinematics, GlobalPoses};
    use mocap_testdata::shared_data;

    use super::*;
    use crate::clips::{load_features, load_motion};

    /// Moves, turns and scales the global poses of a whole take.
    fn transform(poses: &GlobalPoses, turn: Quat, shift: Vec3, scale: f32) -> GlobalPoses {
        let mut out = poses.clone();
        for p in &mut out.positions {
            *p = turn * (*p * scale) + shift;
        }
        out
    }

    #[test]
    fn features_do_not_depend_on_place_heading_or_body_size() {
        let Some(data) = shared_data() else { return };
        let path = data.join("bandai/dataset-1/dataset-1_walk-left_normal_001.bvh");
        let motion = load_motion(&path).unwrap();
        let joints = KeyJoints::detect(motion.skeleton()).unwrap();
        let parents = motion.skeleton().parents();
        let poses = forward_kinematics(&motion);
        let features = |poses: &GlobalPoses| {
            let positions = Positions::new(&poses.positions, poses.joint_count);
            pose_features(&positions, &joints, &parents, motion.fps()).unwrap()
        };
        let base = features(&poses);
        assert_eq!(base.dim, VALUE_COUNT);
        assert_eq!(base.frame_count(), motion.frame_count());
        let moved = transform(
            &poses,
            Quat::from_rotation_y(2.1),
            Vec3::new(300.0, 0.0, -120.0),
            0.62,
        );
        let other = features(&moved);
        // Relative to the value's size where it exceeds 1: the wrist
        // accelerations (values 74-75) are second differences of positions
        // times fps², so they carry the positions' f32 rounding times 900.
        let worst = base
            .values
            .iter()
            .zip(&other.values)
            .map(|(a, b)| (a - b).abs() / a.abs().max(1.0))
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-3, "largest change {worst}");
        // Bandai's walk-left travels diagonally forward and to the left with
        // the body facing forward: the pelvis moves along +x (the body's left)
        // and +z (forward). Walking right mirrors that; a turn to the left
        // turns the facing direction counter-clockwise seen from above
        // (positive turning speed).
        let mean_of = |features: &FeatureSequence, i: usize| {
            let n = features.frame_count();
            (0..n).map(|f| features.frame(f)[i]).sum::<f32>() / n as f32
        };
        let mean = |i: usize| mean_of(&base, i);
        let (vx, vz) = (mean(45), mean(47));
        assert!(
            vx > 0.15 && vz > 0.5,
            "walk-left: pelvis velocity x {vx}, z {vz}"
        );
        let features = |file: &str| load_features(&data.join("bandai").join(file)).unwrap().0;
        // (take, value, bound): walking right and back, turning left and
        // right; a positive bound is a floor, a negative one a ceiling.
        for (file, value, bound) in [
            ("dataset-1/dataset-1_walk-right_normal_001.bvh", 45, -0.15),
            ("dataset-1/dataset-1_walk-back_normal_001.bvh", 47, -0.5),
            ("dataset-2/dataset-2_walk-turn-left_normal_001.bvh", 48, 0.3),
            (
                "dataset-2/dataset-2_walk-turn-right_normal_001.bvh",
                48,
                -0.3,
            ),
        ] {
            let mean = mean_of(&features(file), value);
            let beyond = if bound > 0.0 {
                mean > bound
            } else {
                mean < bound
            };
            assert!(beyond, "{file}: value {value} has mean {mean}");
        }
        // Standing height: the pelvis is about half a body height above the
        // floor.
        let pelvis = mean(27);
        assert!(pelvis > 0.35 && pelvis < 0.65, "pelvis height {pelvis}");
    }
}
