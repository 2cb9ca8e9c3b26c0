//! The motion library index: a trained forest plus, for every library clip,
//! what a query is compared with. Saved as one versioned, checksummed file.
//!
//! # File format
//!
//! ```text
//! offset  size  content
//! 0       8     magic "MOCAPIDX"
//! 8       4     index format version (u32, little endian)
//! 12      4     feature version (u32, little endian), see features::FEATURE_VERSION
//! 16      8     payload length in bytes (u64, little endian)
//! 24      4     CRC-32 of the payload (u32, little endian)
//! 28      ...   payload: the Index, serialised with postcard
//! ```
//!
//! postcard is a compact binary serde format with a stable, documented wire
//! format: the forest of 100 trees and a library of a thousand clips take a
//! few megabytes and load in milliseconds, where JSON would be several times
//! larger and slower to parse for no reader who needs to look inside (the
//! query reports are JSON). The header is read before the payload so that a
//! file from another format or feature version gets a clear "stale, rebuild
//! it" message rather than a decoding error, and the checksum catches a
//! truncated or damaged file before any of it is trusted.
//!
//! # Clip paths
//!
//! The file stores each library clip's path relative to the folder the
//! index file is in (absolute where no relative path exists), and
//! [`Index::load`] turns them back into absolute paths; so an index and its
//! clips can be moved together, and queries name the right files whatever
//! the working directory.

use std::path::{Component, Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::clips::{load_clips, load_features, motion_files, progress_bar, Clip};
use crate::dtw::euclidean;
use crate::error::{Result, SearchError};
use crate::features::{FEATURE_VERSION, VALUE_COUNT};
use crate::forest::{argmax, Forest, ForestConfig, Samples};
use crate::intervals::{FeatureSequence, IntervalLayout};
use crate::labels::LabelRule;

const MAGIC: &[u8; 8] = b"MOCAPIDX";
/// Version of the index file layout; change it when `Index` changes.
pub(crate) const FORMAT_VERSION: u32 = 2;
const HEADER_LEN: usize = 28;

/// How to build an index.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IndexConfig {
    /// Frames each clip is resampled to (`N`; the report uses 10).
    pub frames: usize,
    pub forest: ForestConfig,
}

impl Default for IndexConfig {
    fn default() -> Self {
        IndexConfig {
            frames: 10,
            forest: ForestConfig::default(),
        }
    }
}

/// One clip of the library as stored in the index.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LibraryClip {
    /// The file the clip was read from: as given when the index was built,
    /// in the file relative to the index's folder (see the module docs),
    /// absolute after [`Index::load`].
    pub path: String,
    /// Index into [`Index::classes`].
    pub label: u32,
    pub performer: Option<String>,
    pub frame_count: u32,
    pub fps: f32,
    /// The clip resampled to `frames` frames (`frames * VALUE_COUNT` values).
    pub resampled: Vec<f32>,
    /// The forest's class histogram of the clip (eq. 8 compares these).
    pub histogram: Vec<f32>,
    /// The leaf the clip reaches in every tree (for forest proximity).
    pub leaves: Vec<u32>,
}

/// A trained forest and its motion library.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Index {
    pub config: IndexConfig,
    /// Class names, sorted; labels are indices into this list.
    pub classes: Vec<String>,
    /// How the labels were obtained (the pattern or label file), for reports.
    pub label_rule: String,
    pub forest: Forest,
    pub clips: Vec<LibraryClip>,
    /// Per value, the mean and standard deviation over the library's
    /// resampled frames, to compare clips on the features directly.
    pub value_mean: Vec<f32>,
    pub value_scale: Vec<f32>,
}

/// How library clips are ranked against a query.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Ranking {
    /// Euclidean distance between the forest's class histograms (eq. 8).
    Histogram,
    /// One minus the forest proximity along the trees' paths
    /// ([`Forest::path_proximity`]). For clips of classes the forest was not
    /// trained on the histogram distance measured better
    /// (bench/results/search.md, "Ranking", unseen classes).
    Proximity,
    /// Euclidean distance between the standardised resampled features.
    Features,
}

