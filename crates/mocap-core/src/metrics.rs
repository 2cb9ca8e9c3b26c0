//! The numbers every capability reports, computed in one place: joint
//! position and rotation errors, acceleration error, jitter, bone-length
//! statistics, bone directions compared across rigs, and the feet: planted
//! feet sliding, foot skating, feet below the floor.
//!
//! Conventions:
//! - Positions are compared as given (no root alignment, no Procrustes):
//!   align them first if the comparison calls for it.
//! - Lengths are in the units of the data (centimetres for Bandai).
//! - Finite differences are taken per frame: an acceleration is in units per
//!   frame², a jerk in units per frame³. Multiply by `fps²` (`fps³`) for
//!   units per second² (second³).
//! - Sums are accumulated in double precision.
//! - Two inputs of different shapes (joint or frame counts) give an error,
//!   never a panic or a silently truncated comparison.

use crate::bodymap::{BodyMap, BodyPart};
use crate::error::{Error, Result};
use crate::kinematics::{forward_kinematics, GlobalPoses};
use crate::motion::Motion;
use crate::rotation::{angle_between, Vec3};
use crate::skeleton::Skeleton;

/// Mean over frames of the distance between each joint's positions in `a`
/// and `b` (one value per joint).
pub fn joint_position_errors(a: &GlobalPoses, b: &GlobalPoses) -> Result<Vec<f32>> {
    same_shape(a, b)?;
    nonempty(a.frame_count, 1, "a position error")?;
    let mut sums = vec![0.0f64; a.joint_count];
    for (k, (pa, pb)) in a.positions.iter().zip(&b.positions).enumerate() {
        sums[k % a.joint_count] += pa.distance(*pb) as f64;
    }
    Ok(sums
        .into_iter()
        .map(|s| (s / a.frame_count as f64) as f32)
        .collect())
}

/// Mean per-joint position error (MPJPE): the distance between the
/// positions of each joint in `a` and `b`, averaged over frames and over
/// `joints` (all joints when `None`).
pub fn mean_joint_position_error(
    a: &GlobalPoses,
    b: &GlobalPoses,
    joints: Option<&[usize]>,
) -> Result<f32> {
    same_shape(a, b)?;
    let joints = joint_selection(joints, a.joint_count)?;
    nonempty(a.frame_count, 1, "a position error")?;
    let mut sum = 0.0f64;
    for f in 0..a.frame_count {
        for &j in &joints {
            sum += a.position(f, j).distance(b.position(f, j)) as f64;
        }
    }
    Ok((sum / (a.frame_count * joints.len()) as f64) as f32)
}

/// Mean over frames of the geodesic angle in degrees between each joint's
/// local rotations in `a` and `b` ([`angle_between`]; one value per joint,
/// 0 for a joint without rotation channels in either motion).
pub fn joint_rotation_errors_degrees(a: &Motion, b: &Motion) -> Result<Vec<f32>> {
    same_motion_shape(a, b)?;
    nonempty(a.frame_count(), 1, "a rotation error")?;
    let n = a.skeleton().joint_count();
    let mut out = Vec::with_capacity(n);
    for j in 0..n {
        let mut sum = 0.0f64;
        if rotates(a, b, j) {
            for f in 0..a.frame_count() {
                sum += angle_between(a.local_rotation(f, j), b.local_rotation(f, j)) as f64;
            }
        }
        out.push((sum / a.frame_count() as f64).to_degrees() as f32);
    }
    Ok(out)
}

/// Mean geodesic angle in degrees between the local rotations of `a` and
/// `b`, over frames and over the joints that have rotation channels in
/// either motion.
pub fn mean_rotation_error_degrees(a: &Motion, b: &Motion) -> Result<f32> {
    let per_joint = joint_rotation_errors_degrees(a, b)?;
    let rotating: Vec<f32> = per_joint
        .iter()
        .enumerate()
        .filter(|&(j, _)| rotates(a, b, j))
        .map(|(_, &e)| e)
        .collect();
    if rotating.is_empty() {
        return Err(Error::Invalid(
            "no joint has rotation channels: there is no rotation error to measure".to_string(),
        ));
    }
    Ok((rotating.iter().map(|&e| e as f64).sum::<f64>() / rotating.len() as f64) as f32)
}

