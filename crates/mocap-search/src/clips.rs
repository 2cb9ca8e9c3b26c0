//! Finding, reading and labelling motion clips.

use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use mocap_core::Motion;
use rayon::prelude::*;

use crate::error::{Result, SearchError};
use crate::features::motion_features;
use crate::intervals::FeatureSequence;
use crate::labels::LabelRule;

/// One labelled clip with its per-frame features.
#[derive(Debug, Clone)]
pub struct Clip {
    pub path: PathBuf,
    pub label: String,
    pub performer: Option<String>,
    /// Frames per second of the file.
    pub fps: f64,
    /// The per-frame features at the file's frame rate.
    pub features: FeatureSequence,
}

impl Clip {
    pub fn frame_count(&self) -> usize {
        self.features.frame_count()
    }
}

/// The motion files in `inputs`: each input is a file or a folder searched
/// recursively for `.bvh` and `.amc` files. Sorted by path, so that every
/// run sees the clips in the same order.
pub fn motion_files(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) -> Result<()> {
        let entries = std::fs::read_dir(dir).map_err(|e| SearchError::Io {
            path: dir.to_path_buf(),
            error: e,
        })?;
        for entry in entries {
            let entry = entry.map_err(|e| SearchError::Io {
                path: dir.to_path_buf(),
                error: e,
            })?;
            let path = entry.path();
            if path.is_dir() {
                walk(&path, out)?;
            } else if is_motion_file(&path) {
                out.push(path);
            }
        }
        Ok(())
    }
    let mut files = Vec::new();
    for input in inputs {
        if input.is_dir() {
            walk(input, &mut files)?;
        } else if input.is_file() {
            files.push(input.clone());
        } else {
            return Err(SearchError::Io {
                path: input.clone(),
                error: std::io::Error::new(std::io::ErrorKind::NotFound, "no such file or folder"),
            });
        }
    }
    files.sort();
    files.dedup();
    Ok(files)
}

fn is_motion_file(path: &Path) -> bool {
    matches!(
        path.extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref(),
        Some("bvh") | Some("amc")
    )
}

/// Reads a motion file: BVH, or AMC with the skeleton from the ASF file
/// beside it ([`mocap_core::io::read_motion`]).
pub fn load_motion(path: &Path) -> Result<Motion> {
    Ok(mocap_core::io::read_motion(path)?)
}

/// Reads a motion file and computes its per-frame features; errors name the
/// file.
pub fn load_features(path: &Path) -> Result<(FeatureSequence, f64)> {
    let motion = load_motion(path)?;
    let features = motion_features(&motion).map_err(|e| with_path(e, path))?;
    Ok((features, motion.fps()))
}

/// Adds the file name to errors that do not name one yet.
pub(crate) fn with_path(error: SearchError, path: &Path) -> SearchError {
    match error {
        SearchError::Invalid(message) => {
            SearchError::Invalid(format!("{}: {message}", path.display()))
        }
        SearchError::Core(mocap_core::Error::Invalid(message)) => {
            SearchError::Invalid(format!("{}: {message}", path.display()))
        }
        other => other,
    }
}

/// Reads and labels every clip in `paths`, in parallel, with a progress bar
/// on a terminal when `progress` is set. The labels are checked first, so a
/// file name that gives no label fails before any file is read.
pub fn load_clips(paths: &[PathBuf], rule: &LabelRule, progress: bool) -> Result<Vec<Clip>> {
    let labels = paths
        .iter()
        .map(|p| rule.label_of(p))
        .collect::<Result<Vec<_>>>()?;
    let bar = progress_bar(paths.len(), "reading", progress);
    let clips = paths
        .par_iter()
        .zip(labels)
        .map(|(path, label)| {
            let (features, fps) = load_features(path)?;
            bar.inc(1);
            Ok(Clip {
                path: path.clone(),
                label: label.label,
                performer: label.performer,
                fps,
                features,
            })
        })
        .collect::<Result<Vec<_>>>();
    bar.finish_and_clear();
    clips
}

/// A progress bar on standard error, drawn only when it is a terminal (and
/// `show` is set), so that logs and pipes stay clean.
pub fn progress_bar(len: usize, message: &str, show: bool) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len as u64), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{msg:>10} [{bar:30}] {pos}/{len} ({elapsed})")
            .expect("the template is valid")
            .progress_chars("=> "),
    );
    bar.set_message(message.to_string());
    bar
}