impl Ranking {
    /// What the distance is, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            Ranking::Histogram => "forest histogram, eq. 8",
            Ranking::Proximity => "forest path proximity",
            Ranking::Features => "feature distance",
        }
    }
}

impl std::str::FromStr for Ranking {
    type Err = SearchError;
    fn from_str(s: &str) -> Result<Ranking> {
        match s {
            "histogram" => Ok(Ranking::Histogram),
            "proximity" => Ok(Ranking::Proximity),
            "features" => Ok(Ranking::Features),
            other => Err(SearchError::Invalid(format!(
                "unknown ranking `{other}`; expected histogram, proximity or features"
            ))),
        }
    }
}

/// What the index computes for a query clip.
#[derive(Debug, Clone)]
pub(crate) struct QueryVector {
    pub resampled: FeatureSequence,
    pub histogram: Vec<f32>,
    pub leaves: Vec<u32>,
}

/// A class and its probability.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClassProbability {
    pub class: String,
    pub probability: f32,
}

/// One ranked library clip.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Match {
    pub rank: usize,
    pub path: String,
    pub label: String,
    pub distance: f32,
}

/// The answer to a query: predicted class and ranked library clips.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QueryReport {
    pub query: String,
    pub predicted: String,
    pub probability: f32,
    /// Every class with a non-zero probability, most likely first.
    pub probabilities: Vec<ClassProbability>,
    pub ranking: Ranking,
    pub matches: Vec<Match>,
}

impl QueryReport {
    /// How many of the listed clips are not at their paths: the index keeps
    /// them relative to its own folder, so one moved without its clips
    /// answers with paths that lead nowhere.
    pub fn missing_clips(&self) -> usize {
        self.matches
            .iter()
            .filter(|m| !Path::new(&m.path).exists())
            .count()
    }

    /// Plain text for a terminal.
    pub fn to_text(&self) -> String {
        let mut s = format!(
            "{}: {} (probability {:.2})\n",
            self.query, self.predicted, self.probability
        );
        let others: Vec<String> = self
            .probabilities
            .iter()
            .skip(1)
            .take(4)
            .map(|c| format!("{} {:.2}", c.class, c.probability))
            .collect();
        if !others.is_empty() {
            s += &format!("  then: {}\n", others.join(", "));
        }
        s += &format!("nearest clips ({}):\n", self.ranking.describe());
        for m in &self.matches {
            s += &format!(
                "{:>4}  {:.4}  {:<24} {}\n",
                m.rank, m.distance, m.label, m.path
            );
        }
        s
    }

    /// A Markdown table.
    pub fn to_markdown(&self) -> String {
        let mut s = format!(
            "**{}**: predicted `{}` with probability {:.2}\n\n| rank | distance | label | clip |\n| ---: | ---: | --- | --- |\n",
            self.query, self.predicted, self.probability
        );
        for m in &self.matches {
            s += &format!(
                "| {} | {:.4} | {} | {} |\n",
                m.rank, m.distance, m.label, m.path
            );
        }
        s
    }
}

/// `mocap search index`: reads the clips of `inputs` (files, or folders
/// searched for `.bvh` and `.amc`), labels them by `rule` and builds the
/// index ([`build_index`]). `rule_name` names the rule in reports;
/// `progress` shows progress bars on standard error.
pub fn index_files(
    inputs: &[PathBuf],
    rule: &LabelRule,
    rule_name: &str,
    config: &IndexConfig,
    progress: bool,
) -> Result<Index> {
    let clips = load_clips(&motion_files(inputs)?, rule, progress)?;
    build_index(&clips, rule_name, config, progress)
}

