//! `mocap convert`: motion files read, joined and edited in one order, as a
//! command line describes it.

use std::path::PathBuf;

use crate::error::{Error, Result};
use crate::io::{self, MotionSource};
use crate::motion::Motion;
use crate::ops::{self, FrameRange};
use crate::retarget::Retargeting;

/// The edits of a conversion; each runs when given, in the order of the
/// fields.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ConvertOptions {
    /// Keep these frames.
    pub frames: Option<FrameRange>,
    /// Resample to this many frames per second ([`ops::resample_fps`]).
    pub fps: Option<f64>,
    /// Mirror left and right ([`ops::mirror_auto`]).
    pub mirror: bool,
    /// Multiply every length by this factor ([`ops::scale`]).
    pub scale: Option<f32>,
    /// Play the motion on the rig of this BVH file ([`Retargeting`]).
    pub retarget_to: Option<PathBuf>,
}

/// Reads `inputs` (BVH takes of one skeleton, joined in order, or an ASF
/// skeleton followed by its AMC motions, as [`MotionSource::group`] pairs
/// them) and applies the edits of `options`.
pub fn convert_files(inputs: &[PathBuf], options: &ConvertOptions) -> Result<Motion> {
    let mut motions = io::read_motions(inputs)?.into_iter();
    let Some((first, mut motion)) = motions.next() else {
        return Err(Error::Invalid("no input motion given".into()));
    };
    let first = MotionSource::display_name(&first);
    for (source, next) in motions {
        let name = MotionSource::display_name(&source);
        motion
            .append(&next)
            .map_err(|e| Error::Invalid(format!("joining {name}: {e}")))?;
    }
    if let Some(range) = options.frames {
        motion = ops::trim(&motion, range.resolve(motion.frame_count()))?;
    }
    if let Some(fps) = options.fps {
        motion = ops::resample_fps(&motion, fps)?;
    }
    if options.mirror {
        motion = ops::mirror_auto(&motion)
            .map_err(|e| Error::Invalid(format!("mirroring {first}: {e}")))?;
    }
    if let Some(factor) = options.scale {
        if !(factor.is_finite() && factor > 0.0) {
            return Err(Error::Invalid(format!(
                "cannot scale by {factor}: the factor must be a positive number"
            )));
        }
        motion = ops::scale(&motion, factor);
    }
    if let Some(rig) = &options.retarget_to {
        let target = io::bvh::read_bvh(rig)?;
        motion = Retargeting::detect(motion.skeleton(), target.skeleton())
            .and_then(|r| r.apply(&motion))
            .map_err(|e| {
                Error::Invalid(format!(
                    "retargeting onto the rig of {}: {e}",
                    rig.display()
                ))
            })?;
    }
    Ok(motion)
}
