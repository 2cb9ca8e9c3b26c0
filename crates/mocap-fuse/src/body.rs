//! The person's body, measured beforehand: bone lengths and joint ranges.
//!
//! Both enter the confidence of a sensor's joint ([`crate::confidence`]): a
//! bone that comes out much longer or shorter than this person's, or a joint
//! angle outside this person's range, means the sensor estimated the joint
//! badly.
//!
//! Measured from a short capture ([`BodyModel::measure`]: median bone length
//! and a percentile range of each angle over the frames where the joints
//! involved are Tracked), or from a ground-truth skeleton in motion
//! ([`BodyModel::from_positions`], used with a BVH mapped to the Kinect
//! layout).

use mocap_core::rotation::Vec3;
use serde::{Deserialize, Serialize};

use crate::kinect::{joint::*, TrackingState, JOINT_COUNT, PARENTS};
use crate::recording::JointObservation;

/// The range of a joint angle, in degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AngleRange {
    pub min: f32,
    pub max: f32,
}

/// How the angle at a joint is measured from joint positions: the angle
/// between a reference direction and a bone, optionally signed about an axis.
#[derive(Debug, Clone, Copy)]
pub struct AngleDefinition {
    /// The joint the angle is at (knee, elbow...), for names in reports.
    pub vertex: usize,
    /// Reference direction, from the first joint to the second.
    pub reference: (usize, usize),
    /// The bone whose direction is measured against the reference.
    pub bone: (usize, usize),
    /// Axis (from the first joint to the second) about which the angle is
    /// signed; `None` for an unsigned angle in `[0, 180]`.
    pub signed_about: Option<(usize, usize)>,
}

/// The joint angles with a range of motion. The factor of an angle applies to
/// the far end of its bone (`bone.1`): the knee angle is made by the shank, so
/// a knee bent forward discounts the ankle (and, through the chain, the foot).
///
/// The knees and hips are signed about the hip line (left hip to right hip):
/// flexion and hyperextension have opposite signs, so "a knee bent forward"
/// falls outside the measured range. The hip line comes from the same sensor's
/// skeleton, so a sensor that swapped left and right also flips these signs.
pub const ANGLES: [AngleDefinition; 12] = [
    AngleDefinition {
        vertex: KNEE_LEFT,
        reference: (HIP_LEFT, KNEE_LEFT),
        bone: (KNEE_LEFT, ANKLE_LEFT),
        signed_about: Some((HIP_LEFT, HIP_RIGHT)),
    },
    AngleDefinition {
        vertex: KNEE_RIGHT,
        reference: (HIP_RIGHT, KNEE_RIGHT),
        bone: (KNEE_RIGHT, ANKLE_RIGHT),
        signed_about: Some((HIP_LEFT, HIP_RIGHT)),
    },
    AngleDefinition {
        vertex: HIP_LEFT,
        reference: (SPINE_MID, SPINE_BASE),
        bone: (HIP_LEFT, KNEE_LEFT),
        signed_about: Some((HIP_LEFT, HIP_RIGHT)),
    },
    AngleDefinition {
        vertex: HIP_RIGHT,
        reference: (SPINE_MID, SPINE_BASE),
        bone: (HIP_RIGHT, KNEE_RIGHT),
        signed_about: Some((HIP_LEFT, HIP_RIGHT)),
    },
    AngleDefinition {
        vertex: ANKLE_LEFT,
        reference: (KNEE_LEFT, ANKLE_LEFT),
        bone: (ANKLE_LEFT, FOOT_LEFT),
        signed_about: None,
    },
    AngleDefinition {
        vertex: ANKLE_RIGHT,
        reference: (KNEE_RIGHT, ANKLE_RIGHT),
        bone: (ANKLE_RIGHT, FOOT_RIGHT),
        signed_about: None,
    },
    AngleDefinition {
        vertex: ELBOW_LEFT,
        reference: (SHOULDER_LEFT, ELBOW_LEFT),
        bone: (ELBOW_LEFT, WRIST_LEFT),
        signed_about: None,
    },
    AngleDefinition {
        vertex: ELBOW_RIGHT,
        reference: (SHOULDER_RIGHT, ELBOW_RIGHT),
        bone: (ELBOW_RIGHT, WRIST_RIGHT),
        signed_about: None,
    },
    AngleDefinition {
        vertex: SHOULDER_LEFT,
        reference: (SPINE_SHOULDER, SPINE_MID),
        bone: (SHOULDER_LEFT, ELBOW_LEFT),
        signed_about: None,
    },
    AngleDefinition {
        vertex: SHOULDER_RIGHT,
        reference: (SPINE_SHOULDER, SPINE_MID),
        bone: (SHOULDER_RIGHT, ELBOW_RIGHT),
        signed_about: None,
    },
    AngleDefinition {
        vertex: NECK,
        reference: (SPINE_MID, SPINE_SHOULDER),
        bone: (NECK, HEAD),
        signed_about: None,
    },
    AngleDefinition {
        vertex: SPINE_MID,
        reference: (SPINE_BASE, SPINE_MID),
        bone: (SPINE_MID, SPINE_SHOULDER),
        signed_about: None,
    },
];

