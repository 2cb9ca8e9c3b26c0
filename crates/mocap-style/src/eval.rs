//! Evaluation of style transfer on labelled clips: `mocap style eval`.
//!
//! For every set of clips (the part of the file name before the content,
//! e.g. Bandai's `dataset-1` and `dataset-2`, which have different styles):
//!
//! 1. The held-out takes ([`crate::data::held_out`], never seen by the
//!    shipped model) are the test clips; the others train two independent
//!    classifiers, one of style and one of content ([`crate::classify`]):
//!    the random forests of `mocap-search` over windows of its body-relative
//!    pose features, described by posture, rates of change, walking speed,
//!    step period and spectra (not the autoencoder's features, so the
//!    classifiers do not share its biases). They are chosen on real clips
//!    (the study `style_classifiers`), never on the method's outputs.
//! 2. Every pair (source, style clip) of test clips, the source's content in
//!    `source_contents` and the style clip's in `style_contents`, is
//!    restyled with every method ([`Method`]).
//! 3. Each output is scored: its style as classified against the style
//!    clip's label, its content against the source's label, its gait period
//!    against the style clip's and the source's ([`gait_period`]), foot
//!    skating ([`foot_skating`], [`planted_foot_sliding`]), how far the feet
//!    reach out from under the body ([`largest_foot_reach`]) and jitter
//!    ([`mocap_core::metrics::jitter`]).
//!
//! The classifiers' accuracy on the real test clips is reported as their
//! ceiling, the "source unchanged" row shows the style accuracy of doing
//! nothing, and the "style clip through the autoencoder" row (each style
//! clip encoded and decoded with no conversion) how much of the style the
//! model's latent space keeps: what a restyle could carry at most.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use mocap_core::metrics::{self, jitter};
use mocap_core::rotation::Vec3;
use mocap_core::{forward_kinematics, GlobalPoses, Motion};
use mocap_nn::device::DeviceChoice;
use serde::{Deserialize, Serialize};

use crate::apply::{
    load_model, prepare_source, prepare_style, restyle_prepared, StageTimings, StyleClip,
};
use crate::classify::{ClassifierConfig, ClipClassifier, Descriptor, Model, Windows};
use crate::classify_net::NetConfig;
use crate::contact::travelled;
use crate::convert::{ConvertOptions, Method};
use crate::data::{held_out, labelled_paths, list_bvh, load_clips, Clip, ClipFilter, HeldOutTake};
use crate::features::{gait_period, up_axis, RigLayout};
use crate::filmstrip::{draw_filmstrip, FilmstripRow};
use crate::train::StyleModel;
use crate::{invalid, Result};

/// Options of `mocap style eval`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(default)]
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
    /// The style classifier's model.
    pub style_model: Model,
    /// The content classifier's model.
    pub content_model: Model,
    /// What the style classifier sees.
    pub style_descriptor: Descriptor,
    /// What the content classifier sees.
    pub content_descriptor: Descriptor,
    /// Windows of the style classifier.
    pub style_windows: Windows,
    /// Windows of the content classifier.
    pub content_windows: Windows,
    /// Train the style classifier on the mirror images of its clips too.
    pub style_mirror_training: bool,
    /// Candidate features per tree node of both forests (the search
    /// crate's default when `None`).
    pub candidates: Option<usize>,
    /// Shrinkage of both classifiers' covariance when their model is
    /// [`Model::Discriminant`].
    pub shrinkage: f64,
    /// Sizes and training of the classifiers when their model is
    /// [`Model::ConvNet`].
    #[serde(default)]
    pub net: NetConfig,
    pub seed: u64,
    /// Which take of each group is held out; the model must have been
    /// trained with the same (see [`HeldOutTake`]).
    #[serde(default)]
    pub held_out_take: HeldOutTake,
    /// Folder for filmstrip PNGs (none when `None`).
    pub filmstrips: Option<PathBuf>,
    /// Filmstrips per set.
    pub filmstrip_count: usize,
    pub device: DeviceChoice,
}

/// Which classifier judges the style of outputs (see
/// [`EvalOptions::set_style_judge`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StyleJudge {
    /// The forest on the gait descriptor (the default, chosen by
    /// cross-validation on real clips).
    #[default]
    Forest,
    /// The small conv net on per-frame values and their changes, trained on
    /// the clips and their mirror images (a second opinion).
    ConvNet,
    /// Both, their votes added with equal weight.
    Both,
}

