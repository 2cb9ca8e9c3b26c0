//! The contacts of a whole take and the floor they stand on, and the
//! numbers that judge its feet: planted-foot sliding, feet below the
//! floor, jitter ([`mocap_core::metrics`]).

use std::ops::Range;

use mocap_core::bodymap::BodyMap;
use mocap_core::metrics::{depth_below_floor, jitter, planted_foot_sliding, FloorDepth};
use mocap_core::rotation::Vec3;
use mocap_core::{forward_kinematics, Error, GlobalPoses, Motion, Result};
use serde::{Deserialize, Serialize};

use crate::contacts::{foot_contacts, joint_contacts, resting_height, ContactOptions};
use crate::ground::{quantile, track, up, FeetRig, JointTrack};

/// The fewest frames the feet stage works on: speeds need a frame on each
/// side, jitter four.
pub const MIN_FRAMES: usize = 4;

/// A foot joint below its floor height by more than this fraction of the
/// leg length counts as below the floor (a real take's feet rest within a
/// few millimetres of one height).
pub const BELOW_FLOOR_TOLERANCE: f32 = 0.005;

/// Where a take's floor is: the up axis, and the height along it at which
/// each foot joint rests on the floor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Floor {
    /// The world's up axis (pelvis to head).
    pub up: [f32; 3],
    /// The height along `up` the lowest resting foot joints (the toes, on
    /// most rigs) stand at: the floor as the joints see it (a joint's centre
    /// is above the sole).
    pub height: f32,
    /// Whether `height` was estimated from the take's contacts (else given).
    pub estimated: bool,
    /// Per foot joint (skeleton index), the height it rests at.
    pub joints: Vec<(usize, f32)>,
}

impl Floor {
    pub fn up(&self) -> Vec3 {
        Vec3::from_array(self.up)
    }

    /// The height `joint` rests at on the floor (the floor's own for a
    /// joint that is no foot joint).
    pub fn joint_height(&self, joint: usize) -> f32 {
        self.joints
            .iter()
            .find(|&&(j, _)| j == joint)
            .map_or(self.height, |&(_, h)| h)
    }
}

/// A take's feet as the stage finds them: the legs, the up axis, each foot
/// joint's track and contacts, each foot's contacts and the floor.
pub(crate) struct TakeFeet {
    pub rig: FeetRig,
    pub poses: GlobalPoses,
    pub up: Vec3,
    pub fps: f32,
    /// Per foot, per foot joint: on the ground, within the foot's contacts.
    pub joint_on: [Vec<Vec<bool>>; 2],
    /// Per foot, its contacts.
    pub spans: [Vec<Range<usize>>; 2],
    pub floor: Floor,
}

