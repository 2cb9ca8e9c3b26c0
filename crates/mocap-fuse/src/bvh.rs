//! Fused joints as a BVH motion on a fitted skeleton.
//!
//! A fused frame is 25 joint positions; animation tools want a skeleton with
//! fixed bone lengths and joint rotations. [`fused_to_motion`] builds that:
//!
//! - **the skeleton**: the Kinect v2 joints (same names, so
//!   [`mocap_core::bodymap::BodyMap::detect`] finds the body parts), in
//!   parent-before-child order, rooted at `SpineBase`. Each bone's length is
//!   measured: by default the median over the fused frames, or the person's
//!   body model ([`BoneLengthSource`]); left and right sides get their mean
//!   length. The rest pose
//!   is a T-pose facing +z with y up; joints that branch off a chain (the hips
//!   off the pelvis, the shoulders off the upper spine, the thumbs off the
//!   wrists) keep their median place relative to their parent, measured in
//!   the fused frames;
//! - **the rotations**: each joint with a child on its chain gets the global
//!   rotation that points its bone at the fused child joint. The twist about
//!   the bone is taken from a second direction: the hip line for the pelvis,
//!   the shoulder line for the spine and neck, the plane of the bent elbow or
//!   knee for the limbs (blended with the previous frame's, so a straight limb
//!   keeps its twist instead of spinning), the thumb for the hands. The global
//!   rotation is `G = F R^T`, with `F` the frame built from (bone direction,
//!   twist direction) in this pose and `R` the same frame in the rest pose;
//!   local rotations are `G_parent^-1 G`. Joints at the end of a chain (head,
//!   feet, hand tips, thumbs) carry no rotation of their own.
//!
//! Each bone is aimed from where forward kinematics puts its joint at the
//! fused child joint, so a joint's position differs from the fused one only
//! by its own bone's length difference (the fused skeleton's bones stretch
//! from frame to frame) and, for the branching joints, by their fixed place
//! relative to their parent; differences do not add up along the chain.
//! [`fit_error`] measures them.

use mocap_core::rotation::{Mat3, Quat, Vec3};
use mocap_core::{Channel, Error, Joint, Motion, Result, Skeleton};

use crate::body::{percentile, BodyModel};
use crate::fusion::FusedFrame;
use crate::kinect::{joint::*, JOINT_COUNT, JOINT_NAMES, PARENTS, TOPOLOGICAL_ORDER};

/// Options of the BVH output.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BvhOptions {
    /// Length units per metre in the file: 100 writes centimetres (as the
    /// Bandai Namco and most BVH files), 1 metres.
    pub units_per_metre: f32,
    /// Frames per second of the output; the fused frames are placed on this
    /// grid from the first one's time (gaps hold the previous pose).
    pub fps: f64,
}

impl Default for BvhOptions {
    fn default() -> Self {
        BvhOptions {
            units_per_metre: 100.0,
            fps: 30.0,
        }
    }
}

/// Where the BVH skeleton's bone lengths come from. Either way, left and
/// right bones get the mean of the two sides (people are close to
/// symmetric; one sensor's per-joint biases are not).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BoneLengthSource {
    /// The median length of each bone over the fused frames of this take:
    /// measured from all sensors at once, so single sensors' joint biases
    /// average out. On simulated Bandai takes this BVH is as close to the
    /// truth as the fused joints are; with [`BoneLengthSource::Body`] it is
    /// several millimetres further (`bench/results/fuse.md`).
    Fused,
    /// The person's body model ([`BodyModel::bone_lengths`], measured
    /// beforehand from single sensors' Tracked joints); the fused median
    /// where it has none.
    Body,
}

/// How the twist of a joint's frame is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Twist {
    /// The direction from the first joint to the second.
    Line(usize, usize),
    /// Half the sum of two lines (the mid spine: between hips and shoulders).
    TwoLines((usize, usize), (usize, usize)),
    /// The normal of the plane of a bent limb, `upper x lower` with the three
    /// joints `(root, middle, end)`, kept continuous over frames.
    Bend(usize, usize, usize),
}

/// The frame of a joint: its bone runs to `child`; the rest pose points the
/// bone along `rest_bone` with the twist direction along `rest_twist`.
#[derive(Debug, Clone, Copy)]
struct ChainJoint {
    joint: usize,
    child: usize,
    twist: Twist,
    rest_bone: Vec3,
    rest_twist: Vec3,
}

