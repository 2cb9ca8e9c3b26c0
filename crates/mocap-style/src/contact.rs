//! Foot-contact cleanup of a restyled motion.
//!
//! The output's root moves along the source's horizontal path while its legs
//! take the style's strides, so a foot that should stand still on the ground
//! slides (foot skating). This pass finds each ankle's ground contacts,
//! holds the ankle at one horizontal place through each (its mean position
//! there), eases the correction in and out over a few frames, and reaches
//! the held place by turning the hip and knee (two-bone inverse kinematics).
//! The ankle keeps its global orientation, so the foot and toes keep the
//! style's roll; the root and the upper body are not touched.
//!
//! A contact is a stretch of frames where the ankle is within a tolerance of
//! its lowest height in the clip (3% of the leg length) *and* does not move
//! forward relative to the pelvis along the body's travel: a planted foot
//! falls behind the body, a swinging one passes it. Height alone is not
//! enough. A shuffling style (a sad walk) keeps its swinging foot as low as
//! a planted one; by height alone a restyled walk then had one contact
//! seconds long, and holding the ankle at its mean place through it asked
//! the leg to reach up to 2.6 m (bench/results/style.md, "Foot-contact
//! cleanup"). The ankle is also moved only as far as the leg reaches
//! ([`ContactOptions::reach_limit`]): where the style's strides are much
//! shorter than the source's path needs, the feet cannot all be held and are
//! left to slide rather than be pulled off the body.
//!
//! [`root_from_feet`] attacks the same sliding from the other side: it
//! leaves every joint rotation alone and moves the root instead, so that the
//! feet on the ground stand still and the body is carried by its strides
//! (root motion taken from the feet, as games drive a character). The path
//! then follows the style's strides rather than the source's
//! ([`RootPath::Feet`]). With
//! [`RootFromFeetOptions::keep_source_path_seconds`] (the default root,
//! [`RootPath::FeetAlongSource`]) the feet lead only within a stride: the
//! slow part of the shift they ask for is taken away again, so over spans
//! longer than a second the root keeps to the source's path.

use mocap_core::kinematics::{two_bone_ik, within_reach};
use mocap_core::metrics::heights_above_ground;
use mocap_core::rotation::{Quat, Vec3};
use mocap_core::{forward_kinematics, Motion};
use serde::{Deserialize, Serialize};

use crate::convert::RootPath;
use crate::features::{up_axis, RigLayout};

/// Settings of [`clean_foot_contacts`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactOptions {
    /// An ankle is on the ground within this fraction of the leg length
    /// above its lowest height in the clip (2nd percentile).
    pub height_tolerance: f32,
    /// Frames over which a correction eases in before and out after a
    /// contact.
    pub ease_frames: usize,
    /// Contacts shorter than this many frames are left alone (a foot
    /// brushing the ground in a swing).
    pub min_frames: usize,
    /// End a contact where the foot moves forward relative to the pelvis
    /// (see the module docs); `false`: by height alone (kept to measure the
    /// two side by side, the study `style_foot_cleanup`).
    pub split_at_swing: bool,
    /// Longest hip-to-ankle distance a held ankle may ask for, as a fraction
    /// of the leg's length (thigh plus shin): a correction reaching further
    /// is shortened along its direction. The leg straightens towards a
    /// target it cannot reach, so a little beyond 1 still holds the foot
    /// (the ankle ends up short of the target by at most the excess); far
    /// beyond it, the leg would be pulled off the body.
    pub reach_limit: f32,
}

impl Default for ContactOptions {
    /// Chosen on the evaluation's held-out pairs (the study
    /// `style_foot_cleanup`, bench/results/style.md, "The root and the feet"),
    /// without the style judges: the reach limit, 1.02, among 0.99, 1,
    /// 1.02, 1.05 and 1.1 as the least flat-foot sliding before more
    /// outputs put a foot out further than any real clip; the height
    /// tolerance, 3% of the leg length, among 2%, 3% and 5%: as
    /// little flat-foot sliding as 5%, less jitter and no foot out of reach
    /// more than without the cleanup.
    fn default() -> Self {
        ContactOptions {
            height_tolerance: 0.03,
            ease_frames: 4,
            min_frames: 3,
            split_at_swing: true,
            reach_limit: 1.02,
        }
    }
}