impl std::str::FromStr for StyleJudge {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "forest" => Ok(StyleJudge::Forest),
            "conv-net" => Ok(StyleJudge::ConvNet),
            "both" => Ok(StyleJudge::Both),
            _ => Err(format!(
                "style judge {s:?}: expected forest, conv-net or both"
            )),
        }
    }
}

impl EvalOptions {
    /// Judges style with `judge` in the setting measured for it on real
    /// clips (bench/results/style.md, "Three judges, three seeds").
    pub fn set_style_judge(&mut self, judge: StyleJudge) {
        match judge {
            StyleJudge::Forest => {
                self.style_model = Model::Forest;
                self.style_mirror_training = false;
            }
            StyleJudge::ConvNet | StyleJudge::Both => {
                self.style_model = match judge {
                    StyleJudge::ConvNet => Model::ConvNet,
                    _ => Model::ForestAndConvNet,
                };
                // The net's measured setting; with both, the forest still
                // trains on the clips as they are (`ClipClassifier::train`).
                self.net.velocities = true;
                self.style_mirror_training = true;
            }
        }
    }

    /// The settings of the evaluation's style classifier.
    pub fn style_classifier_config(&self) -> ClassifierConfig {
        ClassifierConfig {
            model: self.style_model,
            descriptor: self.style_descriptor,
            windows: self.style_windows,
            trees: self.trees,
            candidates: self.candidates,
            mirror_training: self.style_mirror_training,
            shrinkage: self.shrinkage,
            net: self.net,
            seed: self.seed,
        }
    }

    /// The settings of the evaluation's content classifier (trained on the
    /// clips as they are, with the next seed).
    pub fn content_classifier_config(&self) -> ClassifierConfig {
        ClassifierConfig {
            model: self.content_model,
            descriptor: self.content_descriptor,
            windows: self.content_windows,
            trees: self.trees,
            candidates: self.candidates,
            mirror_training: false,
            shrinkage: self.shrinkage,
            net: self.net,
            seed: self.seed + 1,
        }
    }
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
            style_model: Model::Forest,
            content_model: Model::Forest,
            style_descriptor: Descriptor::Gait,
            content_descriptor: Descriptor::Gait,
            style_windows: Windows::default(),
            content_windows: Windows::default(),
            style_mirror_training: false,
            candidates: None,
            shrinkage: 0.5,
            net: NetConfig::default(),
            seed: 1,
            held_out_take: HeldOutTake::Last,
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
    /// Mean speed of a flat foot on the ground ([`planted_foot_sliding`]),
    /// file units per second.
    #[serde(default)]
    pub planted_foot_sliding: f64,
    /// Pairs whose output has a foot further out from under its hip than
    /// any of the set's real source and style clips ([`largest_foot_reach`]).
    #[serde(default)]
    pub beyond_real_reach: usize,
    /// Mean jerk of the joints, file units per frame^3.
    pub jitter: f64,
    /// Mean output duration over source duration.
    pub time_scale: f64,
    /// Mean distance the pelvis travels horizontally in the output over
    /// the distance it travels in the source (1 when the root follows the
    /// source's path; the feet set it with `RootPath::Feet`).
    #[serde(default)]
    pub distance_ratio: f64,
    /// Mean horizontal distance between the output's root and where the
    /// source's path puts it (file units; 0 with `RootPath::Source`).
    #[serde(default)]
    pub root_shift: f64,
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
    /// [`planted_foot_sliding`], file units per second.
    #[serde(default)]
    pub planted_foot_sliding: f64,
    /// [`largest_foot_reach`], leg lengths.
    #[serde(default)]
    pub foot_reach: f64,
    pub jitter: f64,
    pub time_scale: f64,
    #[serde(default)]
    pub distance_ratio: f64,
    /// Mean horizontal distance the feet moved the root from the source's
    /// path (file units).
    #[serde(default)]
    pub root_shift: f64,
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
    /// The references: "source unchanged" (the real source scored against
    /// the style clip's label), "style clip itself" (each real style clip
    /// scored as itself) and "style clip through the autoencoder" (each
    /// style clip encoded and decoded, scored as itself).
    pub reference: Vec<MethodScores>,
    /// How the style judge reads each style clip, as it is and through the
    /// autoencoder (the two style-clip rows of `reference`, clip by clip).
    #[serde(default)]
    pub style_clip_readings: Vec<StyleClipReading>,
    pub methods: Vec<MethodScores>,
    pub pairs: Vec<PairResult>,
    pub filmstrips: Vec<PathBuf>,
}

