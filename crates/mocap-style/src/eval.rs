//! Evaluation of style transfer on labelled clips: `mocap style eval`.
//!
//! For every set of clips (the part of the file name before the content,
//! e.g. Bandai's `dataset-1` and `dataset-2`, which have different styles):
//!
//! 1. The held-out takes ([`crate::data::held_out`], never seen by the
//!    shipped model) are the test clips; the others train two independent
//!    classifiers, one of style and one of content: the random forests of
//!    `mocap-search` over body-relative pose features (not the
//!    autoencoder's features, so the classifiers do not share its biases).
//! 2. Every pair (source, style clip) of test clips, the source's content in
//!    `source_contents` and the style clip's in `style_contents`, is
//!    restyled with every method ([`Method`]).
//! 3. Each output is scored: its style as classified against the style
//!    clip's label, its content against the source's label, its gait period
//!    against the style clip's and the source's ([`gait_period`]), foot
//!    skating ([`foot_skating`]) and jitter ([`mocap_core::metrics::jitter`]).
//!
//! The classifiers' accuracy on the real test clips is reported as their
//! ceiling, and the "source unchanged" row shows the style accuracy of doing
//! nothing.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use mocap_core::metrics::jitter;
use mocap_core::{forward_kinematics, Motion};
use mocap_nn::device::DeviceChoice;
use mocap_search::features::motion_features;
use mocap_search::forest::Samples;
use mocap_search::intervals::FeatureSequence;
use mocap_search::{build_index, Clip as SearchClip, Forest, ForestConfig, Index, IndexConfig};
use serde::{Deserialize, Serialize};

use crate::apply::{load_model, prepare_style, restyle, StageTimings, StyleClip};
use crate::convert::{ConvertOptions, Method};
use crate::data::{held_out, labelled_paths, list_bvh, load_clips, Clip, ClipFilter};
use crate::features::{up_axis, RigLayout};
use crate::filmstrip::{draw_filmstrip, FilmstripRow};
use crate::train::StyleModel;
use crate::{invalid, Result};

/// Options of `mocap style eval`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EvalOptions {
    /// Folders or files of labelled clips (`<set>_<content>_<style>_<take>.bvh`).
    pub inputs: Vec<PathBuf>,
    /// The model file; `None`: the shipped default model.
    pub model: Option<PathBuf>,
    pub methods: Vec<Method>,
    /// Contents of the source clips (all when empty).
    pub source_contents: Vec<String>,
    /// Contents of the style clips (all when empty).
    pub style_contents: Vec<String>,
    /// Clips the style classifier trains on (all non-held-out clips when
    /// empty); the content classifier always trains on every non-held-out
    /// clip.
    pub classifier_filter: ClipFilter,
    /// Patch length and stretch of the patch methods.
    pub convert: ConvertOptions,
    /// Trees of each classifier's forest.
    pub trees: usize,
    /// What the style classifier sees.
    pub style_descriptor: Descriptor,
    /// What the content classifier sees.
    pub content_descriptor: Descriptor,
    pub seed: u64,
    /// Folder for filmstrip PNGs (none when `None`).
    pub filmstrips: Option<PathBuf>,
    /// Filmstrips per set.
    pub filmstrip_count: usize,
    pub device: DeviceChoice,
}

impl Default for EvalOptions {
    fn default() -> Self {
        EvalOptions {
            inputs: Vec::new(),
            model: None,
            methods: Method::ALL.to_vec(),
            source_contents: Vec::new(),
            style_contents: Vec::new(),
            classifier_filter: ClipFilter::default(),
            convert: ConvertOptions::default(),
            trees: 100,
            style_descriptor: Descriptor::Statistics,
            content_descriptor: Descriptor::Intervals,
            seed: 1,
            filmstrips: None,
            filmstrip_count: 3,
            device: DeviceChoice::Cpu,
        }
    }
}