const X: Vec3 = Vec3::X;
const Y: Vec3 = Vec3::Y;
const Z: Vec3 = Vec3::Z;
const NX: Vec3 = Vec3::NEG_X;
const NY: Vec3 = Vec3::NEG_Y;

/// Every joint that has a child on its chain. The rest pose is a T-pose
/// facing +z, y up, the person's left at +x. Limb twist directions in the
/// rest pose are the bend normals of a limb bending the natural way (elbow:
/// forearm forward; knee: shank backward).
const CHAINS: [ChainJoint; 16] = {
    let hips = Twist::Line(HIP_RIGHT, HIP_LEFT);
    let shoulders = Twist::Line(SHOULDER_RIGHT, SHOULDER_LEFT);
    let arm_l = Twist::Bend(SHOULDER_LEFT, ELBOW_LEFT, WRIST_LEFT);
    let arm_r = Twist::Bend(SHOULDER_RIGHT, ELBOW_RIGHT, WRIST_RIGHT);
    let leg_l = Twist::Bend(HIP_LEFT, KNEE_LEFT, ANKLE_LEFT);
    let leg_r = Twist::Bend(HIP_RIGHT, KNEE_RIGHT, ANKLE_RIGHT);
    [
        c(SPINE_BASE, SPINE_MID, hips, Y, X),
        c(
            SPINE_MID,
            SPINE_SHOULDER,
            Twist::TwoLines((HIP_RIGHT, HIP_LEFT), (SHOULDER_RIGHT, SHOULDER_LEFT)),
            Y,
            X,
        ),
        c(SPINE_SHOULDER, NECK, shoulders, Y, X),
        c(NECK, HEAD, shoulders, Y, X),
        c(SHOULDER_LEFT, ELBOW_LEFT, arm_l, X, NY),
        c(ELBOW_LEFT, WRIST_LEFT, arm_l, X, NY),
        c(
            WRIST_LEFT,
            HAND_LEFT,
            Twist::Line(WRIST_LEFT, THUMB_LEFT),
            X,
            Z,
        ),
        c(
            HAND_LEFT,
            HAND_TIP_LEFT,
            Twist::Line(WRIST_LEFT, THUMB_LEFT),
            X,
            Z,
        ),
        c(SHOULDER_RIGHT, ELBOW_RIGHT, arm_r, NX, Y),
        c(ELBOW_RIGHT, WRIST_RIGHT, arm_r, NX, Y),
        c(
            WRIST_RIGHT,
            HAND_RIGHT,
            Twist::Line(WRIST_RIGHT, THUMB_RIGHT),
            NX,
            Z,
        ),
        c(
            HAND_RIGHT,
            HAND_TIP_RIGHT,
            Twist::Line(WRIST_RIGHT, THUMB_RIGHT),
            NX,
            Z,
        ),
        c(HIP_LEFT, KNEE_LEFT, leg_l, NY, X),
        c(KNEE_LEFT, ANKLE_LEFT, leg_l, NY, X),
        c(HIP_RIGHT, KNEE_RIGHT, leg_r, NY, X),
        c(KNEE_RIGHT, ANKLE_RIGHT, leg_r, NY, X),
    ]
};

/// The feet hang off the ankles; the ankle's frame takes its twist from the
/// leg (the knee's bend normal), so it is listed apart from [`CHAINS`].
const ANKLES: [(usize, usize, usize); 2] = [
    (ANKLE_LEFT, FOOT_LEFT, KNEE_LEFT),
    (ANKLE_RIGHT, FOOT_RIGHT, KNEE_RIGHT),
];

const fn c(
    joint: usize,
    child: usize,
    twist: Twist,
    rest_bone: Vec3,
    rest_twist: Vec3,
) -> ChainJoint {
    ChainJoint {
        joint,
        child,
        twist,
        rest_bone,
        rest_twist,
    }
}

/// A rotation frame with columns (bone, twist made perpendicular, bone x
/// twist); `None` when the bone has no length or the twist lies along it.
fn frame_of(bone: Vec3, twist: Vec3) -> Option<Mat3> {
    let b = bone.try_normalize()?;
    let t = (twist - b * twist.dot(b)).try_normalize()?;
    Some(Mat3::from_cols(b, t, b.cross(t)))
}