/// The style judge's reading of one held-out style clip.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StyleClipReading {
    pub clip: String,
    /// Its label.
    pub style: String,
    /// The style judged on the real clip.
    pub as_captured: String,
    /// The style judged on the clip encoded and decoded by the model.
    pub through_autoencoder: String,
}

/// What `mocap style eval` reports.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EvalReport {
    pub model: String,
    pub options: EvalOptions,
    pub sets: Vec<SetReport>,
    pub seconds: f64,
}

/// Foot skating: the mean horizontal speed (file units per second) of the
/// ankle and toe joints in the frames where they are on the ground, i.e.
/// within 5% of the leg length above the joint's lowest height in the clip
/// (its 2nd percentile, robust to a stray frame).
pub fn foot_skating(motion: &Motion, rig: &RigLayout) -> f64 {
    FootFrame::of(motion, rig).foot_skating(rig)
}

/// Sliding of the planted foot: the mean horizontal speed (file units per
/// second) of the slower of a foot's ankle and toe joints over the frame
/// steps where both are on the ground, within 2% of the leg length of their
/// lowest heights (the foot flat on the ground).
///
/// [`foot_skating`] counts every foot joint within 5% of the leg length of
/// the ground. That takes in a swinging toe passing low (a walk's toe
/// clears the ground by a centimetre or two) and a heel rolling up while
/// the ball of the foot is planted, so real walks measure 47-53 cm/s by it.
/// A flat foot on the ground stands still in a real take (the Bandai walks:
/// 4.0 cm/s on dataset-1, 6.6 on dataset-2, over 43% and 38% of the feet's
/// frames): its movement is what an animator sees as the foot sliding.
pub fn planted_foot_sliding(motion: &Motion, rig: &RigLayout) -> f64 {
    FootFrame::of(motion, rig).planted_foot_sliding(rig)
}

/// How far a foot reaches out from under the body: the largest horizontal
/// distance between an ankle and its hip over the clip, in leg lengths. Real
/// walks stay near half a leg length (the Bandai walks: at most 0.55); a
/// foot-contact cleanup that holds an ankle where the leg cannot follow
/// pulls it out to nearly a whole leg length, the leg stretched off the body.
pub fn largest_foot_reach(motion: &Motion, rig: &RigLayout) -> f64 {
    FootFrame::of(motion, rig).largest_foot_reach(rig)
}

/// What the foot measures of one motion share: its global poses (one
/// forward kinematics pass), up axis, leg length and frame rate.
struct FootFrame {
    poses: GlobalPoses,
    up: Vec3,
    leg: f32,
    fps: f32,
}

impl FootFrame {
    fn of(motion: &Motion, rig: &RigLayout) -> FootFrame {
        let poses = forward_kinematics(motion);
        let up = up_axis(&poses.positions, poses.joint_count, rig);
        FootFrame {
            poses,
            up,
            leg: rig.leg_length(motion.skeleton()),
            fps: motion.fps() as f32,
        }
    }

    fn feet(rig: &RigLayout) -> [&[usize]; 2] {
        [&rig.left_foot, &rig.right_foot]
    }

    fn foot_skating(&self, rig: &RigLayout) -> f64 {
        metrics::foot_skating(&self.poses, Self::feet(rig), self.up, self.leg, self.fps)
    }

    fn planted_foot_sliding(&self, rig: &RigLayout) -> f64 {
        metrics::planted_foot_sliding(&self.poses, Self::feet(rig), self.up, self.leg, self.fps)
    }

    fn largest_foot_reach(&self, rig: &RigLayout) -> f64 {
        let mut largest = 0.0f32;
        for foot in [&rig.left_foot, &rig.right_foot] {
            let ankle = foot[0];
            let Some(hip) = rig.parents[ankle].and_then(|knee| rig.parents[knee]) else {
                continue;
            };
            for f in 0..self.poses.frame_count {
                let d = self.poses.position(f, ankle) - self.poses.position(f, hip);
                largest = largest.max(d.reject_from_normalized(self.up).length());
            }
        }
        (largest / self.leg.max(1e-6)) as f64
    }
}

