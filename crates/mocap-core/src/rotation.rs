//! Rotations: Euler angles (all six orders), quaternions, matrices,
//! exponential maps and the continuous 6D representation.
//!
//! This is the one place where rotation conversions live; every other crate
//! calls these functions. Quaternion and matrix arithmetic come from `glam`
//! (single precision, which is what BVH files store); what is written here is
//! the motion-capture conventions on top of it.
//!
//! Conventions:
//! - Euler angles are **intrinsic**: [`EulerOrder::ZXY`] with angles `(a, b, c)`
//!   means rotate by `a` about Z, then by `b` about the *new* X, then by `c`
//!   about the newest Y, i.e. `q = Rz(a) * Rx(b) * Ry(c)`. This is how BVH
//!   channel lists are read: `Zrotation Xrotation Yrotation` is `ZXY`.
//! - Angles in this module are radians; [`AngleUnit`] converts file values.
//! - The exponential map is the rotation vector `axis * angle` with the angle
//!   in `[0, pi]`; it equals `2 * log(q)` for the unit quaternion `q` with
//!   `w >= 0`.
//! - The 6D representation (Zhou et al., "On the Continuity of Rotation
//!   Representations in Neural Networks", CVPR 2019) is the first two columns
//!   of the rotation matrix, `[m00, m10, m20, m01, m11, m21]`.

use std::f32::consts::{PI, TAU};

pub use glam::{Mat3, Quat, Vec3};

/// A coordinate axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Axis {
    X,
    Y,
    Z,
}

impl Axis {
    /// The unit vector along this axis.
    pub fn unit(self) -> Vec3 {
        match self {
            Axis::X => Vec3::X,
            Axis::Y => Vec3::Y,
            Axis::Z => Vec3::Z,
        }
    }

    /// Rotation by `angle` radians about this axis.
    pub fn rotation(self, angle: f32) -> Quat {
        let (s, c) = (0.5 * angle).sin_cos();
        match self {
            Axis::X => Quat::from_xyzw(s, 0.0, 0.0, c),
            Axis::Y => Quat::from_xyzw(0.0, s, 0.0, c),
            Axis::Z => Quat::from_xyzw(0.0, 0.0, s, c),
        }
    }

    fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }
}

/// Order of three intrinsic rotations about distinct axes (Tait-Bryan angles).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum EulerOrder {
    XYZ,
    XZY,
    YXZ,
    YZX,
    ZXY,
    ZYX,
}

impl EulerOrder {
    pub const ALL: [EulerOrder; 6] = [
        EulerOrder::XYZ,
        EulerOrder::XZY,
        EulerOrder::YXZ,
        EulerOrder::YZX,
        EulerOrder::ZXY,
        EulerOrder::ZYX,
    ];

    /// The axes in the order the rotations are applied.
    pub fn axes(self) -> [Axis; 3] {
        use Axis::*;
        match self {
            EulerOrder::XYZ => [X, Y, Z],
            EulerOrder::XZY => [X, Z, Y],
            EulerOrder::YXZ => [Y, X, Z],
            EulerOrder::YZX => [Y, Z, X],
            EulerOrder::ZXY => [Z, X, Y],
            EulerOrder::ZYX => [Z, Y, X],
        }
    }

    /// The order made of three distinct axes, or `None` if an axis repeats.
    pub fn from_axes(axes: [Axis; 3]) -> Option<EulerOrder> {
        EulerOrder::ALL.into_iter().find(|o| o.axes() == axes)
    }
}

/// Unit of angles in a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum AngleUnit {
    Degrees,
    Radians,
}

impl AngleUnit {
    /// Factor that turns a value in this unit into radians.
    pub fn to_radians_factor(self) -> f32 {
        match self {
            AngleUnit::Degrees => PI / 180.0,
            AngleUnit::Radians => 1.0,
        }
    }
}

