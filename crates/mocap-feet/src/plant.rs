//! The stage: planted feet pinned, no foot below the floor, the root
//! lowered only where a leg cannot reach.
//!
//! 1. Contacts and the floor ([`crate::floor`]).
//! 2. Per foot contact, the horizontal correction that holds the foot
//!    still: frame after frame, the foot is moved back by the step of its
//!    slowest joint on the ground (the heel while the foot lands, the ball
//!    while the heel lifts: the joint the foot pivots about), less
//!    [`FeetOptions::keep_speed`] (a real planted foot's few centimetres a
//!    second are kept). Inside the contact that is the frame's own step, so
//!    a captured slide and a fused foot's frame-to-frame jitter are both
//!    taken away; near its ends (a real foot moves as it lands and lifts
//!    off) it is the median of the inner steps nearest it. The corrections are summed, smoothed at high frame
//!    rates (a gaussian of 33 ms) and centred on the
//!    contact (the foot held where it was on average), and eased in before
//!    and out after the contact over [`FeetOptions::ease_seconds`]
//!    (between two contacts closer than two eases, one blend from the
//!    first's last correction to the second's first; every blend a quintic
//!    Hermite curve that meets the correction's position and speed, so the
//!    foot gains no jerk where it lands or lifts off).
//! 3. Per frame, the foot is lifted by the deepest of its joints below its
//!    resting height on the floor, beyond half [`crate::BELOW_FLOOR_TOLERANCE`] (a running maximum, smoothed within it,
//!    so the lift is never less than needed and changes smoothly).
//! 4. Where a foot's target is further from its hip than the leg reaches
//!    ([`FeetOptions::reach`] of the leg, or the input's own stretch when
//!    that is more), the root is lowered along up just enough (smoothed the
//!    same way, at most [`FeetOptions::max_root_drop`]); what lowering
//!    cannot reach is shortened, the horizontal pin before the lift.
//! 5. Each leg is turned by two-bone IK
//!    ([`mocap_core::kinematics::two_bone_ik`]) so its ankle reaches the
//!    target; the ankle keeps its global orientation (the foot and toes
//!    keep their roll) and everything above the hips keeps its rotations.

use mocap_core::bodymap::BodyMap;
use mocap_core::kinematics::{two_bone_ik, within_reach};
use mocap_core::ops::{self, rest_pose_lead_in};
use mocap_core::rotation::{Quat, Vec3};
use mocap_core::{forward_kinematics, GlobalPoses, Motion, Result};
use serde::{Deserialize, Serialize};

use crate::contacts::ContactOptions;
use crate::floor::{measure_poses, FeetMeasures, TakeFeet, BELOW_FLOOR_TOLERANCE, MIN_FRAMES};
use crate::ground::Leg;

/// The radius of the running maximum and average that smooth the lift
/// out of the floor (seconds).
const LIFT_SMOOTHING_SECONDS: f32 = 0.067;

/// Settings of [`plant_feet`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FeetOptions {
    pub contacts: ContactOptions,
    /// Time over which a correction eases in before a contact and out after
    /// it, seconds.
    pub ease_seconds: f32,
    /// Planted-foot movement up to this speed (leg lengths per second) is
    /// kept; above it only the excess is taken away.
    pub keep_speed: f32,
    /// The floor's height along up, where the lowest foot joints rest (file
    /// units); `None`: estimated from the contacts.
    pub floor: Option<f32>,
    /// The farthest a target may be from its hip, as a fraction of the
    /// leg's length (thigh plus shin); a leg the input stretches further is
    /// allowed its own stretch.
    pub reach: f32,
    /// The most the root may be lowered, in leg lengths.
    pub max_root_drop: f32,
}

impl Default for FeetOptions {
    fn default() -> Self {
        FeetOptions {
            contacts: ContactOptions::default(),
            ease_seconds: 0.25,
            keep_speed: 0.05,
            floor: None,
            reach: 0.99,
            max_root_drop: 0.1,
        }
    }
}

/// What [`plant_feet`] did to one foot.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct FootReport {
    /// Contacts found, and the frames they cover.
    pub contacts: usize,
    pub contact_frames: usize,
    /// Frames whose leg was turned.
    pub frames_changed: usize,
    /// Frames where the foot was lifted out of the floor.
    pub frames_lifted: usize,
    /// Largest correction of the ankle (file units).
    pub max_shift: f32,
}

