//! The take that goes from stage to stage, and its error against the
//! ground truth.
//!
//! The fuse stage ends with the fused capture on the sample's own rig, in
//! the sample's world; each later stage reads the latest take of the chain
//! and passes its own output on. A stage that cannot run leaves the take
//! as it was, so the next stage still has one.
//!
//! The truth is the sample itself: the chain's frame `i` is the instant
//! `first_time + i / fps`, compared with the sample resampled to `fps`.

use std::path::PathBuf;

use mocap_core::metrics::{jitter, mean_rotation_error_degrees};
use mocap_core::ops::{resample_fps, trim};
use mocap_core::{forward_kinematics, Error, Motion, Result};

use crate::units_per_metre;

/// The latest take of the chain.
#[derive(Debug, Clone)]
pub(crate) struct ChainTake {
    /// The file, a BVH on the sample's rig.
    pub path: PathBuf,
    /// The stage that wrote it.
    pub stage: &'static str,
    /// The sample's time (seconds) of the take's first frame.
    pub first_time: f64,
}

/// `take` and the truth at the same instants, cut to the frames both have.
pub(crate) fn aligned_with_truth(
    take: &Motion,
    sample: &Motion,
    first_time: f64,
) -> Result<(Motion, Motion)> {
    if take.skeleton().joint_count() != sample.skeleton().joint_count() {
        return Err(Error::Invalid(format!(
            "the take has {} joints and the sample {}: not on the sample's rig",
            take.skeleton().joint_count(),
            sample.skeleton().joint_count()
        )));
    }
    let truth = if (take.fps() - sample.fps()).abs() > 1e-6 {
        resample_fps(sample, take.fps())?
    } else {
        sample.clone()
    };
    let offset = (first_time * take.fps()).round().max(0.0) as usize;
    let frames = take
        .frame_count()
        .min(truth.frame_count().saturating_sub(offset));
    if frames < 3 {
        return Err(Error::Invalid(format!(
            "the take and the sample share {frames} frames; at least 3 are needed to compare them"
        )));
    }
    Ok((
        trim(take, 0..frames)?,
        trim(&truth, offset..offset + frames)?,
    ))
}

/// A take's errors against the truth, in millimetres and degrees.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TruthErrors {
    /// Mean per-joint position error.
    pub position_mm: f64,
    /// Mean geodesic angle between the local joint rotations.
    pub rotation_deg: f64,
    /// Mean jerk of all joints (mm per frame³), the take's own.
    pub jitter: f64,
    /// The same of the truth, for scale.
    pub truth_jitter: f64,
}

/// The errors of `take` against the truth (see [`aligned_with_truth`]).
pub(crate) fn errors_against_truth(
    take: &Motion,
    sample: &Motion,
    first_time: f64,
) -> Result<TruthErrors> {
    let (take, truth) = aligned_with_truth(take, sample, first_time)?;
    let mm = 1000.0 / units_per_metre(sample) as f64;
    let (a, b) = (forward_kinematics(&take), forward_kinematics(&truth));
    let position = mocap_core::metrics::mean_joint_position_error(&a, &b, None)?;
    Ok(TruthErrors {
        position_mm: position as f64 * mm,
        rotation_deg: mean_rotation_error_degrees(&take, &truth)? as f64,
        jitter: jitter(&a, None)? as f64 * mm,
        truth_jitter: jitter(&b, None)? as f64 * mm,
    })
}