/// Quaternion of intrinsic Euler angles `angles` (radians, in the order's
/// sequence): `q = R_a0(angles.x) * R_a1(angles.y) * R_a2(angles.z)`.
pub fn euler_to_quat(order: EulerOrder, angles: Vec3) -> Quat {
    let [a0, a1, a2] = order.axes();
    a0.rotation(angles.x) * a1.rotation(angles.y) * a2.rotation(angles.z)
}

/// Intrinsic Euler angles (radians) of `q` in `order`. The middle angle is in
/// `[-pi/2, pi/2]`, the others in `(-pi, pi]`. At gimbal lock (middle angle
/// `+-pi/2`) the first and last angles are not unique; the last is set to 0.
pub fn quat_to_euler(order: EulerOrder, q: Quat) -> Vec3 {
    // Read the angles off the rotation matrix R = R_i(a) R_j(b) R_k(c), with
    // (i, j, k) the axes of the order. For a cyclic order (XYZ, YZX, ZXY)
    // sign = +1, otherwise -1. Then R[i][k] = sign * sin(b), and
    // atan2 of the neighbouring entries gives a and c. Using atan2 on the
    // cosine side (rather than asin) keeps full precision near gimbal lock.
    // Decompose in double precision: near gimbal lock the entries used by
    // atan2 are of the size of cos(b) and single precision would lose them.
    let q = glam::DQuat::from_xyzw(q.x as f64, q.y as f64, q.z as f64, q.w as f64).normalize();
    let m = glam::DMat3::from_quat(q);
    let [ai, aj, ak] = order.axes();
    let (i, j, k) = (ai.index(), aj.index(), ak.index());
    let sign = if (j + 3 - i) % 3 == 1 { 1.0 } else { -1.0 };
    // glam matrices are column-major: m.col(c)[r] is row r, column c.
    let r = |row: usize, col: usize| m.col(col)[row];
    let sin_b = sign * r(i, k);
    let cos_b = (r(i, i) * r(i, i) + r(i, j) * r(i, j)).sqrt();
    let b = sin_b.atan2(cos_b);
    let (a, c) = if cos_b > 1e-12 {
        (
            (-sign * r(j, k)).atan2(r(k, k)),
            (-sign * r(i, j)).atan2(r(i, i)),
        )
    } else {
        // Gimbal lock: only a +- c is determined; put it all in a.
        ((sign * r(k, j)).atan2(r(j, j)), 0.0)
    };
    Vec3::new(a as f32, b as f32, c as f32)
}

/// Like [`quat_to_euler`], but of the equivalent angle triples picks the one
/// nearest to `previous` (also unwrapping each angle by whole turns), so that
/// Euler tracks written frame after frame stay continuous.
pub fn quat_to_euler_near(order: EulerOrder, q: Quat, previous: Vec3) -> Vec3 {
    let first = quat_to_euler(order, q);
    // For Tait-Bryan angles, (a, b, c) and (a + pi, pi - b, c + pi) are the
    // same rotation.
    let second = Vec3::new(first.x + PI, PI - first.y, first.z + PI);
    let near = |e: Vec3| {
        Vec3::new(
            unwrap_angle(e.x, previous.x),
            unwrap_angle(e.y, previous.y),
            unwrap_angle(e.z, previous.z),
        )
    };
    let (a, b) = (near(first), near(second));
    if (a - previous).length_squared() <= (b - previous).length_squared() {
        a
    } else {
        b
    }
}

/// `angle` plus the whole number of turns that brings it nearest `reference`.
pub fn unwrap_angle(angle: f32, reference: f32) -> f32 {
    angle - ((angle - reference) / TAU).round() * TAU
}

/// Unwraps an Euler angle track in place: adds whole turns so that no two
/// neighbouring frames differ by more than half a turn. `turn` is 360 for
/// degrees and `2 pi` for radians.
pub fn unwrap_track(track: &mut [f32], unit: AngleUnit) {
    let turn = match unit {
        AngleUnit::Degrees => 360.0,
        AngleUnit::Radians => TAU,
    };
    for i in 1..track.len() {
        let previous = track[i - 1];
        track[i] -= ((track[i] - previous) / turn).round() * turn;
    }
}