/// What [`plant_feet`] did, and the feet before and after on the input's
/// floor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FeetReport {
    pub frames: usize,
    /// Frames at the start left as they are and not measured: the
    /// skeleton's rest pose and the blend out of it
    /// ([`mocap_core::ops::rest_pose_lead_in`]).
    pub lead_in_frames: usize,
    pub fps: f64,
    /// Left, right.
    pub feet: [FootReport; 2],
    pub floor: crate::floor::Floor,
    /// Frames where the root was lowered, and the most it was (file units).
    pub root_lowered_frames: usize,
    pub max_root_drop: f32,
    /// Frames where a correction was shortened to the leg's reach.
    pub frames_out_of_reach: usize,
    /// Frames changed, both feet and the root together.
    pub frames_changed: usize,
    /// The largest distance any joint moved (file units).
    pub largest_joint_move: f32,
    pub before: FeetMeasures,
    pub after: FeetMeasures,
}

/// The feet stage: `motion` with its planted feet held still, no foot
/// below the floor and the root lowered where a leg cannot reach (see the
/// module docs), on the same skeleton and channels. `map` locates the legs
/// (`BodyMap::detect`, or a rig file). Fails, naming what is missing, on a
/// rig without both legs, the pelvis and the head, and on a take too short.
///
/// A take that starts at the skeleton's rest pose and blends out of it
/// ([`rest_pose_lead_in`]) keeps those frames as they are: they are no
/// stance, and their feet are not measured either.
pub fn plant_feet(
    motion: &Motion,
    map: &BodyMap,
    options: &FeetOptions,
) -> Result<(Motion, FeetReport)> {
    let n = motion.frame_count();
    let lead = rest_pose_lead_in(motion);
    if lead == 0 || n - lead < MIN_FRAMES {
        return plant_motion(motion, map, options);
    }
    let (planted, mut report) = plant_motion(&ops::trim(motion, lead..n)?, map, options)?;
    let mut out = ops::trim(motion, 0..lead)?;
    out.append(&planted)?;
    report.frames = n;
    report.lead_in_frames = lead;
    Ok((out, report))
}