/// Scores of one method (or of the real clips) over the pairs of a set.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MethodScores {
    pub method: String,
    pub pairs: usize,
    /// Outputs classified as the style clip's style.
    pub style_accuracy: f64,
    /// The same, over the pairs whose real style clip the classifier
    /// itself classifies right (the method's accuracy within the
    /// classifier's reach).
    pub style_accuracy_recognised: f64,
    /// Pairs counted in `style_accuracy_recognised`.
    pub recognised_pairs: usize,
    /// Outputs classified as the source's content.
    pub content_accuracy: f64,
    /// Mean |period(output) - period(style clip)|, seconds.
    pub period_error_to_style: f64,
    /// Mean |period(output) - period(source)|, seconds.
    pub period_error_to_source: f64,
    /// Pairs whose output's period is closer to the style clip's than the
    /// source's is (among pairs where the two differ by more than 0.05 s).
    pub closer_to_style: f64,
    /// Pairs where a period could be measured on all three clips.
    pub timed_pairs: usize,
    /// Mean horizontal foot speed on the ground, file units per second.
    pub foot_skating: f64,
    /// Mean jerk of the joints, file units per frame^3.
    pub jitter: f64,
    /// Mean output duration over source duration.
    pub time_scale: f64,
    /// Mean seconds per restyle (prepare to compose, style encoding included).
    pub seconds_per_pair: f64,
}

/// One restyled pair.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PairResult {
    pub source: String,
    pub style_clip: String,
    pub method: Method,
    pub predicted_style: String,
    pub predicted_content: String,
    pub period_output: Option<f64>,
    pub period_style: Option<f64>,
    pub period_source: Option<f64>,
    pub foot_skating: f64,
    pub jitter: f64,
    pub time_scale: f64,
    pub timings: StageTimings,
}

/// The evaluation of one set of clips.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SetReport {
    pub set: String,
    pub styles: Vec<String>,
    pub contents: Vec<String>,
    pub classifier_clips: usize,
    pub test_clips: usize,
    /// Classifier accuracy on the real held-out clips (their ceiling); for
    /// style, over the held-out clips of the contents it was trained on.
    pub classifier_style_accuracy: f64,
    pub classifier_content_accuracy: f64,
    /// Chance level of the style classifier (1 / number of styles).
    pub style_chance: f64,
    /// Held-out clips too short to restyle or time (shorter than two patches).
    pub skipped_clips: Vec<String>,
    /// The real clips: "source unchanged" (scored against the style clip's
    /// label) and "style clip" (each style clip scored as itself).
    pub reference: Vec<MethodScores>,
    pub methods: Vec<MethodScores>,
    pub pairs: Vec<PairResult>,
    pub filmstrips: Vec<PathBuf>,
}

/// What `mocap style eval` reports.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EvalReport {
    pub model: String,
    pub options: EvalOptions,
    pub sets: Vec<SetReport>,
    pub seconds: f64,
}

/// What the classifiers' forests see of a window of a clip.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Descriptor {
    /// mocap-search's own rows: the window resampled to 10 frames and the
    /// means of every feature over every interval of them (pose over time).
    Intervals,
    /// The mean and standard deviation of every feature over the window
    /// (pose statistics, independent of timing).
    Statistics,
}

/// A random-forest classifier of clips (mocap-search's forest over its
/// body-relative pose features), trained on windows of the training clips
/// and voting over the windows of a clip: with a few takes per style,
/// windows give the forest many more samples, and the vote makes a clip's
/// label robust to one odd stride.
enum ClipClassifier {
    Intervals(Index),
    Statistics {
        forest: Forest,
        classes: Vec<String>,
    },
}

/// Window length and hop of the classifiers, seconds.
const CLASSIFIER_WINDOW: f64 = 2.0;
const CLASSIFIER_HOP: f64 = 0.5;