/// What [`clean_foot_contacts`] changed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactReport {
    /// Frames whose leg was turned, per foot (left, right).
    pub frames_changed: [usize; 2],
    /// Mean and largest horizontal distance an ankle was moved over those
    /// frames (file units).
    pub mean_shift: f32,
    pub max_shift: f32,
    /// Frames where the correction was shortened to stay within the leg's
    /// reach ([`ContactOptions::reach_limit`]).
    pub frames_out_of_reach: usize,
}

/// Pins the ankles of `motion` during their ground contacts (see the module
/// docs).
pub fn clean_foot_contacts(
    motion: &mut Motion,
    rig: &RigLayout,
    options: &ContactOptions,
) -> ContactReport {
    let mut report = ContactReport::default();
    let mut shift_sum = 0.0f32;
    for (side, foot) in [&rig.left_foot, &rig.right_foot].into_iter().enumerate() {
        let ankle = foot[0];
        let (Some(knee), Some(hip)) = (
            rig.parents[ankle],
            rig.parents[ankle].and_then(|k| rig.parents[k]),
        ) else {
            continue;
        };
        // Forward kinematics again per foot: the other leg's change does not
        // move this one, but the poses must be the current ones.
        let poses = forward_kinematics(motion);
        let n = poses.frame_count;
        if n < options.min_frames.max(2) {
            continue;
        }
        let up = up_axis(&poses.positions, poses.joint_count, rig);
        let leg = rig.leg_length(motion.skeleton());
        let tolerance = options.height_tolerance * leg;
        let heights = heights_above_ground(&poses, ankle, up);
        let horizontal = |p: Vec3| p.reject_from_normalized(up);
        // Below this speed relative to the pelvis (0.1 leg lengths per
        // second) a foot counts as still: a standing body has no travel to
        // tell a swing by.
        let still = 0.1 * leg / motion.fps() as f32;
        let on_ground = |f: usize| -> bool {
            if heights[f] > tolerance {
                return false;
            }
            if !options.split_at_swing {
                return true;
            }
            // Central differences over frames a..=b.
            let (a, b) = (f.saturating_sub(1), (f + 1).min(n - 1));
            let body = horizontal(poses.position(b, rig.pelvis) - poses.position(a, rig.pelvis));
            let relative = horizontal(poses.position(b, ankle) - poses.position(a, ankle)) - body;
            relative.dot(body.normalize_or_zero()) <= still * (b - a) as f32
        };
        // Horizontal offset of the held place from the ankle, per frame.
        let mut offset = vec![Vec3::ZERO; n];
        let mut weight = vec![0.0f32; n];
        let mut f = 0;
        while f < n {
            if !on_ground(f) {
                f += 1;
                continue;
            }
            let start = f;
            while f < n && on_ground(f) {
                f += 1;
            }
            let end = f; // exclusive
            if end - start < options.min_frames {
                continue;
            }
            let held = (start..end)
                .map(|g| horizontal(poses.position(g, ankle)))
                .fold(Vec3::ZERO, |a, b| a + b)
                / (end - start) as f32;
            for g in start..end {
                offset[g] = held - horizontal(poses.position(g, ankle));
                weight[g] = 1.0;
            }
            // Ease in before and out after, carrying the boundary offset.
            for k in 1..=options.ease_frames {
                let w = 1.0 - k as f32 / (options.ease_frames + 1) as f32;
                if let Some(g) = start.checked_sub(k) {
                    if w > weight[g] {
                        offset[g] = offset[start];
                        weight[g] = w;
                    }
                }
                let g = end - 1 + k;
                if g < n && w > weight[g] {
                    offset[g] = offset[end - 1];
                    weight[g] = w;
                }
            }
        }
        for f in 0..n {
            if weight[f] <= 0.0 {
                continue;
            }
            let h = poses.position(f, hip);
            let k = poses.position(f, knee);
            let a = poses.position(f, ankle);
            let mut shift = offset[f] * weight[f];
            let reach = options.reach_limit * ((k - h).length() + (a - k).length());
            if (a + shift - h).length() > reach {
                shift *= within_reach(a - h, shift, reach);
                report.frames_out_of_reach += 1;
            }
            let Some((turn_hip, turn_knee)) = two_bone_ik(h, k, a, a + shift) else {
                continue;
            };
            let hip_global = poses.rotation(f, hip);
            let knee_global = poses.rotation(f, knee);
            let ankle_global = poses.rotation(f, ankle);
            let hip_new = turn_hip * hip_global;
            let knee_new = turn_hip * turn_knee * knee_global;
            let parent_global = rig.parents[hip].map_or(Quat::IDENTITY, |p| poses.rotation(f, p));
            motion.set_local_rotation(f, hip, (parent_global.inverse() * hip_new).normalize());
            motion.set_local_rotation(f, knee, (hip_new.inverse() * knee_new).normalize());
            motion.set_local_rotation(f, ankle, (knee_new.inverse() * ankle_global).normalize());
            report.frames_changed[side] += 1;
            shift_sum += shift.length();
            report.max_shift = report.max_shift.max(shift.length());
        }
    }
    let changed = report.frames_changed[0] + report.frames_changed[1];
    report.mean_shift = shift_sum / changed.max(1) as f32;
    report
}