fn rotates(a: &Motion, b: &Motion, joint: usize) -> bool {
    a.skeleton().joint(joint).has_rotation_channels()
        || b.skeleton().joint(joint).has_rotation_channels()
}

/// The fewest frames [`acceleration_error`] is defined on: a second
/// difference needs a frame on each side.
pub const ACCELERATION_MIN_FRAMES: usize = 3;

/// Acceleration error: the mean over frames `1..n-1` and over `joints` of
/// `|(a[t+1] - 2 a[t] + a[t-1]) - (b[t+1] - 2 b[t] + b[t-1])|`, the norm of
/// the difference of the second finite differences of the positions, in
/// units per frame² (as in the human-motion literature, e.g. Kanazawa et
/// al., "Learning 3D Human Dynamics from Video", CVPR 2019). Needs at least
/// [`ACCELERATION_MIN_FRAMES`] frames.
pub fn acceleration_error(
    a: &GlobalPoses,
    b: &GlobalPoses,
    joints: Option<&[usize]>,
) -> Result<f32> {
    same_shape(a, b)?;
    let joints = joint_selection(joints, a.joint_count)?;
    nonempty(a.frame_count, ACCELERATION_MIN_FRAMES, "an acceleration")?;
    let accel = |p: &GlobalPoses, f: usize, j: usize| {
        p.position(f + 1, j) - 2.0 * p.position(f, j) + p.position(f - 1, j)
    };
    let mut sum = 0.0f64;
    for f in 1..a.frame_count - 1 {
        for &j in &joints {
            sum += (accel(a, f, j) - accel(b, f, j)).length() as f64;
        }
    }
    Ok((sum / ((a.frame_count - 2) * joints.len()) as f64) as f32)
}

/// Jitter: the mean norm of the third finite difference of the positions
/// (the jerk, `p[t+2] - 3 p[t+1] + 3 p[t] - p[t-1]`) over frames and over
/// `joints`, in units per frame³. The third difference is used rather than
/// the second because it is near zero for smooth motion of any speed,
/// while the second difference of a real take is dominated by its genuine
/// accelerations. Needs at least four frames.
pub fn jitter(poses: &GlobalPoses, joints: Option<&[usize]>) -> Result<f32> {
    let joints = joint_selection(joints, poses.joint_count)?;
    nonempty(poses.frame_count, 4, "a jerk")?;
    let mut sum = 0.0f64;
    for f in 1..poses.frame_count - 2 {
        for &j in &joints {
            let p = |k: usize| poses.position(k, j);
            let jerk: Vec3 = p(f + 2) - 3.0 * p(f + 1) + 3.0 * p(f) - p(f - 1);
            sum += jerk.length() as f64;
        }
    }
    Ok((sum / ((poses.frame_count - 3) * joints.len()) as f64) as f32)
}

/// Length of one bone (joint to parent) over the frames of a take.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoneLengthStats {
    /// The joint at the end of the bone.
    pub joint: usize,
    /// The joint at its start.
    pub parent: usize,
    pub mean: f32,
    /// Population standard deviation (divides by the frame count).
    pub std: f32,
    pub min: f32,
    pub max: f32,
}

/// Statistics of the length of every bone (each joint with a parent) over
/// the frames of `poses`, in skeleton order. For a motion played by FK on a
/// rigid skeleton the lengths are constant; positions from a tracker or a
/// network show how far they stretch.
pub fn bone_length_stats(poses: &GlobalPoses, skeleton: &Skeleton) -> Result<Vec<BoneLengthStats>> {
    if poses.joint_count != skeleton.joint_count() {
        return Err(Error::Invalid(format!(
            "the poses have {} joints but the skeleton has {}",
            poses.joint_count,
            skeleton.joint_count()
        )));
    }
    nonempty(poses.frame_count, 1, "a bone length")?;
    let mut out = Vec::new();
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let Some(parent) = joint.parent else { continue };
        let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
        let (mut min, mut max) = (f32::INFINITY, f32::NEG_INFINITY);
        for f in 0..poses.frame_count {
            let length = poses.position(f, j).distance(poses.position(f, parent));
            sum += length as f64;
            sum_sq += (length as f64) * (length as f64);
            min = min.min(length);
            max = max.max(length);
        }
        let n = poses.frame_count as f64;
        let mean = sum / n;
        let variance = (sum_sq / n - mean * mean).max(0.0);
        out.push(BoneLengthStats {
            joint: j,
            parent,
            mean: mean as f32,
            std: variance.sqrt() as f32,
            min,
            max,
        });
    }
    Ok(out)
}

