//! Editing operations on motions: resample, trim, mirror, scale, turn.
//!
//! Every operation is a pure function: it reads a [`Motion`] and returns a
//! new one, leaving the input untouched. Rotations are always handled as
//! rotations (slerp, matrix products) and written back through
//! [`Motion::set_local_rotation`], which keeps the Euler channels continuous
//! from frame to frame.

use std::ops::Range;

use crate::bodymap::{BodyMap, BodyPart};
use crate::error::{Error, Result};
use crate::kinematics::forward_kinematics;
use crate::motion::{Motion, FRAME_TIME_RANGE, MAX_VALUES};
use crate::rotation::{angle_between, slerp, Axis, Mat3, Quat, Vec3};
use crate::skeleton::{Joint, Skeleton};

/// Frames of a take, as written on the command line: `A..B` (frames `A` up
/// to, not including, `B`, counted from 0), `A..` (to the end) or `..B`
/// (from the start). Parse with `str::parse`; [`FrameRange::resolve`] gives
/// the frames of a take of known length.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FrameRange {
    pub start: Option<usize>,
    pub end: Option<usize>,
}

impl FrameRange {
    /// The frames `range`.
    pub fn new(range: Range<usize>) -> FrameRange {
        FrameRange {
            start: Some(range.start),
            end: Some(range.end),
        }
    }

    /// The frames of a timeline of `frame_count` frames.
    pub fn resolve(&self, frame_count: usize) -> Range<usize> {
        self.start.unwrap_or(0)..self.end.unwrap_or(frame_count)
    }
}

impl std::str::FromStr for FrameRange {
    type Err = Error;

    fn from_str(text: &str) -> Result<FrameRange> {
        let bad = || {
            Error::Invalid(format!(
                "frame range `{text}`: expected A..B (frames A up to, not including, B, counted from 0), A.. or ..B"
            ))
        };
        let (a, b) = text.split_once("..").ok_or_else(bad)?;
        let number = |s: &str| -> Result<Option<usize>> {
            let s = s.trim();
            if s.is_empty() {
                Ok(None)
            } else {
                s.parse().map(Some).map_err(|_| bad())
            }
        };
        let (start, end) = (number(a)?, number(b)?);
        if let (Some(a), Some(b)) = (start, end) {
            if a >= b {
                return Err(Error::Invalid(format!(
                    "frame range `{text}` is empty: the first frame must come before the end"
                )));
            }
        }
        Ok(FrameRange { start, end })
    }
}

/// Samples closer than this to a source frame (in frames) copy that frame's
/// values unchanged instead of interpolating. Files round their frame time
/// (Bandai writes `0.0333333` for 1/30 s), so a sample meant to fall on a
/// source frame can miss it by about 1e-6 per frame of the take.
const ON_FRAME: f64 = 1e-3;

/// The motion resampled to `fps` frames per second over the same time span:
/// frame `k` is at `k / fps` seconds, up to the time of the last source
/// frame. Local rotations are interpolated by slerp, local translations
/// (position channels) linearly; samples that fall on a source frame copy
/// it exactly. The skeleton is kept.
pub fn resample_fps(motion: &Motion, fps: f64) -> Result<Motion> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(Error::Invalid(format!(
            "cannot resample to {fps} frames per second: the rate must be a positive number"
        )));
    }
    let n = source_frames(motion)?;
    let frame_time = 1.0 / fps;
    if !FRAME_TIME_RANGE.contains(&frame_time) {
        return Err(Error::Invalid(format!(
            "cannot resample to {fps} frames per second: the rate must be {} to {}",
            1.0 / FRAME_TIME_RANGE.end(),
            (1.0 / FRAME_TIME_RANGE.start()).round()
        )));
    }
    let span_in_new_frames = (n - 1) as f64 * motion.frame_time() * fps;
    let count = (span_in_new_frames + ON_FRAME).floor() as usize + 1;
    let step = frame_time / motion.frame_time();
    resample_at(motion, count, frame_time, |k| k as f64 * step)
}