/// The chain joint of `joint` in [`CHAINS`], if any.
fn chain_of(joint: usize) -> Option<&'static ChainJoint> {
    CHAINS.iter().find(|c| c.joint == joint)
}

/// The joint's child on its chain (for the ankles, the foot).
fn chain_child(joint: usize) -> Option<usize> {
    chain_of(joint)
        .map(|c| c.child)
        .or_else(|| ANKLES.iter().find(|a| a.0 == joint).map(|a| a.1))
}

/// The rest frame of a chain joint (or ankle).
fn rest_frame(joint: usize) -> Mat3 {
    if let Some(c) = chain_of(joint) {
        frame_of(c.rest_bone, c.rest_twist).expect("rest directions are perpendicular")
    } else {
        frame_of(Z, X).expect("rest directions are perpendicular")
    }
}

/// Per-frame global rotations of the 25 joints (Kinect order) so that each
/// chain joint's bone points at its fused child. `bend` carries each limb's
/// twist direction from frame to frame.
///
/// With `offsets` (the skeleton's rest offsets, metres), each bone is aimed
/// from where forward kinematics puts its joint, not from the fused joint:
/// a bone whose length differs from the fused one then moves only its own
/// end, instead of shifting everything below it (errors do not add up along
/// the chain).
fn global_rotations(
    p: &[Vec3; JOINT_COUNT],
    previous: Option<&[Quat; JOINT_COUNT]>,
    bend: &mut [Option<Vec3>; JOINT_COUNT],
    offsets: Option<&[Vec3; JOINT_COUNT]>,
) -> [Quat; JOINT_COUNT] {
    let mut frames: [Option<Mat3>; JOINT_COUNT] = [None; JOINT_COUNT];
    let mut global = [Quat::IDENTITY; JOINT_COUNT];
    // Where each joint is: forward kinematics so far, or the fused joints.
    let mut at = *p;
    // This frame's twist of each limb, by the limb's root joint: the upper
    // and lower bone share it, so the middle joint turns about one axis.
    let mut limb: [Option<Vec3>; JOINT_COUNT] = [None; JOINT_COUNT];
    for &n in &TOPOLOGICAL_ORDER {
        if let (Some(offsets), Some(parent)) = (offsets, PARENTS[n]) {
            at[n] = at[parent] + global[parent] * offsets[n];
        }
        if let Some(c) = chain_of(n) {
            let bone = p[c.child] - at[n];
            let twist = match c.twist {
                Twist::Line(a, b) => p[b] - p[a],
                Twist::TwoLines((a, b), (d, e)) => {
                    (p[b] - p[a]).normalize_or_zero() + (p[e] - p[d]).normalize_or_zero()
                }
                Twist::Bend(r, m, e) => *limb[r].get_or_insert_with(|| {
                    // The bend normal grows with the bend (|upper x lower| is
                    // the sine of the angle); the previous frame's direction,
                    // given a small weight, takes over when the limb is nearly
                    // straight.
                    let upper = (p[m] - p[r]).normalize_or_zero();
                    let lower = (p[e] - p[m]).normalize_or_zero();
                    let normal = upper.cross(lower);
                    // First frame: a twist from the body, right for a limb
                    // hanging down and for the T-pose alike (legs: the hip
                    // line to the left; left arm: right and down; right arm:
                    // right and up, as the rest pose's bend normals).
                    let carried = bend[r].unwrap_or_else(|| {
                        let left = (p[HIP_LEFT] - p[HIP_RIGHT]).normalize_or(X);
                        let up = (p[SPINE_SHOULDER] - p[SPINE_BASE]).normalize_or(Y);
                        if c.rest_twist == X {
                            left
                        } else if c.rest_twist == NY {
                            -left - up
                        } else {
                            -left + up
                        }
                    });
                    let t = normal + 0.25 * carried;
                    bend[r] = t.try_normalize().or(bend[r]);
                    t
                }),
            };
            frames[n] = frame_of(bone, twist);
        } else if let Some(&(_, foot, knee)) = ANKLES.iter().find(|a| a.0 == n) {
            let twist = frames[knee].map_or(X, |f| f.y_axis);
            frames[n] = frame_of(p[foot] - at[n], twist);
        }
        global[n] = match frames[n] {
            Some(f) => Quat::from_mat3(&(f * rest_frame(n).transpose())).normalize(),
            None => match (chain_child(n), previous) {
                // A degenerate bone this frame: keep the last rotation.
                (Some(_), Some(prev)) => prev[n],
                // Ends of chains turn with their parent.
                _ => PARENTS[n].map_or(Quat::IDENTITY, |q| global[q]),
            },
        };
    }
    global
}