/// The windows of a clip's per-frame features (the whole clip when it is
/// shorter than a window).
fn feature_windows(motion: &Motion) -> Result<Vec<FeatureSequence>> {
    let features = motion_features(motion).map_err(search_error)?;
    let frames = features.frame_count();
    let window = ((CLASSIFIER_WINDOW * motion.fps()).round() as usize).max(2);
    let hop = ((CLASSIFIER_HOP * motion.fps()).round() as usize).max(1);
    if frames <= window {
        return Ok(vec![features]);
    }
    let d = features.dim;
    let mut out = Vec::new();
    let mut start = 0;
    loop {
        let s = start.min(frames - window);
        out.push(FeatureSequence {
            dim: d,
            values: features.values[s * d..(s + window) * d].to_vec(),
        });
        if s + window >= frames {
            break;
        }
        start += hop;
    }
    Ok(out)
}

/// Mean and standard deviation of every feature over a window.
fn statistics_row(w: &FeatureSequence) -> Vec<f32> {
    let n = w.frame_count().max(1) as f64;
    let mut row = vec![0.0f32; 2 * w.dim];
    for i in 0..w.dim {
        let mean = (0..w.frame_count())
            .map(|f| w.values[f * w.dim + i] as f64)
            .sum::<f64>()
            / n;
        let var = (0..w.frame_count())
            .map(|f| (w.values[f * w.dim + i] as f64 - mean).powi(2))
            .sum::<f64>()
            / n;
        row[i] = mean as f32;
        row[w.dim + i] = var.sqrt() as f32;
    }
    row
}

impl ClipClassifier {
    fn train(
        clips: &[(&Clip, String)],
        descriptor: Descriptor,
        trees: usize,
        seed: u64,
    ) -> Result<ClipClassifier> {
        let forest = ForestConfig {
            trees,
            seed,
            ..ForestConfig::default()
        };
        let mut windows = Vec::new();
        for (clip, label) in clips {
            for features in feature_windows(&clip.motion)? {
                windows.push((clip, label, features));
            }
        }
        match descriptor {
            Descriptor::Intervals => {
                let rows: Vec<SearchClip> = windows
                    .into_iter()
                    .map(|(clip, label, features)| SearchClip {
                        path: clip.path.clone(),
                        label: label.clone(),
                        performer: None,
                        fps: clip.motion.fps(),
                        features,
                    })
                    .collect();
                let config = IndexConfig {
                    forest,
                    ..IndexConfig::default()
                };
                let index =
                    build_index(&rows, "file name", &config, false).map_err(search_error)?;
                Ok(ClipClassifier::Intervals(index))
            }
            Descriptor::Statistics => {
                let mut classes: Vec<String> = windows.iter().map(|w| w.1.clone()).collect();
                classes.sort();
                classes.dedup();
                let labels: Vec<u32> = windows
                    .iter()
                    .map(|w| classes.binary_search(w.1).expect("listed") as u32)
                    .collect();
                let rows: Vec<f32> = windows.iter().flat_map(|w| statistics_row(&w.2)).collect();
                let dim = rows.len() / labels.len().max(1);
                let samples = Samples::new(&rows, dim, &labels, classes.len()).map_err(invalid)?;
                let forest = Forest::train(&samples, &forest, &|| {});
                Ok(ClipClassifier::Statistics { forest, classes })
            }
        }
    }

    /// The class with the largest summed forest histogram over the clip's
    /// windows.
    fn predict(&self, motion: &Motion) -> Result<String> {
        let classes = match self {
            ClipClassifier::Intervals(index) => &index.classes,
            ClipClassifier::Statistics { classes, .. } => classes,
        };
        let mut votes = vec![0.0f32; classes.len()];
        for features in feature_windows(motion)? {
            let histogram = match self {
                ClipClassifier::Intervals(index) => index.describe(&features).histogram,
                ClipClassifier::Statistics { forest, .. } => {
                    forest.predict(&statistics_row(&features))
                }
            };
            for (v, h) in votes.iter_mut().zip(&histogram) {
                *v += h;
            }
        }
        Ok(classes[mocap_search::forest::argmax(&votes)].clone())
    }
}