/// The motion resampled to exactly `frame_count` frames spanning the same
/// time as the source (first and last frames kept), with the frame time
/// adjusted to match. Interpolation as in [`resample_fps`].
pub fn resample_frames(motion: &Motion, frame_count: usize) -> Result<Motion> {
    let n = source_frames(motion)?;
    if frame_count == 0 {
        return Err(Error::Invalid(
            "cannot resample to 0 frames: ask for at least one".to_string(),
        ));
    }
    if frame_count == 1 {
        return trim(motion, 0..1);
    }
    if n == 1 {
        return Err(Error::Invalid(format!(
            "cannot resample a one-frame motion to {frame_count} frames: it spans no time"
        )));
    }
    let span = (n - 1) as f64;
    let frame_time = motion.frame_time() * span / (frame_count - 1) as f64;
    resample_at(motion, frame_count, frame_time, |k| {
        k as f64 * span / (frame_count - 1) as f64
    })
}

fn source_frames(motion: &Motion) -> Result<usize> {
    match motion.frame_count() {
        0 => Err(Error::Invalid(
            "cannot resample a motion without frames".to_string(),
        )),
        n => Ok(n),
    }
}

/// Builds `count` frames, frame `k` sampled at source position
/// `source(k)` (in source frames, fractional).
fn resample_at(
    motion: &Motion,
    count: usize,
    frame_time: f64,
    source: impl Fn(usize) -> f64,
) -> Result<Motion> {
    let skeleton = motion.skeleton();
    let channels = skeleton.channel_count();
    // Refused before anything is allocated (`--fps 1e9`).
    if count.saturating_mul(channels) > MAX_VALUES {
        return Err(Error::Invalid(format!(
            "resampling to {count} frames of {channels} channels would make more than the \
             {MAX_VALUES} values a motion may hold"
        )));
    }
    let last = motion.frame_count() - 1;
    let mut values = Vec::with_capacity(count * channels);
    // Frame k starts as a copy of the source frame at or before it; frames
    // between source frames are then overwritten with interpolated poses.
    let mut between = Vec::with_capacity(count);
    for k in 0..count {
        let s = source(k).clamp(0.0, last as f64);
        let mut i = s.floor() as usize;
        let mut t = s - i as f64;
        if t > 1.0 - ON_FRAME {
            i += 1;
            t = 0.0;
        }
        let i = i.min(last);
        values.extend_from_slice(motion.frame(i));
        if t > ON_FRAME && i < last {
            between.push((k, i, t as f32));
        }
    }
    let mut out = Motion::new(skeleton.clone(), frame_time, count, values)?;
    for (k, i, t) in between {
        for (j, joint) in skeleton.joints().iter().enumerate() {
            if joint.has_rotation_channels() {
                let a = motion.local_rotation(i, j);
                let b = motion.local_rotation(i + 1, j);
                out.set_local_rotation(k, j, slerp(a, b, t));
            }
            if joint.has_position_channels() {
                let a = motion.local_translation(i, j);
                let b = motion.local_translation(i + 1, j);
                out.set_local_translation(k, j, a.lerp(b, t));
            }
        }
    }
    Ok(out)
}

/// The frames `range` of the motion (`start..end`, end excluded). Fails when
/// the range is empty or reaches past the last frame.
pub fn trim(motion: &Motion, range: Range<usize>) -> Result<Motion> {
    let n = motion.frame_count();
    if range.start >= range.end {
        return Err(Error::Invalid(format!(
            "frame range {}..{} is empty (the end is excluded; the take has frames 0..{n})",
            range.start, range.end
        )));
    }
    if range.end > n {
        return Err(Error::Invalid(format!(
            "frame range {}..{} is outside the take, which has frames 0..{n}",
            range.start, range.end
        )));
    }
    let channels = motion.skeleton().channel_count();
    let values = motion.values()[range.start * channels..range.end * channels].to_vec();
    Motion::new(
        motion.skeleton().clone(),
        motion.frame_time(),
        range.len(),
        values,
    )
}

