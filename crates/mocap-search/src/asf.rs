//! Clip files: BVH, or AMC with the ASF skeleton file it belongs to.

use std::path::{Path, PathBuf};

use mocap_core::io::MotionSource;

use crate::error::{Result, SearchError};

/// The ASF skeleton of an AMC motion given alone (see
/// [`mocap_core::io::asf_amc::skeleton_file_for`]).
pub fn skeleton_file_for(amc: &Path) -> Result<PathBuf> {
    Ok(mocap_core::io::asf_amc::skeleton_file_for(amc)?)
}

/// The core's motion source for a clip file: a BVH file, or an AMC file
/// with the ASF skeleton found by [`skeleton_file_for`].
pub fn motion_source(path: &Path) -> Result<MotionSource> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("bvh") => Ok(MotionSource::Bvh(path.to_path_buf())),
        Some("amc") => Ok(MotionSource::AsfAmc {
            asf: skeleton_file_for(path)?,
            amc: path.to_path_buf(),
        }),
        _ => Err(SearchError::Invalid(format!(
            "{}: not a motion clip (expected .bvh, or .amc with its .asf beside it)",
            path.display()
        ))),
    }
}