fn search_error(e: mocap_search::SearchError) -> crate::StyleError {
    invalid(format!("classifier: {e}"))
}

/// The gait period in seconds: the lag of the strongest autocorrelation of
/// the feet's heights between 0.4 and 2.5 s (the smallest lag within 90% of
/// the best, so that two strides are not taken for one). `None` when the
/// clip is too short or the feet do not move periodically (best
/// autocorrelation below 0.2).
pub fn gait_period(motion: &Motion, rig: &RigLayout) -> Option<f64> {
    let poses = forward_kinematics(motion);
    let up = up_axis(&poses.positions, poses.joint_count, rig);
    let fps = motion.fps();
    let n = poses.frame_count;
    let min_lag = (0.4 * fps).round() as usize;
    let max_lag = ((2.5 * fps).round() as usize).min(n.saturating_sub(n / 4));
    if max_lag <= min_lag + 2 {
        return None;
    }
    let signal = |joint: usize| -> Vec<f64> {
        let h: Vec<f64> = (0..n)
            .map(|f| poses.position(f, joint).dot(up) as f64)
            .collect();
        let mean = h.iter().sum::<f64>() / n as f64;
        h.into_iter().map(|x| x - mean).collect()
    };
    let feet = [signal(rig.left_foot[0]), signal(rig.right_foot[0])];
    // Normalised autocorrelation (mean over the overlap), summed over feet.
    let energy: f64 = feet
        .iter()
        .map(|s| s.iter().map(|x| x * x).sum::<f64>() / n as f64)
        .sum();
    if energy < 1e-9 {
        return None;
    }
    let r: Vec<f64> = (0..=max_lag)
        .map(|lag| {
            feet.iter()
                .map(|s| (0..n - lag).map(|t| s[t] * s[t + lag]).sum::<f64>() / (n - lag) as f64)
                .sum::<f64>()
                / energy
        })
        .collect();
    let peaks: Vec<usize> = (min_lag.max(1)..max_lag)
        .filter(|&l| r[l] >= r[l - 1] && r[l] >= r[l + 1])
        .collect();
    let best = peaks
        .iter()
        .map(|&l| r[l])
        .fold(f64::NEG_INFINITY, f64::max);
    if best < 0.2 {
        return None;
    }
    let lag = *peaks.iter().find(|&&l| r[l] >= 0.9 * best)?;
    // Parabolic interpolation of the peak for sub-frame precision.
    let (a, b, c) = (r[lag - 1], r[lag], r[lag + 1]);
    let denom = a - 2.0 * b + c;
    let offset = if denom.abs() > 1e-12 {
        0.5 * (a - c) / denom
    } else {
        0.0
    };
    Some((lag as f64 + offset.clamp(-0.5, 0.5)) / fps)
}

/// Foot skating: the mean horizontal speed (file units per second) of the
/// ankle and toe joints in the frames where they are on the ground, i.e.
/// within 5% of the leg length above the joint's lowest height in the clip
/// (its 2nd percentile, robust to a stray frame).
pub fn foot_skating(motion: &Motion, rig: &RigLayout) -> f64 {
    let poses = forward_kinematics(motion);
    let up = up_axis(&poses.positions, poses.joint_count, rig);
    let n = poses.frame_count;
    if n < 2 {
        return 0.0;
    }
    let tolerance = 0.05 * rig.leg_length(motion.skeleton());
    let fps = motion.fps() as f32;
    let mut sum = 0.0f64;
    let mut count = 0usize;
    for &j in rig.left_foot.iter().chain(&rig.right_foot) {
        let mut heights: Vec<f32> = (0..n).map(|f| poses.position(f, j).dot(up)).collect();
        let h = heights.clone();
        heights.sort_by(|a, b| a.total_cmp(b));
        let ground = heights[(n - 1) * 2 / 100];
        for f in 1..n {
            if h[f] <= ground + tolerance && h[f - 1] <= ground + tolerance {
                let d = poses.position(f, j) - poses.position(f - 1, j);
                let horizontal = d - up * d.dot(up);
                sum += (horizontal.length() * fps) as f64;
                count += 1;
            }
        }
    }
    if count == 0 {
        0.0
    } else {
        sum / count as f64
    }
}

