//! Frames of a take matched to its truth's.

use mocap_core::GlobalPoses;

/// The frame shift `k` (take frame `f` is truth frame `f + k`, |k| <= 3)
/// that brings the take's joints nearest the truth's, on average.
pub fn frame_shift(take: &GlobalPoses, truth: &GlobalPoses) -> isize {
    let joints = take.joint_count.min(truth.joint_count);
    let cost = |k: isize| {
        let (mut sum, mut n) = (0.0f32, 0usize);
        for f in 0..take.frame_count as isize {
            let g = f + k;
            if g < 0 || g >= truth.frame_count as isize {
                continue;
            }
            for j in 0..joints {
                sum += (take.position(f as usize, j) - truth.position(g as usize, j)).length();
                n += 1;
            }
        }
        sum / n.max(1) as f32
    };
    (-3..=3)
        .min_by(|&a, &b| cost(a).total_cmp(&cost(b)))
        .unwrap()
}
