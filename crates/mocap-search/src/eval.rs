//! The evaluation of the report, measured, and more.
//!
//! For every split of the labelled clips into training and test clips it
//! trains and tests:
//!
//! - the forest (the report's method);
//! - a single deterministic tree (the best test at every node);
//! - a single random tree (the forest's tree-growing, one tree, all clips);
//! - a nearest-neighbour classifier with dynamic time warping on the same
//!   per-frame features (standardised, resampled to a fixed length);
//!
//! and pools the per-class precision, recall and F-measure over the folds
//! (the report's Fig. 4). Ranking quality is the mean average precision and
//! the precision at 10 of each test clip used as a query against the
//! training clips (relevant = same class).
//!
//! Two experiments go beyond the report:
//!
//! - **unseen classes**: for each class, a forest is trained without it; its
//!   clips then query the whole library, and the ranking is scored on
//!   finding the other clips of that class (histogram distance, forest
//!   proximity, feature distance);
//! - **long takes**: held-out clips are joined end to end into long takes;
//!   for every class in a take a training clip of that class is the query,
//!   and the returned time ranges are scored against the joined clips.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use rand::rngs::Xoshiro256PlusPlus;
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::clips::{load_clips, motion_files, progress_bar, Clip};
use crate::dtw::{dtw_distance, euclidean};
use crate::error::{Result, SearchError};
use crate::features::VALUE_COUNT;
use crate::forest::{argmax, Forest, Samples, Tree};
use crate::index::{build_index, nearest, value_statistics, IndexConfig, Ranking};
use crate::intervals::{FeatureSequence, IntervalLayout};
use crate::labels::LabelRule;
use crate::scores::{average_precision, precision_at, ClassScores, ConfusionMatrix};
use crate::take::{overlap, search_take, TakeMethod, TakeSearchConfig};

/// How clips are split into training and test clips.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SplitRule {
    /// Stratified `k`-fold cross-validation over takes: the clips of every
    /// class are shuffled and dealt to `k` folds; each fold is the test set
    /// once, so every clip is tested exactly once.
    Folds { k: usize },
    /// Leave one performer out: one fold per performer.
    ByPerformer,
    /// Training and test clips given separately (e.g. two folders).
    Given,
}

impl std::fmt::Display for SplitRule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SplitRule::Folds { k } => {
                write!(f, "{k}-fold cross-validation by take, stratified by class")
            }
            SplitRule::ByPerformer => write!(f, "leave one performer out"),
            SplitRule::Given => write!(f, "given training and test clips"),
        }
    }
}

/// What to evaluate and how.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EvalConfig {
    pub index: IndexConfig,
    pub split: SplitRule,
    /// Seed of the fold assignment and of the long-take experiment.
    pub seed: u64,
    /// Classes with fewer clips are left out (they cannot be both trained
    /// and tested); they are listed in the report.
    pub min_clips_per_class: usize,
    /// Besides the macro average over all classes, the report gives the
    /// macro average over the classes with at least this many test clips
    /// (pooled over the folds; in k-fold cross-validation, all their clips).
    #[serde(default = "default_min_clips_for_average")]
    pub min_clips_for_average: usize,
    /// Frames each clip is resampled to for DTW.
    pub dtw_frames: usize,
    /// Also run the deterministic tree, the random tree and DTW.
    pub baselines: bool,
    /// Run the unseen-class experiment (one forest per class).
    pub unseen_classes: bool,
    /// Run the long-take experiment (on the first fold).
    pub takes: bool,
    /// Clips joined into one take in the long-take experiment.
    pub clips_per_take: usize,
    /// Progress bars on a terminal.
    pub progress: bool,
}

/// Ten clips: two test clips in every fold of a 5-fold split.
fn default_min_clips_for_average() -> usize {
    10
}

impl Default for EvalConfig {
    fn default() -> Self {
        EvalConfig {
            index: IndexConfig::default(),
            split: SplitRule::Folds { k: 5 },
            seed: 1,
            min_clips_per_class: 2,
            min_clips_for_average: default_min_clips_for_average(),
            dtw_frames: 30,
            baselines: true,
            unseen_classes: true,
            takes: true,
            clips_per_take: 20,
            progress: false,
        }
    }
}

/// Classification scores of one method, pooled over the folds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodScores {
    pub method: String,
    pub accuracy: f64,
    /// Macro average over all classes.
    pub average: ClassScores,
    /// Macro average over the classes with at least
    /// [`EvalConfig::min_clips_for_average`] test clips, and how many
    /// classes that is.
    pub average_enough_clips: ClassScores,
    pub classes_enough_clips: usize,
    /// In the order of [`EvalReport::classes`].
    pub per_class: Vec<ClassScores>,
    pub confusion: ConfusionMatrix,
    /// Seconds spent training, summed over the folds.
    pub train_seconds: f64,
    /// Seconds spent classifying the test clips, summed over the folds.
    pub test_seconds: f64,
}

/// Ranking quality of one way of ranking.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RankingScores {
    pub ranking: String,
    pub mean_average_precision: f64,
    pub precision_at_10: f64,
    pub queries: usize,
}