/// The angle (degrees) of `def` in a pose, or `None` when a direction is
/// degenerate (two joints at the same place).
pub fn joint_angle(def: &AngleDefinition, positions: &[Vec3; JOINT_COUNT]) -> Option<f32> {
    let dir = |(a, b): (usize, usize)| (positions[b] - positions[a]).try_normalize();
    let u = dir(def.reference)?;
    let v = dir(def.bone)?;
    let cos = u.dot(v).clamp(-1.0, 1.0);
    match def.signed_about {
        None => Some(cos.acos().to_degrees()),
        Some(axis) => {
            let a = dir(axis)?;
            Some(u.cross(v).dot(a).atan2(cos).to_degrees())
        }
    }
}

/// The person's measurements.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BodyModel {
    /// Length in metres of the bone from each joint's parent to the joint
    /// (`None` for the root and for bones never measured).
    pub bone_lengths: [Option<f32>; JOINT_COUNT],
    /// Range of each angle of [`ANGLES`], in the same order.
    pub ranges: Vec<Option<AngleRange>>,
}

/// Options for [`BodyModel::measure`].
#[derive(Debug, Clone, Copy)]
pub struct MeasureOptions {
    /// Lower and upper percentile of an angle kept as its range.
    pub percentiles: (f32, f32),
    /// Degrees added on both sides of the percentile range: a capture of a
    /// few seconds does not reach the person's full range.
    pub margin_degrees: f32,
    /// Fewest Tracked frames for a measurement to be kept.
    pub min_frames: usize,
}

impl Default for MeasureOptions {
    fn default() -> Self {
        MeasureOptions {
            percentiles: (0.02, 0.98),
            margin_degrees: 10.0,
            min_frames: 10,
        }
    }
}