/// How many frames at the start of `motion` are not its motion. Some
/// exporters put the skeleton's rest pose first (the arms, neck and head at
/// zero rotation: the CMU conversions for Daz/Poser, a MotionBuilder bind
/// pose) and blend from it into the motion over the next frames.
///
/// 0 unless frame 0 is the rest pose, frame 1 is not, and the step between
/// them is a jump: some joint moves further than [`LEAD_IN_STEP_FACTOR`]
/// times the take's median largest step and than [`LEAD_IN_MIN_STEP`] of the
/// rest pose's size. The lead-in then runs on while the steps are jumps, at
/// most a quarter second. On the 85 CMU Daz clips in the test data: 5 frames
/// (4 on runs).
pub fn rest_pose_lead_in(motion: &Motion) -> usize {
    let n = motion.frame_count();
    let skeleton = motion.skeleton();
    // The arms, the neck and the head, where the body parts are found, else
    // every joint below the root: a rest pose's legs and spine may be
    // turned (the CMU conversions' legs by up to 11 degrees, their spines
    // by 2, per performer) and the pelvis's rotation is where the body
    // faces.
    use BodyPart::*;
    let joints: Vec<usize> = match BodyMap::detect(skeleton) {
        Ok(map) => [
            Neck,
            Head,
            LeftClavicle,
            LeftShoulder,
            LeftElbow,
            LeftWrist,
            RightClavicle,
            RightShoulder,
            RightElbow,
            RightWrist,
        ]
        .into_iter()
        .filter_map(|part| map.joint(part))
        .collect(),
        Err(_) => (1..skeleton.joint_count()).collect(),
    };
    let turned = |f: usize| {
        joints
            .iter()
            .filter(|&&j| j != 0 && skeleton.joint(j).has_rotation_channels())
            .map(|&j| angle_between(motion.local_rotation(f, j), Quat::IDENTITY))
            .fold(0.0f32, f32::max)
    };
    let rest = LEAD_IN_REST_DEGREES.to_radians();
    if n < 3 || turned(0) > rest || turned(1) <= rest {
        return 0;
    }
    let poses = forward_kinematics(motion);
    let joints = poses.joint_count;
    let steps: Vec<f32> = (0..n - 1)
        .map(|f| {
            (0..joints)
                .map(|j| poses.position(f + 1, j).distance(poses.position(f, j)))
                .fold(0.0f32, f32::max)
        })
        .collect();
    let mut sorted = steps.clone();
    sorted.sort_by(|a, b| a.total_cmp(b));
    let median = sorted[sorted.len() / 2];
    let (lo, hi) = (0..joints).map(|j| poses.position(0, j)).fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    );
    let size = (hi - lo).length();
    let threshold = (LEAD_IN_STEP_FACTOR * median).max(LEAD_IN_MIN_STEP * size);
    let limit = ((0.25 * motion.fps()).round() as usize).max(1);
    if steps[0] <= threshold {
        // No jump out of it: a take that starts at rest.
        return 0;
    }
    let mut lead = 1;
    while lead < steps.len() && lead <= limit && steps[lead] > threshold {
        lead += 1;
    }
    lead.min(n - 1)
}

/// A frame whose arms, neck and head turn by less than this angle
/// (degrees) from their rest is the rest pose ([`rest_pose_lead_in`]).
pub const LEAD_IN_REST_DEGREES: f32 = 1.0;
/// A lead-in frame's step moves some joint further than this many times the
/// take's median largest step ([`rest_pose_lead_in`]) ...
pub const LEAD_IN_STEP_FACTOR: f32 = 2.0;
/// ... and further than this fraction of the rest pose's size.
pub const LEAD_IN_MIN_STEP: f32 = 0.02;