/// Builds the forest and the library from labelled clips.
///
/// Every clip is resampled to `config.frames` frames and turned into its
/// interval means; the forest is trained on them (a progress bar counts the
/// trees when `progress` is set); then every clip's histogram and leaves are
/// stored. `label_rule` is kept for reports.
pub fn build_index(
    clips: &[Clip],
    label_rule: &str,
    config: &IndexConfig,
    progress: bool,
) -> Result<Index> {
    if clips.is_empty() {
        return Err(SearchError::Invalid("no clips to index".into()));
    }
    if config.frames == 0 || config.frames > 1000 {
        return Err(SearchError::Invalid(format!(
            "clips are resampled to {} frames; use 1 to 1000",
            config.frames
        )));
    }
    if config.forest.trees == 0 {
        return Err(SearchError::Invalid(
            "the forest needs at least one tree".into(),
        ));
    }
    let mut classes: Vec<String> = clips.iter().map(|c| c.label.clone()).collect();
    classes.sort();
    classes.dedup();
    let labels: Vec<u32> = clips
        .iter()
        .map(|c| classes.binary_search(&c.label).expect("label is listed") as u32)
        .collect();
    let layout = IntervalLayout::all(config.frames, VALUE_COUNT);
    let resampled: Vec<FeatureSequence> = clips
        .iter()
        .map(|c| c.features.resample(config.frames))
        .collect();
    let rows: Vec<f32> = resampled
        .iter()
        .flat_map(|r| layout.interval_means(r))
        .collect();
    let samples =
        Samples::new(&rows, layout.dim(), &labels, classes.len()).map_err(SearchError::Invalid)?;
    let bar = progress_bar(config.forest.trees, "training", progress);
    let forest = Forest::train(&samples, &config.forest, &|| bar.inc(1));
    bar.finish_and_clear();
    let (value_mean, value_scale) = value_statistics(&resampled);
    let library = clips
        .iter()
        .zip(&resampled)
        .zip(&labels)
        .enumerate()
        .map(|(k, ((clip, r), &label))| {
            let row = &rows[k * layout.dim()..(k + 1) * layout.dim()];
            LibraryClip {
                path: clip.path.display().to_string(),
                label,
                performer: clip.performer.clone(),
                frame_count: clip.frame_count() as u32,
                fps: clip.fps as f32,
                resampled: r.values.clone(),
                histogram: forest.predict(row),
                leaves: forest.leaves(row),
            }
        })
        .collect();
    Ok(Index {
        config: config.clone(),
        classes,
        label_rule: label_rule.to_string(),
        forest,
        clips: library,
        value_mean,
        value_scale,
    })
}

/// Mean and standard deviation of every value over all frames of the
/// resampled clips (a zero deviation becomes 1).
pub(crate) fn value_statistics(clips: &[FeatureSequence]) -> (Vec<f32>, Vec<f32>) {
    let dim = VALUE_COUNT;
    let mut sum = vec![0.0f64; dim];
    let mut sum_sq = vec![0.0f64; dim];
    let mut n = 0usize;
    for clip in clips {
        for f in 0..clip.frame_count() {
            for (i, &v) in clip.frame(f).iter().enumerate() {
                sum[i] += v as f64;
                sum_sq[i] += (v as f64) * (v as f64);
            }
            n += 1;
        }
    }
    let n = n.max(1) as f64;
    let mean: Vec<f32> = sum.iter().map(|s| (s / n) as f32).collect();
    let scale = sum
        .iter()
        .zip(&sum_sq)
        .map(|(s, q)| {
            let var = (q / n - (s / n) * (s / n)).max(0.0);
            let sd = var.sqrt() as f32;
            if sd > 1e-9 {
                sd
            } else {
                1.0
            }
        })
        .collect();
    (mean, scale)
}

impl Index {
    /// The interval layout the forest was trained on.
    pub fn layout(&self) -> IntervalLayout {
        IntervalLayout::all(self.config.frames, VALUE_COUNT)
    }