impl BodyModel {
    /// Measures from skeleton frames (any frame: bone lengths and these angles
    /// do not depend on where the sensor is). A bone counts in frames where
    /// both its joints are Tracked; an angle where all its joints are.
    pub fn measure<'a>(
        frames: impl IntoIterator<Item = &'a [JointObservation; JOINT_COUNT]>,
        options: MeasureOptions,
    ) -> BodyModel {
        let mut lengths: Vec<Vec<f32>> = vec![Vec::new(); JOINT_COUNT];
        let mut angles: Vec<Vec<f32>> = vec![Vec::new(); ANGLES.len()];
        for joints in frames {
            let tracked = |j: usize| joints[j].state == TrackingState::Tracked;
            let positions = joints.map(|j| j.position);
            for n in 0..JOINT_COUNT {
                if let Some(p) = PARENTS[n] {
                    if tracked(n) && tracked(p) {
                        lengths[n].push(positions[n].distance(positions[p]));
                    }
                }
            }
            for (a, def) in ANGLES.iter().enumerate() {
                let mut involved = vec![def.reference.0, def.reference.1, def.bone.0, def.bone.1];
                if let Some((x, y)) = def.signed_about {
                    involved.extend([x, y]);
                }
                if involved.into_iter().all(tracked) {
                    if let Some(angle) = joint_angle(def, &positions) {
                        angles[a].push(angle);
                    }
                }
            }
        }
        Self::from_samples(lengths, angles, options)
    }

    /// Measures from exact joint positions (a ground-truth skeleton).
    pub fn from_positions<'a>(
        poses: impl IntoIterator<Item = &'a [Vec3; JOINT_COUNT]>,
        options: MeasureOptions,
    ) -> BodyModel {
        let frames: Vec<[JointObservation; JOINT_COUNT]> = poses
            .into_iter()
            .map(|p| {
                p.map(|position| JointObservation {
                    position,
                    state: TrackingState::Tracked,
                })
            })
            .collect();
        Self::measure(frames.iter(), options)
    }

    fn from_samples(
        mut lengths: Vec<Vec<f32>>,
        mut angles: Vec<Vec<f32>>,
        options: MeasureOptions,
    ) -> BodyModel {
        let mut bone_lengths = [None; JOINT_COUNT];
        for (n, samples) in lengths.iter_mut().enumerate() {
            if samples.len() >= options.min_frames {
                bone_lengths[n] = Some(percentile(samples, 0.5));
            }
        }
        let ranges = angles
            .iter_mut()
            .map(|samples| {
                (samples.len() >= options.min_frames).then(|| AngleRange {
                    min: percentile(samples, options.percentiles.0) - options.margin_degrees,
                    max: percentile(samples, options.percentiles.1) + options.margin_degrees,
                })
            })
            .collect();
        BodyModel {
            bone_lengths,
            ranges,
        }
    }
}

impl BodyModel {
    /// Reads a body file (the JSON that [`BodyModel::write`] writes).
    pub fn read(path: &std::path::Path) -> mocap_core::Result<BodyModel> {
        let text = std::fs::read_to_string(path).map_err(|e| mocap_core::Error::io(path, e))?;
        let body: BodyModel = serde_json::from_str(&text).map_err(|e| {
            mocap_core::Error::Parse(mocap_core::ParseError {
                location: mocap_core::error::Location {
                    path: path.to_path_buf(),
                    line: e.line(),
                    column: e.column(),
                },
                message: format!(
                    "expected a body file (bone_lengths: 25 numbers or null, ranges: {} objects {{min, max}} or null): {e}",
                    ANGLES.len()
                ),
            })
        })?;
        if body.ranges.len() != ANGLES.len() {
            return Err(mocap_core::Error::Invalid(format!(
                "{}: expected {} joint ranges, found {}",
                path.display(),
                ANGLES.len(),
                body.ranges.len()
            )));
        }
        let bad_length = body
            .bone_lengths
            .iter()
            .flatten()
            .any(|l| !(l.is_finite() && *l > 0.0));
        let bad_range = body
            .ranges
            .iter()
            .flatten()
            .any(|r| !(r.min.is_finite() && r.max.is_finite() && r.min <= r.max));
        if bad_length || bad_range {
            return Err(mocap_core::Error::Invalid(format!(
                "{}: bone lengths must be positive and ranges must have min <= max",
                path.display()
            )));
        }
        Ok(body)
    }

    /// Writes the body as JSON, atomically.
    pub fn write(&self, path: &std::path::Path) -> mocap_core::Result<()> {
        let text = serde_json::to_string_pretty(self).expect("a body model always serializes");
        mocap_core::io::atomic::write_bytes_atomically(path, text.as_bytes())
    }
}