/// Rotation matrix of a quaternion.
pub fn quat_to_mat3(q: Quat) -> Mat3 {
    Mat3::from_quat(q)
}

/// Quaternion of a rotation matrix (assumed orthonormal).
pub fn mat3_to_quat(m: Mat3) -> Quat {
    Quat::from_mat3(&m)
}

/// Exponential map (rotation vector `axis * angle`, angle in `[0, pi]`).
pub fn quat_to_expmap(q: Quat) -> Vec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let v = q.xyz();
    let s = v.length();
    if s < 1e-7 {
        // 2 * atan2(s, w) / s -> 2 / w as s -> 0.
        v * (2.0 / q.w)
    } else {
        v * (2.0 * s.atan2(q.w) / s)
    }
}

/// Quaternion of an exponential map (rotation vector).
pub fn expmap_to_quat(v: Vec3) -> Quat {
    let angle = v.length();
    if angle < 1e-7 {
        // sin(angle / 2) / angle -> 1/2.
        Quat::from_xyzw(0.5 * v.x, 0.5 * v.y, 0.5 * v.z, 1.0).normalize()
    } else {
        let (s, c) = (0.5 * angle).sin_cos();
        let a = v * (s / angle);
        Quat::from_xyzw(a.x, a.y, a.z, c)
    }
}

/// 6D representation: the first two columns of the rotation matrix.
pub fn quat_to_6d(q: Quat) -> [f32; 6] {
    let m = Mat3::from_quat(q);
    [
        m.x_axis.x, m.x_axis.y, m.x_axis.z, m.y_axis.x, m.y_axis.y, m.y_axis.z,
    ]
}

/// Quaternion of a (not necessarily orthonormal) 6D representation, by
/// Gram-Schmidt on the two columns ([`frame_from_axes`]). A degenerate input
/// gives the identity.
pub fn rot6d_to_quat(r: [f32; 6]) -> Quat {
    frame_from_axes(Vec3::new(r[0], r[1], r[2]), Vec3::new(r[3], r[4], r[5]))
}

/// The rotation whose x axis points along `x` and whose y axis is `y` made
/// perpendicular to it (Gram-Schmidt; z is their cross product): the frame
/// of a bone along `x` with its twist fixed by `y`. The identity when `x` is
/// zero or `y` is along it.
pub fn frame_from_axes(x: Vec3, y: Vec3) -> Quat {
    let b1 = x.normalize_or_zero();
    let b2 = (y - b1 * b1.dot(y)).normalize_or_zero();
    if b1 == Vec3::ZERO || b2 == Vec3::ZERO {
        return Quat::IDENTITY;
    }
    Quat::from_mat3(&Mat3::from_cols(b1, b2, b1.cross(b2))).normalize()
}

/// The mean of unit quaternions that lie close together (each sign-aligned
/// to the first, summed, normalised): good for the rotations of a joint over
/// a few frames or a steady take, not for rotations far apart.
pub fn mean_of_close(rotations: impl IntoIterator<Item = Quat>) -> Quat {
    let mut sum = Quat::from_xyzw(0.0, 0.0, 0.0, 0.0);
    let mut first: Option<Quat> = None;
    for q in rotations {
        let reference = *first.get_or_insert(q);
        sum += if q.dot(reference) < 0.0 { -q } else { q };
    }
    sum.normalize()
}

/// Spherical linear interpolation along the shorter arc.
pub fn slerp(a: Quat, b: Quat, t: f32) -> Quat {
    let b = if a.dot(b) < 0.0 { -b } else { b };
    a.slerp(b, t)
}

/// Angle in radians of the rotation taking `a` to `b` (geodesic distance on
/// SO(3)), in `[0, pi]`.
pub fn angle_between(a: Quat, b: Quat) -> f32 {
    let d = (a.conjugate() * b).normalize();
    let s = d.xyz().length();
    2.0 * s.atan2(d.w.abs())
}