/// The fitted skeleton, and where each Kinect joint is in it.
#[derive(Debug, Clone)]
pub struct FittedSkeleton {
    pub skeleton: Skeleton,
    /// Index in `skeleton` of each Kinect joint.
    pub joint_index: [usize; JOINT_COUNT],
    /// Bone lengths used (metres), Kinect order (0 for the root).
    pub bone_lengths: [f32; JOINT_COUNT],
    /// Rest offsets (metres), Kinect order.
    pub offsets: [Vec3; JOINT_COUNT],
}

/// Builds the skeleton (see the module documentation) from the fused poses
/// (metres), with bone lengths from `source`.
pub fn fit_skeleton(
    poses: &[[Vec3; JOINT_COUNT]],
    body: &BodyModel,
    source: BoneLengthSource,
    units_per_metre: f32,
) -> Result<FittedSkeleton> {
    if poses.is_empty() {
        return Err(Error::Invalid(
            "no fused frames to fit a skeleton to".into(),
        ));
    }
    let mut lengths = [0.0f32; JOINT_COUNT];
    for n in 0..JOINT_COUNT {
        let Some(p) = PARENTS[n] else { continue };
        lengths[n] = match (source, body.bone_lengths[n]) {
            (BoneLengthSource::Body, Some(l)) if l.is_finite() && l > 0.0 => l,
            _ => {
                let mut seen: Vec<f32> = poses.iter().map(|q| q[n].distance(q[p])).collect();
                percentile(&mut seen, 0.5)
            }
        };
    }
    let lengths: [f32; JOINT_COUNT] =
        std::array::from_fn(|n| 0.5 * (lengths[n] + lengths[crate::kinect::MIRROR[n]]));
    // Rest offsets, in metres: along the rest bone direction of the parent's
    // chain, or (branching joints) the median direction in the parent's
    // frame, taken over the fused poses.
    let mut offsets = [Vec3::ZERO; JOINT_COUNT];
    let mut bend = [None; JOINT_COUNT];
    let globals: Vec<[Quat; JOINT_COUNT]> = {
        let mut out: Vec<[Quat; JOINT_COUNT]> = Vec::with_capacity(poses.len());
        for p in poses {
            let g = global_rotations(p, out.last(), &mut bend, None);
            out.push(g);
        }
        out
    };
    for n in 0..JOINT_COUNT {
        let Some(parent) = PARENTS[n] else { continue };
        let direction = if chain_child(parent) == Some(n) {
            rest_frame(parent).x_axis
        } else {
            // In the parent's rest frame: G^-1 (p_n - p_parent), whose median
            // over frames is the branch's usual place.
            let local: Vec<Vec3> = poses
                .iter()
                .zip(&globals)
                .map(|(p, g)| g[parent].inverse() * (p[n] - p[parent]).normalize_or_zero())
                .collect();
            let axis = |k: usize| {
                let mut v: Vec<f32> = local.iter().map(|d| d[k]).collect();
                percentile(&mut v, 0.5)
            };
            Vec3::new(axis(0), axis(1), axis(2)).normalize_or(Y)
        };
        offsets[n] = direction * lengths[n];
    }
    let mut joint_index = [0usize; JOINT_COUNT];
    for (i, &n) in TOPOLOGICAL_ORDER.iter().enumerate() {
        joint_index[n] = i;
    }
    let rotation = vec![Channel::Zrotation, Channel::Xrotation, Channel::Yrotation];
    let joints: Vec<Joint> = TOPOLOGICAL_ORDER
        .iter()
        .map(|&n| {
            let mut joint = Joint::new(
                JOINT_NAMES[n],
                PARENTS[n].map(|p| joint_index[p]),
                offsets[n] * units_per_metre,
            );
            joint.channels = if PARENTS[n].is_none() {
                [
                    vec![Channel::Xposition, Channel::Yposition, Channel::Zposition],
                    rotation.clone(),
                ]
                .concat()
            } else {
                rotation.clone()
            };
            let has_children = PARENTS.contains(&Some(n));
            if !has_children {
                // An end site a little beyond each chain end, along its bone.
                let along = (offsets[n]).normalize_or(Y);
                let size = match n {
                    HEAD => 0.1,
                    FOOT_LEFT | FOOT_RIGHT => 0.04,
                    _ => 0.02,
                };
                joint.end_sites = vec![along * size * units_per_metre];
            }
            joint
        })
        .collect();
    Ok(FittedSkeleton {
        skeleton: Skeleton::new(joints)?,
        joint_index,
        bone_lengths: lengths,
        offsets,
    })
}