/// Joint ranges from a skeleton's range-of-motion limits (ASF `limits`, kept
/// by the ASF reader in [`mocap_core::Joint::limits`]), as an alternative to
/// measuring them.
///
/// The limits bound the Euler angles of one joint's rotation; our ranges
/// bound angles between bones measured from joint positions ([`ANGLES`]).
/// So each angle's range is found by sampling: the joint at the angle's
/// vertex (the knee for the knee angle...) is turned through a grid of 9
/// values per limited degree of freedom, the rest of the skeleton held in its
/// rest pose, and the angle measured on the Kinect joints of each sample
/// ([`crate::kinect::truth_from_motion`]); the range is the smallest and largest
/// angle seen. Angles whose vertex joint has no rotation limits stay `None`.
/// Only the vertex joint turns, so an angle that two joints make together
/// (clavicle and shoulder) gets the range of the one at the vertex.
pub fn ranges_from_limits(
    skeleton: &mocap_core::Skeleton,
) -> mocap_core::Result<Vec<Option<AngleRange>>> {
    use mocap_core::bodymap::{BodyMap, KINECT_V2_BODY_PARTS};
    use mocap_core::rotation::Quat;
    const STEPS: usize = 9;
    let map = BodyMap::detect(skeleton)?;
    let mut ranges = vec![None; ANGLES.len()];
    for (a, def) in ANGLES.iter().enumerate() {
        let Some(joint) = KINECT_V2_BODY_PARTS[def.vertex].and_then(|part| map.joint(part)) else {
            continue;
        };
        let Some(limits) = &skeleton.joint(joint).limits else {
            continue;
        };
        let dofs: Vec<_> = limits
            .dofs
            .iter()
            .filter(|d| d.channel.is_rotation())
            .collect();
        if dofs.is_empty() {
            continue;
        }
        let samples = STEPS.pow(dofs.len() as u32);
        let mut motion = mocap_core::Motion::rest(skeleton.clone(), 1.0 / 30.0, samples)?;
        for i in 0..samples {
            // Sample i's angle of each dof: digit k of i in base STEPS.
            let mut rest = i;
            let mut local = Quat::IDENTITY;
            for d in &dofs {
                let step = rest % STEPS;
                rest /= STEPS;
                let degrees = d.min + (d.max - d.min) * step as f32 / (STEPS - 1) as f32;
                // Intrinsic, in the order listed (as BVH channels).
                local *= d.channel.axis().rotation(degrees.to_radians());
            }
            let q = limits.axis_frame * local * limits.axis_frame.inverse();
            motion.set_local_rotation(i, joint, q);
        }
        let truth = crate::kinect::truth_from_motion(&motion, Some(1.0))?;
        let angles: Vec<f32> = truth
            .frames
            .iter()
            .filter_map(|p| joint_angle(def, p))
            .collect();
        if let (Some(min), Some(max)) = (
            angles.iter().copied().reduce(f32::min),
            angles.iter().copied().reduce(f32::max),
        ) {
            ranges[a] = Some(AngleRange { min, max });
        }
    }
    Ok(ranges)
}

/// Joint ranges from the limits of the ASF skeleton in the file `asf`
/// ([`ranges_from_limits`]).
pub fn ranges_from_asf(asf: &std::path::Path) -> mocap_core::Result<Vec<Option<AngleRange>>> {
    use mocap_core::io::asf_amc::{read_asf, LengthUnit};
    ranges_from_limits(&read_asf(asf)?.to_skeleton(LengthUnit::Centimetres)?)
}

/// `mocap fuse measure`: the person measured from recordings
/// ([`BodyModel::measure`]), with the joint ranges taken from the limits of
/// an ASF skeleton instead when `limits` is given ([`ranges_from_asf`]),
/// written to `output`; the recordings are read with the default
/// [`crate::ReadOptions`] ([`measure_recordings_with`]).
pub fn measure_recordings(
    recordings: &[std::path::PathBuf],
    limits: Option<&std::path::Path>,
    output: &std::path::Path,
) -> mocap_core::Result<BodyModel> {
    let reading = crate::recording::ReadOptions::default();
    Ok(measure_recordings_with(recordings, &reading, limits, output)?.0)
}