/// The motion in other units: offsets, end sites, position channels and
/// translation limits multiplied by `factor` (e.g. 0.01 for centimetres to
/// metres). Rotations are unchanged. `factor` should be positive.
pub fn scale(motion: &Motion, factor: f32) -> Motion {
    let skeleton = motion.skeleton();
    let joints: Vec<Joint> = skeleton
        .joints()
        .iter()
        .map(|joint| {
            let mut joint = joint.clone();
            joint.offset *= factor;
            for end in &mut joint.end_sites {
                *end *= factor;
            }
            if let Some(limits) = &mut joint.limits {
                for dof in limits.dofs.iter_mut().filter(|d| d.channel.is_position()) {
                    dof.min *= factor;
                    dof.max *= factor;
                }
            }
            joint
        })
        .collect();
    let mut values = motion.values().to_vec();
    let per_frame = skeleton.channel_count();
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let start = skeleton.channel_start(j);
        for (k, channel) in joint.channels.iter().enumerate() {
            if channel.is_position() {
                for frame in values.chunks_exact_mut(per_frame) {
                    frame[start + k] *= factor;
                }
            }
        }
    }
    let skeleton = Skeleton::new(joints).expect("scaling keeps names, order and channels");
    Motion::new(skeleton, motion.frame_time(), motion.frame_count(), values)
        .expect("scaling keeps the shape of the values")
}

/// The take turned by `rotation` about the world origin (e.g. a turn about
/// the vertical, to face the performer another way): every root's local
/// rotation and translation (position channels, or the offset where it has
/// none) are pre-multiplied by it, so every global position and rotation is
/// turned and the rotations below the roots are kept. Fails when a root
/// cannot hold any rotation (fewer than three rotation channels).
pub fn turn(motion: &Motion, rotation: Quat) -> Result<Motion> {
    let skeleton = motion.skeleton();
    let roots: Vec<usize> = (0..skeleton.joint_count())
        .filter(|&j| skeleton.joint(j).parent.is_none())
        .collect();
    let mut joints = skeleton.joints().to_vec();
    for &r in &roots {
        let root = &mut joints[r];
        if root.euler_order().is_none() {
            return Err(Error::Invalid(format!(
                "cannot turn the take: its root {:?} has no three rotation channels",
                root.name
            )));
        }
        if !root.has_position_channels() {
            root.offset = rotation * root.offset;
        }
    }
    let skeleton = Skeleton::new(joints).expect("turning keeps names, order and channels");
    let mut out = Motion::new(
        skeleton,
        motion.frame_time(),
        motion.frame_count(),
        motion.values().to_vec(),
    )?;
    for f in 0..motion.frame_count() {
        for &r in &roots {
            out.set_local_rotation(f, r, rotation * motion.local_rotation(f, r));
            if motion.skeleton().joint(r).has_position_channels() {
                out.set_local_translation(f, r, rotation * motion.local_translation(f, r));
            }
        }
    }
    Ok(out)
}

/// The world axis that points from the right hip to the left hip in the
/// first frame (the axis of largest absolute component), i.e. the axis a
/// mirror should flip. The first frame is used rather than the all-zero rest
/// pose because some rigs (Bandai Namco) lay every bone along its local X
/// axis when all channels are zero, which is no human pose.
pub fn lateral_axis(motion: &Motion, map: &BodyMap) -> Result<Axis> {
    let left = map.require(BodyPart::LeftHip)?;
    let right = map.require(BodyPart::RightHip)?;
    if motion.frame_count() == 0 {
        return Err(Error::Invalid(
            "cannot find the lateral axis of a motion without frames".to_string(),
        ));
    }
    let poses = forward_kinematics(&trim(motion, 0..1)?);
    let d = (poses.position(0, left) - poses.position(0, right)).abs();
    Ok(if d.x >= d.y && d.x >= d.z {
        Axis::X
    } else if d.y >= d.z {
        Axis::Y
    } else {
        Axis::Z
    })
}

/// [`mirror`] with the left/right pairs of the detected [`BodyMap`]
/// ([`BodyMap::mirror_pairs`]) and the axis of [`lateral_axis`].
pub fn mirror_auto(motion: &Motion) -> Result<Motion> {
    let map = BodyMap::detect(motion.skeleton())?;
    let pairs = map.mirror_pairs(motion.skeleton());
    let axis = lateral_axis(motion, &map)?;
    mirror(motion, &pairs, axis)
}