    /// Resamples a query's per-frame features and runs it through the forest.
    pub(crate) fn describe(&self, features: &FeatureSequence) -> QueryVector {
        let resampled = features.resample(self.config.frames);
        self.describe_resampled(resampled)
    }

    /// Like [`Index::describe`] for a clip already resampled to `frames`.
    pub(crate) fn describe_resampled(&self, resampled: FeatureSequence) -> QueryVector {
        let row = self.layout().interval_means(&resampled);
        QueryVector {
            histogram: self.forest.predict(&row),
            leaves: self.forest.leaves(&row),
            resampled,
        }
    }

    /// Standardised resampled values (for [`Ranking::Features`]).
    fn standardise(&self, values: &[f32]) -> Vec<f32> {
        values
            .iter()
            .enumerate()
            .map(|(k, v)| {
                let i = k % VALUE_COUNT;
                (v - self.value_mean[i]) / self.value_scale[i]
            })
            .collect()
    }

    /// Distance between two described clips under `ranking`.
    pub(crate) fn pair_distance(&self, a: &QueryVector, b: &QueryVector, ranking: Ranking) -> f32 {
        match ranking {
            Ranking::Histogram => euclidean(&a.histogram, &b.histogram),
            Ranking::Proximity => 1.0 - self.forest.path_proximity(&a.leaves, &b.leaves),
            Ranking::Features => {
                let (x, y) = (
                    self.standardise(&a.resampled.values),
                    self.standardise(&b.resampled.values),
                );
                euclidean(&x, &y) / (x.len().max(1) as f32).sqrt()
            }
        }
    }

    /// Distance from the query to every library clip under `ranking`.
    pub(crate) fn distances(&self, query: &QueryVector, ranking: Ranking) -> Vec<f32> {
        match ranking {
            Ranking::Histogram => self
                .clips
                .iter()
                .map(|c| euclidean(&query.histogram, &c.histogram))
                .collect(),
            Ranking::Proximity => self
                .clips
                .iter()
                .map(|c| 1.0 - self.forest.path_proximity(&query.leaves, &c.leaves))
                .collect(),
            Ranking::Features => {
                let q = self.standardise(&query.resampled.values);
                let scale = (q.len().max(1) as f32).sqrt();
                self.clips
                    .iter()
                    .map(|c| euclidean(&q, &self.standardise(&c.resampled)) / scale)
                    .collect()
            }
        }
    }

    /// `mocap search query`: reads the clip at `path` (BVH, or AMC next to
    /// its ASF), classifies it and ranks the library (best `top` clips).
    pub fn query_file(&self, path: &Path, top: usize, ranking: Ranking) -> Result<QueryReport> {
        let (features, _fps) = load_features(path)?;
        Ok(self.query(&path.display().to_string(), &features, top, ranking))
    }

    /// Classifies a query and ranks the library (best `top` clips).
    pub fn query(
        &self,
        name: &str,
        features: &FeatureSequence,
        top: usize,
        ranking: Ranking,
    ) -> QueryReport {
        let query = self.describe(features);
        let distances = self.distances(&query, ranking);
        let matches = nearest(&distances, top)
            .into_iter()
            .enumerate()
            .map(|(rank, k)| Match {
                rank: rank + 1,
                path: self.clips[k].path.clone(),
                label: self.classes[self.clips[k].label as usize].clone(),
                distance: distances[k],
            })
            .collect();
        let mut probabilities: Vec<ClassProbability> = self
            .classes
            .iter()
            .zip(&query.histogram)
            .filter(|(_, &p)| p > 0.0)
            .map(|(c, &p)| ClassProbability {
                class: c.clone(),
                probability: p,
            })
            .collect();
        probabilities.sort_by(|a, b| b.probability.total_cmp(&a.probability));
        let best = argmax(&query.histogram);
        QueryReport {
            query: name.to_string(),
            predicted: self.classes[best].clone(),
            probability: query.histogram[best],
            probabilities,
            ranking,
            matches,
        }
    }