/// [`measure_recordings`], the recordings read as `reading` says
/// ([`crate::read_recordings_with`]); also returns how they were read.
pub fn measure_recordings_with(
    recordings: &[std::path::PathBuf],
    reading: &crate::recording::ReadOptions,
    limits: Option<&std::path::Path>,
    output: &std::path::Path,
) -> mocap_core::Result<(BodyModel, crate::recording::RecordingsReport)> {
    let read = crate::recording::read_recordings_with(recordings, reading)?;
    let frames = read.frames;
    let mut body = BodyModel::measure(frames.iter().map(|f| &f.joints), MeasureOptions::default());
    if let Some(asf) = limits {
        body.ranges = ranges_from_asf(asf)?;
    }
    body.write(output)?;
    Ok((body, read.report))
}

/// The `q`-quantile of `samples` (sorted in place; nearest rank).
pub fn percentile(samples: &mut [f32], q: f32) -> f32 {
    samples.sort_by(f32::total_cmp);
    let i = ((samples.len() - 1) as f32 * q).round() as usize;
    samples[i.min(samples.len() - 1)]
}

/// The median of `values` (the mean of the middle two for an even count),
/// sorting them; `None` for none.
pub(crate) fn median(values: &mut [f64]) -> Option<f64> {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(values[n / 2]),
        _ => Some(0.5 * (values[n / 2 - 1] + values[n / 2])),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A standing pose (metres), facing +z, y up; left is +x.
    pub(crate) fn standing_pose() -> [Vec3; JOINT_COUNT] {
        let mut p = [Vec3::ZERO; JOINT_COUNT];
        p[SPINE_BASE] = Vec3::new(0.0, 1.0, 0.0);
        p[SPINE_MID] = Vec3::new(0.0, 1.25, 0.0);
        p[SPINE_SHOULDER] = Vec3::new(0.0, 1.45, 0.0);
        p[NECK] = Vec3::new(0.0, 1.52, 0.0);
        p[HEAD] = Vec3::new(0.0, 1.65, 0.0);
        for (s, side) in [(1.0, 0usize), (-1.0, 1)] {
            let o = side * 4;
            p[SHOULDER_LEFT + o] = Vec3::new(0.18 * s, 1.42, 0.0);
            p[ELBOW_LEFT + o] = Vec3::new(0.2 * s, 1.14, 0.0);
            p[WRIST_LEFT + o] = Vec3::new(0.21 * s, 0.9, 0.02);
            p[HAND_LEFT + o] = Vec3::new(0.21 * s, 0.83, 0.03);
            let o = side * 4;
            p[HIP_LEFT + o] = Vec3::new(0.09 * s, 0.95, 0.0);
            p[KNEE_LEFT + o] = Vec3::new(0.1 * s, 0.53, 0.03);
            p[ANKLE_LEFT + o] = Vec3::new(0.1 * s, 0.1, -0.01);
            p[FOOT_LEFT + o] = Vec3::new(0.1 * s, 0.03, 0.12);
        }
        let o = [
            (HAND_TIP_LEFT, HAND_LEFT, 1.0),
            (HAND_TIP_RIGHT, HAND_RIGHT, -1.0),
        ];
        for (tip, hand, _) in o {
            p[tip] = p[hand] + Vec3::new(0.0, -0.08, 0.0);
        }
        p[THUMB_LEFT] = p[WRIST_LEFT] + Vec3::new(0.0, -0.05, 0.04);
        p[THUMB_RIGHT] = p[WRIST_RIGHT] + Vec3::new(0.0, -0.05, 0.04);
        p
    }

    #[test]
    fn asf_limits_give_knee_and_elbow_ranges_that_flex_one_way() {
        let root = std::env::var_os("MOCAP_SHARED_DATA")
            .map(std::path::PathBuf::from)
            .unwrap_or_else(|| {
                std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
            });
        let asf = root.join("hdm05-sample/HDM_bd.asf");
        if !asf.exists() {
            eprintln!("note: {} not found; skipping", asf.display());
            return;
        }
        let skeleton = mocap_core::io::asf_amc::read_asf(&asf)
            .unwrap()
            .to_skeleton(mocap_core::io::asf_amc::LengthUnit::Centimetres)
            .unwrap();
        let ranges = ranges_from_limits(&skeleton).unwrap();
        for (a, def) in ANGLES.iter().enumerate() {
            eprintln!(
                "{}: {:?}",
                crate::kinect::JOINT_NAMES[def.vertex],
                ranges[a]
            );
        }
        // HDM05's knees: rx in (-10, 170) about an axis across the leg; the
        // knee angle is signed, so the range reaches far one way (flexion)
        // and only a little the other (hyperextension): the measured sign
        // convention must match the one of a walking person.
        let knee = ranges[0].unwrap();
        let (small, large) = if knee.max.abs() > knee.min.abs() {
            (knee.min, knee.max)
        } else {
            (knee.max, knee.min)
        };
        assert!(large.abs() > 150.0 && small.abs() < 20.0, "{knee:?}");
        let other = ranges[1].unwrap();
        assert!((other.min - knee.min).abs() < 1.0 && (other.max - knee.max).abs() < 1.0);
        // Elbow (unsigned): straight to well bent.
        let elbow = ranges[6].unwrap();
        assert!(elbow.min < 15.0 && elbow.max > 120.0, "{elbow:?}");
        // A walking knee measured from positions flexes the same way.
        let walking = {
            let mut p = tests::standing_pose();
            let shank = p[ANKLE_LEFT].distance(p[KNEE_LEFT]);
            p[ANKLE_LEFT] = p[KNEE_LEFT] + Vec3::new(0.0, -0.8, -0.6).normalize() * shank;
            joint_angle(&ANGLES[0], &p).unwrap()
        };
        assert_eq!(walking.signum(), large.signum(), "{walking} vs {knee:?}");
    }

    #[test]
    fn knee_angle_changes_sign_when_the_knee_bends_forward() {
        let mut p = standing_pose();
        let knee = joint_angle(&ANGLES[0], &p).unwrap();
        // Bend the left shank backwards (ankle behind, -z): flexion.
        p[ANKLE_LEFT] = p[KNEE_LEFT] + Vec3::new(0.0, -0.3, -0.3);
        let flexed = joint_angle(&ANGLES[0], &p).unwrap();
        // And forwards (ankle in front, +z): the knee bent the wrong way.
        p[ANKLE_LEFT] = p[KNEE_LEFT] + Vec3::new(0.0, -0.3, 0.3);
        let forward = joint_angle(&ANGLES[0], &p).unwrap();
        assert!(
            flexed.signum() != forward.signum(),
            "{knee} {flexed} {forward}"
        );
        assert!(flexed.abs() > 40.0 && forward.abs() > 40.0);
    }

    #[test]
    fn measure_takes_the_median_of_tracked_bones() {
        let pose = standing_pose();
        let mut frames = Vec::new();
        for i in 0..21 {
            let mut f = pose.map(|position| JointObservation {
                position,
                state: TrackingState::Tracked,
            });
            // A third of the frames have a wrong elbow, Inferred: not counted.
            if i % 3 == 0 {
                f[ELBOW_LEFT].position += Vec3::new(0.0, 0.0, 0.5);
                f[ELBOW_LEFT].state = TrackingState::Inferred;
            }
            // One Tracked outlier does not move the median.
            if i == 1 {
                f[KNEE_LEFT].position += Vec3::new(0.0, -0.2, 0.0);
            }
            frames.push(f);
        }
        let body = BodyModel::measure(frames.iter(), MeasureOptions::default());
        let expected = pose[ELBOW_LEFT].distance(pose[SHOULDER_LEFT]);
        assert!((body.bone_lengths[ELBOW_LEFT].unwrap() - expected).abs() < 1e-6);
        let thigh = pose[KNEE_LEFT].distance(pose[HIP_LEFT]);
        assert!((body.bone_lengths[KNEE_LEFT].unwrap() - thigh).abs() < 1e-6);
        assert!(body.bone_lengths[SPINE_BASE].is_none());
        let knee = body.ranges[0].unwrap();
        assert!(knee.max - knee.min >= 20.0, "the margin widens the range");
    }
}