/// The mirror image of the motion: left and right swapped and the world
/// reflected across the plane through the origin normal to `lateral` (the
/// sagittal plane of a performer facing along another axis).
///
/// With `S` the reflection and `m(j)` the twin of joint `j` (itself for a
/// joint on the midline), the result has global positions
/// `x'_j = S x_m(j)` in every frame. Global rotations are mirrored as
/// `R'_j = S R_m(j) A_j`, where `A_j` is a fixed reflection (a signed axis
/// permutation) expressing how the local frame of `m(j)` relates to the
/// mirror image of `j`'s frame; it is found from the rest offsets by
/// [`mirror_frames`]. Then the local rotations are
/// `q'_j = A_p^T q_m(j) A_j` (with `p` the parent, and `A_p = S` above a
/// root), local translations `t'_j = A_p^T t_m(j)`, and the rest offsets
/// and end sites are mirrored the same way, so the result is the exact
/// mirror image for any rig, including rigs whose local frames are not
/// aligned with the world (Bandai's left and right frames are mirrored in
/// their local Z or Y axes and negated along the bone). For a symmetric rig
/// the mirrored skeleton equals the input up to its asymmetry; the channel
/// values do not depend on the offsets, so they can also be played on the
/// original skeleton. Mirroring twice gives back the input.
///
/// `pairs` are `(left, right)` joints ([`crate::bodymap::mirror_pairs`]);
/// they must mirror the hierarchy (the twins' parents are twins). Joint
/// range-of-motion limits are kept as they are. Fails on a bad pair, or
/// when a joint with fewer than three rotation channels cannot hold its
/// mirrored rotation.
pub fn mirror(motion: &Motion, pairs: &[(usize, usize)], lateral: Axis) -> Result<Motion> {
    let skeleton = motion.skeleton();
    let twin = twins(skeleton, pairs)?;
    let frames = mirror_frames(motion, pairs, lateral)?;
    let s = reflection(lateral);
    let above = |j: usize| skeleton.joint(j).parent.map_or(s, |p| frames[p]);

    // Mirrored skeleton: t'_c = A_p^T t_m(c), ends e'_j = A_j^T e_m(j).
    let joints: Vec<Joint> = skeleton
        .joints()
        .iter()
        .enumerate()
        .map(|(j, joint)| {
            let source = skeleton.joint(twin[j]);
            let mut joint = joint.clone();
            joint.offset = above(j).transpose() * source.offset;
            if source.end_sites.len() == joint.end_sites.len() {
                for (end, &from) in joint.end_sites.iter_mut().zip(&source.end_sites) {
                    *end = frames[j].transpose() * from;
                }
            }
            joint
        })
        .collect();
    let mirrored = Skeleton::new(joints)?;
    let mut out = Motion::new(
        mirrored,
        motion.frame_time(),
        motion.frame_count(),
        motion.values().to_vec(),
    )?;
    let targets: Vec<Mat3> = (0..skeleton.joint_count())
        .map(|j| above(j).transpose())
        .collect();
    for f in 0..motion.frame_count() {
        for (j, joint) in skeleton.joints().iter().enumerate() {
            let q = Mat3::from_quat(motion.local_rotation(f, twin[j]));
            let rotation = Quat::from_mat3(&(targets[j] * q * frames[j])).normalize();
            out.set_local_rotation(f, j, rotation);
            if joint.has_position_channels() {
                out.set_local_translation(f, j, targets[j] * motion.local_translation(f, twin[j]));
            }
        }
    }
    check_rotations_held(motion, &out, &twin, &frames, &targets)?;
    Ok(out)
}