/// The fused frames on a regular grid of `fps` from the first frame's time;
/// instants without a fused frame hold the previous pose.
pub fn regular_poses(frames: &[FusedFrame], fps: f64) -> Vec<[Vec3; JOINT_COUNT]> {
    let Some(first) = frames.first() else {
        return Vec::new();
    };
    let t0 = first.time;
    let mut out: Vec<[Vec3; JOINT_COUNT]> = Vec::with_capacity(frames.len());
    for f in frames {
        let i = ((f.time - t0) * fps).round().max(0.0) as usize;
        if i < out.len() {
            // Two frames on one grid instant (a finer input grid): keep the later.
            out[i] = f.joints;
            continue;
        }
        let hold = out.last().copied().unwrap_or(f.joints);
        out.resize(i, hold);
        out.push(f.joints);
    }
    out
}

/// The fused frames as a BVH motion (see the module documentation), bone
/// lengths from the fused frames ([`BoneLengthSource::Fused`]).
pub fn fused_to_motion(
    frames: &[FusedFrame],
    body: &BodyModel,
    options: &BvhOptions,
) -> Result<Motion> {
    fused_to_motion_with(frames, body, options, BoneLengthSource::Fused)
}

/// [`fused_to_motion`] with bone lengths from `lengths`.
pub fn fused_to_motion_with(
    frames: &[FusedFrame],
    body: &BodyModel,
    options: &BvhOptions,
    lengths: BoneLengthSource,
) -> Result<Motion> {
    options.check()?;
    let poses = regular_poses(frames, options.fps);
    poses_to_motion_with(&poses, body, options, lengths)
}

impl BvhOptions {
    /// A positive frame rate and unit, or an error saying which is not.
    pub fn check(&self) -> Result<()> {
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(Error::Invalid(format!(
                "BVH frame rate must be positive, got {}",
                self.fps
            )));
        }
        if !(self.units_per_metre.is_finite() && self.units_per_metre > 0.0) {
            return Err(Error::Invalid(format!(
                "units per metre must be positive, got {}",
                self.units_per_metre
            )));
        }
        Ok(())
    }
}

/// Joint positions (metres, Kinect order, one array per frame at
/// `options.fps`) as a BVH motion on a fitted skeleton, bone lengths from
/// the poses ([`BoneLengthSource::Fused`]).
pub fn poses_to_motion(
    poses: &[[Vec3; JOINT_COUNT]],
    body: &BodyModel,
    options: &BvhOptions,
) -> Result<Motion> {
    poses_to_motion_with(poses, body, options, BoneLengthSource::Fused)
}

/// [`poses_to_motion`] with bone lengths from `lengths`.
pub fn poses_to_motion_with(
    poses: &[[Vec3; JOINT_COUNT]],
    body: &BodyModel,
    options: &BvhOptions,
    lengths: BoneLengthSource,
) -> Result<Motion> {
    let fitted = fit_skeleton(poses, body, lengths, options.units_per_metre)?;
    poses_on_skeleton(poses, &fitted, options)
}