/// Mean jerk of all joints (see [`mocap_core::metrics::jitter`]).
fn motion_jitter(motion: &Motion) -> f64 {
    jitter(&forward_kinematics(motion), None).map_or(f64::NAN, |v| v as f64)
}

/// Runs the evaluation (see the module docs).
pub fn evaluate(options: &EvalOptions) -> Result<EvalReport> {
    let started = Instant::now();
    let model = load_model(options.model.as_deref(), options.device)?;
    let files = labelled_paths(&list_bvh(&options.inputs)?, &ClipFilter::default())?;
    let mut sets: BTreeMap<String, Vec<(PathBuf, crate::data::Labels)>> = BTreeMap::new();
    for f in files {
        sets.entry(f.1.set.clone()).or_default().push(f);
    }
    let mut reports = Vec::new();
    for (set, files) in sets {
        reports.push(evaluate_set(&model, &set, &files, options)?);
    }
    Ok(EvalReport {
        model: options
            .model
            .as_ref()
            .map_or("built-in default".to_string(), |p| p.display().to_string()),
        options: options.clone(),
        sets: reports,
        seconds: started.elapsed().as_secs_f64(),
    })
}

fn accepts(list: &[String], content: &str) -> bool {
    list.is_empty() || list.iter().any(|c| c == content)
}