/// Settings of [`root_from_feet`]. Lengths are fractions of the leg length,
/// so they hold for any rig and unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RootFromFeetOptions {
    /// The feet lead the root while the lowest foot joint is within this
    /// fraction of the leg length of its ground; above it (a run's flight)
    /// the root keeps its own velocity, with a linear blend in between.
    pub height_tolerance: f32,
    /// How sharply the lowest foot joint wins the vote: a joint this much
    /// higher (fraction of the leg length) than the lowest weighs e^-1 as
    /// much.
    pub height_scale: f32,
    /// How sharply the slowest foot joint wins: one faster than the slowest
    /// by this many leg lengths per second weighs e^-1 as much. A swing
    /// foot passes within a centimetre or two of the ground; its speed
    /// tells it from the planted one.
    pub speed_scale: f32,
    /// Standard deviation of the gaussian that smooths the root's
    /// frame-to-frame steps, in seconds: the votes carry the decoder's
    /// jitter.
    pub smoothing_seconds: f32,
    /// When set, the feet lead the root only within about this many
    /// seconds: the difference between the feet's path and the source's
    /// is high-passed (minus its slow course, a gaussian-weighted local
    /// line of this standard deviation in seconds), so over longer spans the
    /// root follows the source's path, its shape and length, while within a
    /// stride the planted foot carries it.
    pub keep_source_path_seconds: Option<f32>,
}

impl RootFromFeetOptions {
    /// The settings for a [`RootPath`]: `None` for the source's path;
    /// [`RootPath::FeetAlongSource`] keeps the source's path beyond one
    /// second, about one gait cycle (a walk's is 1.0-1.3 s), so that the
    /// feet lead only within a stride.
    pub fn for_path(path: RootPath) -> Option<RootFromFeetOptions> {
        match path {
            RootPath::Source => None,
            RootPath::FeetAlongSource => Some(RootFromFeetOptions {
                keep_source_path_seconds: Some(1.0),
                ..RootFromFeetOptions::default()
            }),
            RootPath::Feet => Some(RootFromFeetOptions::default()),
        }
    }
}

impl Default for RootFromFeetOptions {
    /// Chosen on real walks (the root they give a real take travels 92-98%
    /// of its captured distance) and on the evaluation's restyled pairs (no
    /// more jitter than with the source's path); see `bench/results/style.md`.
    fn default() -> Self {
        RootFromFeetOptions {
            height_tolerance: 0.05,
            height_scale: 0.01,
            speed_scale: 0.1,
            smoothing_seconds: 0.05,
            keep_source_path_seconds: None,
        }
    }
}