fn same_shape(a: &GlobalPoses, b: &GlobalPoses) -> Result<()> {
    if a.joint_count != b.joint_count || a.frame_count != b.frame_count {
        return Err(Error::Invalid(format!(
            "cannot compare poses of different shapes: {} frames of {} joints against {} \
             frames of {} joints",
            a.frame_count, a.joint_count, b.frame_count, b.joint_count
        )));
    }
    Ok(())
}

fn same_motion_shape(a: &Motion, b: &Motion) -> Result<()> {
    let (ja, jb) = (a.skeleton().joint_count(), b.skeleton().joint_count());
    if ja != jb || a.frame_count() != b.frame_count() {
        return Err(Error::Invalid(format!(
            "cannot compare motions of different shapes: {} frames of {ja} joints against {} \
             frames of {jb} joints",
            a.frame_count(),
            b.frame_count()
        )));
    }
    Ok(())
}

/// The joints to average over: all of them, or the given ones after
/// checking they exist.
fn joint_selection(joints: Option<&[usize]>, joint_count: usize) -> Result<Vec<usize>> {
    match joints {
        None => Ok((0..joint_count).collect()),
        Some([]) => Err(Error::Invalid(
            "the list of joints to measure is empty".to_string(),
        )),
        Some(list) => {
            if let Some(&bad) = list.iter().find(|&&j| j >= joint_count) {
                return Err(Error::Invalid(format!(
                    "joint index {bad} is outside the poses ({joint_count} joints)"
                )));
            }
            Ok(list.to_vec())
        }
    }
}

fn nonempty(frames: usize, needed: usize, what: &str) -> Result<()> {
    if frames < needed {
        return Err(Error::Invalid(format!(
            "{what} needs at least {needed} frame{}, got {frames}",
            if needed == 1 { "" } else { "s" }
        )));
    }
    Ok(())
}

/// The limb bones compared by [`largest_bone_angle_degrees`], as (the part
/// the bone starts at, the part it ends at).
pub const LIMB_BONES: [(BodyPart, BodyPart); 11] = [
    (BodyPart::LeftShoulder, BodyPart::LeftElbow),
    (BodyPart::LeftElbow, BodyPart::LeftWrist),
    (BodyPart::RightShoulder, BodyPart::RightElbow),
    (BodyPart::RightElbow, BodyPart::RightWrist),
    (BodyPart::LeftHip, BodyPart::LeftKnee),
    (BodyPart::LeftKnee, BodyPart::LeftAnkle),
    (BodyPart::RightHip, BodyPart::RightKnee),
    (BodyPart::RightKnee, BodyPart::RightAnkle),
    (BodyPart::LeftAnkle, BodyPart::LeftToe),
    (BodyPart::RightAnkle, BodyPart::RightToe),
    (BodyPart::Neck, BodyPart::Head),
];