/// Fails when a joint with fewer than three rotation channels could not
/// hold the rotation [`mirror`] gave it.
fn check_rotations_held(
    motion: &Motion,
    out: &Motion,
    twin: &[usize],
    frames: &[Mat3],
    targets: &[Mat3],
) -> Result<()> {
    const TOLERANCE_DEG: f32 = 0.5;
    let skeleton = motion.skeleton();
    for (j, joint) in skeleton.joints().iter().enumerate() {
        if joint.euler_order().is_some() {
            continue;
        }
        for f in 0..motion.frame_count() {
            let q = Mat3::from_quat(motion.local_rotation(f, twin[j]));
            let wanted = Quat::from_mat3(&(targets[j] * q * frames[j]));
            let off = angle_between(wanted, out.local_rotation(f, j)).to_degrees();
            if off > TOLERANCE_DEG {
                return Err(Error::Invalid(format!(
                    "cannot mirror joint {:?}: its rotation channels ({}) cannot hold the \
                     mirrored rotation of {:?} at frame {f} ({off:.1} degrees off)",
                    joint.name,
                    joint
                        .channels
                        .iter()
                        .filter(|c| c.is_rotation())
                        .map(|c| c.name())
                        .collect::<Vec<_>>()
                        .join(" "),
                    skeleton.joint(twin[j]).name,
                )));
            }
        }
    }
    Ok(())
}

/// The twin of every joint (itself on the midline), after checking that the
/// pairs are joints of the skeleton, that no joint is in two pairs, and that
/// twins hang from twins.
fn twins(skeleton: &Skeleton, pairs: &[(usize, usize)]) -> Result<Vec<usize>> {
    let n = skeleton.joint_count();
    let mut twin: Vec<usize> = (0..n).collect();
    let mut paired = vec![false; n];
    for &(left, right) in pairs {
        if left >= n || right >= n {
            return Err(Error::Invalid(format!(
                "mirror pair ({left}, {right}) names a joint outside the skeleton ({n} joints)"
            )));
        }
        for j in [left, right] {
            if paired[j] || left == right {
                return Err(Error::Invalid(format!(
                    "joint {:?} is in more than one mirror pair",
                    skeleton.joint(j).name
                )));
            }
            paired[j] = true;
        }
        twin[left] = right;
        twin[right] = left;
    }
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let twin_parent = skeleton.joint(twin[j]).parent;
        if joint.parent.map(|p| twin[p]) != twin_parent {
            let name =
                |p: Option<usize>| p.map_or("none".to_string(), |p| skeleton.joint(p).name.clone());
            return Err(Error::Invalid(format!(
                "mirror pairs do not mirror the hierarchy: {:?} hangs from {} but its twin {:?} \
                 hangs from {} (expected {})",
                joint.name,
                name(joint.parent),
                skeleton.joint(twin[j]).name,
                name(twin_parent),
                name(joint.parent.map(|p| twin[p])),
            )));
        }
    }
    Ok(twin)
}

/// The reflection of the world across the plane normal to `axis`.
fn reflection(axis: Axis) -> Mat3 {
    Mat3::from_diagonal(Vec3::ONE - 2.0 * axis.unit())
}

/// How many degrees a candidate frame reflection may fit the rest offsets
/// worse than the best one and still count as fitting (real rigs are not
/// exactly symmetric: CMU's left and right legs differ by about 2 degrees).
const FIT_TOLERANCE_DEG: f32 = 3.0;