/// [`plant_feet`] on every frame of `motion`.
fn plant_motion(
    motion: &Motion,
    map: &BodyMap,
    options: &FeetOptions,
) -> Result<(Motion, FeetReport)> {
    let take = TakeFeet::find(motion, map, &options.contacts, options.floor)?;
    let n = take.poses.frame_count;
    let fps = take.fps;
    let leg_length = take.rig.leg_length.max(1e-6);
    let up = take.up;
    let ease = ((options.ease_seconds * fps).round() as usize).max(1);
    let keep_step = options.keep_speed * leg_length / fps;
    let before = measure_poses(&take.poses, &take.rig, &take.floor, fps)?;
    // A foot within the tolerance of the floor is on it, not below; one
    // deeper is lifted to half the tolerance, clear of it.
    let tolerance = 0.5 * BELOW_FLOOR_TOLERANCE * leg_length;

    // Per foot: the ankle's target shift.
    let mut feet = [FootReport::default(), FootReport::default()];
    let mut shifts: [Vec<Vec3>; 2] = [vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]];
    for side in 0..2 {
        let leg = &take.rig.legs[side];
        let horizontal = pin_offsets(&take, side, leg, keep_step, ease);
        let raw_lift: Vec<f32> = (0..n)
            .map(|f| {
                leg.foot
                    .iter()
                    .map(|&j| take.floor.joint_height(j) - take.poses.position(f, j).dot(up))
                    .fold(0.0f32, f32::max)
                    - tolerance
            })
            .collect();
        let lift_radius = ((LIFT_SMOOTHING_SECONDS * fps).round() as usize).max(1);
        let lift = smooth_above(
            &raw_lift.iter().map(|&l| l.max(0.0)).collect::<Vec<_>>(),
            lift_radius,
        );
        for f in 0..n {
            shifts[side][f] = horizontal[f] + up * lift[f];
        }
        feet[side].contacts = take.spans[side].len();
        feet[side].contact_frames = take.spans[side].iter().map(|s| s.len()).sum();
        feet[side].frames_lifted = lift.iter().filter(|&&l| l > 0.0).count();
    }

    // The root: lowered where a target is out of reach.
    let reach_of = |f: usize, leg: &Leg| -> f32 {
        let p = |j| take.poses.position(f, j);
        let full = (p(leg.knee) - p(leg.hip)).length() + (p(leg.ankle) - p(leg.knee)).length();
        (options.reach * full).max((p(leg.ankle) - p(leg.hip)).length())
    };
    let max_drop = options.max_root_drop * leg_length;
    let raw_drop: Vec<f32> = match take.rig.carrier {
        None => vec![0.0; n],
        Some(_) => (0..n)
            .map(|f| {
                (0..2)
                    .map(|side| {
                        let leg = &take.rig.legs[side];
                        let v = take.poses.position(f, leg.ankle) + shifts[side][f]
                            - take.poses.position(f, leg.hip);
                        drop_to_reach(v, up, reach_of(f, leg), max_drop)
                    })
                    .fold(0.0f32, f32::max)
            })
            .collect(),
    };
    let drop: Vec<f32> = smooth_above(&raw_drop, ease)
        .into_iter()
        .map(|d| d.min(max_drop))
        .collect();

    // Apply: the root, then each leg by IK.
    let mut out = motion.clone();
    let mut out_of_reach = 0;
    let mut changed = vec![false; n];
    if let Some(carrier) = take.rig.carrier {
        let parent = motion.skeleton().joint(carrier).parent;
        for f in (0..n).filter(|&f| drop[f] > 0.0) {
            let to_local = parent.map_or(Quat::IDENTITY, |p| take.poses.rotation(f, p).inverse());
            let t = out.local_translation(f, carrier) + to_local * (-up * drop[f]);
            out.set_local_translation(f, carrier, t);
            changed[f] = true;
        }
    }
    for side in 0..2 {
        let leg = &take.rig.legs[side];
        for f in 0..n {
            let shift = shifts[side][f];
            if shift == Vec3::ZERO && drop[f] <= 0.0 {
                continue;
            }
            let lowered = -up * drop[f];
            let p = |j| take.poses.position(f, j) + lowered;
            let (h, k, a) = (p(leg.hip), p(leg.knee), p(leg.ankle));
            let mut target = take.poses.position(f, leg.ankle) + shift;
            let reach = reach_of(f, leg);
            if (target - h).length() > reach {
                target = shortened_to_reach(h, a, target, up, reach);
                out_of_reach += 1;
            }
            let Some((turn_hip, turn_knee)) = two_bone_ik(h, k, a, target) else {
                continue;
            };
            turn_leg(&mut out, &take.poses, f, leg, turn_hip, turn_knee);
            changed[f] = true;
            feet[side].frames_changed += 1;
            feet[side].max_shift = feet[side].max_shift.max((target - a - lowered).length());
        }
    }

    let after_poses = forward_kinematics(&out);
    let after = measure_poses(&after_poses, &take.rig, &take.floor, fps)?;
    let largest_joint_move = take
        .poses
        .positions
        .iter()
        .zip(&after_poses.positions)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0f32, f32::max);
    let report = FeetReport {
        frames: n,
        lead_in_frames: 0,
        fps: motion.fps(),
        feet,
        floor: take.floor.clone(),
        root_lowered_frames: drop.iter().filter(|&&d| d > 0.0).count(),
        max_root_drop: drop.iter().copied().fold(0.0, f32::max),
        frames_out_of_reach: out_of_reach,
        frames_changed: changed.iter().filter(|&&c| c).count(),
        largest_joint_move,
        before,
        after,
    };
    Ok((out, report))
}