/// Moves the root horizontally so that the foot on the ground stands still
/// (see the module docs); joint rotations and the root's height and heading
/// are kept. For every step from frame `f - 1` to `f`, the foot joints
/// (ankles and toes) vote: a planted joint still in the world means the
/// root moved by minus the joint's movement relative to the pelvis. The
/// votes are weighted towards the lowest and slowest joint (a softmin over
/// height above its ground and horizontal speed), which is the one a real
/// foot pivots on: the heel after it strikes, the ball of the foot as the
/// heel rises. With no foot near the ground the root keeps its own step.
/// The steps are then smoothed along time.
pub fn root_from_feet(
    motion: &mut Motion,
    rig: &RigLayout,
    options: &RootFromFeetOptions,
) -> RootShift {
    let poses = forward_kinematics(motion);
    let n = poses.frame_count;
    if n < 2 {
        return RootShift::default();
    }
    let up = up_axis(&poses.positions, poses.joint_count, rig);
    let horizontal = |p: Vec3| p.reject_from_normalized(up);
    let leg = rig.leg_length(motion.skeleton()).max(1e-6);
    let tolerance = options.height_tolerance * leg;
    let height_scale = (options.height_scale * leg).max(1e-6);
    let speed_scale = (options.speed_scale * leg / motion.fps() as f32).max(1e-6);
    let feet: Vec<(usize, Vec<f32>)> = rig
        .left_foot
        .iter()
        .chain(&rig.right_foot)
        .map(|&j| (j, heights_above_ground(&poses, j, up)))
        .collect();
    let root = |f: usize| horizontal(poses.position(f, rig.pelvis));
    let relative = |f: usize, j: usize| horizontal(poses.position(f, j)) - root(f);
    let travel = |f: usize, j: usize| horizontal(poses.position(f, j) - poses.position(f - 1, j));
    // own[f] and steps[f]: the root's horizontal step from frame f - 1 to
    // f, as it is and as the feet say (both 0 for f = 0).
    let own: Vec<Vec3> = (0..n)
        .map(|f| {
            if f == 0 {
                Vec3::ZERO
            } else {
                root(f) - root(f - 1)
            }
        })
        .collect();
    let mut steps = own.clone();
    for f in 1..n {
        let height = |h: &[f32]| h[f].max(h[f - 1]);
        let lowest = feet
            .iter()
            .map(|(_, h)| height(h))
            .fold(f32::INFINITY, f32::min);
        let on_ground = if tolerance > 0.0 {
            (1.0 - lowest / tolerance).clamp(0.0, 1.0)
        } else {
            1.0
        };
        if on_ground <= 0.0 {
            continue;
        }
        let slowest = feet
            .iter()
            .map(|(j, _)| travel(f, *j).length())
            .fold(f32::INFINITY, f32::min);
        let (mut vote, mut total) = (Vec3::ZERO, 0.0f32);
        for (j, h) in &feet {
            let w = (-(height(h) - lowest) / height_scale
                - (travel(f, *j).length() - slowest) / speed_scale)
                .exp();
            vote -= (relative(f, *j) - relative(f - 1, *j)) * w;
            total += w;
        }
        steps[f] = vote / total * on_ground + own[f] * (1.0 - on_ground);
    }
    let steps = smooth_steps(&steps, options.smoothing_seconds * motion.fps() as f32);
    // shift[f]: how far the feet's path is from the root's own at frame f.
    let mut shift = vec![Vec3::ZERO; n];
    for f in 1..n {
        shift[f] = shift[f - 1] + steps[f] - own[f];
    }
    if let Some(seconds) = options.keep_source_path_seconds {
        let sigma = seconds * motion.fps() as f32;
        let slow = local_linear_trend(&shift, sigma);
        for (s, slow) in shift.iter_mut().zip(slow) {
            *s -= slow;
        }
        // The clip starts and ends where the source does: what is left of
        // the shift at either end is eased out over about half of `sigma`
        // (a clip is often one of a sequence, so its ends are where the next
        // one takes over). Without this a restyled walk started 11 cm off
        // the source's first position.
        let (first, last) = (shift[0], shift[n - 1]);
        let tau = 0.5 * sigma.max(1.0);
        let ease = |d: usize| (-((d * d) as f32) / (2.0 * tau * tau)).exp();
        for (f, s) in shift.iter_mut().enumerate() {
            *s -= first * ease(f) + last * ease(n - 1 - f);
        }
    }
    let parent = motion.skeleton().joint(rig.pelvis).parent;
    for (f, &shift) in shift.iter().enumerate() {
        let to_local = parent.map_or(Quat::IDENTITY, |p| poses.rotation(f, p).inverse());
        let t = motion.local_translation(f, rig.pelvis);
        motion.set_local_translation(f, rig.pelvis, t + to_local * shift);
    }
    let lengths = shift.iter().map(|s| s.length());
    RootShift {
        mean: lengths.clone().sum::<f32>() / n as f32,
        max: lengths.fold(0.0, f32::max),
    }
}

