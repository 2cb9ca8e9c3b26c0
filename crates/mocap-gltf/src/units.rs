//! The take's length unit and up axis, read from the take itself: glTF
//! lengths are metres and its up axis is +Y, while a motion file's numbers
//! are in whatever unit its exporter used (Bandai: centimetres; CMU's BVH
//! conversions: the ASF unit) and no BVH says which.
//!
//! The rule: the **rest height** is the length of the bones from an ankle
//! up to the pelvis and from the pelvis up to the head joint (the body map
//! finds them; the longer leg), so the rest pose does not matter (Bandai's
//! lays every bone along X). A skeleton with no body found measures its
//! longest chain of bones from a root down. The take is in the one known
//! unit that puts that height between [`PLAUSIBLE_HEIGHT`] metres (a person
//! from about 1 to 2.3 m tall; the known units are far enough apart that at
//! most one fits). Where none fits, the unit is not known: lengths are
//! scaled to a height of [`NOMINAL_HEIGHT`], and the note says so.

use std::ops::RangeInclusive;

use mocap_core::bodymap::{BodyMap, BodyPart};
use mocap_core::kinematics::{forward_kinematics_range, GlobalPoses};
use mocap_core::metrics::up_axis;
use mocap_core::rotation::{Quat, Vec3};
use mocap_core::{Motion, Skeleton};

/// A length unit a take may be in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LengthUnit {
    /// Its name in notes, plural ("centimetres").
    pub name: &'static str,
    /// Its symbol after a number ("cm").
    pub symbol: &'static str,
    /// Metres in one unit.
    pub metres: f32,
}

/// The units the rule tells apart, far enough apart (a factor of 5.6 or
/// more) that at most one puts a person's height in [`PLAUSIBLE_HEIGHT`].
pub const KNOWN_UNITS: [LengthUnit; 4] = [
    LengthUnit {
        name: "metres",
        symbol: "m",
        metres: 1.0,
    },
    LengthUnit {
        name: "centimetres",
        symbol: "cm",
        metres: 0.01,
    },
    LengthUnit {
        name: "millimetres",
        symbol: "mm",
        metres: 0.001,
    },
    // CMU's ASF files say `:units length 0.45`: a unit is 1/0.45 inch. The
    // CMU BVH conversions of 3ds Max, MotionBuilder and Xia's keep it.
    LengthUnit {
        name: "CMU ASF units of 1/0.45 inch",
        symbol: "ASF units",
        metres: 0.0254 / 0.45,
    },
];

/// Rest heights (ankle to head joint, metres) of the people takes show.
pub const PLAUSIBLE_HEIGHT: RangeInclusive<f32> = 0.8..=2.0;

/// The rest height, in metres, a take of no known unit is scaled to: a
/// person about 1.6 m tall.
pub const NOMINAL_HEIGHT: f32 = 1.4;

/// What the rule reads from a skeleton.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TakeUnits {
    /// The unit found; `None` when no known unit puts the rest height in
    /// [`PLAUSIBLE_HEIGHT`].
    pub unit: Option<LengthUnit>,
    /// The rest height in the take's own units.
    pub rest_height: f32,
    /// Whether the rest height was measured on a body (ankle to head
    /// joint) rather than the longest chain of bones.
    pub measured_on_body: bool,
}

impl TakeUnits {
    /// Metres in one of the take's units: the factor that scales it to
    /// glTF's lengths.
    pub fn metres_per_unit(&self) -> f32 {
        match self.unit {
            Some(unit) => unit.metres,
            None if self.rest_height > 0.0 => NOMINAL_HEIGHT / self.rest_height,
            None => 1.0,
        }
    }

    /// What a converter tells the person: the factor and why.
    pub fn note(&self) -> String {
        let measure = if self.measured_on_body {
            "rest height"
        } else {
            "no body found; longest chain of bones"
        };
        let factor = self.metres_per_unit();
        match self.unit {
            Some(_) if factor == 1.0 => format!(
                "lengths kept: the take's units read as metres ({measure} {:.2} m)",
                self.rest_height
            ),
            Some(unit) => format!(
                "lengths scaled by {}: the take's units read as {} ({measure} {} {})",
                short(factor),
                unit.name,
                short(self.rest_height),
                unit.symbol
            ),
            None => format!(
                "lengths scaled by {}: the take's units are none of {} ({measure} {} \
                 units), so it was scaled to a rest height of {NOMINAL_HEIGHT} m",
                short(factor),
                KNOWN_UNITS.map(|u| u.symbol).join(", "),
                short(self.rest_height)
            ),
        }
    }
}