/// Joint positions (metres, Kinect order, one array per frame at
/// `options.fps`) as a BVH motion on a skeleton already fitted (to these
/// poses or to others of the same person: a fused take and its truth on one
/// skeleton).
pub fn poses_on_skeleton(
    poses: &[[Vec3; JOINT_COUNT]],
    fitted: &FittedSkeleton,
    options: &BvhOptions,
) -> Result<Motion> {
    let mut motion = Motion::rest(fitted.skeleton.clone(), 1.0 / options.fps, poses.len())?;
    let mut bend = [None; JOINT_COUNT];
    let mut previous: Option<[Quat; JOINT_COUNT]> = None;
    for (f, p) in poses.iter().enumerate() {
        let global = global_rotations(p, previous.as_ref(), &mut bend, Some(&fitted.offsets));
        for n in 0..JOINT_COUNT {
            let local = match PARENTS[n] {
                Some(parent) => global[parent].inverse() * global[n],
                None => global[n],
            };
            motion.set_local_rotation(f, fitted.joint_index[n], local.normalize());
        }
        motion.set_local_translation(
            f,
            fitted.joint_index[SPINE_BASE],
            p[SPINE_BASE] * options.units_per_metre,
        );
        previous = Some(global);
    }
    Ok(motion)
}

/// How far the BVH's joints are from the fused joints.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FitError {
    /// Mean over frames and the 25 joints (mm).
    pub mean_mm: f64,
    /// 95th percentile of the per-joint distances (mm).
    pub p95_mm: f64,
    pub max_mm: f64,
    /// Mean over the joints on bone chains alone, without the hand tips,
    /// thumbs and feet, whose Kinect estimates are the noisiest (mm).
    pub body_mean_mm: f64,
    pub frames: usize,
}