/// How far `root_from_feet` moved the root from its own path,
/// horizontally, in file units.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct RootShift {
    /// Mean over the frames.
    pub mean: f32,
    /// Largest over the frames.
    pub max: f32,
}

/// The slow course of a series: at every frame, the value at that frame of
/// the straight line fitted to the series by least squares with gaussian
/// weights (standard deviation `sigma` frames). In the middle of a series
/// this is plain gaussian smoothing; unlike it, it follows a steady trend
/// up to the ends, where the window is one-sided (a cut, renormalised
/// gaussian would lag a steady drag there by about `sigma` frames' worth).
fn local_linear_trend(values: &[Vec3], sigma: f32) -> Vec<Vec3> {
    if sigma <= 0.0 {
        return values.to_vec();
    }
    let reach = (3.0 * sigma).ceil() as usize;
    let n = values.len();
    (0..n)
        .map(|f| {
            // Weighted sums of 1, d, d^2, y and d y, with d = g - f.
            let (mut s0, mut s1, mut s2) = (0.0f32, 0.0f32, 0.0f32);
            let (mut t0, mut t1) = (Vec3::ZERO, Vec3::ZERO);
            for (g, &y) in values
                .iter()
                .enumerate()
                .take((f + reach).min(n - 1) + 1)
                .skip(f.saturating_sub(reach))
            {
                let d = g as f32 - f as f32;
                let w = (-d * d / (2.0 * sigma * sigma)).exp();
                s0 += w;
                s1 += w * d;
                s2 += w * d * d;
                t0 += y * w;
                t1 += y * (w * d);
            }
            let det = s0 * s2 - s1 * s1;
            if det.abs() < 1e-9 * s0 * s0.max(s2) {
                t0 / s0
            } else {
                (t0 * s2 - t1 * s1) / det
            }
        })
        .collect()
}

/// Horizontal distance the pelvis travels over the clip (file units): the
/// length of its path on the ground, sway included.
pub fn travelled(motion: &Motion, rig: &RigLayout) -> f32 {
    let poses = forward_kinematics(motion);
    let up = up_axis(&poses.positions, poses.joint_count, rig);
    (1..poses.frame_count)
        .map(|f| {
            let d = poses.position(f, rig.pelvis) - poses.position(f - 1, rig.pelvis);
            d.reject_from_normalized(up).length()
        })
        .sum()
}

