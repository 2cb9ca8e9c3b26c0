//! `mocap info`: what a motion file holds (joints, channels, frames, frame
//! rate, duration, bounding box, the rig its body parts were found by).

use std::path::PathBuf;

use serde::Serialize;

use crate::bodymap::{BodyMap, BodyPart};
use crate::error::Result;
use crate::io::MotionSource;
use crate::kinematics::bounding_box;
use crate::motion::Motion;

/// What `mocap info` reports about one motion.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MotionInfo {
    pub file: String,
    pub joints: usize,
    pub end_sites: usize,
    pub channels: usize,
    pub frames: usize,
    pub frame_time: f64,
    pub fps: f64,
    pub duration_seconds: f64,
    /// Smallest and largest global joint coordinates over the take.
    pub bounding_box: Option<[[f32; 3]; 2]>,
    pub root: String,
    pub joint_names: Vec<String>,
    /// The built-in rig the body parts were found by, `None` when the
    /// required parts are not found (retargeting and style transfer then
    /// need a rig file).
    pub rig: Option<String>,
    /// The body parts found, by key (`pelvis`, `left_clavicle`...).
    pub body_parts: Vec<String>,
}

impl MotionInfo {
    /// Describes `motion`, read from the file named `file`.
    pub fn of(file: impl Into<String>, motion: &Motion) -> MotionInfo {
        let skeleton = motion.skeleton();
        let map = BodyMap::detect(skeleton).ok();
        MotionInfo {
            file: file.into(),
            joints: skeleton.joint_count(),
            end_sites: skeleton.joints().iter().map(|j| j.end_sites.len()).sum(),
            channels: skeleton.channel_count(),
            frames: motion.frame_count(),
            frame_time: motion.frame_time(),
            fps: motion.fps(),
            duration_seconds: motion.duration(),
            bounding_box: bounding_box(motion).map(|(lo, hi)| [lo.to_array(), hi.to_array()]),
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

    /// Plain text for a terminal: the file name, then indented lines.
    pub fn to_text(&self) -> String {
        let mut s = format!("{}\n", self.file);
        s += &format!(
            "  joints     {} ({} end sites), root {}\n",
            self.joints, self.end_sites, self.root
        );
        s += &format!("  channels   {} per frame\n", self.channels);
        s += &format!(
            "  frames     {} at {:.3} fps (frame time {} s), {:.3} s\n",
            self.frames, self.fps, self.frame_time, self.duration_seconds
        );
        if let Some([lo, hi]) = self.bounding_box {
            s += &format!(
                "  bounds     x {:.2}..{:.2}  y {:.2}..{:.2}  z {:.2}..{:.2}\n",
                lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]
            );
        }
        match &self.rig {
            Some(rig) => {
                s += &format!(
                    "  rig        {rig} ({} of {} body parts)\n",
                    self.body_parts.len(),
                    BodyPart::COUNT
                )
            }
            None => s +=
                "  rig        body parts not found (search, restyling and retargeting need them: \
                      describe the rig in a file and give it with --rig FILE: docs/rigs.md)\n",
        }
        s
    }
}

/// Reads every motion of `paths` (BVH files, or an ASF skeleton followed by
/// its AMC motions, as [`MotionSource::group`] pairs them) and describes
/// it; `progress(done, total)` is called after each.
pub fn describe_files(
    paths: &[PathBuf],
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Vec<MotionInfo>> {
    let sources = MotionSource::group(paths)?;
    let mut infos = Vec::with_capacity(sources.len());
    for (k, source) in sources.iter().enumerate() {
        let motion = source.read()?;
        infos.push(MotionInfo::of(source.display_name(), &motion));
        progress(k + 1, sources.len());
    }
    Ok(infos)
}
