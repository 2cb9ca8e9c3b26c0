//! The errors every part measures against a clean take: the mean rotation
//! error in degrees, and the position and acceleration errors after forward
//! kinematics (`mocap_core::metrics`).

use mocap_core::{forward_kinematics, metrics, Motion};

/// Mean geodesic angle (degrees) between the local rotations of two
/// motions on the same skeleton (`mocap_core::metrics`).
pub fn rotation_error_deg(a: &Motion, b: &Motion) -> f64 {
    metrics::mean_rotation_error_degrees(a, b).map_or(f64::NAN, |e| e as f64)
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
