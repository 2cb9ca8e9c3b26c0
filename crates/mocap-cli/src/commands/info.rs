use std::path::PathBuf;

use anyhow::Context;
use mocap_core::bodymap::{BodyMap, BodyPart};
use mocap_core::io::MotionSource;
use mocap_core::{forward_kinematics, Motion};
use serde::Serialize;

use super::GlobalOptions;

#[derive(clap::Args)]
pub struct Args {
    /// Motion files: BVH, or an ASF skeleton followed by its AMC motions.
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Print one JSON array with an object per motion.
    #[arg(long)]
    json: bool,
}

/// What `mocap info` reports about one motion.
#[derive(Serialize)]
struct Info {
    file: String,
    joints: usize,
    end_sites: usize,
    channels: usize,
    frames: usize,
    frame_time: f64,
    fps: f64,
    duration_seconds: f64,
    /// Smallest and largest global joint coordinates over the take.
    bounding_box: Option<[[f32; 3]; 2]>,
    root: String,
    joint_names: Vec<String>,
    /// The built-in rig the body parts were found by, `None` when the
    /// required parts are not found (retargeting and style transfer then
    /// need a rig file).
    rig: Option<String>,
    /// The body parts found, by key (`pelvis`, `left_clavicle`...).
    body_parts: Vec<String>,
}

fn describe(source: &MotionSource, motion: &Motion) -> Info {
    let skeleton = motion.skeleton();
    let poses = forward_kinematics(motion);
    let map = BodyMap::detect(skeleton).ok();
    Info {
        file: source.display_name(),
        joints: skeleton.joint_count(),
        end_sites: skeleton.joints().iter().map(|j| j.end_sites.len()).sum(),
        channels: skeleton.channel_count(),
        frames: motion.frame_count(),
        frame_time: motion.frame_time(),
        fps: motion.fps(),
        duration_seconds: motion.duration(),
        bounding_box: poses
            .bounding_box()
            .map(|(lo, hi)| [lo.to_array(), hi.to_array()]),
        root: skeleton
            .joints()
            .first()
            .map(|j| j.name.clone())
            .unwrap_or_default(),
        joint_names: skeleton.joints().iter().map(|j| j.name.clone()).collect(),
        rig: map.as_ref().map(|m| m.rig().to_string()),
        body_parts: map
            .iter()
            .flat_map(|m| m.parts().map(|(part, _)| part.key().to_string()))
            .collect(),
    }
}

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    let sources = MotionSource::group(&args.files)?;
    let progress = options.progress(sources.len(), "reading");
    let mut infos = Vec::new();
    for source in &sources {
        let motion = source.read()?;
        infos.push(describe(source, &motion));
        progress.inc(1);
    }
    progress.finish_and_clear();
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&infos).context("writing JSON")?
        );
        return Ok(());
    }
    for info in &infos {
        println!("{}", info.file);
        println!(
            "  joints     {} ({} end sites), root {}",
            info.joints, info.end_sites, info.root
        );
        println!("  channels   {} per frame", info.channels);
        println!(
            "  frames     {} at {:.3} fps (frame time {} s), {:.3} s",
            info.frames, info.fps, info.frame_time, info.duration_seconds
        );
        if let Some([lo, hi]) = info.bounding_box {
            println!(
                "  bounds     x {:.2}..{:.2}  y {:.2}..{:.2}  z {:.2}..{:.2}",
                lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]
            );
        }
        match &info.rig {
            Some(rig) => println!(
                "  rig        {rig} ({} of {} body parts)",
                info.body_parts.len(),
                BodyPart::COUNT
            ),
            None => println!(
                "  rig        body parts not found (search, restyling and retargeting need them: \
                 describe the rig in a file and give it with --rig FILE: docs/rigs.md)"
            ),
        }
    }
    Ok(())
}
