//! Where fused frames go: JSON lines written as they come, and BVH files
//! written at the end (a skeleton needs the whole take to be fitted).
//!
//! The format of each output is chosen by its extension: `.jsonl` (or
//! `.json`) for fused frames as JSON lines ([`crate::net::fused_frame_json`]),
//! `.bvh` for a motion on a fitted skeleton ([`crate::bvh`]).

use std::path::{Path, PathBuf};

use mocap_core::{Error, Result};
use serde::Serialize;

use crate::body::BodyModel;
use crate::bvh::{
    fit_error, fused_to_motion_with, regular_poses, BoneLengthSource, BvhOptions, FitError,
};
use crate::fusion::FusedFrame;
use crate::net::{FrameSink, JsonlSink};

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
    reports: Vec<OutputReport>,
}

impl FusedOutputs {
    /// Opens the outputs (JSON lines files are created now, BVH files are
    /// written by [`FrameSink::finish`]). `body` gives the BVH's bone lengths.
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
            reports: Vec::new(),
        })
    }

    /// Where the BVH outputs' bone lengths come from (default: the fused
    /// take, [`BoneLengthSource::Fused`]).
    pub fn with_bone_lengths(mut self, lengths: BoneLengthSource) -> Self {
        self.lengths = lengths;
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
        let motion =
            fused_to_motion_with(&self.frames, &self.body, &self.bvh_options, self.lengths)?;
        let poses = regular_poses(&self.frames, self.bvh_options.fps);
        for path in std::mem::take(&mut self.bvh) {
            mocap_core::io::bvh::write_bvh(&path, &motion)?;
            let back = mocap_core::io::bvh::read_bvh(&path)?;
            let error = fit_error(&back, &poses, self.bvh_options.units_per_metre)?;
            self.reports.push(OutputReport {
                path,
                format: OutputFormat::Bvh,
                frames: motion.frame_count(),
                fit_error: Some(error),
            });
        }
        Ok(())
    }
}