/// The frame reflection `A_j` of every joint used by [`mirror`]: a signed
/// permutation of the local axes with determinant -1 such that
/// `A_j t_c` points like `t_m(c)` for each child `c` (and end site) of `j`,
/// where `t` are rest offsets and `m` swaps twins. Twins get transposed
/// reflections (`A_m(j) = A_j^T`, so mirroring twice is the identity), and a
/// joint on the midline gets the reflection across one of its local
/// coordinate planes.
///
/// Offsets alone often leave a choice (a bone along its local X axis maps
/// to its twin under several reflections, which differ by a twist about the
/// bone). The choice does not change the mirrored positions, only how the
/// mirrored rotation is split between a joint and its children, so it is
/// made to keep local rotations natural. Among the reflections that fit the
/// offsets within 3 degrees of the best (`FIT_TOLERANCE_DEG`):
/// - a joint without rotation channels takes its parent's reflection (so it
///   stays unrotated);
/// - a joint on the midline takes the reflection across the local
///   coordinate plane nearest the body's sagittal plane in the first frame
///   (the local axis nearest the direction from the right hip and shoulder
///   to the left ones, or the world `lateral` axis when the pairs give
///   none), keeping its parent's (for the root: the world's, `S`)
///   plane while that is within 60 degrees, so its frame is mirrored onto
///   itself. This is read from the motion because the all-zero rest pose of
///   some rigs is no human pose (Bandai's lays every bone along its local X
///   axis); a motion without frames falls back on the offsets;
/// - a left or right joint prefers its parent's reflection (a chain keeps
///   its convention), then `-I` (the "mirror behaviour" of Maya and
///   MotionBuilder rigs such as Bandai's, whose right-side offsets are the
///   negated left ones), then the best fit.
pub fn mirror_frames(
    motion: &Motion,
    pairs: &[(usize, usize)],
    lateral: Axis,
) -> Result<Vec<Mat3>> {
    let skeleton = motion.skeleton();
    let twin = twins(skeleton, pairs)?;
    let s = reflection(lateral);
    let n = skeleton.joint_count();
    // The body's lateral direction in each joint's frame, in the first
    // frame: across the pairs that hang from the midline (hips and
    // shoulders), not the world axis `lateral`. Whatever plane the world is
    // reflected across, a midline joint's frame must be reflected across
    // its own local plane nearest the body's sagittal plane, so that its
    // axes point along the mirrored body as they did along the body. Judged
    // against the world axis instead, a performer facing 45 degrees off it
    // had midline joints pick the wrong plane: the same positions, but
    // rotations split into unnatural ones (a neck twisted half a turn; 35 of
    // the 174 dataset-1 Bandai takes, most of the walks to the side).
    let lateral_in_joint: Vec<Option<Vec3>> = if motion.frame_count() > 0 {
        let poses = forward_kinematics(&trim(motion, 0..1)?);
        let across: Vec3 = pairs
            .iter()
            .filter(|&&(left, _)| skeleton.joint(left).parent.is_some_and(|p| twin[p] == p))
            .map(|&(left, right)| poses.position(0, left) - poses.position(0, right))
            .sum();
        let body_lateral = across.try_normalize().unwrap_or(lateral.unit());
        (0..n)
            .map(|j| Some(poses.rotation(0, j).inverse() * body_lateral))
            .collect()
    } else {
        vec![None; n]
    };
    let children: Vec<Vec<usize>> = (0..n).map(|j| skeleton.children(j).collect()).collect();
    let candidates = signed_reflections();
    let mut frames: Vec<Option<Mat3>> = vec![None; n];
    for j in 0..n {
        if frames[j].is_some() {
            continue;
        }
        let joint = skeleton.joint(j);
        let other = skeleton.joint(twin[j]);
        // Directions that A_j must carry over: child offsets to the twin
        // child's offsets, end sites to the twin's end sites.
        let mut constraints: Vec<(Vec3, Vec3)> = children[j]
            .iter()
            .map(|&c| (skeleton.joint(c).offset, skeleton.joint(twin[c]).offset))
            .collect();
        if joint.end_sites.len() == other.end_sites.len() {
            constraints.extend(
                joint
                    .end_sites
                    .iter()
                    .copied()
                    .zip(other.end_sites.iter().copied()),
            );
        }
        let constraints: Vec<(Vec3, Vec3)> = constraints
            .into_iter()
            .filter_map(|(u, v)| Some((u.try_normalize()?, v.try_normalize()?)))
            .collect();
        let misfit = |a: &Mat3| {
            constraints
                .iter()
                .map(|&(u, v)| (*a * u).dot(v).clamp(-1.0, 1.0).acos().to_degrees())
                .fold(0.0f32, f32::max)
        };
        let on_midline = twin[j] == j;
        // A joint on the midline mirrors its frame onto itself across one of
        // its local coordinate planes.
        let allowed: Vec<(Mat3, f32)> = candidates
            .iter()
            .filter(|a| !on_midline || is_axis_reflection(a))
            .map(|a| (*a, misfit(a)))
            .collect();
        let best = allowed
            .iter()
            .map(|&(_, e)| e)
            .fold(f32::INFINITY, f32::min);
        let fits = |a: Mat3| {
            allowed
                .iter()
                .any(|&(c, e)| c == a && e <= best + FIT_TOLERANCE_DEG)
        };
        let best_fit = allowed
            .iter()
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .expect("there are candidate reflections")
            .0;
        let parent = joint.parent.map(|p| frames[p].expect("parents come first"));
        let keeps_rotation = !joint.has_rotation_channels() && !other.has_rotation_channels();
        let chosen = match (parent, lateral_in_joint[j]) {
            // A joint that cannot rotate must take its parent's frame.
            (Some(p), _) if keeps_rotation && allowed.iter().any(|&(c, _)| c == p) => p,
            // A midline joint keeps its parent's plane while that is near
            // the body's sagittal plane. The root's parent is the world,
            // reflected by `S`: a root that keeps `S` has its rotation
            // mirrored by conjugation, `S R S`, as a still root stays still.
            (parent, Some(n)) if on_midline => midline_reflection(parent.or(Some(s)), n),
            (None, None) if fits(s) => s,
            (Some(p), _) if fits(p) => p,
            _ if !on_midline && fits(-Mat3::IDENTITY) => -Mat3::IDENTITY,
            _ => best_fit,
        };
        frames[j] = Some(chosen);
        frames[twin[j]] = Some(chosen.transpose());
    }
    Ok(frames
        .into_iter()
        .map(|a| a.expect("every joint is visited"))
        .collect())
}