    /// Writes the index atomically (see the module docs for the layout).
    pub fn save(&self, path: &Path) -> Result<()> {
        let folder = absolute(&index_folder(path));
        let mut stored = self.clone();
        for clip in &mut stored.clips {
            let clip_path = absolute(Path::new(&clip.path));
            let relative = relative_to(&clip_path, &folder).unwrap_or(clip_path);
            clip.path = relative.to_string_lossy().into_owned();
        }
        let payload = postcard::to_stdvec(&stored)
            .map_err(|e| SearchError::Invalid(format!("cannot serialise the index: {e}")))?;
        let mut header = Vec::with_capacity(HEADER_LEN);
        header.extend_from_slice(MAGIC);
        header.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        header.extend_from_slice(&FEATURE_VERSION.to_le_bytes());
        header.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        header.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
        mocap_core::io::atomic::write_atomically(path, |w| {
            w.write_all(&header)?;
            w.write_all(&payload)
        })?;
        Ok(())
    }

    /// Reads an index written by [`Index::save`], checking its header,
    /// versions, checksum and contents.
    pub fn load(path: &Path) -> Result<Index> {
        let bytes = std::fs::read(path).map_err(|e| SearchError::Io {
            path: path.to_path_buf(),
            error: e,
        })?;
        let mut index = Index::from_bytes(&bytes, path)?;
        let folder = absolute(&index_folder(path));
        for clip in &mut index.clips {
            let stored = Path::new(&clip.path);
            if stored.is_relative() {
                clip.path = lexical_clean(&folder.join(stored))
                    .to_string_lossy()
                    .into_owned();
            }
        }
        Ok(index)
    }

    /// Decodes index file contents; `path` names the file in errors. Clip
    /// paths stay as stored (relative to the index file's folder).
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Index> {
        let bad = |message: String| SearchError::BadIndex {
            path: path.to_path_buf(),
            message,
        };
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(bad(
                "not a mocap search index (it does not start with MOCAPIDX); build one with `mocap search index`".into(),
            ));
        }
        if bytes.len() < HEADER_LEN {
            return Err(bad(format!(
                "truncated: {} bytes, shorter than the {HEADER_LEN}-byte header",
                bytes.len()
            )));
        }
        let u32_at = |k: usize| u32::from_le_bytes(bytes[k..k + 4].try_into().expect("4 bytes"));
        let format = u32_at(8);
        let features = u32_at(12);
        let length = u64::from_le_bytes(bytes[16..24].try_into().expect("8 bytes"));
        let checksum = u32_at(24);
        if format != FORMAT_VERSION {
            return Err(SearchError::StaleIndex {
                path: path.to_path_buf(),
                message: format!(
                    "written in index format version {format}, this build reads version {FORMAT_VERSION}"
                ),
            });
        }
        if features != FEATURE_VERSION {
            return Err(SearchError::StaleIndex {
                path: path.to_path_buf(),
                message: format!(
                    "built with feature version {features}, this build computes version {FEATURE_VERSION}"
                ),
            });
        }
        let payload = &bytes[HEADER_LEN..];
        if payload.len() as u64 != length {
            return Err(bad(format!(
                "truncated or extended: the header announces {length} bytes of data, the file holds {}",
                payload.len()
            )));
        }
        if crc32fast::hash(payload) != checksum {
            return Err(bad(
                "corrupted: the checksum of the data does not match the header".into(),
            ));
        }
        let index: Index = postcard::from_bytes(payload)
            .map_err(|e| bad(format!("cannot decode the index data: {e}")))?;
        index.check().map_err(bad)?;
        Ok(index)
    }

    /// Internal consistency, so that nothing read from a file can panic later.
    fn check(&self) -> std::result::Result<(), String> {
        let classes = self.classes.len();
        let layout = self.layout();
        if classes == 0 || self.forest.class_count() != classes {
            return Err("the forest's classes do not match the class list".into());
        }
        if self.forest.dim() != layout.dim() || !self.forest.is_consistent() {
            return Err("the forest does not fit the feature layout".into());
        }
        if self.value_mean.len() != VALUE_COUNT || self.value_scale.len() != VALUE_COUNT {
            return Err("the feature statistics have the wrong size".into());
        }
        let trees = self.forest.trees();
        for (k, c) in self.clips.iter().enumerate() {
            let leaves_ok = c.leaves.len() == trees.len()
                && c.leaves
                    .iter()
                    .zip(trees)
                    .all(|(&l, t)| (l as usize) < t.node_count());
            if c.label as usize >= classes
                || c.resampled.len() != self.config.frames * VALUE_COUNT
                || c.histogram.len() != classes
                || !leaves_ok
            {
                return Err(format!("library clip {k} ({}) is malformed", c.path));
            }
        }
        Ok(())
    }
}

