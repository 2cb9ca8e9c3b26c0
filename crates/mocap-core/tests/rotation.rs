//! Property tests of the rotation conversions: round trips for all Euler
//! orders, near gimbal lock and near 180 degrees.

use mocap_core::rotation::*;
use proptest::prelude::*;
use std::f32::consts::{FRAC_PI_2, PI};

/// Rotations are equal up to the sign of the quaternion.
fn assert_same_rotation(a: Quat, b: Quat, tolerance_rad: f32) {
    let angle = angle_between(a, b);
    assert!(angle < tolerance_rad, "{a:?} vs {b:?}: {angle} rad apart");
}

fn any_order() -> impl Strategy<Value = EulerOrder> {
    prop::sample::select(EulerOrder::ALL.to_vec())
}

fn any_angles() -> impl Strategy<Value = Vec3> {
    (-PI..PI, -FRAC_PI_2..FRAC_PI_2, -PI..PI).prop_map(|(a, b, c)| Vec3::new(a, b, c))
}

fn any_quat() -> impl Strategy<Value = Quat> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
        .prop_filter("non-zero", |(x, y, z, w)| {
            x * x + y * y + z * z + w * w > 1e-3
        })
        .prop_map(|(x, y, z, w)| Quat::from_xyzw(x, y, z, w).normalize())
}

#[test]
fn intrinsic_order_matches_channel_order() {
    // BVH "Zrotation Xrotation Yrotation" is the matrix Rz * Rx * Ry.
    let q = euler_to_quat(EulerOrder::ZXY, Vec3::new(FRAC_PI_2, FRAC_PI_2, 0.3));
    let expected = Quat::from_rotation_z(FRAC_PI_2)
        * Quat::from_rotation_x(FRAC_PI_2)
        * Quat::from_rotation_y(0.3);
    assert_same_rotation(q, expected, 1e-6);
    // By hand: Ry(0.3) takes X to (cos .3, 0, -sin .3), Rx(90) takes that
    // to (cos .3, sin .3, 0), Rz(90) to (-sin .3, cos .3, 0).
    let x = q * Vec3::X;
    assert!((x - Vec3::new(-(0.3f32.sin()), 0.3f32.cos(), 0.0)).length() < 1e-6);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn euler_round_trip(order in any_order(), angles in any_angles()) {
        let q = euler_to_quat(order, angles);
        let back = quat_to_euler(order, q);
        assert_same_rotation(euler_to_quat(order, back), q, 2e-4);
        // Away from gimbal lock the angles themselves come back.
        if angles.y.abs() < 1.5 {
            prop_assert!((back - angles).abs().max_element() < 1e-3, "{angles:?} -> {back:?}");
        }
    }

    #[test]
    fn euler_round_trip_near_gimbal_lock(
        order in any_order(),
        a in -PI..PI,
        c in -PI..PI,
        eps in -1e-3f32..1e-3,
        sign in prop::bool::ANY,
    ) {
        let b = if sign { FRAC_PI_2 - eps.abs() } else { -FRAC_PI_2 + eps.abs() };
        let q = euler_to_quat(order, Vec3::new(a, b, c));
        let back = quat_to_euler(order, q);
        assert_same_rotation(euler_to_quat(order, back), q, 2e-3);
    }

    #[test]
    fn euler_near_previous_is_continuous(order in any_order(), angles in any_angles(), step in any_angles()) {
        let next = angles + step * 0.01;
        let q = euler_to_quat(order, next);
        // Shift the previous frame by whole turns: the result must follow it.
        let previous = angles + Vec3::new(2.0 * PI, -2.0 * PI, 4.0 * PI);
        let e = quat_to_euler_near(order, q, previous);
        assert_same_rotation(euler_to_quat(order, e), q, 2e-4);
        prop_assert!((e - previous).abs().max_element() < 0.2, "{previous:?} -> {e:?}");
    }

    #[test]
    fn matrix_round_trip(q in any_quat()) {
        assert_same_rotation(mat3_to_quat(quat_to_mat3(q)), q, 1e-4);
    }

    #[test]
    fn expmap_round_trip(q in any_quat()) {
        let v = quat_to_expmap(q);
        prop_assert!(v.length() <= PI + 1e-5);
        assert_same_rotation(expmap_to_quat(v), q, 1e-4);
    }

    #[test]
    fn expmap_near_180_degrees(axis in any_quat(), eps in 0.0f32..1e-3) {
        let axis = (axis * Vec3::X).normalize();
        let q = Quat::from_axis_angle(axis, PI - eps);
        let v = quat_to_expmap(q);
        prop_assert!((v.length() - (PI - eps)).abs() < 1e-3);
        assert_same_rotation(expmap_to_quat(v), q, 1e-3);
    }

    #[test]
    fn expmap_small_angles(axis in any_quat(), angle in 0.0f32..1e-5) {
        let axis = (axis * Vec3::X).normalize();
        let v = quat_to_expmap(Quat::from_axis_angle(axis, angle));
        prop_assert!((v - axis * angle).length() < 1e-7);
    }

    #[test]
    fn rot6d_round_trip(q in any_quat()) {
        assert_same_rotation(rot6d_to_quat(quat_to_6d(q)), q, 1e-4);
    }

    #[test]
    fn slerp_ends_and_midpoint(a in any_quat(), b in any_quat()) {
        assert_same_rotation(slerp(a, b, 0.0), a, 1e-3);
        assert_same_rotation(slerp(a, b, 1.0), b, 1e-3);
        let m = slerp(a, b, 0.5);
        let (da, db) = (angle_between(a, m), angle_between(m, b));
        prop_assert!((da - db).abs() < 2e-3, "{da} vs {db}");
        prop_assert!(da <= PI / 2.0 + 1e-3, "took the long way");
    }
}

#[test]
fn unwrap_track_removes_turns() {
    let mut track = vec![170.0, 179.0, -178.0, -170.0, 175.0];
    unwrap_track(&mut track, AngleUnit::Degrees);
    assert_eq!(track, vec![170.0, 179.0, 182.0, 190.0, 175.0]);
}
