//! Foot contacts found from the motion, and the floor they stand on.
//!
//! A foot joint (ankle or toe) is on the ground while it is low and slow,
//! with hysteresis: it touches down when its height above its lowest
//! height in the take is under [`ContactOptions::enter_height`] *and* its
//! horizontal speed under [`ContactOptions::enter_speed`], and lifts off
//! only when it rises above [`ContactOptions::leave_height`] *or* moves
//! faster than [`ContactOptions::leave_speed`]. A foot is in contact while
//! either of its joints is (the heel strikes, the foot rolls onto the ball,
//! the heel lifts while the toe still pivots); contacts shorter than
//! [`ContactOptions::min_seconds`] are a foot brushing the ground and are
//! dropped. Lengths are fractions of the leg length and speeds leg lengths
//! per second, so the same settings hold for every rig and unit.
//!
//! The thresholds are generous (a planted foot of a real take stands
//! still, a swinging one moves at two to four times the body's speed), so
//! that a planted foot that slides, the fault the stage repairs, is still
//! found: the stance feet of a cleaned fused take drag at up to a leg a
//! second (80 cm/s on the Bandai rig) and stand 3-8% of the leg above
//! their lowest (docs/research/feet.md, "Contacts on fused takes").
//!
//! The floor: each kind of foot joint (ankles, toes) rests at one height on
//! the floor, the same for both feet; it is the [`FLOOR_QUANTILE`] of the
//! joint's heights over the frames it is on the ground, both feet pooled, so that a foot that sinks through the floor on one side
//! is seen against the other.

use std::ops::Range;

use serde::{Deserialize, Serialize};

use crate::ground::{quantile, JointTrack};

/// Settings of the contact detection (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ContactOptions {
    /// A joint touches down below this height above its lowest, in leg lengths.
    pub enter_height: f32,
    /// ... and lifts off above this one (more than `enter_height`).
    pub leave_height: f32,
    /// A joint touches down below this horizontal speed, leg lengths per second.
    pub enter_speed: f32,
    /// ... and lifts off above this one (more than `enter_speed`).
    pub leave_speed: f32,
    /// Contacts shorter than this (seconds) are dropped.
    pub min_seconds: f32,
}

impl Default for ContactOptions {
    fn default() -> Self {
        ContactOptions {
            enter_height: 0.05,
            leave_height: 0.08,
            enter_speed: 1.0,
            leave_speed: 1.4,
            min_seconds: 0.1,
        }
    }
}

/// Which quantile of a joint's heights while it is on the ground is its
/// height on the floor: low, as a rolling foot's joints rise before they
/// lift off while a planted one rests within a few millimetres of one
/// height, and above the very lowest, a stray frame.
pub const FLOOR_QUANTILE: f32 = 0.1;

/// The frames a joint is on the ground, with hysteresis (see the module
/// docs). `ground` is the joint's lowest height (its heights are measured
/// above it); thresholds in file units and units per second.
pub fn joint_contacts(
    track: &JointTrack,
    ground: f32,
    leg: f32,
    options: &ContactOptions,
) -> Vec<bool> {
    let mut on = false;
    track
        .height
        .iter()
        .zip(&track.speed)
        .map(|(&h, &v)| {
            let (h, v) = ((h - ground) / leg, v / leg);
            on = if on {
                h <= options.leave_height && v <= options.leave_speed
            } else {
                h < options.enter_height && v < options.enter_speed
            };
            on
        })
        .collect()
}

/// The stretches of frames where any of `joints` is on the ground, the
/// ones of fewer than `min_frames` frames dropped.
pub(crate) fn foot_contacts(
    joints: &[Vec<bool>],
    frames: usize,
    min_frames: usize,
) -> Vec<Range<usize>> {
    let on = |f: usize| joints.iter().any(|c| c[f]);
    let mut spans = Vec::new();
    let mut f = 0;
    while f < frames {
        if !on(f) {
            f += 1;
            continue;
        }
        let start = f;
        while f < frames && on(f) {
            f += 1;
        }
        if f - start >= min_frames.max(1) {
            spans.push(start..f);
        }
    }
    spans
}

/// A joint kind's height on the floor: the [`FLOOR_QUANTILE`] of the
/// heights of the joints (one per foot) over the frames they are on the
/// ground within a foot contact; `None` when none is.
pub fn resting_height(tracks: &[(&JointTrack, &[bool])]) -> Option<f32> {
    let heights: Vec<f32> = tracks
        .iter()
        .flat_map(|(t, on)| (0..t.height.len()).filter(|&f| on[f]).map(|f| t.height[f]))
        .collect();
    quantile(&heights, FLOOR_QUANTILE)
}