/// A motion judged and measured on its own: the style and content the
/// classifiers give it, its gait period and [`MotionMeasures`]. What it was
/// made from (source, style clip, method, the partners' periods, time
/// scale, distance ratio, root shift, timings) is left neutral for the
/// caller to fill in.
fn judged(
    motion: &Motion,
    rig: &RigLayout,
    style_classifier: &ClipClassifier,
    content_classifier: &ClipClassifier,
) -> Result<PairResult> {
    let measures = MotionMeasures::of(motion, rig);
    Ok(PairResult {
        source: String::new(),
        style_clip: String::new(),
        method: Method::ElasticPatches,
        predicted_style: style_classifier.predict(motion)?,
        predicted_content: content_classifier.predict(motion)?,
        period_output: gait_period(motion, rig),
        period_style: None,
        period_source: None,
        foot_skating: measures.foot_skating,
        planted_foot_sliding: measures.planted_foot_sliding,
        foot_reach: measures.foot_reach,
        jitter: measures.jitter,
        time_scale: 1.0,
        distance_ratio: 1.0,
        root_shift: 0.0,
        timings: StageTimings::default(),
    })
}

/// The evaluation's foot measures and jitter of one motion, from one
/// forward kinematics pass.
#[derive(Debug, Clone, Copy)]
pub struct MotionMeasures {
    /// [`foot_skating`], file units per second.
    pub foot_skating: f64,
    /// [`planted_foot_sliding`], file units per second.
    pub planted_foot_sliding: f64,
    /// [`largest_foot_reach`], leg lengths.
    pub foot_reach: f64,
    /// Mean jerk of all joints ([`mocap_core::metrics::jitter`]).
    pub jitter: f64,
}

impl MotionMeasures {
    pub fn of(motion: &Motion, rig: &RigLayout) -> MotionMeasures {
        let frame = FootFrame::of(motion, rig);
        MotionMeasures {
            foot_skating: frame.foot_skating(rig),
            planted_foot_sliding: frame.planted_foot_sliding(rig),
            foot_reach: frame.largest_foot_reach(rig),
            jitter: jitter(&frame.poses, None).map_or(f64::NAN, |v| v as f64),
        }
    }
}

/// Where the left and the right ankle's sideways offsets from the pelvis
/// (body frame, body heights) are among mocap-search's per-frame pose values
/// (`left_ankle.x`, `right_ankle.x`).
fn sideways_ankle_values() -> [usize; 2] {
    ["left_ankle.x", "right_ankle.x"].map(|name| {
        mocap_search::VALUE_NAMES
            .iter()
            .position(|n| *n == name)
            .expect("a pose value of mocap-search")
    })
}