/// A number in a note: four significant digits, no trailing zeros.
fn short(x: f32) -> String {
    let digits = (3 - x.abs().log10().floor() as i32).clamp(0, 8) as usize;
    let text = format!("{x:.digits$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// The take's units by the rule of this module.
pub fn take_units(skeleton: &Skeleton) -> TakeUnits {
    let (rest_height, measured_on_body) = match body_height(skeleton) {
        Some(height) => (height, true),
        None => (longest_chain(skeleton), false),
    };
    let unit = KNOWN_UNITS
        .into_iter()
        .find(|u| PLAUSIBLE_HEIGHT.contains(&(rest_height * u.metres)));
    TakeUnits {
        unit,
        rest_height,
        measured_on_body,
    }
}

/// Ankle to pelvis (the longer leg) plus pelvis to head joint, along the
/// bones; `None` where the body map finds no such body.
fn body_height(skeleton: &Skeleton) -> Option<f32> {
    let map = BodyMap::detect(skeleton).ok()?;
    let pelvis = map.joint(BodyPart::Pelvis)?;
    let head = skeleton.chain_length(map.joint(BodyPart::Head)?, pelvis)?;
    let leg = [BodyPart::LeftAnkle, BodyPart::RightAnkle]
        .into_iter()
        .filter_map(|ankle| skeleton.chain_length(map.joint(ankle)?, pelvis))
        .fold(None, |longest: Option<f32>, l| {
            Some(longest.map_or(l, |m| m.max(l)))
        })?;
    Some(head + leg).filter(|h| *h > 0.0)
}

/// The longest chain of bones from a root down to a joint or an end site.
fn longest_chain(skeleton: &Skeleton) -> f32 {
    // Children come after their parents: one pass from the last joint up.
    let mut below = vec![0.0f32; skeleton.joint_count()];
    for j in (0..skeleton.joint_count()).rev() {
        let joint = skeleton.joint(j);
        let ends = joint.end_sites.iter().map(|e| e.length());
        let children = skeleton
            .children(j)
            .map(|c| below[c] + skeleton.joint(c).offset.length());
        below[j] = ends.chain(children).fold(0.0, f32::max);
    }
    (0..skeleton.joint_count())
        .filter(|&j| skeleton.joint(j).parent.is_none())
        .map(|j| below[j])
        .fold(0.0, f32::max)
}

/// Frames whose poses decide the up axis: enough to average over a take
/// and few enough that a long take costs nothing.
const UP_AXIS_FRAMES: usize = 256;

/// The rotation that turns the take so that its up axis is +Y, with the
/// axis it found, when the take is not Y-up already: its up axis is where
/// the head stands above the pelvis on average ([`up_axis`]). `None` for a
/// Y-up take and for a skeleton with no body found (taken as Y-up, the BVH
/// convention).
pub fn turn_to_y_up(motion: &Motion) -> Option<(Vec3, Quat)> {
    let skeleton = motion.skeleton();
    let map = BodyMap::detect(skeleton).ok()?;
    let (pelvis, head) = (map.joint(BodyPart::Pelvis)?, map.joint(BodyPart::Head)?);
    let frames = motion.frame_count();
    let step = frames.div_ceil(UP_AXIS_FRAMES).max(1);
    let mut poses = GlobalPoses {
        joint_count: skeleton.joint_count(),
        frame_count: 0,
        positions: Vec::new(),
        rotations: Vec::new(),
    };
    for f in (0..frames).step_by(step) {
        let pose = forward_kinematics_range(motion, f..f + 1);
        poses.positions.extend(pose.positions);
        poses.rotations.extend(pose.rotations);
        poses.frame_count += 1;
    }
    let up = up_axis(&poses, pelvis, head);
    (up != Vec3::Y).then(|| (up, Quat::from_rotation_arc(up, Vec3::Y)))
}

/// The name of an axis direction in notes ("+Z").
pub fn axis_name(axis: Vec3) -> String {
    let sign = if axis.max_element() > 0.0 { '+' } else { '-' };
    let name = if axis.x != 0.0 {
        'X'
    } else if axis.y != 0.0 {
        'Y'
    } else {
        'Z'
    };
    format!("{sign}{name}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_notes_keep_four_significant_digits() {
        assert_eq!(short(0.01), "0.01");
        assert_eq!(short(134.5678), "134.6");
        assert_eq!(short(0.05644444), "0.05644");
        assert_eq!(short(1.0), "1");
        assert_eq!(short(2000.0), "2000");
    }

    #[test]
    fn axis_names() {
        assert_eq!(axis_name(Vec3::Z), "+Z");
        assert_eq!(axis_name(-Vec3::X), "-X");
    }
}
