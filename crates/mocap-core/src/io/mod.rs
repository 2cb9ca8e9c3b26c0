//! Reading and writing motion files.
//!
//! - [`bvh`]: Biovision Hierarchy, read and write;
//! - [`asf_amc`]: Acclaim skeleton and motion (CMU, HDM05), read;
//! - [`positions`]: global joint positions as CSV or JSON;
//! - [`atomic`]: writing a file so that it is either whole or absent.
//!
//! [`read_motion`] picks the reader from the file names, so that every
//! command accepts the same inputs.

pub mod asf_amc;
pub mod atomic;
pub mod bvh;
pub mod positions;

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::motion::Motion;

/// The kinds of motion input a command accepts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MotionSource {
    /// One BVH file.
    Bvh(PathBuf),
    /// An ASF skeleton with one AMC motion of it.
    AsfAmc { asf: PathBuf, amc: PathBuf },
}

impl MotionSource {
    /// Groups command-line paths into motions: each `.bvh` is one motion; an
    /// `.asf` pairs with every `.amc` that follows it (`X.asf A.amc B.amc`);
    /// an `.amc` with no `.asf` before it takes the one beside it
    /// ([`asf_amc::skeleton_file_for`]).
    pub fn group(paths: &[PathBuf]) -> Result<Vec<MotionSource>> {
        let mut sources = Vec::new();
        let mut current_asf: Option<&PathBuf> = None;
        for path in paths {
            match extension(path).as_str() {
                "bvh" => sources.push(MotionSource::Bvh(path.clone())),
                "asf" => current_asf = Some(path),
                // An AMC takes the ASF given before it, else the one beside
                // it (`asf_amc::skeleton_file_for`).
                "amc" => sources.push(MotionSource::AsfAmc {
                    asf: match current_asf {
                        Some(asf) => asf.clone(),
                        None => asf_amc::skeleton_file_for(path)?,
                    },
                    amc: path.clone(),
                }),
                _ => {
                    return Err(Error::Invalid(format!(
                        "{}: unknown motion file type (expected .bvh, or .asf followed by .amc)",
                        path.display()
                    )))
                }
            }
        }
        if let (Some(asf), false) = (
            current_asf,
            sources
                .iter()
                .any(|s| matches!(s, MotionSource::AsfAmc { .. })),
        ) {
            return Err(Error::Invalid(format!(
                "{}: an ASF skeleton needs at least one AMC motion after it",
                asf.display()
            )));
        }
        Ok(sources)
    }

    /// A short name for messages and reports.
    pub fn display_name(&self) -> String {
        match self {
            MotionSource::Bvh(p) => p.display().to_string(),
            MotionSource::AsfAmc { amc, .. } => amc.display().to_string(),
        }
    }

    /// The number of frames and the frame time of the motion, from the
    /// file's header, without reading the frames, where the format gives
    /// them there (BVH's `Frames:` and `Frame Time:`); `None` where only
    /// reading the motion tells (AMC). For refusing a take too long for a
    /// command before it is read.
    pub fn announced_length(&self) -> Result<Option<(usize, f64)>> {
        match self {
            MotionSource::Bvh(path) => {
                let (_, frames, frame_time) = bvh::read_bvh_header(path)?;
                Ok(Some((frames, frame_time)))
            }
            MotionSource::AsfAmc { .. } => Ok(None),
        }
    }

    pub fn read(&self) -> Result<Motion> {
        match self {
            MotionSource::Bvh(path) => bvh::read_bvh(path),
            MotionSource::AsfAmc { asf, amc } => asf_amc::read_asf_amc(asf, amc),
        }
    }
}

/// Reads every motion named by `paths` (see [`MotionSource::group`]).
pub fn read_motions(paths: &[PathBuf]) -> Result<Vec<(MotionSource, Motion)>> {
    MotionSource::group(paths)?
        .into_iter()
        .map(|s| s.read().map(|m| (s, m)))
        .collect()
}

/// Reads one motion file: a BVH file, or an AMC motion with the ASF
/// skeleton beside it ([`asf_amc::skeleton_file_for`]).
pub fn read_motion(path: &Path) -> Result<Motion> {
    // One path groups into one motion or an error (a lone `.asf` is one).
    let source = MotionSource::group(&[path.to_path_buf()])?
        .pop()
        .expect("a path that groups without error is one motion");
    source.read()
}

/// Writes a motion to `path`, choosing the format from the extension.
pub fn write_motion(path: &Path, motion: &Motion) -> Result<()> {
    match extension(path).as_str() {
        "bvh" => bvh::write_bvh(path, motion),
        _ => Err(Error::Invalid(format!(
            "{}: can only write .bvh motion files",
            path.display()
        ))),
    }
}

/// The files among `inputs` whose extension is one of `extensions` (lower
/// case; files are matched in any case): files as given, folders searched
/// recursively; sorted and without repeats. An input that does not exist is
/// an error naming it.
pub fn find_files(inputs: &[PathBuf], extensions: &[&str]) -> Result<Vec<PathBuf>> {
    fn walk(dir: &Path, extensions: &[&str], out: &mut Vec<PathBuf>) -> Result<()> {
        let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
        for entry in entries {
            let path = entry.map_err(|e| Error::io(dir, e))?.path();
            if path.is_dir() {
                walk(&path, extensions, out)?;
            } else if extensions.contains(&extension(&path).as_str()) {
                out.push(path);
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    for input in inputs {
        if input.is_dir() {
            walk(input, extensions, &mut out)?;
        } else if input.is_file() {
            out.push(input.clone());
        } else {
            return Err(Error::Invalid(format!(
                "{}: no such file or folder",
                input.display()
            )));
        }
    }
    out.sort();
    out.dedup();
    Ok(out)
}

/// The BVH files among `inputs` (files as given, folders searched
/// recursively), sorted and without repeats. An input that does not exist,
/// or no BVH file at all, is an error naming the inputs.
pub fn find_bvh_files(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let out = find_files(inputs, &["bvh"])?;
    if out.is_empty() {
        let names: Vec<String> = inputs.iter().map(|p| p.display().to_string()).collect();
        return Err(Error::Invalid(format!(
            "no .bvh files in {}",
            names.join(", ")
        )));
    }
    Ok(out)
}

fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}