/// Indices of the `top` smallest distances, nearest first (ties by index).
pub(crate) fn nearest(distances: &[f32], top: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..distances.len()).collect();
    let by = |a: &usize, b: &usize| distances[*a].total_cmp(&distances[*b]).then(a.cmp(b));
    let top = top.min(order.len());
    if top == 0 {
        return Vec::new();
    }
    if top < order.len() {
        order.select_nth_unstable_by(top - 1, by);
        order.truncate(top);
    }
    order.sort_by(by);
    order
}

/// The folder an index file is in (`.` for a bare file name).
fn index_folder(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// `path` made absolute: the canonical path where it exists (symbolic links
/// resolved, so that `..` in a relative path means what the file system
/// says), else joined to the working directory and cleaned lexically.
fn absolute(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    let joined = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir()
            .map(|d| d.join(path))
            .unwrap_or_else(|_| path.to_path_buf())
    };
    lexical_clean(&joined)
}

/// Drops `.` components and folds `name/..` pairs, without touching the
/// file system.
fn lexical_clean(path: &Path) -> PathBuf {
    let mut out: Vec<Component> = Vec::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => match out.last() {
                Some(Component::Normal(_)) => {
                    out.pop();
                }
                Some(Component::RootDir) | Some(Component::Prefix(_)) => {}
                _ => out.push(c),
            },
            other => out.push(other),
        }
    }
    if out.is_empty() {
        return PathBuf::from(".");
    }
    out.iter().collect()
}

/// `path` relative to the folder `base` (both absolute and clean), or
/// `None` where they share no root (other drives on Windows).
fn relative_to(path: &Path, base: &Path) -> Option<PathBuf> {
    let p: Vec<Component> = path.components().collect();
    let b: Vec<Component> = base.components().collect();
    if p.first() != b.first() {
        return None;
    }
    let common = p.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    for c in &p[common..] {
        out.push(c);
    }
    Some(out)
}

#[cfg(test)]
mod path_tests {
    use super::*;

    #[test]
    fn relative_paths_go_up_and_down_from_the_index_folder() {
        let rel = relative_to(
            Path::new("/work/shared/data/a.bvh"),
            Path::new("/work/main/models"),
        );
        assert_eq!(rel, Some(PathBuf::from("../../shared/data/a.bvh")));
        let rel = relative_to(
            Path::new("/work/main/models/a.bvh"),
            Path::new("/work/main/models"),
        );
        assert_eq!(rel, Some(PathBuf::from("a.bvh")));
        // And back: the index folder joined with the stored path.
        let back = lexical_clean(&Path::new("/work/main/models").join("../../shared/data/a.bvh"));
        assert_eq!(back, PathBuf::from("/work/shared/data/a.bvh"));
    }

    #[test]
    fn lexical_clean_folds_dots() {
        assert_eq!(lexical_clean(Path::new("a/./b/../c")), PathBuf::from("a/c"));
        assert_eq!(lexical_clean(Path::new("../a/..")), PathBuf::from(".."));
        assert_eq!(lexical_clean(Path::new("/..")), PathBuf::from("/"));
    }
}
