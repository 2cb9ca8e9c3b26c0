//! Where the sliding that the feet stage leaves on a fused take comes from.
//!
//! The sliding measure (`mocap_core::metrics::planted_foot_sliding`)
//! averages, over the frame steps where a foot is flat on its ground (ankle
//! and toe within 2% of the leg length of their 2nd-percentile height), the
//! speed of the foot's slower joint. A take's own flat steps are a fair
//! sample on a clean capture; on a noisy one the feet's heights jitter by
//! about that band, so its flat steps are few and not the stance frames.
//! Given the take's truth (the same rig, frame for frame: the demo's
//! `fuse/fused-on-sample-rig.bvh` or `clean/cleaned.bvh` and the sample it
//! was captured from), the study also measures the sliding over the
//! truth's flat steps: how much the feet move while the real feet stand.
//!
//! cargo run --release -p mocap-studies --example feet_sliding_sources -- TAKE.bvh TRUTH.bvh [TAKE TRUTH]...

use mocap_core::bodymap::BodyMap;
use mocap_core::io::bvh::read_bvh;
use mocap_core::metrics::{flat_foot_steps, foot_joints};
use mocap_core::{forward_kinematics, GlobalPoses};
use mocap_feet::plant_feet;
use mocap_studies::feet::{with_thresholds, CONTACT_THRESHOLDS};
use mocap_studies::frames::frame_shift;

type Error = Box<dyn std::error::Error>;

/// `steps` (entry `g - 1` for the step `g - 1 -> g` of the truth) as steps
/// of the take, whose frame `f` is the truth's `f + shift`.
fn shifted(steps: &[Vec<bool>; 2], shift: isize, frames: usize) -> [Vec<bool>; 2] {
    steps.clone().map(|s| {
        (1..frames)
            .map(|f| {
                let g = f as isize + shift;
                g >= 1 && (g as usize) <= s.len() && s[g as usize - 1]
            })
            .collect()
    })
}

/// Mean over `steps` (per foot, entry `f - 1` for the step `f - 1 -> f`)
/// of the slower foot joint's horizontal speed, the number of steps, and
/// the share of them slower than `held` (the feet stage's kept speed: a
/// step the stage held, or one that was still anyway).
fn sliding_over(
    poses: &GlobalPoses,
    feet: [&[usize]; 2],
    steps: &[Vec<bool>; 2],
    up: glam::Vec3,
    fps: f32,
    held: f32,
) -> (f32, usize, f32) {
    let mut speeds = Vec::new();
    for (foot, steps) in feet.iter().zip(steps) {
        for f in (1..poses.frame_count.min(steps.len() + 1)).filter(|&f| steps[f - 1]) {
            let slowest = foot
                .iter()
                .map(|&j| {
                    let d = poses.position(f, j) - poses.position(f - 1, j);
                    d.reject_from_normalized(up).length() * fps
                })
                .fold(f32::INFINITY, f32::min);
            speeds.push(slowest);
        }
    }
    let n = speeds.len();
    let slow = speeds.iter().filter(|&&v| v <= held).count();
    (
        speeds.iter().sum::<f32>() / n.max(1) as f32,
        n,
        slow as f32 / n.max(1) as f32,
    )
}

fn main() -> Result<(), Error> {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() || !paths.len().is_multiple_of(2) {
        return Err("TAKE.bvh TRUTH.bvh [TAKE TRUTH]...".into());
    }
    println!("| take | contact thresholds | contact frames (left + right) | own flat steps: sliding before → after (steps) | sliding on the truth's flat steps: before → after | of them held still: before → after | the truth itself |");
    println!("| --- | --- | --- | --- | --- | --- | --- |");
    for pair in paths.chunks(2) {
        let (take, truth) = (read_bvh(pair[0].as_ref())?, read_bvh(pair[1].as_ref())?);
        let map = BodyMap::detect(take.skeleton())?;
        let truth_map = BodyMap::detect(truth.skeleton())?;
        let fps = take.fps() as f32;
        let feet = foot_joints(&map)?;
        let feet = [feet[0].as_slice(), feet[1].as_slice()];
        let truth_feet = foot_joints(&truth_map)?;
        let truth_feet = [truth_feet[0].as_slice(), truth_feet[1].as_slice()];
        let before = forward_kinematics(&take);
        let truth_poses = forward_kinematics(&truth);
        let shift = frame_shift(&before, &truth_poses);
        // The stage's, the former default and the loosest thresholds.
        for thresholds in [0, 1, CONTACT_THRESHOLDS.len() - 1].map(|i| CONTACT_THRESHOLDS[i]) {
            let (enter_height, leave_height, enter_speed, leave_speed) = thresholds;
            let options = with_thresholds(thresholds);
            let (planted, report) = plant_feet(&take, &map, &options)?;
            let up = report.floor.up();
            let leg = report.before.leg_length;
            let after = forward_kinematics(&planted);
            // A little above the stage's kept speed, for the IK's rounding.
            let held = 1.1 * options.keep_speed * leg;
            let own = |poses: &GlobalPoses| {
                let steps = flat_foot_steps(poses, feet, up, leg);
                sliding_over(poses, feet, &steps, up, fps, held)
            };
            let truth_steps = flat_foot_steps(&truth_poses, truth_feet, up, leg);
            let stance = shifted(&truth_steps, shift, take.frame_count());
            let (own_before, _, _) = own(&before);
            let (own_after, n_after, _) = own(&after);
            let (on_truth_before, n_truth, held_before) =
                sliding_over(&before, feet, &stance, up, fps, held);
            let (on_truth_after, _, held_after) =
                sliding_over(&after, feet, &stance, up, fps, held);
            let (truth_itself, _, _) =
                sliding_over(&truth_poses, truth_feet, &truth_steps, up, fps, held);
            println!(
                "| {} (shift {shift}) | {enter_height}/{leave_height}, {enter_speed}/{leave_speed} | {} + {} | {own_before:.1} → {own_after:.1} ({n_after}) | {on_truth_before:.1} → {on_truth_after:.1} ({n_truth} steps) | {:.0}% → {:.0}% | {truth_itself:.1} |",
                pair[0], report.feet[0].contact_frames, report.feet[1].contact_frames,
                100.0 * held_before, 100.0 * held_after,
            );
        }
    }
    Ok(())
}