/// Gaussian smoothing (standard deviation `sigma` frames) of the steps
/// `1..`; the first entry (no step) stays 0, and the kernel is cut and
/// renormalised at the ends.
fn smooth_steps(steps: &[Vec3], sigma: f32) -> Vec<Vec3> {
    if sigma <= 0.0 || steps.len() < 3 {
        return steps.to_vec();
    }
    let reach = (3.0 * sigma).ceil() as usize;
    let kernel: Vec<f32> = (0..=reach)
        .map(|k| (-((k * k) as f32) / (2.0 * sigma * sigma)).exp())
        .collect();
    let n = steps.len();
    let mut out = vec![Vec3::ZERO; n];
    for (f, o) in out.iter_mut().enumerate().skip(1) {
        let (mut sum, mut weight) = (Vec3::ZERO, 0.0);
        for g in f.saturating_sub(reach).max(1)..=(f + reach).min(n - 1) {
            let w = kernel[f.abs_diff(g)];
            sum += steps[g] * w;
            weight += w;
        }
        *o = sum / weight;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::test_support::bandai_walk;
    use crate::eval::{foot_skating, largest_foot_reach, planted_foot_sliding};

    #[test]
    fn pinning_undoes_a_sliding_root_on_a_real_walk() {
        let Some(mut motion) = bandai_walk("dataset-1_walk_proud_002.bvh") else {
            return;
        };
        let rig = RigLayout::from_skeleton(motion.skeleton()).unwrap();
        let real = motion.clone();
        // Drag the pelvis sideways at 40 cm/s: the planted feet slide.
        let fps = motion.fps() as f32;
        for f in 0..motion.frame_count() {
            let t = motion.local_translation(f, rig.pelvis);
            let drift = Vec3::new(40.0 * f as f32 / fps, 0.0, 0.0);
            motion.set_local_translation(f, rig.pelvis, t + drift);
        }
        let sliding = foot_skating(&motion, &rig);
        let skating_real = foot_skating(&real, &rig);
        assert!(
            sliding > skating_real + 20.0,
            "drift: {skating_real} -> {sliding}"
        );
        let before = forward_kinematics(&motion);
        let planted = planted_foot_sliding(&motion, &rig);
        assert!(
            planted > planted_foot_sliding(&real, &rig) + 30.0,
            "flat feet: {} -> {planted}",
            planted_foot_sliding(&real, &rig)
        );
        let report = clean_foot_contacts(&mut motion, &rig, &ContactOptions::default());
        let changed = report.frames_changed;
        assert!(changed[0] > 10 && changed[1] > 10, "{changed:?}");
        // The flat feet come back near the real walk's sliding (40.1 -> 4.7
        // cm/s against its 2.0). The coarse skating falls by less than half
        // of what the drag added (63.9 -> 50.4 against the walk's 34.0): it
        // also counts a foot 3-5% of the leg above the ground, which the
        // cleanup leaves alone, and a foot swinging forward near it.
        let cleaned = foot_skating(&motion, &rig);
        assert!(
            cleaned - skating_real < 0.6 * (sliding - skating_real),
            "{skating_real}: {sliding} -> {cleaned}"
        );
        let planted_after = planted_foot_sliding(&motion, &rig);
        let planted_real = planted_foot_sliding(&real, &rig);
        assert!(
            planted_after < planted_real + 3.0,
            "{planted_real}: {planted} -> {planted_after}"
        );
        // A real walk's feet reach at most about half a leg from under the
        // hips; held in place against a 40 cm/s drag they reach further, but
        // stay under the body.
        assert!(largest_foot_reach(&real, &rig) < 0.6);
        assert!(largest_foot_reach(&motion, &rig) < 0.8);
        // Bone lengths and everything above the hips are kept.
        let after = forward_kinematics(&motion);
        let ankle = rig.left_foot[0];
        let knee = rig.parents[ankle].unwrap();
        for f in 0..motion.frame_count() {
            let shin =
                |p: &mocap_core::GlobalPoses| (p.position(f, ankle) - p.position(f, knee)).length();
            assert!((shin(&before) - shin(&after)).abs() < 1e-2);
            assert!((before.position(f, rig.head) - after.position(f, rig.head)).length() < 1e-3);
        }
    }

    /// On real takes (feet planted) the feet move the root about as the
    /// capture did: walks forward, back, sideways, turning, and a run.
    #[test]
    fn the_feet_carry_a_real_take_about_as_far_as_it_went() {
        for name in [
            "dataset-1_walk_proud_002.bvh",
            "dataset-1_walk_old_001.bvh",
            "dataset-1_walk-back_normal_001.bvh",
            "dataset-1_walk-left_normal_001.bvh",
            "dataset-2_walk-turn-left_feminine_001.bvh",
            "dataset-1_run_normal_001.bvh",
        ] {
            let Some(mut motion) = bandai_walk(name) else {
                return;
            };
            let rig = RigLayout::from_skeleton(motion.skeleton()).unwrap();
            let (distance, skating) = (travelled(&motion, &rig), foot_skating(&motion, &rig));
            let before = forward_kinematics(&motion);
            root_from_feet(&mut motion, &rig, &RootFromFeetOptions::default());
            let after = forward_kinematics(&motion);
            let ratio = travelled(&motion, &rig) / distance;
            let end = motion.frame_count() - 1;
            let off = (after.position(end, rig.pelvis) - before.position(end, rig.pelvis)).length();
            assert!(
                (0.9..1.02).contains(&ratio),
                "{name}: distance ratio {ratio}"
            );
            assert!(
                off < 0.1 * distance,
                "{name}: ends {off} off after {distance}"
            );
            assert!(
                foot_skating(&motion, &rig) < skating + 1.0,
                "{name}: skating {skating} -> {}",
                foot_skating(&motion, &rig)
            );
            // Only the root moved: the head keeps its place relative to it.
            let head = |p: &mocap_core::GlobalPoses, f| {
                p.position(f, rig.head) - p.position(f, rig.pelvis)
            };
            assert!((head(&before, end) - head(&after, end)).length() < 1e-3);
        }
    }

    #[test]
    fn the_feet_undo_a_sliding_root_on_a_real_walk() {
        let Some(real) = bandai_walk("dataset-1_walk_proud_002.bvh") else {
            return;
        };
        let rig = RigLayout::from_skeleton(real.skeleton()).unwrap();
        let mut motion = real.clone();
        // Drag the pelvis sideways at 40 cm/s: the planted feet slide.
        let fps = motion.fps() as f32;
        for f in 0..motion.frame_count() {
            let t = motion.local_translation(f, rig.pelvis);
            motion.set_local_translation(
                f,
                rig.pelvis,
                t + Vec3::new(40.0 * f as f32 / fps, 0.0, 0.0),
            );
        }
        let sliding = foot_skating(&motion, &rig);
        assert!(sliding > foot_skating(&real, &rig) + 20.0);
        root_from_feet(&mut motion, &rig, &RootFromFeetOptions::default());
        let fixed = foot_skating(&motion, &rig);
        assert!(
            fixed < foot_skating(&real, &rig) + 5.0,
            "{sliding} -> {fixed}"
        );
        // The drag is gone: the path is the real one again, within a tenth
        // of the drag at the end.
        let end = motion.frame_count() - 1;
        let drag = 40.0 * end as f32 / fps;
        let path = |m: &Motion| forward_kinematics(m).position(end, rig.pelvis);
        let off = (path(&motion) - path(&real)).length();
        assert!(
            off < 0.1 * drag,
            "ends {off} from the real path after a drag of {drag}"
        );
    }

    /// Along the source's path, the feet undo sliding within a stride (a
    /// fast sideways wobble of the root) but keep the path's slow course (a
    /// steady drag stays, as it is the path the source gives).
    #[test]
    fn along_the_source_the_feet_undo_a_wobble_but_keep_the_course() {
        let Some(real) = bandai_walk("dataset-1_walk_proud_002.bvh") else {
            return;
        };
        let rig = RigLayout::from_skeleton(real.skeleton()).unwrap();
        let fps = real.fps() as f32;
        let along = RootFromFeetOptions::for_path(RootPath::FeetAlongSource).unwrap();
        let moved = |offset: &dyn Fn(f32) -> Vec3| {
            let mut motion = real.clone();
            for f in 0..motion.frame_count() {
                let t = motion.local_translation(f, rig.pelvis);
                motion.set_local_translation(f, rig.pelvis, t + offset(f as f32 / fps));
            }
            motion
        };
        let pelvis = |m: &Motion| {
            let poses = forward_kinematics(m);
            (0..m.frame_count())
                .map(|f| poses.position(f, rig.pelvis))
                .collect::<Vec<_>>()
        };
        let mean_distance = |a: &[Vec3], b: &[Vec3]| {
            a.iter().zip(b).map(|(p, q)| p.distance(*q)).sum::<f32>() / a.len() as f32
        };
        let real_path = pelvis(&real);

        // A 6 cm sideways wobble at 2 Hz: the planted feet slide.
        let mut motion =
            moved(&|t| Vec3::new(6.0 * (std::f32::consts::TAU * 2.0 * t).sin(), 0.0, 0.0));
        let sliding = foot_skating(&motion, &rig);
        let real_skating = foot_skating(&real, &rig);
        assert!(sliding > real_skating + 20.0, "{real_skating} -> {sliding}");
        let shift = root_from_feet(&mut motion, &rig, &along);
        let fixed = foot_skating(&motion, &rig);
        assert!(fixed < real_skating + 3.0, "{sliding} -> {fixed}");
        let off = mean_distance(&pelvis(&motion), &real_path);
        assert!(off < 1.5, "{off} from the real path on average");
        assert!(shift.mean > 2.0 && shift.max < 12.0, "{shift:?}");

        // A steady drag of 40 cm/s is the source's course: kept, within a
        // few centimetres, where the feet alone undo it.
        let dragged = moved(&|t| Vec3::new(40.0 * t, 0.0, 0.0));
        let mut motion = dragged.clone();
        root_from_feet(&mut motion, &rig, &along);
        let off = mean_distance(&pelvis(&motion), &pelvis(&dragged));
        assert!(off < 1.5, "{off} from the dragged path on average");
    }
}