/// The mean over frames of the two ankles' sideways offsets from the pelvis
/// in the body frame (mocap-search's `left_ankle.x` and `right_ankle.x`,
/// summed). About zero in a straight walk, well off it in a turn (its feet
/// land to one side): how the studies and the tests tell whether a restyled
/// turn kept its footwork.
pub fn feet_sideways_offset(motion: &Motion) -> Result<f64> {
    let statistics = crate::classify::clip_pose_statistics(motion)?;
    Ok(sideways_ankle_values()
        .iter()
        .map(|&i| statistics[i] as f64)
        .sum())
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
            .map_or(crate::apply::BUILT_IN_MODEL.to_string(), |p| {
                p.display().to_string()
            }),
        options: options.clone(),
        sets: reports,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// The style classifier (trained on the clips `options.classifier_filter`
/// accepts) and the content classifier (every clip) of a set.
pub fn train_classifiers(
    clips: &[Clip],
    options: &EvalOptions,
) -> Result<(ClipClassifier, ClipClassifier)> {
    let style = ClipClassifier::train(
        &clips
            .iter()
            .filter(|c| options.classifier_filter.accepts(&c.labels))
            .map(|c| (c, c.labels.style.clone()))
            .collect::<Vec<_>>(),
        options.style_classifier_config(),
    )?;
    let content = ClipClassifier::train(
        &clips
            .iter()
            .map(|c| (c, c.labels.content.clone()))
            .collect::<Vec<_>>(),
        options.content_classifier_config(),
    )?;
    Ok((style, content))
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
    let held = held_out(files, options.held_out_take);
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
    let (style_classifier, content_classifier) = train_classifiers(&classifier_clips, options)?;
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
    let bar = mocap_nn::train::work_bar(sources.len() as u64, &format!("{set}: sources restyled"));
    for source in &sources {
        let source_distance = travelled(&source.motion, rig);
        // Encoded once for all its pairs; each pair's timings include it.
        let prepared_source = prepare_source(model, &source.motion, options.convert.asymmetry)?;
        // The source as it is, scored once; each pair's "source unchanged"
        // row takes the style clip's name and period.
        let unchanged = PairResult {
            source: source.name.clone(),
            period_source: periods[&source.name],
            ..judged(&source.motion, rig, &style_classifier, &content_classifier)?
        };
        for (k, style) in style_clips.iter().enumerate() {
            if source.name == style.name {
                continue;
            }
            for &method in &options.methods {
                let convert = ConvertOptions {
                    method,
                    ..options.convert
                };
                let restyled = restyle_prepared(
                    model,
                    &prepared_source,
                    &[(&prepared[k], 1.0)],
                    &convert,
                    prepare_times[k],
                )?;
                let out = &restyled.motion;
                pairs.push(PairResult {
                    source: source.name.clone(),
                    style_clip: style.name.clone(),
                    method,
                    period_style: periods[&style.name],
                    period_source: periods[&source.name],
                    time_scale: out.duration() / source.motion.duration(),
                    distance_ratio: (travelled(out, rig) / source_distance) as f64,
                    root_shift: restyled.root_shift.mean as f64,
                    timings: restyled.timings,
                    ..judged(out, rig, &style_classifier, &content_classifier)?
                });
            }
            // The source left unchanged, scored against the style clip.
            source_rows.push(PairResult {
                style_clip: style.name.clone(),
                period_style: periods[&style.name],
                ..unchanged.clone()
            });
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
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
    // The furthest any real source or style clip puts a foot from under its
    // hip: how far the outputs' feet may reach and still look like these.
    let real_reach = sources
        .iter()
        .chain(&style_clips)
        .map(|c| largest_foot_reach(&c.motion, rig))
        .fold(0.0, f64::max);
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
            planted_foot_sliding: mean(&|r| r.planted_foot_sliding),
            beyond_real_reach: rows.iter().filter(|r| r.foot_reach > real_reach).count(),
            jitter: mean(&|r| r.jitter),
            time_scale: mean(&|r| r.time_scale),
            distance_ratio: mean(&|r| r.distance_ratio),
            root_shift: mean(&|r| r.root_shift),
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
                period_style: periods[&c.name],
                period_source: periods[&c.name],
                ..judged(&c.motion, rig, &style_classifier, &content_classifier)?
            })
        })
        .collect::<Result<_>>()?;
    // Each style clip through the autoencoder alone (encoded and decoded
    // with no conversion: strength 0 on itself): how much of its style the
    // model's latent space keeps, the most a restyle with it could carry.
    let reconstruction = ConvertOptions {
        strength: 0.0,
        fade_in_frames: 0.0,
        ..options.convert
    };
    let decoded_rows: Vec<PairResult> = style_clips
        .iter()
        .zip(&prepared)
        .map(|(c, style)| -> Result<PairResult> {
            let source = prepare_source(model, &c.motion, reconstruction.asymmetry)?;
            let out = restyle_prepared(
                model,
                &source,
                &[(style, 1.0)],
                &reconstruction,
                StageTimings::default(),
            )?
            .motion;
            Ok(PairResult {
                source: c.name.clone(),
                style_clip: c.name.clone(),
                period_style: periods[&c.name],
                period_source: periods[&c.name],
                time_scale: out.duration() / c.motion.duration(),
                distance_ratio: (travelled(&out, rig) / travelled(&c.motion, rig)) as f64,
                ..judged(&out, rig, &style_classifier, &content_classifier)?
            })
        })
        .collect::<Result<_>>()?;
    let style_clip_readings = style_clips
        .iter()
        .zip(style_rows.iter().zip(&decoded_rows))
        .map(|(c, (real, decoded))| StyleClipReading {
            clip: c.name.clone(),
            style: c.labels.style.clone(),
            as_captured: real.predicted_style.clone(),
            through_autoencoder: decoded.predicted_style.clone(),
        })
        .collect();
    let reference = vec![
        score("source unchanged".into(), source_rows.iter().collect()),
        score("style clip itself".into(), style_rows.iter().collect()),
        score(
            "style clip through the autoencoder".into(),
            decoded_rows.iter().collect(),
        ),
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
        style_clip_readings,
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
        let prepared_source = prepare_source(model, &source.motion, options.convert.asymmetry)?;
        for &method in &options.methods {
            let convert = ConvertOptions {
                method,
                ..options.convert
            };
            let r = restyle_prepared(
                model,
                &prepared_source,
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
        draw_filmstrip(&path, &rows, 8)?;
        paths.push(path);
    }
    Ok(paths)
}

/// What a judge is, in words, for the report.
fn judge_description(
    model: Model,
    descriptor: Descriptor,
    trees: usize,
    shrinkage: f64,
    net: &NetConfig,
) -> String {
    let descriptor = match descriptor {
        Descriptor::Intervals => "interval-means",
        Descriptor::Statistics => "statistics",
        Descriptor::Gait => "gait",
        Descriptor::IntervalsGait => "interval-means + gait",
    };
    let net_text = format!(
        "conv net ({} channels, kernel {}, {} epochs) on the per-frame pose values{}",
        net.width,
        net.kernel,
        net.epochs,
        if net.velocities {
            " and their changes"
        } else {
            ""
        }
    );
    match model {
        Model::Forest => format!("forest of {trees} trees on the {descriptor} descriptor"),
        Model::ForestAndConvNet => format!(
            "forest of {trees} trees on the {descriptor} descriptor and {net_text}, votes added"
        ),
        Model::NearestMean => format!("nearest class mean on the {descriptor} descriptor"),
        Model::Discriminant => {
            format!("linear discriminant (shrinkage {shrinkage}) on the {descriptor} descriptor")
        }
        Model::ConvNet => net_text,
    }
}

impl EvalReport {
    /// The tables of the report in Markdown.
    pub fn to_markdown(&self) -> String {
        let o = &self.options;
        let mut s = format!(
            "Judges (seed {}): style: {}{}; content: {}.\n\n",
            o.seed,
            judge_description(
                o.style_model,
                o.style_descriptor,
                o.trees,
                o.shrinkage,
                &o.net
            ),
            if o.style_mirror_training {
                ", trained on the mirror images of its clips too"
            } else {
                ""
            },
            judge_description(
                o.content_model,
                o.content_descriptor,
                o.trees,
                o.shrinkage,
                &o.net
            ),
        );
        // The settings the outputs were restyled with, so that a report says
        // which variant it measured.
        let c = &o.convert;
        s.push_str(&format!(
            "Restyled with: patches of {} frames (elastic: +-{:.0}% in steps of {}), root {}, \
             asymmetry {}{}, strength {}.\n\n",
            c.patch,
            100.0 * c.stretch,
            c.stretch_step,
            c.root.name(),
            c.asymmetry.name(),
            if c.foot_contacts {
                ", ankles pinned on the ground"
            } else {
                ""
            },
            c.strength,
        ));
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
                 \\|T_out - T_source\\| (s) | closer to style | foot skating (units/s) | planted foot sliding (units/s) | feet beyond real reach (pairs) | jitter \
                 (units/frame³) | duration ratio | distance ratio | root off the source's path (units) | s per restyle |\n",
            );
            s.push_str(
                "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
            );
            for m in set.reference.iter().chain(&set.methods) {
                s.push_str(&format!(
                    "| {} | {} | {:.1}% | {:.1}% ({} pairs) | {:.1}% | {:.3} | {:.3} | {:.0}% ({} timed) | {:.2} | {:.2} | {} | {:.4} | {:.2} | {:.2} | {:.2} | {:.3} |\n",
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
                    m.planted_foot_sliding,
                    m.beyond_real_reach,
                    m.jitter,
                    m.time_scale,
                    m.distance_ratio,
                    m.root_shift,
                    m.seconds_per_pair,
                ));
            }
            s.push('\n');
            let misread = |through: fn(&StyleClipReading) -> &str| -> String {
                let list: Vec<String> = set
                    .style_clip_readings
                    .iter()
                    .filter(|r| through(r) != r.style)
                    .map(|r| format!("{} as {}", r.clip, through(r)))
                    .collect();
                if list.is_empty() {
                    "none".into()
                } else {
                    list.join(", ")
                }
            };
            if !set.style_clip_readings.is_empty() {
                s.push_str(&format!(
                    "Style clips the style classifier misreads: as captured: {}; through the \
                     autoencoder: {}.\n\n",
                    misread(|r| &r.as_captured),
                    misread(|r| &r.through_autoencoder),
                ));
            }
        }
        s
    }
}