/// The reflection across a local coordinate plane for a joint on the
/// midline whose frame holds the body's lateral direction as `n` (unit) in
/// the first frame: the parent's plane while its normal stays within 60
/// degrees of `n` (so a head turned 50 degrees keeps the neck's plane; one
/// turned further in the first frame gets its own plane, which keeps the
/// positions but not the most natural rotations), else the plane normal to
/// the local axis nearest `n`.
fn midline_reflection(parent: Option<Mat3>, n: Vec3) -> Mat3 {
    if let Some(p) = parent {
        if let Some(normal) = reflection_normal(&p) {
            if normal.dot(n).abs() >= 0.5 {
                return p;
            }
        }
    }
    let axis = n.abs().max_position();
    Mat3::from_diagonal(Vec3::ONE - 2.0 * Vec3::AXES[axis])
}

fn diagonal(a: &Mat3) -> Vec3 {
    Vec3::new(a.x_axis.x, a.y_axis.y, a.z_axis.z)
}

/// The normal of `a` if it is the reflection across a coordinate plane
/// (diag(-1, 1, 1), diag(1, -1, 1) or diag(1, 1, -1)).
fn reflection_normal(a: &Mat3) -> Option<Vec3> {
    let d = diagonal(a);
    let is_diagonal = *a == Mat3::from_diagonal(d);
    (is_diagonal && d.element_sum() == 1.0).then(|| (Vec3::ONE - d) * 0.5)
}

fn is_axis_reflection(a: &Mat3) -> bool {
    reflection_normal(a).is_some()
}

/// The 24 signed permutation matrices with determinant -1.
fn signed_reflections() -> Vec<Mat3> {
    const PERMUTATIONS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let unit = |k: usize| [Vec3::X, Vec3::Y, Vec3::Z][k];
    let mut out = Vec::with_capacity(24);
    for perm in PERMUTATIONS {
        for signs in 0..8u32 {
            let sign = |k: u32| if signs & (1 << k) == 0 { 1.0 } else { -1.0 };
            let m = Mat3::from_cols(
                sign(0) * unit(perm[0]),
                sign(1) * unit(perm[1]),
                sign(2) * unit(perm[2]),
            );
            if m.determinant() < 0.0 {
                out.push(m);
            }
        }
    }
    out
}