fn evaluate_set(
    model: &StyleModel,
    set: &str,
    files: &[(PathBuf, crate::data::Labels)],
    options: &EvalOptions,
) -> Result<SetReport> {
    let held = held_out(files);
    let is_test = |p: &Path| {
        held.contains(
            &p.file_stem()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned(),
        )
    };
    let classifier_files: Vec<_> = files.iter().filter(|(p, _)| !is_test(p)).cloned().collect();
    let test_files: Vec<_> = files.iter().filter(|(p, _)| is_test(p)).cloned().collect();
    if classifier_files.is_empty() || test_files.is_empty() {
        return Err(invalid(format!(
            "set `{set}`: needs clips to train the classifiers and held-out clips (groups of two \
             takes or more) to test on"
        )));
    }
    let classifier_clips = load_clips(&classifier_files)?;
    let test_clips = load_clips(&test_files)?;
    let style_classifier = ClipClassifier::train(
        &classifier_clips
            .iter()
            .filter(|c| options.classifier_filter.accepts(&c.labels))
            .map(|c| (c, c.labels.style.clone()))
            .collect::<Vec<_>>(),
        options.style_descriptor,
        options.trees,
        options.seed,
    )?;
    let content_classifier = ClipClassifier::train(
        &classifier_clips
            .iter()
            .map(|c| (c, c.labels.content.clone()))
            .collect::<Vec<_>>(),
        options.content_descriptor,
        options.trees,
        options.seed + 1,
    )?;
    let mut styles: Vec<String> = classifier_clips
        .iter()
        .map(|c| c.labels.style.clone())
        .collect();
    styles.sort();
    styles.dedup();
    let mut contents: Vec<String> = classifier_clips
        .iter()
        .map(|c| c.labels.content.clone())
        .collect();
    contents.sort();
    contents.dedup();

    // Classifier ceilings on the real held-out clips (for style, over the
    // held-out clips of the contents the style classifier was trained on).
    let mut style_hits = 0;
    let mut style_tests = 0;
    let mut content_hits = 0;
    for c in &test_clips {
        if options.classifier_filter.accepts(&c.labels) {
            style_tests += 1;
            style_hits += (style_classifier.predict(&c.motion)? == c.labels.style) as usize;
        }
        content_hits += (content_classifier.predict(&c.motion)? == c.labels.content) as usize;
    }
    let rig = &model.description.rig;
    // Clips shorter than two patches give no patches to match or periods to
    // measure: they are left out of the pairs (and listed in the report).
    let min_seconds = 2.0 * options.convert.patch as f64 / model.description.fps;
    let long_enough = |c: &&Clip| c.motion.duration() >= min_seconds;
    let skipped_clips: Vec<String> = test_clips
        .iter()
        .filter(|c| !long_enough(c))
        .map(|c| format!("{} ({} frames)", c.name, c.motion.frame_count()))
        .collect();
    let sources: Vec<&Clip> = test_clips
        .iter()
        .filter(long_enough)
        .filter(|c| accepts(&options.source_contents, &c.labels.content))
        .collect();
    let style_clips: Vec<&Clip> = test_clips
        .iter()
        .filter(long_enough)
        .filter(|c| accepts(&options.style_contents, &c.labels.content))
        .collect();
    let mut prepared: Vec<StyleClip> = Vec::new();
    let mut prepare_times = Vec::new();
    for c in &style_clips {
        let mut t = StageTimings::default();
        prepared.push(prepare_style(
            model,
            &c.motion,
            &c.path.display().to_string(),
            &mut t,
        )?);
        prepare_times.push(t);
    }
    let periods: BTreeMap<String, Option<f64>> = test_clips
        .iter()
        .map(|c| (c.name.clone(), gait_period(&c.motion, rig)))
        .collect();

    let mut pairs = Vec::new();
    let mut source_rows = Vec::new();
    for source in &sources {
        for (k, style) in style_clips.iter().enumerate() {
            if source.name == style.name {
                continue;
            }
            for &method in &options.methods {
                let convert = ConvertOptions {
                    method,
                    ..options.convert
                };
                let restyled = restyle(
                    model,
                    &source.motion,
                    &[(&prepared[k], 1.0)],
                    &convert,
                    prepare_times[k],
                )?;
                let out = &restyled.motion;
                pairs.push(PairResult {
                    source: source.name.clone(),
                    style_clip: style.name.clone(),
                    method,
                    predicted_style: style_classifier.predict(out)?,
                    predicted_content: content_classifier.predict(out)?,
                    period_output: gait_period(out, rig),
                    period_style: periods[&style.name],
                    period_source: periods[&source.name],
                    foot_skating: foot_skating(out, rig),
                    jitter: motion_jitter(out),
                    time_scale: out.duration() / source.motion.duration(),
                    timings: restyled.timings,
                });
            }
            // The source left unchanged, scored against the style clip.
            source_rows.push(PairResult {
                source: source.name.clone(),
                style_clip: style.name.clone(),
                method: Method::ElasticPatches,
                predicted_style: style_classifier.predict(&source.motion)?,
                predicted_content: content_classifier.predict(&source.motion)?,
                period_output: periods[&source.name],
                period_style: periods[&style.name],
                period_source: periods[&source.name],
                foot_skating: foot_skating(&source.motion, rig),
                jitter: motion_jitter(&source.motion),
                time_scale: 1.0,
                timings: StageTimings::default(),
            });
        }
    }
    let filmstrips = match &options.filmstrips {
        Some(dir) => draw_filmstrips(
            model,
            dir,
            &sources,
            &style_clips,
            &prepared,
            &prepare_times,
            &periods,
            options,
        )?,
        None => Vec::new(),
    };
    if pairs.is_empty() {
        return Err(invalid(format!(
            "set `{set}`: no (source, style clip) pair among the held-out clips; check the \
             source and style contents"
        )));
    }
    let labels: BTreeMap<&str, &crate::data::Labels> = test_clips
        .iter()
        .map(|c| (c.name.as_str(), &c.labels))
        .collect();
    // Whether the style classifier recognises each real style clip.
    let mut recognised: BTreeMap<String, bool> = BTreeMap::new();
    for c in &style_clips {
        recognised.insert(
            c.name.clone(),
            style_classifier.predict(&c.motion)? == c.labels.style,
        );
    }
    let score = |name: String, rows: Vec<&PairResult>| -> MethodScores {
        let n = rows.len().max(1) as f64;
        let mean = |f: &dyn Fn(&PairResult) -> f64| rows.iter().map(|r| f(r)).sum::<f64>() / n;
        let timed: Vec<(f64, f64, f64)> = rows
            .iter()
            .filter_map(|r| Some((r.period_output?, r.period_style?, r.period_source?)))
            .collect();
        let tn = timed.len().max(1) as f64;
        let distinct: Vec<_> = timed.iter().filter(|t| (t.1 - t.2).abs() > 0.05).collect();
        let style_hit = |r: &PairResult| r.predicted_style == labels[r.style_clip.as_str()].style;
        let known: Vec<&&PairResult> = rows.iter().filter(|r| recognised[&r.style_clip]).collect();
        MethodScores {
            method: name,
            pairs: rows.len(),
            style_accuracy: mean(&|r| style_hit(r) as u8 as f64),
            style_accuracy_recognised: known.iter().filter(|r| style_hit(r)).count() as f64
                / known.len().max(1) as f64,
            recognised_pairs: known.len(),
            content_accuracy: mean(&|r| {
                (r.predicted_content == labels[r.source.as_str()].content) as u8 as f64
            }),
            period_error_to_style: timed.iter().map(|t| (t.0 - t.1).abs()).sum::<f64>() / tn,
            period_error_to_source: timed.iter().map(|t| (t.0 - t.2).abs()).sum::<f64>() / tn,
            closer_to_style: distinct
                .iter()
                .filter(|t| (t.0 - t.1).abs() < (t.2 - t.1).abs())
                .count() as f64
                / distinct.len().max(1) as f64,
            timed_pairs: timed.len(),
            foot_skating: mean(&|r| r.foot_skating),
            jitter: mean(&|r| r.jitter),
            time_scale: mean(&|r| r.time_scale),
            seconds_per_pair: mean(&|r| r.timings.total()),
        }
    };
    let methods = options
        .methods
        .iter()
        .map(|&m| {
            score(
                m.name().to_string(),
                pairs.iter().filter(|r| r.method == m).collect(),
            )
        })
        .collect();
    // Each style clip as itself (its style, its content, its own period).
    let style_rows: Vec<PairResult> = style_clips
        .iter()
        .map(|c| -> Result<PairResult> {
            Ok(PairResult {
                source: c.name.clone(),
                style_clip: c.name.clone(),
                method: Method::ElasticPatches,
                predicted_style: style_classifier.predict(&c.motion)?,
                predicted_content: content_classifier.predict(&c.motion)?,
                period_output: periods[&c.name],
                period_style: periods[&c.name],
                period_source: periods[&c.name],
                foot_skating: foot_skating(&c.motion, rig),
                jitter: motion_jitter(&c.motion),
                time_scale: 1.0,
                timings: StageTimings::default(),
            })
        })
        .collect::<Result<_>>()?;
    let reference = vec![
        score("source unchanged".into(), source_rows.iter().collect()),
        score("style clip itself".into(), style_rows.iter().collect()),
    ];
    Ok(SetReport {
        set: set.to_string(),
        style_chance: 1.0 / styles.len().max(1) as f64,
        styles,
        contents,
        classifier_clips: classifier_clips.len(),
        test_clips: test_clips.len(),
        classifier_style_accuracy: style_hits as f64 / style_tests.max(1) as f64,
        classifier_content_accuracy: content_hits as f64 / test_clips.len() as f64,
        skipped_clips,
        reference,
        methods,
        pairs,
        filmstrips,
    })
}

