//! Where fused frames go ([`FrameSink`]): JSON lines written as they come
//! ([`JsonlSink`], one line per frame by [`fused_frame_json`]), memory
//! ([`MemorySink`]), and BVH files written at the end (a skeleton needs the
//! whole take to be fitted), several at once ([`FusedOutputs`]).
//!
//! The format of each output is chosen by its extension: `.jsonl` (or
//! `.json`) for fused frames as JSON lines ([`fused_frame_json`]),
//! `.bvh` for a motion on a fitted skeleton ([`crate::bvh`]).
//!
//! JSON lines keep the world of the calibration: the fused joints as fused
//! (the reference sensor's camera frame for a calibration from the body).
//! BVH files stand on the floor found under the feet by default
//! ([`BvhWorld::Floor`], [`crate::floor`]): upright, `+y` up, the floor at
//! `y = 0`, the first pelvis at `x = z = 0`, as other captures are; or keep
//! the calibration's world ([`BvhWorld::Calibration`]).

use std::path::{Path, PathBuf};

use mocap_core::io::atomic::AtomicFile;
use mocap_core::{Error, Result};
use mocap_feet::{plant_feet_if_asked, FeetOptions, FeetReport};
use serde::Serialize;

use crate::body::BodyModel;
use crate::bvh::{
    fit_error, poses_to_motion_with, regular_poses, BoneLengthSource, BvhOptions, FitError,
};
use crate::floor::{fit_floor, stand_on_floor, BvhWorld, FloorReport};
use crate::fusion::FusedFrame;

/// Where fused frames go.
pub trait FrameSink {
    fn write(&mut self, frame: &FusedFrame) -> Result<()>;
    /// Flushes and closes the output.
    fn finish(&mut self) -> Result<()>;
}

/// Fused frames as JSON lines (`{"t":..,"joints":[[x,y,z],..],"confidence":[..]}`),
/// written as they come through a [`AtomicFile`]: its temporary file replaces
/// the output on `finish`, and is removed when the sink is dropped unfinished
/// (an error) or the process is interrupted.
pub struct JsonlSink {
    out: Option<AtomicFile>,
}

impl JsonlSink {
    pub fn create(path: PathBuf) -> Result<JsonlSink> {
        Ok(JsonlSink {
            out: Some(AtomicFile::create(&path)?),
        })
    }
}

/// One fused frame as a JSON line (no newline).
pub fn fused_frame_json(frame: &FusedFrame) -> String {
    use std::fmt::Write as _;
    let mut s = format!("{{\"t\":{},\"joints\":[", frame.time);
    for (n, p) in frame.joints.iter().enumerate() {
        let _ = write!(
            s,
            "{}[{:.4},{:.4},{:.4}]",
            if n > 0 { "," } else { "" },
            p.x,
            p.y,
            p.z
        );
    }
    s.push_str("],\"confidence\":[");
    for (n, c) in frame.confidence.iter().enumerate() {
        let _ = write!(s, "{}{:.3}", if n > 0 { "," } else { "" }, c);
    }
    s.push_str("]}");
    s
}

impl FrameSink for JsonlSink {
    fn write(&mut self, frame: &FusedFrame) -> Result<()> {
        use std::io::Write;
        if let Some(out) = self.out.as_mut() {
            writeln!(out, "{}", fused_frame_json(frame)).map_err(|e| Error::io(out.path(), e))?;
        }
        Ok(())
    }

    fn finish(&mut self) -> Result<()> {
        match self.out.take() {
            Some(out) => out.commit(),
            None => Ok(()),
        }
    }
}

/// Keeps fused frames in memory (for a BVH written at the end, and tests).
#[derive(Default)]
pub struct MemorySink {
    pub frames: Vec<FusedFrame>,
}

impl FrameSink for MemorySink {
    fn write(&mut self, frame: &FusedFrame) -> Result<()> {
        self.frames.push(frame.clone());
        Ok(())
    }
    fn finish(&mut self) -> Result<()> {
        Ok(())
    }
}

/// The format of an output file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum OutputFormat {
    Jsonl,
    Bvh,
}

impl OutputFormat {
    /// The format of `path` by its extension.
    pub fn of(path: &Path) -> Result<OutputFormat> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match ext.as_deref() {
            Some("jsonl") | Some("json") => Ok(OutputFormat::Jsonl),
            Some("bvh") => Ok(OutputFormat::Bvh),
            _ => Err(Error::Invalid(format!(
                "{}: output must end in .jsonl (fused joints as JSON lines) or .bvh (a motion on a fitted skeleton)",
                path.display()
            ))),
        }
    }
}

/// What was written to one output.
#[derive(Debug, Clone, Serialize)]
pub struct OutputReport {
    pub path: PathBuf,
    pub format: OutputFormat,
    pub frames: usize,
    /// For a BVH: forward kinematics of the file as written (read back) vs
    /// the fused joints.
    pub fit_error: Option<FitError>,
    /// For a BVH with [`OutputFiles::feet`]: what the feet stage did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub feet: Option<FeetReport>,
    /// For a BVH stood on the floor ([`BvhWorld::Floor`]): the floor found
    /// and the transform from the calibration's world. `None` for JSON
    /// lines, for [`BvhWorld::Calibration`], and when no floor was found
    /// (the BVH then keeps the calibration's world).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub floor: Option<FloorReport>,
}

