//! Foot-contact cleanup of a restyled motion.
//!
//! The output's root moves along the source's horizontal path while its legs
//! take the style's strides, so a foot that should stand still on the ground
//! slides (foot skating). This pass finds the frames where each ankle is on
//! the ground (within a tolerance of its lowest height in the clip), holds
//! the ankle at one horizontal place through each such stretch (its mean
//! position there), eases the correction in and out over a few frames, and
//! reaches the held place by turning the hip and knee (two-bone inverse
//! kinematics). The ankle keeps its global orientation, so the foot and toes
//! keep the style's roll; the root and the upper body are not touched.

use mocap_core::rotation::{Quat, Vec3};
use mocap_core::{forward_kinematics, Motion};

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
}

impl Default for ContactOptions {
    fn default() -> Self {
        ContactOptions {
            height_tolerance: 0.05,
            ease_frames: 4,
            min_frames: 3,
        }
    }
}

/// Pins the ankles of `motion` during their ground contacts (see the module
/// docs). Returns the number of frames changed per foot.
pub fn clean_foot_contacts(
    motion: &mut Motion,
    rig: &RigLayout,
    options: &ContactOptions,
) -> [usize; 2] {
    let mut changed = [0; 2];
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
        let tolerance = options.height_tolerance * rig.leg_length(motion.skeleton());
        let heights: Vec<f32> = (0..n).map(|f| poses.position(f, ankle).dot(up)).collect();
        let mut sorted = heights.clone();
        sorted.sort_by(|a, b| a.total_cmp(b));
        let ground = sorted[(n - 1) * 2 / 100];
        let horizontal = |p: Vec3| p - up * p.dot(up);
        // Horizontal offset of the held place from the ankle, per frame.
        let mut offset = vec![Vec3::ZERO; n];
        let mut weight = vec![0.0f32; n];
        let mut f = 0;
        while f < n {
            if heights[f] > ground + tolerance {
                f += 1;
                continue;
            }
            let start = f;
            while f < n && heights[f] <= ground + tolerance {
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
            let target = poses.position(f, ankle) + offset[f] * weight[f];
            let h = poses.position(f, hip);
            let k = poses.position(f, knee);
            let a = poses.position(f, ankle);
            let Some((turn_hip, turn_knee)) = two_bone(h, k, a, target) else {
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
            changed[side] += 1;
        }
    }
    changed
}

/// Two-bone inverse kinematics: the world-space turns of the hip (about
/// the hip) and of the knee (about the knee, applied before the hip's) that
/// bring the ankle `a` of the chain hip `h` - knee `k` - ankle `a` as close
/// to `target` as the bone lengths allow. The knee bends in the plane it
/// already bends in. `None` for a straight or degenerate leg.
fn two_bone(h: Vec3, k: Vec3, a: Vec3, target: Vec3) -> Option<(Quat, Quat)> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::test_support::bandai_walk;
    use crate::eval::foot_skating;

    #[test]
    fn pinning_undoes_a_sliding_root_on_a_real_walk() {
        let Some(mut motion) = bandai_walk("dataset-1_walk_proud_002.bvh") else {
            return;
        };
        let rig = RigLayout::from_skeleton(motion.skeleton()).unwrap();
        let real = foot_skating(&motion, &rig);
        // Drag the pelvis sideways at 40 cm/s: the planted feet slide.
        let fps = motion.fps() as f32;
        for f in 0..motion.frame_count() {
            let t = motion.local_translation(f, rig.pelvis);
            let drift = Vec3::new(40.0 * f as f32 / fps, 0.0, 0.0);
            motion.set_local_translation(f, rig.pelvis, t + drift);
        }
        let sliding = foot_skating(&motion, &rig);
        assert!(sliding > real + 20.0, "drift: {real} -> {sliding}");
        let before = forward_kinematics(&motion);
        let changed = clean_foot_contacts(&mut motion, &rig, &ContactOptions::default());
        assert!(changed[0] > 10 && changed[1] > 10, "{changed:?}");
        let cleaned = foot_skating(&motion, &rig);
        assert!(cleaned < 0.5 * sliding, "{sliding} -> {cleaned}");
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
            let (turn_hip, turn_knee) = two_bone(h, k, a, target).expect("bent leg");
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
        let (turn_hip, turn_knee) = two_bone(h, k, a, Vec3::new(0.0, -200.0, 0.0)).unwrap();
        let new_ankle = h + turn_hip * (k - h) + turn_hip * turn_knee * (a - k);
        assert!(new_ankle.y < a.y);
    }
}
