//! `mocap info`: what a motion file holds (joints, channels, frames, frame
//! rate, duration, bounding box, the rig its body parts were found by, and
//! how).

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::Serialize;

use crate::bodymap::{BodyMap, BodyPart};
use crate::error::Result;
use crate::io::MotionSource;
use crate::kinematics::bounding_box;
use crate::motion::Motion;
use crate::ops::rest_pose_lead_in;

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
    /// Frames at the start that hold the skeleton's rest pose and the
    /// blend out of it rather than the motion ([`rest_pose_lead_in`]).
    pub lead_in_frames: usize,
    /// Smallest and largest global joint coordinates over the take.
    pub bounding_box: Option<[[f32; 3]; 2]>,
    pub root: String,
    pub joint_names: Vec<String>,
    /// The rig the body parts were found on ([`BodyMap::rig`]: a naming
    /// convention, a rig file's name, `unnamed` when found by shape), `None`
    /// when the required parts are not found (retargeting and style transfer
    /// then need a rig file).
    pub rig: Option<String>,
    /// How the body parts were found ([`crate::bodymap::FoundBy::key`]): `names`, `shape`,
    /// `rig_file`; `None` when they are not found.
    pub found_by: Option<String>,
    /// The body parts found, by key (`pelvis`, `left_clavicle`...).
    pub body_parts: Vec<String>,
    /// The joint of each body part found, by part key.
    pub body_part_joints: BTreeMap<String, String>,
    /// Why the body parts are not found, with a rig-file template to start
    /// from ([`BodyMap::detect`]'s error); `None` when they are found.
    pub body_parts_error: Option<String>,
}

impl MotionInfo {
    /// Describes `motion`, read from the file named `file`.
    pub fn of(file: impl Into<String>, motion: &Motion) -> MotionInfo {
        let skeleton = motion.skeleton();
        let detected = BodyMap::detect(skeleton);
        let body_parts_error = detected.as_ref().err().map(|e| e.to_string());
        let map = detected.ok();
        MotionInfo {
            file: file.into(),
            joints: skeleton.joint_count(),
            end_sites: skeleton.joints().iter().map(|j| j.end_sites.len()).sum(),
            channels: skeleton.channel_count(),
            frames: motion.frame_count(),
            frame_time: motion.frame_time(),
            fps: motion.fps(),
            duration_seconds: motion.duration(),
            lead_in_frames: rest_pose_lead_in(motion),
            bounding_box: bounding_box(motion).map(|(lo, hi)| [lo.to_array(), hi.to_array()]),
            root: skeleton
                .joints()
                .first()
                .map(|j| j.name.clone())
                .unwrap_or_default(),
            joint_names: skeleton.joints().iter().map(|j| j.name.clone()).collect(),
            rig: map.as_ref().map(|m| m.rig().to_string()),
            found_by: map.as_ref().map(|m| m.found_by().key().to_string()),
            body_parts: map
                .iter()
                .flat_map(|m| m.parts().map(|(part, _)| part.key().to_string()))
                .collect(),
            body_part_joints: map
                .iter()
                .flat_map(|m| m.parts())
                .map(|(part, joint)| (part.key().to_string(), skeleton.joint(joint).name.clone()))
                .collect(),
            body_parts_error,
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
        if self.lead_in_frames > 0 {
            s += &format!(
                "  lead-in    frames 0..{k} are the rest pose and the blend out of it \
                 (`mocap convert --frames {k}..` drops them)\n",
                k = self.lead_in_frames
            );
        }
        if let Some([lo, hi]) = self.bounding_box {
            s += &format!(
                "  bounds     x {:.2}..{:.2}  y {:.2}..{:.2}  z {:.2}..{:.2}\n",
                lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]
            );
        }
        match (&self.rig, &self.body_parts_error) {
            (Some(rig), _) => {
                let how = match self.found_by.as_deref() {
                    Some("names") => ", found by joint name",
                    Some("shape") => ", found by the skeleton's shape",
                    Some("rig_file") => ", from a rig file",
                    _ => "",
                };
                s += &format!(
                    "  rig        {rig} ({} of {} body parts{how})\n",
                    self.body_parts.len(),
                    BodyPart::COUNT
                );
                // Parts found by shape: show which joints, to check.
                if self.found_by.as_deref() == Some("shape") {
                    let parts: Vec<String> = self
                        .body_parts
                        .iter()
                        .filter_map(|part| {
                            Some(format!("{part} {}", self.body_part_joints.get(part)?))
                        })
                        .collect();
                    s += &format!("  parts      {}\n", parts.join(", "));
                }
            }
            (None, error) => {
                s += "  rig        body parts not found (search, restyling and retargeting need \
                      them: describe the rig in a file and give it with --rig FILE: \
                      docs/rigs.md)\n";
                if let Some(template) = error.as_deref().and_then(|e| e.split_once("\n\n")) {
                    s += "             a rig file to start from:\n";
                    for line in template.1.lines() {
                        s += &format!("               {line}\n");
                    }
                }
            }
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
