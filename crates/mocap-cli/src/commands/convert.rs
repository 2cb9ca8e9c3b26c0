use std::path::PathBuf;

use anyhow::{anyhow, bail, Context};
use mocap_core::io::{self, MotionSource};
use mocap_core::ops;
use mocap_core::retarget::Retargeting;

use super::GlobalOptions;

#[derive(clap::Args)]
#[command(
    after_help = "Steps run in this order: join inputs, --frames, --fps, --mirror, --scale, --retarget-to.\n\
Examples:\n  mocap convert walk.bvh --fps 30 walk30.bvh\n  mocap convert HDM_bd.asf HDM_bd_walk.amc walk.bvh\n  mocap convert take.bvh --frames 100..400 --mirror clip.bvh\n  mocap convert cmu_walk.bvh --retarget-to mixamo_character.bvh walk_on_mixamo.bvh"
)]
pub struct Args {
    /// Inputs then the output: `IN.bvh OUT.bvh`, `X.asf X.amc OUT.bvh`, or several
    /// BVH takes of one skeleton (joined in order) then OUT.bvh.
    #[arg(required = true, num_args = 1.., action = clap::ArgAction::Append)]
    paths: Vec<PathBuf>,
    /// Resample to this many frames per second (slerp on rotations).
    #[arg(long)]
    fps: Option<f64>,
    /// Mirror left and right.
    #[arg(long)]
    mirror: bool,
    /// Multiply every length (offsets, positions) by this factor, e.g. 0.01 for cm -> m.
    #[arg(long)]
    scale: Option<f32>,
    /// Keep frames A..B (0-based, B excluded; `A..` to the end).
    #[arg(long, value_name = "A..B")]
    frames: Option<String>,
    /// Play the motion on the rig of this BVH file: body parts matched by joint name, bone
    /// directions kept, strides scaled by the legs' lengths. The first frames of the input and
    /// of this file are the two rigs' reference poses (best both standing or both T-poses).
    #[arg(long, value_name = "RIG.bvh")]
    retarget_to: Option<PathBuf>,
}

/// Parses `A..B` or `A..` into a frame range for a take of `len` frames.
fn parse_frame_range(text: &str, len: usize) -> anyhow::Result<std::ops::Range<usize>> {
    let (a, b) = text
        .split_once("..")
        .ok_or_else(|| anyhow!("--frames {text:?}: expected A..B, e.g. 100..400"))?;
    let start: usize = a
        .trim()
        .parse()
        .with_context(|| format!("--frames {text:?}: {a:?} is not a frame number"))?;
    let end: usize = if b.trim().is_empty() {
        len
    } else {
        b.trim()
            .parse()
            .with_context(|| format!("--frames {text:?}: {b:?} is not a frame number"))?
    };
    Ok(start..end)
}

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    let (output, inputs) = match args.paths.split_last() {
        Some((output, inputs)) if !inputs.is_empty() => (output, inputs),
        _ => bail!("`mocap convert` needs at least one input and an output path"),
    };
    let mut motions = io::read_motions(inputs)?.into_iter();
    let Some((first, mut motion)) = motions.next() else {
        bail!("no input motion given");
    };
    let first = MotionSource::display_name(&first);
    for (source, next) in motions {
        motion
            .append(&next)
            .with_context(|| format!("joining {}", MotionSource::display_name(&source)))?;
    }
    if let Some(range) = &args.frames {
        let range = parse_frame_range(range, motion.frame_count())?;
        motion = ops::trim(&motion, range)?;
    }
    if let Some(fps) = args.fps {
        motion = ops::resample_fps(&motion, fps)?;
    }
    if args.mirror {
        motion = ops::mirror_auto(&motion).with_context(|| format!("mirroring {first}"))?;
    }
    if let Some(factor) = args.scale {
        motion = ops::scale(&motion, factor);
    }
    if let Some(rig) = &args.retarget_to {
        let target = io::bvh::read_bvh(rig)?;
        motion = Retargeting::detect(&motion, &target)
            .and_then(|r| r.apply(&motion))
            .with_context(|| format!("retargeting onto the rig of {}", rig.display()))?;
    }
    io::write_motion(output, &motion)?;
    if !options.quiet {
        eprintln!(
            "wrote {} ({} frames at {:.3} fps, {} joints)",
            output.display(),
            motion.frame_count(),
            motion.fps(),
            motion.skeleton().joint_count()
        );
    }
    Ok(())
}