/// The largest angle (degrees), over all frames and the [`LIMB_BONES`] both
/// rigs have, between the direction of a bone in `a` and the same bone in
/// `b`: two motions of possibly different rigs (located by
/// [`BodyMap::detect`]) with the same number of frames. What retargeting
/// should keep.
pub fn largest_bone_angle_degrees(a: &Motion, b: &Motion) -> Result<f32> {
    if a.frame_count() != b.frame_count() {
        return Err(Error::Invalid(format!(
            "comparing bones of motions of {} and {} frames",
            a.frame_count(),
            b.frame_count()
        )));
    }
    let (map_a, map_b) = (
        BodyMap::detect(a.skeleton())?,
        BodyMap::detect(b.skeleton())?,
    );
    let (poses_a, poses_b) = (forward_kinematics(a), forward_kinematics(b));
    let direction = |poses: &GlobalPoses, map: &BodyMap, f, (from, to): (BodyPart, BodyPart)| {
        Some((poses.position(f, map.joint(to)?) - poses.position(f, map.joint(from)?)).normalize())
    };
    let mut largest = 0.0f32;
    for f in 0..a.frame_count() {
        for bone in LIMB_BONES {
            if let (Some(x), Some(y)) = (
                direction(&poses_a, &map_a, f, bone),
                direction(&poses_b, &map_b, f, bone),
            ) {
                largest = largest.max(x.angle_between(y).to_degrees());
            }
        }
    }
    Ok(largest)
}

/// The world's up axis of a take: the coordinate axis (with its sign) along
/// which the head stands above the pelvis on average over the frames.
pub fn up_axis(poses: &GlobalPoses, pelvis: usize, head: usize) -> Vec3 {
    let mut d = Vec3::ZERO;
    for f in 0..poses.frame_count {
        d += poses.position(f, head) - poses.position(f, pelvis);
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

/// Height of `joint` above its own ground on every frame: its height along
/// `up` minus its lowest height in the take, taken as the 2nd percentile so
/// a stray frame does not set it.
pub fn heights_above_ground(poses: &GlobalPoses, joint: usize, up: Vec3) -> Vec<f32> {
    let n = poses.frame_count;
    let heights: Vec<f32> = (0..n).map(|f| poses.position(f, joint).dot(up)).collect();
    if n == 0 {
        return heights;
    }
    let mut sorted = heights.clone();
    sorted.sort_by(|a, b| a.total_cmp(b));
    let ground = sorted[(n - 1) * 2 / 100];
    heights.into_iter().map(|h| h - ground).collect()
}

/// The joints of the two feet (left, right): each foot's ankle, then its
/// toe when the rig has one, as [`foot_joints`] lists them.
pub type FootJoints<'a> = [&'a [usize]; 2];

/// The joints of each foot of a rig (left, right): the ankle, then the toe
/// when the rig has one. Fails, naming the part, without an ankle.
pub fn foot_joints(map: &BodyMap) -> Result<[Vec<usize>; 2]> {
    let foot = |ankle: BodyPart, toe: BodyPart| -> Result<Vec<usize>> {
        let mut v = vec![map.require(ankle)?];
        v.extend(map.joint(toe));
        Ok(v)
    };
    Ok([
        foot(BodyPart::LeftAnkle, BodyPart::LeftToe)?,
        foot(BodyPart::RightAnkle, BodyPart::RightToe)?,
    ])
}

/// Per foot (left, right) and frame step `f - 1 -> f` (entry `f - 1`):
/// whether the foot is flat on the ground at both frames, that is every
/// joint of it (ankle and toe) within 2% of the leg length `leg` of its
/// lowest height ([`heights_above_ground`]). A real take's flat feet stand
/// still; [`planted_foot_sliding`] measures how much a motion's slide.
pub fn flat_foot_steps(
    poses: &GlobalPoses,
    feet: FootJoints,
    up: Vec3,
    leg: f32,
) -> [Vec<bool>; 2] {
    let tolerance = 0.02 * leg;
    feet.map(|foot| {
        let heights: Vec<Vec<f32>> = foot
            .iter()
            .map(|&j| heights_above_ground(poses, j, up))
            .collect();
        let flat = |f: usize| heights.iter().all(|h| h[f] <= tolerance);
        (1..poses.frame_count)
            .map(|f| flat(f) && flat(f - 1))
            .collect()
    })
}

/// Horizontal speed of `joint` from frame `f - 1` to `f`, units per second.
fn horizontal_speed(poses: &GlobalPoses, f: usize, joint: usize, up: Vec3, fps: f32) -> f32 {
    let d = poses.position(f, joint) - poses.position(f - 1, joint);
    d.reject_from_normalized(up).length() * fps
}

/// Foot skating: the mean horizontal speed (file units per second) of the
/// foot joints in the frames where they are on the ground, i.e. within 5%
/// of the leg length `leg` above the joint's lowest height in the take
/// ([`heights_above_ground`]). 0 when no joint is ever on the ground.
///
/// It counts a swinging toe passing low and a heel rolling up while the
/// ball of the foot is planted, so real walks measure 47-53 cm/s by it;
/// [`planted_foot_sliding`] is what an animator sees as a foot sliding.
pub fn foot_skating(poses: &GlobalPoses, feet: FootJoints, up: Vec3, leg: f32, fps: f32) -> f64 {
    let tolerance = 0.05 * leg;
    let mut speeds = Vec::new();
    for &j in feet[0].iter().chain(feet[1]) {
        let h = heights_above_ground(poses, j, up);
        for f in 1..poses.frame_count {
            if h[f] <= tolerance && h[f - 1] <= tolerance {
                speeds.push(horizontal_speed(poses, f, j, up, fps));
            }
        }
    }
    mean_or_zero(&speeds)
}

/// Sliding of the planted foot: the mean horizontal speed (file units per
/// second) of the slower of a foot's joints (ankle and toe) over the frame
/// steps where the foot is flat on the ground ([`flat_foot_steps`]: every
/// joint of it within 2% of the leg length `leg` of its lowest height). 0
/// when no foot is ever flat.
///
/// A flat foot on the ground stands still in a real take (the Bandai walks:
/// 4.0 cm/s on dataset-1, 6.6 on dataset-2, over 43% and 38% of the feet's
/// frames): its movement is what an animator sees as the foot sliding.
pub fn planted_foot_sliding(
    poses: &GlobalPoses,
    feet: FootJoints,
    up: Vec3,
    leg: f32,
    fps: f32,
) -> f64 {
    let flat = flat_foot_steps(poses, feet, up, leg);
    let mut speeds = Vec::new();
    for (foot, steps) in feet.into_iter().zip(&flat) {
        for f in (1..poses.frame_count).filter(|&f| steps[f - 1]) {
            let slowest = foot
                .iter()
                .map(|&j| horizontal_speed(poses, f, j, up, fps))
                .fold(f32::INFINITY, f32::min);
            speeds.push(slowest);
        }
    }
    mean_or_zero(&speeds)
}

/// How far the foot joints go below their floor ([`depth_below_floor`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FloorDepth {
    /// Frames where a foot joint of either foot is below its floor height.
    pub frames_below: usize,
    /// Frames measured.
    pub frames: usize,
    /// Mean depth (file units) over the frames below: per frame, the
    /// deepest joint's depth.
    pub mean_depth: f32,
    /// The deepest any foot joint goes below its floor height (file units).
    pub max_depth: f32,
}