/// The horizontal shift that holds foot `side` still through its contacts,
/// eased in and out (see the module docs).
fn pin_offsets(take: &TakeFeet, side: usize, leg: &Leg, keep_step: f32, ease: usize) -> Vec<Vec3> {
    let n = take.poses.frame_count;
    let up = take.up;
    let horizontal = |v: Vec3| v.reject_from_normalized(up);
    let on = &take.joint_on[side];
    let mut offset = vec![Vec3::ZERO; n];
    let spans = &take.spans[side];
    let frames = |seconds: f32| (seconds * take.fps).round() as usize;
    let (edge, radius) = (frames(CONTACT_EDGE_SECONDS), frames(STEP_MEDIAN_SECONDS));
    for span in spans {
        // The pivot's step into each frame after the first.
        let steps: Vec<Vec3> = (span.start + 1..span.end)
            .map(|f| {
                leg.foot
                    .iter()
                    .enumerate()
                    .filter(|&(k, _)| on[k][f - 1] && on[k][f])
                    .map(|(_, &j)| {
                        horizontal(take.poses.position(f, j) - take.poses.position(f - 1, j))
                    })
                    .min_by(|a, b| a.length().total_cmp(&b.length()))
                    .unwrap_or(Vec3::ZERO)
            })
            .collect();
        let mut d = Vec3::ZERO;
        let mut held = Vec::with_capacity(span.len());
        held.push(d);
        let inner = inner_steps(steps.len(), edge);
        for i in 0..steps.len() {
            // The frame's own step inside: its median would keep a fused
            // foot's jitter, whose median is near zero
            // (docs/research/feet.md, "Where the sliding on fused takes
            // comes from").
            let step = if inner.contains(&i) {
                steps[i]
            } else {
                robust_step(&steps, i, edge, radius)
            };
            let length = step.length();
            if length > keep_step {
                d -= step * (1.0 - keep_step / length);
            }
            held.push(d);
        }
        let held = gaussian(&held, HELD_SMOOTHING_SECONDS * take.fps);
        let mean = held.iter().fold(Vec3::ZERO, |s, &v| s + v) / held.len() as f32;
        for (f, v) in span.clone().zip(held) {
            offset[f] = v - mean;
        }
    }
    // Between contacts: one blend from a contact's last correction to the
    // next one's first, or, across a long gap (and before the first and
    // after the last), an ease out to none and an ease in. Each blend meets
    // the correction's position and speed at both ends with no jump in
    // acceleration (quintic Hermite), so the foot gains no jerk there.
    let mut previous_end: Option<usize> = None;
    for i in 0..=spans.len() {
        let gap_start = previous_end.unwrap_or(0);
        let gap_end = spans.get(i).map_or(n, |s| s.start);
        let from = previous_end.map(|e| {
            let v = if spans[i - 1].len() >= 2 {
                offset[e - 1] - offset[e - 2]
            } else {
                Vec3::ZERO
            };
            (e - 1, offset[e - 1], v)
        });
        let to = spans.get(i).map(|s| {
            let v = if s.len() >= 2 {
                offset[s.start + 1] - offset[s.start]
            } else {
                Vec3::ZERO
            };
            (s.start, offset[s.start], v)
        });
        match (from, to) {
            (Some(a), Some(b)) if gap_end - gap_start <= 2 * ease => {
                blend(&mut offset, a, b);
            }
            _ => {
                if let Some(a) = from {
                    let end = (a.0 + ease + 1).min(gap_end);
                    blend(&mut offset, a, (end, Vec3::ZERO, Vec3::ZERO));
                }
                if let Some(b) = to {
                    let start = b.0.saturating_sub(ease + 1).max(gap_start);
                    // An ease out that reaches this far already set these
                    // frames (a short gap after the take's start): keep
                    // the larger correction.
                    let mut eased = offset.clone();
                    blend(&mut eased, (start, Vec3::ZERO, Vec3::ZERO), b);
                    for g in start..b.0 {
                        if eased[g].length() >= offset[g].length() {
                            offset[g] = eased[g];
                        }
                    }
                }
            }
        }
        previous_end = spans.get(i).map(|s| s.end);
    }
    offset
}

/// Gaussian smoothing (standard deviation `sigma` frames) of `values`, the
/// kernel cut at 3 sigma and renormalised at the ends; none below 1.5
/// frames (at 30 fps the median of the steps is smooth enough, and more
/// smoothing leaves a dragged foot sliding).
fn gaussian(values: &[Vec3], sigma: f32) -> Vec<Vec3> {
    if sigma < 1.5 {
        return values.to_vec();
    }
    let reach = (3.0 * sigma).ceil() as usize;
    let n = values.len();
    (0..n)
        .map(|f| {
            let (mut sum, mut weight) = (Vec3::ZERO, 0.0);
            for (g, &v) in values
                .iter()
                .enumerate()
                .take((f + reach + 1).min(n))
                .skip(f.saturating_sub(reach))
            {
                let d = g as f32 - f as f32;
                let w = (-d * d / (2.0 * sigma * sigma)).exp();
                sum += v * w;
                weight += w;
            }
            sum / weight
        })
        .collect()
}