/// The unseen-class experiment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnseenReport {
    /// Per ranking, averaged over the held-out classes.
    pub rankings: Vec<RankingScores>,
    /// Per held-out class, the mean average precision of each ranking (in
    /// the order of `rankings`).
    pub per_class: Vec<(String, Vec<f64>)>,
    /// Mean average precision of a random ranking, for reference.
    pub chance_map: f64,
    /// Whether a query's class is in the library at all, told by the
    /// forest's top class probability: per threshold, the share of clips of
    /// trained classes (cross-validation test clips) and of clips of the
    /// held-out class that fall below it.
    #[serde(default)]
    pub novelty: Vec<NoveltyRow>,
}

/// One threshold of [`UnseenReport::novelty`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoveltyRow {
    /// Top class probability below which a query is called "not in the
    /// library".
    pub threshold: f32,
    /// Share of clips of trained classes called so (false alarms).
    pub known_below: f64,
    /// Share of clips of classes the forest never saw called so.
    pub unseen_below: f64,
}

/// The top class probabilities [`UnseenReport::novelty`] is measured at.
const NOVELTY_THRESHOLDS: [f32; 6] = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8];

/// The long-take experiment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TakeEvalReport {
    pub takes: usize,
    pub take_seconds: f64,
    pub queries: usize,
    pub rankings: Vec<TakeMethodScores>,
}

/// How well one method finds the clips of the query's class in a take.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TakeMethodScores {
    pub method: String,
    /// Fraction of the top-k ranges (k = number of clips of the query's
    /// class in the take) that overlap a distinct clip of that class with
    /// intersection over union at least 0.5.
    pub iou_hits: f64,
    /// Fraction of the top-k ranges whose centre lies in a clip of that
    /// class.
    pub centre_hits: f64,
    /// Mean milliseconds per search of one take.
    pub milliseconds_per_search: f64,
}

/// Everything the evaluation measured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EvalReport {
    pub dataset: String,
    pub label_rule: String,
    pub split: String,
    pub folds: usize,
    pub clips: usize,
    pub classes: Vec<String>,
    /// Classes left out for having too few clips, with their clip count.
    pub excluded_classes: Vec<(String, usize)>,
    pub config: EvalConfig,
    pub methods: Vec<MethodScores>,
    pub ranking: Vec<RankingScores>,
    pub unseen: Option<UnseenReport>,
    pub takes: Option<TakeEvalReport>,
    pub notes: Vec<String>,
    /// Seconds the whole evaluation took.
    pub seconds: f64,
}

/// Training and test clips of one fold, as indices into the clip list.
#[derive(Debug, Clone)]
pub struct Fold {
    pub train: Vec<usize>,
    pub test: Vec<usize>,
}

/// What is computed once per clip.
struct Prepared {
    labels: Vec<u32>,
    /// Interval means of every clip, `layout.dim()` each.
    rows: Vec<f32>,
    dim: usize,
    /// Resampled to `N` frames.
    resampled: Vec<FeatureSequence>,
    /// Resampled to `dtw_frames` frames.
    dtw: Vec<FeatureSequence>,
}

impl Prepared {
    fn row(&self, k: usize) -> &[f32] {
        &self.rows[k * self.dim..(k + 1) * self.dim]
    }
}

/// `mocap search eval`: reads the clips of `inputs` (files, or folders
/// searched for `.bvh` and `.amc`), labels them by `rule` and evaluates:
/// split by `config.split` ([`evaluate`]), or, when `test` names files or
/// folders, trained on `inputs` and tested on those
/// ([`evaluate_train_test`]). `rule_name` names the rule and `dataset` the
/// data in the report (default: the inputs joined by ` + `).
pub fn evaluate_files(
    inputs: &[PathBuf],
    test: &[PathBuf],
    rule: &LabelRule,
    rule_name: &str,
    dataset: Option<&str>,
    config: &EvalConfig,
) -> Result<EvalReport> {
    let dataset = dataset.map(str::to_string).unwrap_or_else(|| {
        let names: Vec<String> = inputs.iter().map(|d| d.display().to_string()).collect();
        names.join(" + ")
    });
    let clips = load_clips(&motion_files(inputs)?, rule, config.progress)?;
    if test.is_empty() {
        evaluate(&clips, &dataset, rule_name, config)
    } else {
        let test = load_clips(&motion_files(test)?, rule, config.progress)?;
        evaluate_train_test(&clips, &test, &dataset, rule_name, config)
    }
}

/// Evaluates on labelled clips split by `config.split` (folds or
/// performers). `dataset` and `label_rule` name the data in the report.
pub fn evaluate(
    clips: &[Clip],
    dataset: &str,
    label_rule: &str,
    config: &EvalConfig,
) -> Result<EvalReport> {
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for c in clips {
        *counts.entry(c.label.as_str()).or_default() += 1;
    }
    let excluded: Vec<(String, usize)> = counts
        .iter()
        .filter(|(_, &n)| n < config.min_clips_per_class)
        .map(|(l, &n)| (l.to_string(), n))
        .collect();
    let kept: Vec<Clip> = clips
        .iter()
        .filter(|c| counts[c.label.as_str()] >= config.min_clips_per_class)
        .cloned()
        .collect();
    let classes: Vec<String> = counts
        .iter()
        .filter(|(_, &n)| n >= config.min_clips_per_class)
        .map(|(l, _)| l.to_string())
        .collect();
    if classes.len() < 2 {
        return Err(SearchError::Invalid(format!(
            "{} classes with at least {} clips; the evaluation needs two",
            classes.len(),
            config.min_clips_per_class
        )));
    }
    let labels = label_indices(&kept, &classes);
    let folds = match &config.split {
        SplitRule::Folds { k } => stratified_folds(&labels, classes.len(), *k, config.seed)?,
        SplitRule::ByPerformer => performer_folds(&kept)?,
        SplitRule::Given => {
            return Err(SearchError::Invalid(
                "a given split needs training and test clips: use evaluate_train_test".into(),
            ))
        }
    };
    let mut report = run(&kept, &classes, &folds, dataset, label_rule, config)?;
    report.excluded_classes = excluded;
    Ok(report)
}