/// The files fused frames go to (`mocap fuse run` and `serve`), and how the
/// BVH ones are made.
#[derive(Debug, Clone)]
pub struct OutputFiles {
    /// `.jsonl` files (fused joints as JSON lines) and `.bvh` files (a motion
    /// on a fitted skeleton), by extension ([`OutputFormat::of`]).
    pub paths: Vec<PathBuf>,
    /// Length units per metre of the BVH files (100: centimetres).
    pub bvh_units_per_metre: f32,
    /// Where the BVH skeleton's bone lengths come from.
    pub bvh_lengths: BoneLengthSource,
    /// Hold planted feet still and above the floor in the BVH files
    /// (mocap-feet, as `mocap feet`).
    pub feet: Option<FeetOptions>,
    /// The BVH files' world: upright on the floor under the feet (default),
    /// or the calibration's. JSON lines always keep the calibration's.
    pub bvh_world: BvhWorld,
}

/// Fused frames to several outputs at once.
pub struct FusedOutputs {
    jsonl: Vec<(PathBuf, JsonlSink)>,
    bvh: Vec<PathBuf>,
    frames: Vec<FusedFrame>,
    written: usize,
    body: BodyModel,
    bvh_options: BvhOptions,
    lengths: BoneLengthSource,
    feet: Option<FeetOptions>,
    world: BvhWorld,
    reports: Vec<OutputReport>,
}

impl FusedOutputs {
    /// Opens the outputs (JSON lines files are created now, BVH files are
    /// written by [`FrameSink::finish`]). `body` gives the BVH's bone lengths.
    /// The BVH files stand on the floor ([`BvhWorld::Floor`]; see
    /// [`FusedOutputs::with_world`]).
    pub fn create(paths: &[PathBuf], body: BodyModel, bvh_options: BvhOptions) -> Result<Self> {
        let mut jsonl = Vec::new();
        let mut bvh = Vec::new();
        for path in paths {
            match OutputFormat::of(path)? {
                OutputFormat::Jsonl => jsonl.push((path.clone(), JsonlSink::create(path.clone())?)),
                OutputFormat::Bvh => bvh.push(path.clone()),
            }
        }
        Ok(FusedOutputs {
            jsonl,
            bvh,
            frames: Vec::new(),
            written: 0,
            body,
            bvh_options,
            lengths: BoneLengthSource::Fused,
            feet: None,
            world: BvhWorld::Floor,
            reports: Vec::new(),
        })
    }

    /// Opens `files` ([`FusedOutputs::create`]) for frames at `fps`.
    pub fn open(files: &OutputFiles, body: BodyModel, fps: f64) -> Result<Self> {
        let bvh_options = BvhOptions {
            units_per_metre: files.bvh_units_per_metre,
            fps,
        };
        let mut outputs = FusedOutputs::create(&files.paths, body, bvh_options)?
            .with_bone_lengths(files.bvh_lengths)
            .with_world(files.bvh_world);
        outputs.feet = files.feet;
        Ok(outputs)
    }

    /// Where the BVH outputs' bone lengths come from (default: the fused
    /// take, [`BoneLengthSource::Fused`]).
    pub fn with_bone_lengths(mut self, lengths: BoneLengthSource) -> Self {
        self.lengths = lengths;
        self
    }

    /// The BVH outputs' world (default: on the floor, [`BvhWorld::Floor`]).
    pub fn with_world(mut self, world: BvhWorld) -> Self {
        self.world = world;
        self
    }

    /// What was written, after [`FrameSink::finish`].
    pub fn reports(&self) -> &[OutputReport] {
        &self.reports
    }
}

impl FrameSink for FusedOutputs {
    fn write(&mut self, frame: &FusedFrame) -> Result<()> {
        for (_, sink) in self.jsonl.iter_mut() {
            sink.write(frame)?;
        }
        if !self.bvh.is_empty() {
            self.frames.push(frame.clone());
        }
        self.written += 1;
        Ok(())
    }

    fn finish(&mut self) -> Result<()> {
        for (path, sink) in self.jsonl.iter_mut() {
            sink.finish()?;
            self.reports.push(OutputReport {
                path: path.clone(),
                format: OutputFormat::Jsonl,
                frames: self.written,
                fit_error: None,
                feet: None,
                floor: None,
            });
        }
        self.jsonl.clear();
        if self.bvh.is_empty() {
            return Ok(());
        }
        if self.frames.is_empty() {
            return Err(Error::Invalid(
                "no fused frames: nothing to write to the BVH output".into(),
            ));
        }
        self.bvh_options.check()?;
        // The fused frames on the BVH's grid, once: stood on the floor,
        // fitted, and what the written file is measured against.
        let mut poses = regular_poses(&self.frames, self.bvh_options.fps);
        let floor = match self.world {
            BvhWorld::Floor => fit_floor(&poses)
                .map(|floor| FloorReport::new(floor, stand_on_floor(&mut poses, &floor))),
            BvhWorld::Calibration => None,
        };
        let motion = poses_to_motion_with(&poses, &self.body, &self.bvh_options, self.lengths)?;
        let (motion, feet) = plant_feet_if_asked(motion, self.feet.as_ref())
            .map_err(|e| Error::Invalid(format!("--feet, on the fused take: {e}")))?;
        for path in std::mem::take(&mut self.bvh) {
            mocap_core::io::bvh::write_bvh(&path, &motion)?;
            let back = mocap_core::io::bvh::read_bvh(&path)?;
            let error = fit_error(&back, &poses, self.bvh_options.units_per_metre)?;
            self.reports.push(OutputReport {
                path,
                format: OutputFormat::Bvh,
                frames: motion.frame_count(),
                fit_error: Some(error),
                feet: feet.clone(),
                floor,
            });
        }
        Ok(())
    }
}
