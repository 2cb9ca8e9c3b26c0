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
    Ok(mocap_core::io::find_files(inputs, &["bvh", "amc"])?)
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
pub(crate) fn progress_bar(len: usize, message: &str, show: bool) -> ProgressBar {
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