/// Evaluates with training and test clips given separately. Test clips of
/// a class absent from the training clips count as errors.
pub fn evaluate_train_test(
    train: &[Clip],
    test: &[Clip],
    dataset: &str,
    label_rule: &str,
    config: &EvalConfig,
) -> Result<EvalReport> {
    if train.is_empty() || test.is_empty() {
        return Err(SearchError::Invalid(
            "the evaluation needs training and test clips".into(),
        ));
    }
    let clips: Vec<Clip> = train.iter().chain(test).cloned().collect();
    let mut classes: Vec<String> = clips.iter().map(|c| c.label.clone()).collect();
    classes.sort();
    classes.dedup();
    let folds = vec![Fold {
        train: (0..train.len()).collect(),
        test: (train.len()..clips.len()).collect(),
    }];
    let config = EvalConfig {
        split: SplitRule::Given,
        ..config.clone()
    };
    let mut report = run(&clips, &classes, &folds, dataset, label_rule, &config)?;
    let unseen: Vec<&String> = classes
        .iter()
        .filter(|c| !train.iter().any(|t| &&t.label == c))
        .collect();
    if !unseen.is_empty() {
        report.notes.push(format!(
            "test classes absent from the training clips (always wrong): {}",
            unseen
                .iter()
                .map(|s| s.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    Ok(report)
}

fn label_indices(clips: &[Clip], classes: &[String]) -> Vec<u32> {
    clips
        .iter()
        .map(|c| classes.binary_search(&c.label).expect("class listed") as u32)
        .collect()
}

/// Deals the clips of every class, shuffled, to `k` folds. The deal of each
/// class starts where the previous class's ended, so that small classes do
/// not all land in the first folds. `labels[i]` is clip `i`'s class, below
/// `classes`; folds with no test or no training clip are left out. Public so
/// that another classifier can be tested on the very folds `evaluate` uses.
pub fn stratified_folds(labels: &[u32], classes: usize, k: usize, seed: u64) -> Result<Vec<Fold>> {
    if k < 2 {
        return Err(SearchError::Invalid(format!(
            "cross-validation needs at least 2 folds, got {k}"
        )));
    }
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut fold_of = vec![0usize; labels.len()];
    let mut next = 0usize;
    for class in 0..classes as u32 {
        let mut members: Vec<usize> = (0..labels.len()).filter(|&i| labels[i] == class).collect();
        members.shuffle(&mut rng);
        for m in members {
            fold_of[m] = next % k;
            next += 1;
        }
    }
    Ok((0..k)
        .map(|f| Fold {
            train: (0..labels.len()).filter(|&i| fold_of[i] != f).collect(),
            test: (0..labels.len()).filter(|&i| fold_of[i] == f).collect(),
        })
        .filter(|f| !f.test.is_empty() && !f.train.is_empty())
        .collect())
}

fn performer_folds(clips: &[Clip]) -> Result<Vec<Fold>> {
    let mut performers: Vec<&str> = Vec::new();
    for c in clips {
        let p = c.performer.as_deref().ok_or_else(|| {
            SearchError::Invalid(format!(
                "{}: no performer; a split by performer needs `{{performer}}` in the label pattern or a performer column in the label file",
                c.path.display()
            ))
        })?;
        if !performers.contains(&p) {
            performers.push(p);
        }
    }
    if performers.len() < 2 {
        return Err(SearchError::Invalid(format!(
            "a split by performer needs at least two performers, found {}",
            performers.len()
        )));
    }
    performers.sort();
    Ok(performers
        .iter()
        .map(|p| Fold {
            train: (0..clips.len())
                .filter(|&i| clips[i].performer.as_deref() != Some(p))
                .collect(),
            test: (0..clips.len())
                .filter(|&i| clips[i].performer.as_deref() == Some(p))
                .collect(),
        })
        .collect())
}

/// Accumulates one method's results over the folds.
struct Tally {
    method: String,
    confusion: ConfusionMatrix,
    train_seconds: f64,
    test_seconds: f64,
}

impl Tally {
    fn new(method: &str, classes: usize) -> Tally {
        Tally {
            method: method.into(),
            confusion: ConfusionMatrix::new(classes),
            train_seconds: 0.0,
            test_seconds: 0.0,
        }
    }

    fn scores(self, min_clips: usize) -> MethodScores {
        let classes = self.confusion.classes();
        let min_support = u32::try_from(min_clips).unwrap_or(u32::MAX);
        MethodScores {
            method: self.method,
            accuracy: self.confusion.accuracy(),
            average: self.confusion.macro_average(),
            average_enough_clips: self.confusion.macro_average_over(min_support),
            classes_enough_clips: (0..classes)
                .filter(|&c| self.confusion.class_scores(c).support >= min_support.max(1))
                .count(),
            per_class: (0..classes)
                .map(|c| self.confusion.class_scores(c))
                .collect(),
            confusion: self.confusion,
            train_seconds: self.train_seconds,
            test_seconds: self.test_seconds,
        }
    }
}

/// Average precision and precision at 10 summed over queries.
#[derive(Default)]
struct RankTally {
    ap: f64,
    p10: f64,
    queries: usize,
}

impl RankTally {
    /// Scores one query given its distances to the library clips.
    fn add(&mut self, distances: &[f32], library_labels: &[u32], label: u32) {
        let order = nearest(distances, distances.len());
        let relevant: Vec<bool> = order.iter().map(|&k| library_labels[k] == label).collect();
        let total = library_labels.iter().filter(|&&l| l == label).count();
        if total == 0 {
            return;
        }
        self.ap += average_precision(&relevant, total);
        self.p10 += precision_at(&relevant, 10);
        self.queries += 1;
    }

    fn scores(&self, name: &str) -> RankingScores {
        let n = self.queries.max(1) as f64;
        RankingScores {
            ranking: name.into(),
            mean_average_precision: self.ap / n,
            precision_at_10: self.p10 / n,
            queries: self.queries,
        }
    }
}

fn prepare(clips: &[Clip], labels: Vec<u32>, config: &EvalConfig) -> Prepared {
    let layout = IntervalLayout::all(config.index.frames, VALUE_COUNT);
    let resampled: Vec<FeatureSequence> = clips
        .par_iter()
        .map(|c| c.features.resample(config.index.frames))
        .collect();
    let rows: Vec<f32> = resampled
        .par_iter()
        .flat_map_iter(|r| layout.interval_means(r))
        .collect();
    let dtw = clips
        .par_iter()
        .map(|c| c.features.resample(config.dtw_frames))
        .collect();
    Prepared {
        labels,
        rows,
        dim: layout.dim(),
        resampled,
        dtw,
    }
}

/// Standardises every frame of `clip` with per-value mean and scale.
fn standardised(clip: &FeatureSequence, mean: &[f32], scale: &[f32]) -> FeatureSequence {
    FeatureSequence {
        dim: clip.dim,
        values: clip
            .values
            .iter()
            .enumerate()
            .map(|(k, v)| (v - mean[k % clip.dim]) / scale[k % clip.dim])
            .collect(),
    }
}

fn run(
    clips: &[Clip],
    classes: &[String],
    folds: &[Fold],
    dataset: &str,
    label_rule: &str,
    config: &EvalConfig,
) -> Result<EvalReport> {
    let started = Instant::now();
    let labels = label_indices(clips, classes);
    let data = prepare(clips, labels, config);
    let c = classes.len();
    let mut forest_tally = Tally::new("forest", c);
    // The top class probability of every test clip (of a trained class).
    let mut known_top = Vec::new();
    let mut det_tally = Tally::new("deterministic tree", c);
    let mut random_tally = Tally::new("random tree", c);
    let mut dtw_tally = Tally::new("DTW 1-NN", c);
    let mut rank_in_sample = RankTally::default();
    let mut rank_oob = RankTally::default();
    let mut rank_proximity = RankTally::default();
    let mut rank_features = RankTally::default();
    let mut rank_dtw = RankTally::default();
    let bar = progress_bar(folds.len(), "folds", config.progress);
    for (fold_number, fold) in folds.iter().enumerate() {
        let train_rows: Vec<f32> = fold
            .train
            .iter()
            .flat_map(|&k| data.row(k).iter().copied())
            .collect();
        let train_labels: Vec<u32> = fold.train.iter().map(|&k| data.labels[k]).collect();
        let samples =
            Samples::new(&train_rows, data.dim, &train_labels, c).map_err(SearchError::Invalid)?;
        let seeded = ForestSeed(config.index.forest.seed ^ fold_number as u64);

        // The forest.
        let t = Instant::now();
        let mut forest_config = config.index.forest.clone();
        forest_config.seed = seeded.0;
        let forest = Forest::train(&samples, &forest_config, &|| {});
        forest_tally.train_seconds += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let test_histograms: Vec<Vec<f32>> = fold
            .test
            .iter()
            .map(|&k| forest.predict(data.row(k)))
            .collect();
        forest_tally.test_seconds += t.elapsed().as_secs_f64();
        for (&k, h) in fold.test.iter().zip(&test_histograms) {
            forest_tally
                .confusion
                .add(data.labels[k] as usize, argmax(h));
            known_top.push(h.iter().copied().fold(0.0, f32::max));
        }

        // Ranking: test clips query the training clips.
        let library_in_sample: Vec<Vec<f32>> = fold
            .train
            .iter()
            .map(|&k| forest.predict(data.row(k)))
            .collect();
        let library_oob: Vec<Vec<f32>> = fold
            .train
            .iter()
            .enumerate()
            .map(|(s, &k)| forest.predict_out_of_bag(data.row(k), s))
            .collect();
        let library_leaves: Vec<Vec<u32>> = fold
            .train
            .iter()
            .map(|&k| forest.leaves(data.row(k)))
            .collect();
        let train_resampled: Vec<FeatureSequence> = fold
            .train
            .iter()
            .map(|&k| data.resampled[k].clone())
            .collect();
        let (mean, scale) = value_statistics(&train_resampled);
        let library_features: Vec<FeatureSequence> = train_resampled
            .iter()
            .map(|r| standardised(r, &mean, &scale))
            .collect();
        for (&k, h) in fold.test.iter().zip(&test_histograms) {
            let label = data.labels[k];
            let d: Vec<f32> = library_in_sample.iter().map(|l| euclidean(h, l)).collect();
            rank_in_sample.add(&d, &train_labels, label);
            let d: Vec<f32> = library_oob.iter().map(|l| euclidean(h, l)).collect();
            rank_oob.add(&d, &train_labels, label);
            let leaves = forest.leaves(data.row(k));
            let d: Vec<f32> = library_leaves
                .iter()
                .map(|l| 1.0 - forest.path_proximity(&leaves, l))
                .collect();
            rank_proximity.add(&d, &train_labels, label);
            let q = standardised(&data.resampled[k], &mean, &scale);
            let d: Vec<f32> = library_features
                .iter()
                .map(|l| euclidean(&q.values, &l.values))
                .collect();
            rank_features.add(&d, &train_labels, label);
        }

        if config.baselines {
            // A single random tree on all training clips.
            let t = Instant::now();
            let all: Vec<u32> = (0..samples.len() as u32).collect();
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(seeded.0);
            let tree = Tree::train(&samples, &all, &config.index.forest.tree, &mut rng);
            random_tally.train_seconds += t.elapsed().as_secs_f64();
            let t = Instant::now();
            for &k in &fold.test {
                random_tally
                    .confusion
                    .add(data.labels[k] as usize, argmax(tree.histogram(data.row(k))));
            }
            random_tally.test_seconds += t.elapsed().as_secs_f64();

            // The deterministic tree.
            let t = Instant::now();
            let tree = Tree::train_deterministic(&samples, &config.index.forest.tree);
            det_tally.train_seconds += t.elapsed().as_secs_f64();
            let t = Instant::now();
            for &k in &fold.test {
                det_tally
                    .confusion
                    .add(data.labels[k] as usize, argmax(tree.histogram(data.row(k))));
            }
            det_tally.test_seconds += t.elapsed().as_secs_f64();

            // DTW nearest neighbour on standardised features; "training"
            // is computing the standardisation.
            let t = Instant::now();
            let train_dtw: Vec<FeatureSequence> =
                fold.train.iter().map(|&k| data.dtw[k].clone()).collect();
            let (mean, scale) = value_statistics(&train_dtw);
            let library: Vec<FeatureSequence> = train_dtw
                .iter()
                .map(|s| standardised(s, &mean, &scale))
                .collect();
            dtw_tally.train_seconds += t.elapsed().as_secs_f64();
            let t = Instant::now();
            let distances: Vec<Vec<f32>> = fold
                .test
                .par_iter()
                .map(|&k| {
                    let q = standardised(&data.dtw[k], &mean, &scale);
                    library.iter().map(|l| dtw_distance(&q, l)).collect()
                })
                .collect();
            dtw_tally.test_seconds += t.elapsed().as_secs_f64();
            for (&k, d) in fold.test.iter().zip(&distances) {
                let best = nearest(d, 1)[0];
                dtw_tally
                    .confusion
                    .add(data.labels[k] as usize, train_labels[best] as usize);
                rank_dtw.add(d, &train_labels, data.labels[k]);
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();

    let min_clips = config.min_clips_for_average;
    let mut methods = vec![forest_tally.scores(min_clips)];
    let mut ranking = vec![
        rank_in_sample.scores("forest histogram, eq. 8 (library histograms in-sample)"),
        rank_oob.scores("forest histogram, eq. 8 (library histograms out-of-bag)"),
        rank_proximity.scores("forest path proximity"),
        rank_features.scores("feature distance (standardised, N frames)"),
    ];
    if config.baselines {
        methods.push(det_tally.scores(min_clips));
        methods.push(random_tally.scores(min_clips));
        methods.push(dtw_tally.scores(min_clips));
        ranking.push(rank_dtw.scores("DTW distance"));
    }
    let unseen = if config.unseen_classes {
        Some(unseen_classes(&data, classes, config, &known_top)?)
    } else {
        None
    };
    let takes = if config.takes {
        long_takes(clips, &data, &folds[0], classes, config)?
    } else {
        None
    };
    Ok(EvalReport {
        dataset: dataset.into(),
        label_rule: label_rule.into(),
        split: config.split.to_string(),
        folds: folds.len(),
        clips: clips.len(),
        classes: classes.to_vec(),
        excluded_classes: Vec::new(),
        config: config.clone(),
        methods,
        ranking,
        unseen,
        takes,
        notes: Vec::new(),
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// A forest seed derived for one fold.
struct ForestSeed(u64);

/// Leave one class out of training; its clips then query the whole
/// library.
fn unseen_classes(
    data: &Prepared,
    classes: &[String],
    config: &EvalConfig,
    known_top: &[f32],
) -> Result<UnseenReport> {
    let mut unseen_top = Vec::new();
    let names = [Ranking::Histogram, Ranking::Proximity, Ranking::Features].map(Ranking::describe);
    let (mean, scale) = value_statistics(&data.resampled);
    let features: Vec<FeatureSequence> = data
        .resampled
        .iter()
        .map(|r| standardised(r, &mean, &scale))
        .collect();
    let n = data.labels.len();
    let mut per_class = Vec::new();
    let mut totals = [0.0f64; 3];
    let mut p10 = [0.0f64; 3];
    let mut chance = 0.0;
    let bar = progress_bar(classes.len(), "unseen", config.progress);
    for (held_out, name) in classes.iter().enumerate() {
        let held_out = held_out as u32;
        let members: Vec<usize> = (0..n).filter(|&k| data.labels[k] == held_out).collect();
        let train: Vec<usize> = (0..n).filter(|&k| data.labels[k] != held_out).collect();
        // Relabel the remaining classes 0..c-1 for training.
        let remap = |l: u32| if l > held_out { l - 1 } else { l };
        let rows: Vec<f32> = train
            .iter()
            .flat_map(|&k| data.row(k).iter().copied())
            .collect();
        let labels: Vec<u32> = train.iter().map(|&k| remap(data.labels[k])).collect();
        let samples = Samples::new(&rows, data.dim, &labels, classes.len() - 1)
            .map_err(SearchError::Invalid)?;
        let forest = Forest::train(&samples, &config.index.forest, &|| {});
        let histograms: Vec<Vec<f32>> = (0..n).map(|k| forest.predict(data.row(k))).collect();
        let leaves: Vec<Vec<u32>> = (0..n).map(|k| forest.leaves(data.row(k))).collect();
        let mut tallies = [
            RankTally::default(),
            RankTally::default(),
            RankTally::default(),
        ];
        for &q in &members {
            unseen_top.push(histograms[q].iter().copied().fold(0.0, f32::max));
            // The library is every other clip; relevant = the held-out class.
            let others: Vec<usize> = (0..n).filter(|&k| k != q).collect();
            let library_labels: Vec<u32> = others.iter().map(|&k| data.labels[k]).collect();
            let d: Vec<f32> = others
                .iter()
                .map(|&k| euclidean(&histograms[q], &histograms[k]))
                .collect();
            tallies[0].add(&d, &library_labels, held_out);
            let d: Vec<f32> = others
                .iter()
                .map(|&k| 1.0 - forest.path_proximity(&leaves[q], &leaves[k]))
                .collect();
            tallies[1].add(&d, &library_labels, held_out);
            let d: Vec<f32> = others
                .iter()
                .map(|&k| euclidean(&features[q].values, &features[k].values))
                .collect();
            tallies[2].add(&d, &library_labels, held_out);
        }
        let maps: Vec<f64> = tallies
            .iter()
            .map(|t| t.scores("").mean_average_precision)
            .collect();
        for m in 0..3 {
            totals[m] += maps[m];
            p10[m] += tallies[m].scores("").precision_at_10;
        }
        chance += (members.len() - 1) as f64 / (n - 1) as f64;
        per_class.push((name.clone(), maps));
        bar.inc(1);
    }
    bar.finish_and_clear();
    let c = classes.len() as f64;
    Ok(UnseenReport {
        rankings: (0..3)
            .map(|m| RankingScores {
                ranking: names[m].into(),
                mean_average_precision: totals[m] / c,
                precision_at_10: p10[m] / c,
                queries: n,
            })
            .collect(),
        per_class,
        chance_map: chance / c,
        novelty: NOVELTY_THRESHOLDS
            .iter()
            .map(|&t| {
                let below =
                    |v: &[f32]| v.iter().filter(|&&p| p < t).count() as f64 / v.len().max(1) as f64;
                NoveltyRow {
                    threshold: t,
                    known_below: below(known_top),
                    unseen_below: below(&unseen_top),
                }
            })
            .collect(),
    })
}

/// Joins the first fold's test clips into long takes and searches them
/// with training clips of each class the take contains.
fn long_takes(
    clips: &[Clip],
    data: &Prepared,
    fold: &Fold,
    classes: &[String],
    config: &EvalConfig,
) -> Result<Option<TakeEvalReport>> {
    let fps = clips[fold.test[0]].fps;
    if fold
        .test
        .iter()
        .chain(&fold.train)
        .any(|&k| (clips[k].fps - fps).abs() > 1e-6)
    {
        return Ok(None); // joining clips needs one frame rate
    }
    let train_clips: Vec<Clip> = fold.train.iter().map(|&k| clips[k].clone()).collect();
    let index = build_index(&train_clips, "eval", &config.index, false)?;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(config.seed);
    let mut order = fold.test.clone();
    order.shuffle(&mut rng);
    let mut by_class: Vec<Vec<usize>> = vec![Vec::new(); classes.len()];
    for &k in &fold.train {
        by_class[data.labels[k] as usize].push(k);
    }
    let methods = [
        (
            "subsequence DTW",
            TakeMethod::SubsequenceDtw,
            Ranking::Features,
        ),
        (
            "windows, feature distance",
            TakeMethod::Windows,
            Ranking::Features,
        ),
        (
            "windows, forest histogram",
            TakeMethod::Windows,
            Ranking::Histogram,
        ),
        (
            "windows, forest proximity",
            TakeMethod::Windows,
            Ranking::Proximity,
        ),
    ];
    let mut hits = [0.0f64; 4];
    let mut centre_hits = [0.0f64; 4];
    let mut method_seconds = [0.0f64; 4];
    let mut queries = 0usize;
    let mut takes = 0usize;
    let mut seconds = 0.0f64;
    for chunk in order.chunks(config.clips_per_take.max(2)) {
        // The take: the chunk's clips end to end; where each one lies.
        let mut values = Vec::new();
        let mut segments = Vec::new();
        for &k in chunk {
            let start = values.len() / VALUE_COUNT;
            values.extend_from_slice(&clips[k].features.values);
            segments.push((start, values.len() / VALUE_COUNT, data.labels[k]));
        }
        let take = FeatureSequence {
            dim: VALUE_COUNT,
            values,
        };
        takes += 1;
        seconds += take.frame_count() as f64 / fps;
        let mut present: Vec<u32> = segments.iter().map(|s| s.2).collect();
        present.sort();
        present.dedup();
        for class in present {
            let candidates = &by_class[class as usize];
            if candidates.is_empty() {
                continue;
            }
            let query = &clips[candidates[rng.random_range(0..candidates.len())]];
            let relevant: Vec<(usize, usize)> = segments
                .iter()
                .filter(|s| s.2 == class)
                .map(|s| (s.0, s.1))
                .collect();
            queries += 1;
            for (m, &(_, method, ranking)) in methods.iter().enumerate() {
                let search = TakeSearchConfig {
                    method,
                    ranking,
                    top: relevant.len(),
                    ..TakeSearchConfig::default()
                };
                let t = Instant::now();
                let found = search_take(&index, &query.features, fps, &take, fps, &search)?;
                method_seconds[m] += t.elapsed().as_secs_f64();
                let mut used = vec![false; relevant.len()];
                let mut hit = 0usize;
                let mut centre = 0usize;
                for f in &found {
                    let range = (f.start_frame, f.end_frame);
                    if let Some(r) = (0..relevant.len())
                        .find(|&r| !used[r] && overlap(range, relevant[r]) >= 0.5)
                    {
                        used[r] = true;
                        hit += 1;
                    }
                    let mid = (f.start_frame + f.end_frame) / 2;
                    if relevant.iter().any(|r| mid >= r.0 && mid < r.1) {
                        centre += 1;
                    }
                }
                hits[m] += hit as f64 / relevant.len() as f64;
                centre_hits[m] += centre as f64 / relevant.len() as f64;
            }
        }
    }
    let q = queries.max(1) as f64;
    Ok(Some(TakeEvalReport {
        takes,
        take_seconds: seconds / takes.max(1) as f64,
        queries,
        rankings: methods
            .iter()
            .enumerate()
            .map(|(m, (name, _, _))| TakeMethodScores {
                method: name.to_string(),
                iou_hits: hits[m] / q,
                centre_hits: centre_hits[m] / q,
                milliseconds_per_search: method_seconds[m] * 1000.0 / q,
            })
            .collect(),
    }))
}

impl EvalReport {
    /// Where some classes have fewer than
    /// [`EvalConfig::min_clips_for_average`] test clips: which, and every
    /// method's macro F over all classes beside its macro F over the others.
    fn small_classes_markdown(&self) -> String {
        let min = self.config.min_clips_for_average;
        let Some(first) = self.methods.first() else {
            return String::new();
        };
        let small: Vec<String> = self
            .classes
            .iter()
            .zip(&first.per_class)
            .filter(|(_, c)| c.support > 0 && (c.support as usize) < min)
            .map(|(name, c)| format!("{name} ({})", c.support))
            .collect();
        if small.is_empty() {
            return String::new();
        }
        let all = first.per_class.iter().filter(|c| c.support > 0).count();
        // In cross-validation a small class's test clip was learnt from its
        // class's few other clips; with given test clips, from the training
        // clips, however many.
        let why = match self.config.split {
            SplitRule::Given => "their F is 0 or 1 by a clip or two",
            _ => "each of their clips is classified by a forest that saw only the class's other few clips, so their F is 0 or 1 by a clip or two",
        };
        let mut s = format!(
            "\nThe F-measure above is the macro average over all {all} classes. {} of them have fewer than {min} test clips: {}; {why}. Both averages:\n\n| method | F, all {all} classes | F, the {} classes with >= {min} clips |\n| --- | ---: | ---: |\n",
            small.len(),
            small.join(", "),
            first.classes_enough_clips
        );
        for m in &self.methods {
            let enough = if first.classes_enough_clips == 0 {
                "-".to_string()
            } else {
                format!("{:.3}", m.average_enough_clips.f_measure)
            };
            s += &format!("| {} | {:.3} | {enough} |\n", m.method, m.average.f_measure);
        }
        s
    }

    /// The report as Markdown: setup, the classification table, per-class
    /// scores (Fig. 4), ranking quality, and the two extra experiments.
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        let f = &self.config.index.forest;
        s += &format!("### {} ({})\n\n", self.dataset, self.label_rule);
        s += &format!(
            "{} clips, {} classes, {} ({} folds). Clips resampled to N = {} frames, {} per-frame values, {} interval features. Forest: {} trees, {} candidate tests per node, stop at entropy <= {}, bootstrap {}. DTW on {} frames.\n\n",
            self.clips,
            self.classes.len(),
            self.split,
            self.folds,
            self.config.index.frames,
            VALUE_COUNT,
            VALUE_COUNT * self.config.index.frames * (self.config.index.frames + 1) / 2,
            f.trees,
            f.tree
                .candidates_per_node
                .map(|k| k.to_string())
                .unwrap_or_else(|| "all".into()),
            f.tree.min_entropy,
            f.bootstrap,
            self.config.dtw_frames,
        );
        if !self.excluded_classes.is_empty() {
            let list: Vec<String> = self
                .excluded_classes
                .iter()
                .map(|(c, n)| format!("{c} ({n})"))
                .collect();
            s += &format!(
                "Left out (fewer than {} clips): {}.\n\n",
                self.config.min_clips_per_class,
                list.join(", ")
            );
        }
        s += "| method | accuracy | precision | recall | F-measure | train s | test s |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: |\n";
        for m in &self.methods {
            s += &format!(
                "| {} | {:.3} | {:.3} | {:.3} | **{:.3}** | {:.2} | {:.3} |\n",
                m.method,
                m.accuracy,
                m.average.precision,
                m.average.recall,
                m.average.f_measure,
                m.train_seconds,
                m.test_seconds
            );
        }
        s += &self.small_classes_markdown();
        s += "\nPer class (precision / recall / F of the forest; F of the others):\n\n| class | clips | P | R | F |";
        for m in self.methods.iter().skip(1) {
            s += &format!(" F {} |", m.method);
        }
        s += "\n| --- | ---: | ---: | ---: | ---: |";
        for _ in self.methods.iter().skip(1) {
            s += " ---: |";
        }
        s += "\n";
        for (c, name) in self.classes.iter().enumerate() {
            let forest = &self.methods[0].per_class[c];
            s += &format!(
                "| {name} | {} | {:.3} | {:.3} | {:.3} |",
                forest.support, forest.precision, forest.recall, forest.f_measure
            );
            for m in self.methods.iter().skip(1) {
                s += &format!(" {:.3} |", m.per_class[c].f_measure);
            }
            s += "\n";
        }
        s += "\nRanking (test clips query the training clips; relevant = same class):\n\n| ranking | mAP | P@10 |\n| --- | ---: | ---: |\n";
        for r in &self.ranking {
            s += &format!(
                "| {} | {:.3} | {:.3} |\n",
                r.ranking, r.mean_average_precision, r.precision_at_10
            );
        }
        if let Some(u) = &self.unseen {
            s += &format!(
                "\nUnseen classes (each class left out of training in turn; its clips query all other clips; chance mAP {:.3}):\n\n| ranking | mAP | P@10 |\n| --- | ---: | ---: |\n",
                u.chance_map
            );
            for r in &u.rankings {
                s += &format!(
                    "| {} | {:.3} | {:.3} |\n",
                    r.ranking, r.mean_average_precision, r.precision_at_10
                );
            }
            s += "\n| held-out class |";
            for r in &u.rankings {
                s += &format!(" mAP {} |", r.ranking);
            }
            s += "\n| --- |";
            for _ in &u.rankings {
                s += " ---: |";
            }
            s += "\n";
            for (name, maps) in &u.per_class {
                s += &format!("| {name} |");
                for m in maps {
                    s += &format!(" {m:.3} |");
                }
                s += "\n";
            }
            if !u.novelty.is_empty() {
                s += "\nIs the query's class in the library at all? Called \"not in the library\" when the forest's top class probability is below a threshold: the share of test clips of trained classes (cross-validation) and of clips of the held-out class (above) so called:\n\n| top probability below | trained classes (false alarms) | held-out class (found) |\n| ---: | ---: | ---: |\n";
                for row in &u.novelty {
                    s += &format!(
                        "| {:.1} | {:.1}% | {:.1}% |\n",
                        row.threshold,
                        100.0 * row.known_below,
                        100.0 * row.unseen_below
                    );
                }
            }
        }
        if let Some(t) = &self.takes {
            s += &format!(
                "\nLong takes: {} takes of about {:.0} s made of held-out clips joined end to end, {} queries (a training clip of each class in the take; k = clips of that class in the take):\n\n| method | top-k ranges with IoU >= 0.5 | top-k range centres inside | ms per search |\n| --- | ---: | ---: | ---: |\n",
                t.takes, t.take_seconds, t.queries
            );
            for m in &t.rankings {
                s += &format!(
                    "| {} | {:.3} | {:.3} | {:.1} |\n",
                    m.method, m.iou_hits, m.centre_hits, m.milliseconds_per_search
                );
            }
        }
        for note in &self.notes {
            s += &format!("\nNote: {note}\n");
        }
        s += &format!("\nEvaluation time: {:.1} s.\n", self.seconds);
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stratified_folds_test_every_clip_once() {
        let labels: Vec<u32> = (0..23).map(|k| (k % 3) as u32).collect();
        let folds = stratified_folds(&labels, 3, 5, 9).unwrap();
        assert_eq!(folds.len(), 5);
        let mut tested = vec![0; labels.len()];
        for f in &folds {
            for &k in &f.test {
                tested[k] += 1;
                assert!(!f.train.contains(&k));
            }
            assert_eq!(f.train.len() + f.test.len(), labels.len());
            // Every class is in every fold's training set.
            for c in 0..3 {
                assert!(f.train.iter().any(|&k| labels[k] == c));
            }
        }
        assert!(tested.iter().all(|&t| t == 1));
        assert!(stratified_folds(&labels, 3, 1, 0).is_err());
    }
}
