//! `mocap convert`: read, join, edit and write motions (mocap-core).

use std::path::PathBuf;

use anyhow::bail;
use mocap_core::convert::{convert_files, ConvertOptions};
use mocap_core::io::write_motion_noted;
use mocap_core::ops::FrameRange;

use super::GlobalOptions;

#[derive(clap::Args)]
#[command(
    after_help = "Steps run in this order: join inputs, --frames, --fps, --mirror, --scale, --retarget-to.\n\
The output's extension picks its format: .bvh, or .glb/.gltf (glTF 2.0: a skinned body in metres, Y up).\n\
Examples:\n  mocap convert walk.bvh --fps 30 walk30.bvh\n  mocap convert walk.bvh walk.glb\n  mocap convert character.glb character.bvh\n  mocap convert HDM_bd.asf HDM_bd_walk.amc walk.bvh\n  mocap convert take.bvh --frames 100..400 --mirror clip.bvh\n  mocap convert cmu_walk.bvh --retarget-to mixamo_character.bvh walk_on_mixamo.bvh"
)]
pub struct Args {
    /// Inputs then the output: `IN OUT`, `X.asf X.amc OUT`, or several takes of one
    /// skeleton (joined in order) then OUT. Inputs: BVH, ASF/AMC, glTF (.glb, .gltf) and
    /// sensor recordings; OUT: .bvh, .glb or .gltf.
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
    /// Keep frames A..B (0-based, B excluded; `A..` to the end, `..B` from the start).
    #[arg(long, value_name = "A..B")]
    frames: Option<FrameRange>,
    /// Play the motion on the rig of this BVH file: body parts matched by joint name, bone
    /// directions kept, strides scaled by the legs' lengths. Each rig is related to one T-pose
    /// from its rest pose, so the result does not depend on where the input starts.
    #[arg(long, value_name = "RIG.bvh")]
    retarget_to: Option<PathBuf>,
}

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    let (output, inputs) = match args.paths.split_last() {
        Some((output, inputs)) if !inputs.is_empty() => (output, inputs),
        _ => bail!("`mocap convert` needs at least one input and an output path"),
    };
    let convert = ConvertOptions {
        frames: args.frames,
        fps: args.fps,
        mirror: args.mirror,
        scale: args.scale,
        retarget_to: args.retarget_to,
    };
    let motion = convert_files(inputs, &convert)?;
    let read: Vec<&std::path::Path> = inputs.iter().map(|p| p.as_path()).collect();
    options.note_if_replacing_an_input(&read, output);
    let notes = write_motion_noted(output, &motion)?;
    if !options.quiet {
        // What the writer changed on the way (glTF's units and axes).
        for note in &notes {
            eprintln!("note: {note}");
        }
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