/// How far the foot joints of `feet` go below the floor: `floor` gives, per
/// joint, the height along `up` it stands at on the floor (a joint's centre
/// rests above the floor by the foot's thickness there: an ankle higher than
/// a toe). A joint below that height by more than `tolerance` (file units)
/// counts as below the floor; the depths are measured from the floor
/// height itself.
pub fn depth_below_floor(
    poses: &GlobalPoses,
    feet: FootJoints,
    up: Vec3,
    floor: &dyn Fn(usize) -> f32,
    tolerance: f32,
) -> FloorDepth {
    let mut out = FloorDepth {
        frames: poses.frame_count,
        ..FloorDepth::default()
    };
    let mut sum = 0.0f64;
    for f in 0..poses.frame_count {
        let deepest = feet[0]
            .iter()
            .chain(feet[1])
            .map(|&j| floor(j) - poses.position(f, j).dot(up))
            .fold(0.0f32, f32::max);
        if deepest > tolerance {
            out.frames_below += 1;
            sum += deepest as f64;
            out.max_depth = out.max_depth.max(deepest);
        }
    }
    out.mean_depth = (sum / out.frames_below.max(1) as f64) as f32;
    out
}

/// The mean of `speeds` in f64 (0 for none).
fn mean_or_zero(speeds: &[f32]) -> f64 {
    if speeds.is_empty() {
        0.0
    } else {
        speeds.iter().map(|&v| v as f64).sum::<f64>() / speeds.len() as f64
    }
}