/// Fills the frames strictly between `a.0` and `b.0` of `offset` with the
/// quintic Hermite curve from position `a.1` with velocity `a.2` (per frame)
/// to `b.1` with velocity `b.2`, accelerations zero at both ends. Frames
/// past the end of `offset` are skipped.
fn blend(offset: &mut [Vec3], a: (usize, Vec3, Vec3), b: (usize, Vec3, Vec3)) {
    let span = (b.0 - a.0) as f32;
    for g in a.0 + 1..b.0.min(offset.len()) {
        let t = (g - a.0) as f32 / span;
        let (t2, t3) = (t * t, t * t * t);
        let (t4, t5) = (t3 * t, t3 * t2);
        let h0 = 1.0 - 10.0 * t3 + 15.0 * t4 - 6.0 * t5;
        let h1 = t - 6.0 * t3 + 8.0 * t4 - 3.0 * t5;
        let h4 = -4.0 * t3 + 7.0 * t4 - 3.0 * t5;
        let h5 = 10.0 * t3 - 15.0 * t4 + 6.0 * t5;
        offset[g] = a.1 * h0 + a.2 * (span * h1) + b.2 * (span * h4) + b.1 * h5;
    }
}

/// Frames at each end of a contact whose steps are not trusted (a foot
/// landing or lifting off moves while it is already, or still, low and
/// slow), and frames each side of a step whose median stands for it.
const CONTACT_EDGE_SECONDS: f32 = 0.067;
const STEP_MEDIAN_SECONDS: f32 = 0.1;

/// Standard deviation of the gaussian that smooths a contact's summed
/// correction (seconds): the steps carry the capture's noise, which a high
/// frame rate makes larger against the kept speed.
const HELD_SMOOTHING_SECONDS: f32 = 0.033;

/// The inner steps of a contact of `n` steps: all but the `edge` first and
/// last ([`CONTACT_EDGE_SECONDS`]), or all of a contact too short for that.
fn inner_steps(n: usize, edge: usize) -> std::ops::Range<usize> {
    if n > 2 * edge + 1 {
        edge..n - edge
    } else {
        0..n
    }
}

/// The step of a contact's pivot into frame `i + 1` as the stage corrects
/// it near the contact's ends: the median (per coordinate) of the steps
/// within [`STEP_MEDIAN_SECONDS`] of it (`radius` frames), among the
/// contact's inner steps ([`inner_steps`]: a step near an end takes the
/// nearest inner ones). A planted foot that slides slides over the whole
/// contact; a real one moves only as it lands and lifts off.
fn robust_step(steps: &[Vec3], i: usize, edge: usize, radius: usize) -> Vec3 {
    let inner = inner_steps(steps.len(), edge);
    let (lo, hi) = (inner.start, inner.end);
    let centre = i.clamp(lo, hi - 1);
    let window = &steps[centre.saturating_sub(radius).max(lo)..(centre + radius + 1).min(hi)];
    let median = |axis: usize| {
        let mut v: Vec<f32> = window.iter().map(|s| s[axis]).collect();
        v.sort_by(|a, b| a.total_cmp(b));
        let m = v.len() / 2;
        if v.len() % 2 == 1 {
            v[m]
        } else {
            0.5 * (v[m - 1] + v[m])
        }
    };
    Vec3::new(median(0), median(1), median(2))
}

/// The least lowering along `up` (at most `max_drop`) that brings a target
/// at `v` from its hip within `reach`; `max_drop` when none does.
fn drop_to_reach(v: Vec3, up: Vec3, reach: f32, max_drop: f32) -> f32 {
    if v.length() <= reach {
        return 0.0;
    }
    // |v + d up|^2 = reach^2, the smaller root.
    let vu = v.dot(up);
    let disc = vu * vu - (v.length_squared() - reach * reach);
    if disc < 0.0 {
        return max_drop;
    }
    (-vu - disc.sqrt()).clamp(0.0, max_drop)
}

/// The ankle target nearest `target` that a leg from hip `h` with its ankle
/// at `a` reaches (`reach`): the horizontal pin gives way before the lift
/// along `up`, since a foot out of the floor matters more than one held
/// still; when the lift alone is out of reach, the whole correction is
/// shortened.
fn shortened_to_reach(h: Vec3, a: Vec3, target: Vec3, up: Vec3, reach: f32) -> Vec3 {
    let wanted = target - a;
    let lifted = a + up * wanted.dot(up);
    if (lifted - h).length() <= reach {
        let pin = wanted.reject_from_normalized(up);
        lifted + pin * within_reach(lifted - h, pin, reach)
    } else {
        a + wanted * within_reach(a - h, wanted, reach)
    }
}

