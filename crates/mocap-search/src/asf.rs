//! Clip files: BVH, or AMC with the ASF skeleton file it belongs to.

use std::path::{Path, PathBuf};

use mocap_core::io::MotionSource;

use crate::error::{Result, SearchError};

/// The ASF skeleton of an AMC motion: in the same folder, the `.asf` file
/// whose name (without extension) is the longest prefix of the AMC's name
/// (`HDM_bd.asf` for `HDM_bd_walk4StepsLstart_001_120.amc`, `01.asf` for
/// `01_02.amc`), or the only `.asf` file there.
pub fn skeleton_file_for(amc: &Path) -> Result<PathBuf> {
    let dir = match amc.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let stem = amc
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let entries = std::fs::read_dir(dir).map_err(|e| SearchError::Io {
        path: dir.to_path_buf(),
        error: e,
    })?;
    let mut skeletons: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| e.eq_ignore_ascii_case("asf"))
        })
        .collect();
    skeletons.sort();
    let prefix_len = |p: &PathBuf| {
        let s = p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        stem.starts_with(&s).then_some(s.len())
    };
    if let Some(best) = skeletons
        .iter()
        .filter_map(|p| prefix_len(p).map(|n| (n, p)))
        .max_by_key(|(n, _)| *n)
    {
        return Ok(best.1.clone());
    }
    if skeletons.len() == 1 {
        return Ok(skeletons.remove(0));
    }
    Err(SearchError::Invalid(format!(
        "{}: no ASF skeleton file for this AMC motion in {} (expected one whose name starts the AMC's name, e.g. `HDM_bd.asf` for `HDM_bd_*.amc`)",
        amc.display(),
        dir.display()
    )))
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