/// Filmstrips of the pairs of different styles whose gait periods differ
/// most (where the timing change shows), one row per method.
#[allow(clippy::too_many_arguments)]
fn draw_filmstrips(
    model: &StyleModel,
    dir: &Path,
    sources: &[&Clip],
    style_clips: &[&Clip],
    prepared: &[StyleClip],
    prepare_times: &[StageTimings],
    periods: &BTreeMap<String, Option<f64>>,
    options: &EvalOptions,
) -> Result<Vec<PathBuf>> {
    let mut candidates: Vec<(f64, usize, usize)> = Vec::new();
    for (i, source) in sources.iter().enumerate() {
        for (k, style) in style_clips.iter().enumerate() {
            if source.labels.style == style.labels.style {
                continue;
            }
            if let (Some(a), Some(b)) = (periods[&source.name], periods[&style.name]) {
                candidates.push(((a - b).abs(), i, k));
            }
        }
    }
    candidates.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut paths = Vec::new();
    let mut used_sources = Vec::new();
    for &(_, i, k) in &candidates {
        if paths.len() >= options.filmstrip_count {
            break;
        }
        // Different sources, for variety.
        if used_sources.contains(&i) {
            continue;
        }
        used_sources.push(i);
        let (source, style) = (sources[i], style_clips[k]);
        let mut outputs = Vec::new();
        for &method in &options.methods {
            let convert = ConvertOptions {
                method,
                ..options.convert
            };
            let r = restyle(
                model,
                &source.motion,
                &[(&prepared[k], 1.0)],
                &convert,
                prepare_times[k],
            )?;
            outputs.push((method, r.motion));
        }
        std::fs::create_dir_all(dir).map_err(|e| mocap_core::Error::io(dir, e))?;
        let path = dir.join(format!("{}__{}.png", source.name, style.name));
        let mut rows = vec![
            FilmstripRow::new(format!("source: {}", source.name), &source.motion),
            FilmstripRow::new(format!("style: {}", style.name), &style.motion),
        ];
        for (m, motion) in &outputs {
            rows.push(FilmstripRow::new(format!("output: {}", m.name()), motion));
        }
        draw_filmstrip(&path, &rows, &model.description.rig, 8)?;
        paths.push(path);
    }
    Ok(paths)
}