/// Compares forward kinematics of `motion` (a motion from [`fused_to_motion`]
/// or the BVH file it was written to, read back) with joint positions in
/// metres at the same frames.
pub fn fit_error(
    motion: &Motion,
    poses: &[[Vec3; JOINT_COUNT]],
    units_per_metre: f32,
) -> Result<FitError> {
    let skeleton = motion.skeleton();
    let mut index = [0usize; JOINT_COUNT];
    for (n, name) in JOINT_NAMES.iter().enumerate() {
        index[n] = skeleton
            .find(name)
            .ok_or_else(|| Error::Invalid(format!("the motion has no joint named {name}")))?;
    }
    if motion.frame_count() != poses.len() {
        return Err(Error::Invalid(format!(
            "the motion has {} frames but there are {} poses to compare with",
            motion.frame_count(),
            poses.len()
        )));
    }
    let fk = mocap_core::forward_kinematics(motion);
    let mut all = Vec::with_capacity(poses.len() * JOINT_COUNT);
    let (mut body_sum, mut body_count) = (0.0f64, 0usize);
    let extremities = [
        HAND_TIP_LEFT,
        THUMB_LEFT,
        HAND_TIP_RIGHT,
        THUMB_RIGHT,
        FOOT_LEFT,
        FOOT_RIGHT,
    ];
    for (f, p) in poses.iter().enumerate() {
        for n in 0..JOINT_COUNT {
            let d = (fk.position(f, index[n]) / units_per_metre).distance(p[n]) as f64 * 1000.0;
            all.push(d as f32);
            if !extremities.contains(&n) {
                body_sum += d;
                body_count += 1;
            }
        }
    }
    if all.is_empty() {
        return Err(Error::Invalid("no frames to compare".into()));
    }
    let mean = all.iter().map(|&d| d as f64).sum::<f64>() / all.len() as f64;
    let max = all.iter().copied().fold(0.0f32, f32::max) as f64;
    let p95 = percentile(&mut all, 0.95) as f64;
    Ok(FitError {
        mean_mm: mean,
        p95_mm: p95,
        max_mm: max,
        body_mean_mm: body_sum / body_count.max(1) as f64,
        frames: poses.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::MeasureOptions;

    fn walking_poses(count: usize) -> Vec<[Vec3; JOINT_COUNT]> {
        // The standing pose, turning about y while swinging arms and legs;
        // bones keep their lengths (each limb turns rigidly about its root).
        let base = crate::body::tests::standing_pose();
        (0..count)
            .map(|i| {
                let t = i as f32 / 30.0;
                let mut p = base;
                let swing = Quat::from_rotation_x(0.6 * (3.0 * t).sin());
                let bend = Quat::from_rotation_x(-0.5 - 0.4 * (3.0 * t).cos());
                let leg: &[usize] = &[KNEE_LEFT, ANKLE_LEFT, FOOT_LEFT];
                let arm: &[usize] = &[
                    ELBOW_RIGHT,
                    WRIST_RIGHT,
                    HAND_RIGHT,
                    HAND_TIP_RIGHT,
                    THUMB_RIGHT,
                ];
                for (root, below) in [(HIP_LEFT, leg), (SHOULDER_RIGHT, arm)] {
                    let r = p[root];
                    for &j in below {
                        p[j] = r + swing * (p[j] - r);
                    }
                    let m = p[below[0]];
                    for &j in &below[1..] {
                        p[j] = m + bend * (p[j] - m);
                    }
                }
                let turn = Quat::from_rotation_y(0.8 * t);
                let shift = Vec3::new(0.3 * t, 0.0, 0.1);
                p.map(|q| turn * q + shift)
            })
            .collect()
    }

    #[test]
    fn rigid_motion_is_reproduced_by_forward_kinematics() {
        let poses = walking_poses(60);
        let body = BodyModel::from_positions(poses.iter(), MeasureOptions::default());
        let options = BvhOptions::default();
        let motion = poses_to_motion(&poses, &body, &options).unwrap();
        let error = fit_error(&motion, &poses, options.units_per_metre).unwrap();
        // Bones keep their lengths and the branches their places, so only
        // float rounding and Euler conversions remain.
        assert!(error.max_mm < 1.0, "{error:?}");
        // The written file reads back to the same motion.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fused.bvh");
        mocap_core::io::bvh::write_bvh(&path, &motion).unwrap();
        let back = mocap_core::io::bvh::read_bvh(&path).unwrap();
        let error = fit_error(&back, &poses, options.units_per_metre).unwrap();
        assert!(error.max_mm < 1.0, "{error:?}");
        let map = mocap_core::bodymap::BodyMap::detect(back.skeleton()).unwrap();
        assert_eq!(map.rig(), "Kinect v2");
    }

    #[test]
    fn stretched_bones_show_in_the_fit_error_and_the_bvh_keeps_the_measured_lengths() {
        let poses = walking_poses(30);
        let body = BodyModel::from_positions(poses.iter(), MeasureOptions::default());
        let mut stretched = poses.clone();
        for p in stretched.iter_mut() {
            // A shank 5 cm too long in the fused data.
            let d = (p[ANKLE_LEFT] - p[KNEE_LEFT]).normalize();
            p[ANKLE_LEFT] += d * 0.05;
            p[FOOT_LEFT] += d * 0.05;
        }
        let options = BvhOptions::default();
        let motion =
            poses_to_motion_with(&stretched, &body, &options, BoneLengthSource::Body).unwrap();
        let fk = mocap_core::forward_kinematics(&motion);
        let sk = motion.skeleton();
        let (knee, ankle) = (sk.find("KneeLeft").unwrap(), sk.find("AnkleLeft").unwrap());
        let shank = fk.position(7, ankle).distance(fk.position(7, knee)) / 100.0;
        let measured = body.bone_lengths[ANKLE_LEFT].unwrap();
        assert!((shank - measured).abs() < 1e-4, "{shank} vs {measured}");
        let error = fit_error(&motion, &stretched, 100.0).unwrap();
        assert!(error.max_mm > 45.0 && error.max_mm < 55.0, "{error:?}");
    }

    #[test]
    fn a_straight_arm_keeps_its_twist() {
        // The arm straightens and bends again: the upper arm's twist must not
        // jump while it is straight.
        let base = crate::body::tests::standing_pose();
        let mut poses = Vec::new();
        for i in 0..40 {
            let mut p = base;
            let bend = ((i as f32 - 20.0).abs() / 20.0) * 1.2; // 1.2 rad .. 0 .. 1.2
            let m = p[ELBOW_LEFT];
            let r = Quat::from_rotation_x(-bend);
            for j in [WRIST_LEFT, HAND_LEFT, HAND_TIP_LEFT, THUMB_LEFT] {
                p[j] = m + r * (p[j] - m);
            }
            poses.push(p);
        }
        let body = BodyModel::from_positions(poses.iter(), MeasureOptions::default());
        let motion = poses_to_motion(&poses, &body, &BvhOptions::default()).unwrap();
        let shoulder = motion.skeleton().find("ShoulderLeft").unwrap();
        for f in 1..poses.len() {
            let a = motion.local_rotation(f - 1, shoulder);
            let b = motion.local_rotation(f, shoulder);
            assert!(
                a.angle_between(b) < 0.2,
                "frame {f}: {}",
                a.angle_between(b)
            );
        }
    }
}
