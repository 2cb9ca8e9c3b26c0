//! Labelled clips: BVH files named `<set>_<content>_<style>_<take>.bvh`
//! (the Bandai Namco convention, e.g. `dataset-1_walk-back_proud_001.bvh`),
//! the held-out evaluation takes, and mirrored copies.
//!
//! The held-out rule is the same for training and evaluation, so that the
//! shipped model never saw the clips it is evaluated on: in every group of
//! takes with the same set, content and style that has two takes or more,
//! the last take (by name) is held out.

use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};

use mocap_core::io::bvh::read_bvh;
use mocap_core::ops::mirror_auto;
use mocap_core::Motion;
use serde::{Deserialize, Serialize};

use crate::{invalid, Result};

/// The labels read from a clip's file name.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Labels {
    /// Everything before the content (`dataset-1`); may be empty.
    pub set: String,
    pub content: String,
    pub style: String,
    pub take: String,
}

/// Labels of a file named `<set>_<content>_<style>_<take>.bvh` (the set may
/// itself hold underscores; content and style may not). `None` for a name
/// with fewer than three `_`-separated parts.
pub fn labels_from_name(path: &Path) -> Option<Labels> {
    let stem = path.file_stem()?.to_string_lossy().into_owned();
    let mut parts = stem.rsplitn(4, '_');
    let take = parts.next()?.to_string();
    let style = parts.next()?.to_string();
    let content = parts.next()?.to_string();
    let set = parts.next().unwrap_or("").to_string();
    if take.is_empty() || style.is_empty() || content.is_empty() {
        return None;
    }
    Some(Labels {
        set,
        content,
        style,
        take,
    })
}

/// A clip read from a file, with its labels.
#[derive(Debug, Clone)]
pub struct Clip {
    /// File name without folder or extension.
    pub name: String,
    pub path: PathBuf,
    pub labels: Labels,
    pub motion: Motion,
}

/// The BVH files among `inputs` (files, or folders searched recursively),
/// sorted by path.
pub fn list_bvh(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    Ok(mocap_core::io::find_bvh_files(inputs)?)
}

/// The contents the shipped model was trained on and the evaluation's
/// classifiers learn from: the Bandai walks, straight, back, sideways and
/// turning (`bench/style/run.sh`).
pub const WALKING_CONTENTS: [&str; 6] = [
    "walk",
    "walk-back",
    "walk-left",
    "walk-right",
    "walk-turn-left",
    "walk-turn-right",
];

/// Which labelled clips to use.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ClipFilter {
    /// Keep only these contents (all when empty).
    pub contents: Vec<String>,
    /// Keep only these styles (all when empty).
    pub styles: Vec<String>,
}

impl ClipFilter {
    pub fn accepts(&self, labels: &Labels) -> bool {
        (self.contents.is_empty() || self.contents.contains(&labels.content))
            && (self.styles.is_empty() || self.styles.contains(&labels.style))
    }
}

/// The labelled files among `paths` that `filter` accepts, with their
/// labels. A file whose name carries no labels is an error naming it.
pub fn labelled_paths(paths: &[PathBuf], filter: &ClipFilter) -> Result<Vec<(PathBuf, Labels)>> {
    let mut out = Vec::new();
    for p in paths {
        let labels = labels_from_name(p).ok_or_else(|| {
            invalid(format!(
                "{}: cannot read content and style labels from the name; expected \
                 <set>_<content>_<style>_<take>.bvh",
                p.display()
            ))
        })?;
        if filter.accepts(&labels) {
            out.push((p.clone(), labels));
        }
    }
    Ok(out)
}

/// Which take of every (set, content, style) group of two takes or more is
/// held out for evaluation: the last (the shipped model's split) or the
/// first (the other fold, to measure a second time on other clips).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum HeldOutTake {
    #[default]
    Last,
    First,
}

impl std::str::FromStr for HeldOutTake {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "last" => Ok(HeldOutTake::Last),
            "first" => Ok(HeldOutTake::First),
            _ => Err(format!("held-out take {s:?}: expected last or first")),
        }
    }
}

/// The names (file stems) of the held-out takes among labelled files: the
/// last (or first, see [`HeldOutTake`]) take of every (set, content, style)
/// group of two takes or more.
pub fn held_out(files: &[(PathBuf, Labels)], which: HeldOutTake) -> HashSet<String> {
    let mut groups: BTreeMap<(String, String, String), Vec<String>> = BTreeMap::new();
    for (path, l) in files {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        groups
            .entry((l.set.clone(), l.content.clone(), l.style.clone()))
            .or_default()
            .push(stem);
    }
    groups
        .into_values()
        .filter(|v| v.len() >= 2)
        .filter_map(|v| match which {
            HeldOutTake::Last => v.into_iter().max(),
            HeldOutTake::First => v.into_iter().min(),
        })
        .collect()
}

/// Reads labelled files.
pub fn load_clips(files: &[(PathBuf, Labels)]) -> Result<Vec<Clip>> {
    files
        .iter()
        .map(|(path, labels)| {
            Ok(Clip {
                name: path
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                path: path.clone(),
                labels: labels.clone(),
                motion: read_bvh(path)?,
            })
        })
        .collect()
}

/// The mirror image of a clip (left and right swapped), for the mirrored
/// copies of training clips and style statistics.
pub fn mirrored(motion: &Motion) -> Result<Motion> {
    Ok(mirror_auto(motion)?)
}

#[cfg(test)]
pub(crate) mod test_support {
    use mocap_core::io::bvh::read_bvh;
    use mocap_core::Motion;

    /// A Bandai take by file name (dataset from the name), if the shared
    /// data is there.
    pub fn bandai_walk(name: &str) -> Option<Motion> {
        let set = name.split('_').next()?;
        let path = mocap_testdata::shared(format!("bandai/{set}/{name}"))?;
        Some(read_bvh(&path).expect("readable Bandai take"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_come_from_the_name() {
        let l = labels_from_name(Path::new("a/dataset-1_walk-back_not-confident_001.bvh")).unwrap();
        assert_eq!(l.set, "dataset-1");
        assert_eq!(l.content, "walk-back");
        assert_eq!(l.style, "not-confident");
        assert_eq!(l.take, "001");
        let l = labels_from_name(Path::new("walk_proud_3.bvh")).unwrap();
        assert_eq!((l.set.as_str(), l.content.as_str()), ("", "walk"));
        assert!(labels_from_name(Path::new("walking.bvh")).is_none());
    }

    #[test]
    fn the_last_take_of_each_group_is_held_out() {
        let files: Vec<(PathBuf, Labels)> = [
            "d_walk_old_001.bvh",
            "d_walk_old_002.bvh",
            "d_walk_sad_001.bvh",
            "d_run_old_004.bvh",
            "d_run_old_001.bvh",
            "e_walk_old_009.bvh",
        ]
        .iter()
        .map(|n| (PathBuf::from(n), labels_from_name(Path::new(n)).unwrap()))
        .collect();
        let h = held_out(&files, HeldOutTake::Last);
        let mut v: Vec<&str> = h.iter().map(String::as_str).collect();
        v.sort();
        assert_eq!(v, ["d_run_old_004", "d_walk_old_002"]);
        // The other fold: the first take of the same groups.
        let h = held_out(&files, HeldOutTake::First);
        let mut v: Vec<&str> = h.iter().map(String::as_str).collect();
        v.sort();
        assert_eq!(v, ["d_run_old_001", "d_walk_old_001"]);
        assert_eq!("first".parse(), Ok(HeldOutTake::First));
        assert!("middle".parse::<HeldOutTake>().is_err());
    }
}