/// `values` (non-negative) made smooth without going below them: the
/// running maximum over `radius` frames each side, then a triangular
/// average of the same radius (each output averages maxima that all
/// include the frame's own value).
fn smooth_above(values: &[f32], radius: usize) -> Vec<f32> {
    let n = values.len();
    if radius == 0 || values.iter().all(|&v| v <= 0.0) {
        return values.to_vec();
    }
    let window = |f: usize| f.saturating_sub(radius)..(f + radius + 1).min(n);
    let dilated: Vec<f32> = (0..n)
        .map(|f| values[window(f)].iter().copied().fold(0.0, f32::max))
        .collect();
    (0..n)
        .map(|f| {
            let (mut sum, mut weight) = (0.0, 0.0);
            for g in window(f) {
                let w = (radius + 1 - f.abs_diff(g)) as f32;
                sum += dilated[g] * w;
                weight += w;
            }
            sum / weight
        })
        .collect()
}

/// Turns `leg` in frame `f` of `motion` by the world-space turns of the
/// hip and the knee ([`two_bone_ik`]), keeping the ankle's global
/// orientation; `poses` are the frame's poses before.
fn turn_leg(motion: &mut Motion, poses: &GlobalPoses, f: usize, leg: &Leg, hip: Quat, knee: Quat) {
    let skeleton = motion.skeleton();
    let parent = |j: usize| skeleton.joint(j).parent;
    let global = |j: usize| poses.rotation(f, j);
    let parent_global = |j: usize| parent(j).map_or(Quat::IDENTITY, global);
    let (h, k, a) = (leg.hip, leg.knee, leg.ankle);
    // New globals: the hip's subtree turned by `hip`, the knee's also by
    // `knee`; the ankle's kept.
    let hip_local = parent_global(h).inverse() * (hip * global(h));
    let knee_parent = hip * parent_global(k);
    let knee_local = knee_parent.inverse() * (hip * knee * global(k));
    let ankle_parent = hip * knee * parent_global(a);
    let ankle_local = ankle_parent.inverse() * global(a);
    motion.set_local_rotation(f, h, hip_local.normalize());
    motion.set_local_rotation(f, k, knee_local.normalize());
    motion.set_local_rotation(f, a, ankle_local.normalize());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoothing_above_never_goes_below() {
        let values = [
            0.0, 0.0, 3.0, 0.0, 1.0, 5.0, 5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
        ];
        let smooth = smooth_above(&values, 2);
        for (v, s) in values.iter().zip(&smooth) {
            assert!(s >= v, "{values:?} -> {smooth:?}");
        }
        // It spreads at most twice the radius.
        assert_eq!(smooth.last(), Some(&0.0));
    }

    #[test]
    fn a_blend_meets_both_ends_in_place_and_speed() {
        let mut offset = vec![Vec3::ZERO; 21];
        let (a, va) = (Vec3::new(2.0, 0.0, 0.0), Vec3::new(-0.5, 0.0, 0.0));
        let (b, vb) = (Vec3::new(-1.0, 0.0, 1.0), Vec3::new(0.2, 0.0, 0.0));
        offset[0] = a;
        offset[20] = b;
        blend(&mut offset, (0, a, va), (20, b, vb));
        // Speeds at the ends are the given ones (to first order).
        assert!(((offset[1] - offset[0]) - va).length() < 0.05);
        assert!(((offset[20] - offset[19]) - vb).length() < 0.05);
        // Acceleration near the ends is small.
        let acc = offset[2] - 2.0 * offset[1] + offset[0];
        assert!(acc.length() < 0.05, "{acc:?}");
    }

    #[test]
    fn out_of_reach_the_pin_gives_way_before_the_lift() {
        let up = Vec3::Y;
        let (h, a) = (Vec3::new(0.0, 80.0, 0.0), Vec3::new(0.0, 2.0, 0.0));
        // 3 up out of the floor and 40 sideways: the leg (reach 79.2)
        // cannot do both.
        let target = a + Vec3::new(40.0, 3.0, 0.0);
        let got = shortened_to_reach(h, a, target, up, 79.2);
        assert!(((got - h).length() - 79.2).abs() < 1e-3, "{got:?}");
        assert!((got.y - target.y).abs() < 1e-4, "the lift is kept: {got:?}");
        assert!(got.x > 0.0 && got.x < 40.0);
        // The move along up alone is out of reach too (down, here): the
        // whole correction is shortened along itself.
        let deep = a + Vec3::new(30.0, -5.0, 0.0);
        let got = shortened_to_reach(h, a, deep, up, 79.2);
        assert!(((got - h).length() - 79.2).abs() < 1e-3, "{got:?}");
        let along = (got - a).normalize().dot((deep - a).normalize());
        assert!(along > 0.9999, "along the correction: {got:?}");
    }
}