impl TakeFeet {
    pub fn find(
        motion: &Motion,
        map: &BodyMap,
        options: &ContactOptions,
        floor: Option<f32>,
    ) -> Result<TakeFeet> {
        let rig = FeetRig::new(motion, map)?;
        let min_frames = ((options.min_seconds * motion.fps() as f32).round() as usize).max(2);
        let needed = MIN_FRAMES.max(min_frames);
        if motion.frame_count() < needed {
            return Err(Error::Invalid(format!(
                "the feet stage needs at least {needed} frames (contacts of {} frames or \
                 more, speeds from a frame on each side); this take has {}",
                min_frames,
                motion.frame_count()
            )));
        }
        let poses = forward_kinematics(motion);
        let up = up(&poses, &rig);
        let fps = motion.fps() as f32;
        let leg = rig.leg_length.max(1e-6);
        let n = poses.frame_count;
        let tracks: [Vec<JointTrack>; 2] = rig
            .foot_joints()
            .map(|foot| foot.iter().map(|&j| track(&poses, j, up, fps)).collect());
        let mut joint_on: [Vec<Vec<bool>>; 2] = [Vec::new(), Vec::new()];
        let mut spans: [Vec<Range<usize>>; 2] = [Vec::new(), Vec::new()];
        for side in 0..2 {
            let on: Vec<Vec<bool>> = tracks[side]
                .iter()
                .map(|t: &JointTrack| {
                    let ground = quantile(&t.height, 0.02).unwrap_or(0.0);
                    joint_contacts(t, ground, leg, options)
                })
                .collect();
            spans[side] = foot_contacts(&on, n, min_frames);
            let mut within = vec![false; n];
            for s in &spans[side] {
                within[s.clone()].fill(true);
            }
            joint_on[side] = on
                .into_iter()
                .map(|c| c.iter().zip(&within).map(|(&a, &b)| a && b).collect())
                .collect();
        }
        // The floor: per joint kind (ankle, toe), its resting height.
        let kinds = rig.legs[0].foot.len().max(rig.legs[1].foot.len());
        let mut rest = Vec::with_capacity(kinds);
        for k in 0..kinds {
            let pairs: Vec<(&JointTrack, &[bool])> = (0..2)
                .filter(|&s| k < tracks[s].len())
                .map(|s| (&tracks[s][k], joint_on[s][k].as_slice()))
                .collect();
            let fallback = || {
                let all: Vec<f32> = pairs.iter().flat_map(|(t, _)| t.height.clone()).collect();
                quantile(&all, 0.02).unwrap_or(0.0)
            };
            rest.push(resting_height(&pairs).unwrap_or_else(fallback));
        }
        let lowest = rest.iter().copied().fold(f32::INFINITY, f32::min);
        let shift = floor.map_or(0.0, |given| given - lowest);
        let mut joints = Vec::new();
        for leg in &rig.legs {
            for (k, &j) in leg.foot.iter().enumerate() {
                joints.push((j, rest[k] + shift));
            }
        }
        let floor = Floor {
            up: up.to_array(),
            height: floor.unwrap_or(lowest),
            estimated: floor.is_none(),
            joints,
        };
        Ok(TakeFeet {
            rig,
            poses,
            up,
            fps,
            joint_on,
            spans,
            floor,
        })
    }
}

/// What judges a take's feet, in file units.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct FeetMeasures {
    /// Planted-foot sliding, units per second
    /// ([`mocap_core::metrics::planted_foot_sliding`]).
    pub sliding: f64,
    /// Feet below the floor ([`mocap_core::metrics::depth_below_floor`],
    /// tolerance [`BELOW_FLOOR_TOLERANCE`]).
    pub below_floor: FloorDepth,
    /// Mean jerk of all joints, units per frame³
    /// ([`mocap_core::metrics::jitter`]).
    pub jitter: f32,
    /// Rest leg length (file units): sliding / leg_length is in leg lengths
    /// per second, comparable across rigs.
    pub leg_length: f32,
}

/// The measures of `poses` against `floor`.
pub(crate) fn measure_poses(
    poses: &GlobalPoses,
    rig: &FeetRig,
    floor: &Floor,
    fps: f32,
) -> Result<FeetMeasures> {
    let up = floor.up();
    let feet = rig.foot_joints();
    let leg = rig.leg_length;
    Ok(FeetMeasures {
        sliding: planted_foot_sliding(poses, feet, up, leg, fps),
        below_floor: depth_below_floor(
            poses,
            feet,
            up,
            &|j| floor.joint_height(j),
            BELOW_FLOOR_TOLERANCE * leg,
        ),
        jitter: jitter(poses, None)?,
        leg_length: leg,
    })
}

/// The floor of `motion` (estimated from its contacts, or at height
/// `floor` along up with the joints' resting heights above it estimated).
pub fn estimate_floor(
    motion: &Motion,
    map: &BodyMap,
    options: &ContactOptions,
    floor: Option<f32>,
) -> Result<Floor> {
    Ok(TakeFeet::find(motion, map, options, floor)?.floor)
}

/// The feet measures of `motion` against `floor` (of this take, or of the
/// take it was made from: compare a stage's input and output on one floor).
pub fn measure_feet(motion: &Motion, map: &BodyMap, floor: &Floor) -> Result<FeetMeasures> {
    let rig = FeetRig::new(motion, map)?;
    if motion.frame_count() < MIN_FRAMES {
        return Err(Error::Invalid(format!(
            "measuring the feet needs at least {MIN_FRAMES} frames; this take has {}",
            motion.frame_count()
        )));
    }
    measure_poses(
        &forward_kinematics(motion),
        &rig,
        floor,
        motion.fps() as f32,
    )
}
