//! The errors every part measures against a clean take: the mean rotation
//! error in degrees, and the position and acceleration errors after forward
//! kinematics (`mocap_core::metrics`).

use mocap_core::bodymap::BodyMap;
use mocap_core::{forward_kinematics, metrics, Motion};

/// Mean geodesic angle (degrees) between the local rotations of two
/// motions on the same skeleton (`mocap_core::metrics`).
pub fn rotation_error_deg(a: &Motion, b: &Motion) -> f64 {
    metrics::mean_rotation_error_degrees(a, b).map_or(f64::NAN, |e| e as f64)
}

/// The joints of `motion`'s body parts with rotation channels (none when
/// its body parts are not found): the joints a model cleans on any rig.
pub fn body_part_joints(motion: &Motion) -> Vec<usize> {
    let skeleton = motion.skeleton();
    BodyMap::detect(skeleton).map_or_else(
        |_| Vec::new(),
        |map| {
            map.parts()
                .map(|(_, j)| j)
                .filter(|&j| skeleton.joint(j).has_rotation_channels())
                .collect()
        },
    )
}

/// The mean rotation error (degrees) of [`rotation_error_deg`] over every
/// joint with rotations, and over `joints` alone (NaN when it is empty).
pub fn rotation_errors_deg(a: &Motion, b: &Motion, joints: &[usize]) -> (f64, f64) {
    let Ok(per_joint) = metrics::joint_rotation_errors_degrees(a, b) else {
        return (f64::NAN, f64::NAN);
    };
    let mean = |js: &mut dyn Iterator<Item = usize>| {
        let (sum, count) = js.fold((0.0f64, 0usize), |(s, c), j| {
            (s + per_joint[j] as f64, c + 1)
        });
        if count == 0 {
            f64::NAN
        } else {
            sum / count as f64
        }
    };
    let skeleton = a.skeleton();
    let all = mean(
        &mut (0..skeleton.joint_count()).filter(|&j| skeleton.joint(j).has_rotation_channels()),
    );
    (all, mean(&mut joints.iter().copied()))
}

/// Mean per-joint position error and acceleration error (units per frame^2)
/// after forward kinematics (`mocap_core::metrics`); NaN for takes too short.
pub fn position_errors(a: &Motion, b: &Motion) -> (f64, f64) {
    let (pa, pb) = (forward_kinematics(a), forward_kinematics(b));
    let position =
        metrics::mean_joint_position_error(&pa, &pb, None).map_or(f64::NAN, |e| e as f64);
    let acceleration = metrics::acceleration_error(&pa, &pb, None).map_or(f64::NAN, |e| e as f64);
    (position, acceleration)
}