impl EvalReport {
    /// The tables of the report in Markdown.
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        for set in &self.sets {
            s.push_str(&format!(
                "### {}\n\n{} styles (chance {:.1}%), {} contents; classifiers trained on {} clips, \
                 {} held-out test clips; classifier accuracy on the real held-out clips: style \
                 {:.1}% (clips of the contents the style classifier trained on), content {:.1}%.\n\n",
                set.set,
                set.styles.len(),
                100.0 * set.style_chance,
                set.contents.len(),
                set.classifier_clips,
                set.test_clips,
                100.0 * set.classifier_style_accuracy,
                100.0 * set.classifier_content_accuracy,
            ));
            if !set.skipped_clips.is_empty() {
                s.push_str(&format!(
                    "Held-out clips left out (shorter than two patches): {}.\n\n",
                    set.skipped_clips.join(", ")
                ));
            }
            s.push_str(
                "| method | pairs | style acc. | style acc. where the classifier knows the style clip | content acc. | \\|T_out - T_style\\| (s) | \
                 \\|T_out - T_source\\| (s) | closer to style | foot skating (units/s) | jitter \
                 (units/frame³) | duration ratio | s per restyle |\n",
            );
            s.push_str(
                "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
            );
            for m in set.reference.iter().chain(&set.methods) {
                s.push_str(&format!(
                    "| {} | {} | {:.1}% | {:.1}% ({} pairs) | {:.1}% | {:.3} | {:.3} | {:.0}% ({} timed) | {:.2} | {:.4} | {:.2} | {:.3} |\n",
                    m.method,
                    m.pairs,
                    100.0 * m.style_accuracy,
                    100.0 * m.style_accuracy_recognised,
                    m.recognised_pairs,
                    100.0 * m.content_accuracy,
                    m.period_error_to_style,
                    m.period_error_to_source,
                    100.0 * m.closer_to_style,
                    m.timed_pairs,
                    m.foot_skating,
                    m.jitter,
                    m.time_scale,
                    m.seconds_per_pair,
                ));
            }
            s.push('\n');
        }
        s
    }
}
