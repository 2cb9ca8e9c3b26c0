//! The evaluation's independent classifiers of real clips: style and
//! content.
//!
//! They must not share the method's view of motion, so they never see the
//! autoencoder's features or latents: they use `mocap-search`'s
//! body-relative pose features (56 numbers per frame: joint positions in a
//! body frame, distances, flexions, tilt, pelvis velocity, limb speeds) and
//! its random forests. A clip is cut into overlapping windows; each window
//! becomes one row of numbers (a [`Descriptor`]); the forest is trained on
//! the windows of the training clips, and a clip's label is the class with
//! the largest summed forest histogram over its windows. With a few takes per
//! style, windows give the forest many more samples, and the vote makes a
//! clip's label robust to one odd stride. [`Model::ConvNet`] is a second
//! kind of judge on the same windows: a small conv net that reads the
//! per-frame values themselves instead of a descriptor row
//! ([`crate::classify_net`]).

use mocap_core::Motion;
use mocap_search::motion_features;
use mocap_search::Samples;
use mocap_search::{FeatureSequence, IntervalLayout};
use mocap_search::{Forest, ForestConfig};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use crate::classify_net::{FittedNet, NetConfig};
use crate::data::{mirrored, Clip};
use crate::{invalid, Result};

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
    /// [`Descriptor::Statistics`] plus how the body moves, which is where a
    /// style shows when the poses are alike (see `gait_row`): rates of
    /// change of every feature, direction-free walking speed, step period
    /// and regularity, and the spectra of the signals a gait swings.
    Gait,
    /// [`Descriptor::Intervals`] and [`Descriptor::Gait`] side by side: the
    /// order of poses (what is done) and how it is done.
    IntervalsGait,
}

/// Window length and hop of the classifiers.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Windows {
    /// Seconds per window.
    pub length: f64,
    /// Seconds between window starts.
    pub hop: f64,
}

impl Default for Windows {
    fn default() -> Self {
        Windows {
            length: 2.0,
            hop: 0.5,
        }
    }
}

/// The windows of a clip's per-frame features (the whole clip when it is
/// shorter than a window).
pub(crate) fn feature_windows(motion: &Motion, windows: Windows) -> Result<Vec<FeatureSequence>> {
    let features = pose_values(motion)?;
    let frames = features.frame_count();
    let window = ((windows.length * motion.fps()).round() as usize).max(2);
    let hop = ((windows.hop * motion.fps()).round() as usize).max(1);
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

/// The first [`POSE_VALUES`] of mocap-search's per-frame features: the
/// classifiers index into them by position, and values the search crate may
/// append later must not change what the evaluation measures.
const POSE_VALUES: usize = 56;

fn pose_values(motion: &Motion) -> Result<FeatureSequence> {
    let features = motion_features(motion).map_err(search_error)?;
    if features.dim < POSE_VALUES {
        return Err(invalid(format!(
            "classifier: mocap-search gives {} values per frame, {POSE_VALUES} expected",
            features.dim
        )));
    }
    if features.dim == POSE_VALUES {
        return Ok(features);
    }
    let values = features
        .values
        .chunks(features.dim)
        .flat_map(|frame| frame[..POSE_VALUES].iter().copied())
        .collect();
    Ok(FeatureSequence {
        dim: POSE_VALUES,
        values,
    })
}

/// The mean and then the standard deviation, over all frames of a clip, of
/// each of the pose values the judges read (what
/// [`Descriptor::Statistics`] sees of a window, for the whole clip).
pub fn clip_pose_statistics(motion: &Motion) -> Result<Vec<f32>> {
    Ok(statistics_row(&pose_values(motion)?))
}

/// Mean and standard deviation of every feature over a window.
pub(crate) fn statistics_row(w: &FeatureSequence) -> Vec<f32> {
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

// Indices into mocap-search's 56 pose values (its `VALUE_NAMES`).
const HEAD_Y: usize = 1;
const HEAD_Z: usize = 2;
const LEFT_WRIST_Y: usize = 4;
const LEFT_WRIST_Z: usize = 5;
const RIGHT_WRIST_Z: usize = 8;
const PELVIS_HEIGHT: usize = 27;
const ANKLE_ANKLE: usize = 29;
const LEFT_ELBOW_FLEXION: usize = 38;
const LEFT_KNEE_FLEXION: usize = 40;
const TILT_FORWARD: usize = 43;
const TILT_LATERAL: usize = 44;
const PELVIS_VELOCITY_X: usize = 45;
const PELVIS_VELOCITY_Z: usize = 47;
const TURN_SPEED: usize = 48;
const LEFT_ANKLE_ABOVE_RIGHT: usize = 55;

/// Signals whose spectra the gait descriptor keeps: the bob of the head and
/// pelvis, the arm swing, the sway of the trunk, the legs' scissoring.
const SPECTRUM_SIGNALS: [usize; 12] = [
    HEAD_Y,
    HEAD_Z,
    LEFT_WRIST_Y,
    LEFT_WRIST_Z,
    RIGHT_WRIST_Z,
    PELVIS_HEIGHT,
    ANKLE_ANKLE,
    LEFT_ELBOW_FLEXION,
    LEFT_KNEE_FLEXION,
    TILT_FORWARD,
    TILT_LATERAL,
    LEFT_ANKLE_ABOVE_RIGHT,
];

/// Frequency bands (Hz) of the spectra: below, at and above the usual step
/// rate (about 1.5-2 Hz), and the fast shakes of an energetic style.
const BANDS: [(f64, f64); 5] = [(0.3, 0.9), (0.9, 1.5), (1.5, 2.5), (2.5, 4.0), (4.0, 8.0)];

/// The gait descriptor of a window (frame rate `fps`):
///
/// - mean and deviation of every feature (posture);
/// - mean absolute rate of change of every feature, per second (how briskly
///   each part moves: a tired walk and an active one hold similar poses at
///   different speeds);
/// - horizontal pelvis speed (mean and deviation) and absolute turning
///   speed, free of the walking direction, since the style classifier trains
///   on walks forward, backward and sideways;
/// - the step period (lag of the strongest autocorrelation of the distance
///   between the ankles, 0.25-1.25 s) and that autocorrelation (how regular
///   the steps are);
/// - the power of 12 swinging signals (head and pelvis bob, arm swing, trunk
///   sway, knee and elbow flexion, the legs' alternation) in 5 bands of
///   0.3-8 Hz (Hann-windowed discrete
///   Fourier transform), as a share of the signal's power so that it says
///   rhythm, not amplitude (the deviation already says amplitude).
pub fn gait_row(w: &FeatureSequence, fps: f64) -> Vec<f32> {
    let n = w.frame_count();
    let d = w.dim;
    let column = |i: usize| -> Vec<f64> { (0..n).map(|f| w.values[f * d + i] as f64).collect() };
    let mut row = statistics_row(w);
    for i in 0..d {
        let c = column(i);
        let rate = if n > 1 {
            c.windows(2).map(|p| (p[1] - p[0]).abs()).sum::<f64>() / (n - 1) as f64 * fps
        } else {
            0.0
        };
        row.push(rate as f32);
    }
    let speed: Vec<f64> = (0..n)
        .map(|f| {
            let vx = w.values[f * d + PELVIS_VELOCITY_X] as f64;
            let vz = w.values[f * d + PELVIS_VELOCITY_Z] as f64;
            (vx * vx + vz * vz).sqrt()
        })
        .collect();
    let (mean, deviation) = mean_deviation(&speed);
    row.push(mean as f32);
    row.push(deviation as f32);
    let turn: Vec<f64> = column(TURN_SPEED).iter().map(|v| v.abs()).collect();
    row.push(mean_deviation(&turn).0 as f32);
    let (period, regularity) = strongest_period(&column(ANKLE_ANKLE), fps, 0.25, 1.25);
    row.push(period as f32);
    row.push(regularity as f32);
    for &i in &SPECTRUM_SIGNALS {
        row.extend(band_shares(&column(i), fps).iter().map(|&v| v as f32));
    }
    row
}

fn mean_deviation(x: &[f64]) -> (f64, f64) {
    let n = x.len().max(1) as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    (mean, var.sqrt())
}

/// The lag (seconds) between `min_s` and `max_s` of the largest normalised
/// autocorrelation of `x`, and that autocorrelation; (0, 0) when the window
/// is too short or the signal flat.
fn strongest_period(x: &[f64], fps: f64, min_s: f64, max_s: f64) -> (f64, f64) {
    let n = x.len();
    let (mean, deviation) = mean_deviation(x);
    let min_lag = ((min_s * fps).round() as usize).max(1);
    // At least a quarter of the window must overlap.
    let max_lag = ((max_s * fps).round() as usize).min(n.saturating_sub(n / 4).max(1) - 1);
    if deviation < 1e-9 || max_lag <= min_lag {
        return (0.0, 0.0);
    }
    let c: Vec<f64> = x.iter().map(|v| v - mean).collect();
    let var = deviation * deviation;
    let mut best = (0.0, f64::NEG_INFINITY);
    for lag in min_lag..=max_lag {
        let r = (0..n - lag).map(|t| c[t] * c[t + lag]).sum::<f64>() / ((n - lag) as f64 * var);
        if r > best.1 {
            best = (lag as f64 / fps, r);
        }
    }
    best
}

/// The share of the power of `x` (mean removed, Hann window) in each of
/// [`BANDS`].
fn band_shares(x: &[f64], fps: f64) -> [f64; BANDS.len()] {
    let n = x.len();
    let mut out = [0.0; BANDS.len()];
    if n < 4 {
        return out;
    }
    let (mean, _) = mean_deviation(x);
    let windowed: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(t, v)| {
            let hann = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * t as f64 / (n - 1) as f64).cos();
            (v - mean) * hann
        })
        .collect();
    let mut total = 0.0;
    for k in 1..=n / 2 {
        let (mut re, mut im) = (0.0, 0.0);
        for (t, v) in windowed.iter().enumerate() {
            let phase = 2.0 * std::f64::consts::PI * (k * t) as f64 / n as f64;
            re += v * phase.cos();
            im -= v * phase.sin();
        }
        let power = re * re + im * im;
        total += power;
        let frequency = k as f64 * fps / n as f64;
        if let Some(b) = BANDS
            .iter()
            .position(|&(lo, hi)| frequency >= lo && frequency < hi)
        {
            out[b] += power;
        }
    }
    if total > 1e-12 {
        for v in &mut out {
            *v /= total;
        }
    }
    out
}

/// Frames a window is resampled to for [`Descriptor::Intervals`] (as the
/// search crate's index does).
const INTERVAL_FRAMES: usize = 10;

fn descriptor_row(descriptor: Descriptor, w: &FeatureSequence, fps: f64) -> Vec<f32> {
    let intervals =
        || IntervalLayout::all(INTERVAL_FRAMES, w.dim).interval_means(&w.resample(INTERVAL_FRAMES));
    match descriptor {
        Descriptor::Intervals => intervals(),
        Descriptor::Statistics => statistics_row(w),
        Descriptor::Gait => gait_row(w, fps),
        Descriptor::IntervalsGait => {
            let mut row = intervals();
            row.extend(gait_row(w, fps));
            row
        }
    }
}

/// Which model a classifier fits to the window rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Model {
    /// mocap-search's random forest; a clip's label is the class with the
    /// largest summed histogram over its windows.
    Forest,
    /// Nearest class mean, every value scaled by its pooled within-class
    /// deviation (a Gaussian classifier with a shared diagonal covariance):
    /// with a few takes per class it has far fewer things to fit than a
    /// forest. A clip's label is the class nearest on average over its
    /// windows.
    NearestMean,
    /// Linear discriminant analysis with a shrunk covariance: the class
    /// means, and the pooled within-class correlation of the values shrunk
    /// towards the identity, `R_s = (1 - s) R + s I`
    /// ([`ClassifierConfig::shrinkage`] = `s`). A clip's label is the class
    /// nearest in that Mahalanobis distance on average over its windows. At
    /// `s = 1` it is [`Model::NearestMean`]; below, values that move
    /// together (the deviation and rate of change of one joint) stop being
    /// counted twice.
    Discriminant,
    /// A small 1-D convolutional network on the window's per-frame values
    /// (not the descriptor; see `classify_net`); a clip's label is
    /// the class with the largest summed probability over its windows.
    ConvNet,
    /// Both [`Model::Forest`] and [`Model::ConvNet`], their votes added
    /// with equal weight (each window gives each model's class
    /// distribution, summing to 1). The forest is trained on the clips as
    /// they are and the network, with [`ClassifierConfig::mirror_training`],
    /// on their mirror images too: each model in the setting it was
    /// measured best in.
    ForestAndConvNet,
}

/// How a classifier is built.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ClassifierConfig {
    pub model: Model,
    pub descriptor: Descriptor,
    pub windows: Windows,
    pub trees: usize,
    /// Candidate features tried at each node of a tree (the forest's
    /// default when `None`).
    pub candidates: Option<usize>,
    /// Add the mirror image of every training clip (same label): for style,
    /// a mirrored walk has the same style and there are few takes per style.
    /// Not for contents whose name says a side (walk-left).
    pub mirror_training: bool,
    /// Shrinkage `s` of [`Model::Discriminant`]'s correlation towards the
    /// identity, in `(0, 1]`.
    pub shrinkage: f64,
    /// Sizes and training of [`Model::ConvNet`].
    #[serde(default)]
    pub net: NetConfig,
    pub seed: u64,
}

/// A classifier of clips (see the module docs).
pub struct ClipClassifier {
    config: ClassifierConfig,
    fitted: Fitted,
    classes: Vec<String>,
}

/// What a classifier learnt.
enum Fitted {
    /// A model of descriptor rows.
    Rows(RowModel),
    /// The conv net, which reads the windows themselves.
    ConvNet(Box<FittedNet>),
    /// A forest of descriptor rows and a conv net, votes added.
    Both(RowModel, Box<FittedNet>),
}

/// A model fitted to one descriptor row per window.
enum RowModel {
    Forest(Forest),
    NearestMean {
        /// Class means, `classes x dim`.
        means: Vec<Vec<f64>>,
        /// 1 / pooled within-class variance of every value (0 for a value
        /// that never varies within a class).
        weights: Vec<f64>,
    },
    Discriminant {
        /// Class means, `classes x dim`.
        means: Vec<Vec<f64>>,
        /// 1 / pooled within-class deviation of every value (0 for a value
        /// that never varies within a class).
        scales: Vec<f64>,
        /// Inverse of the shrunk within-class correlation of the scaled
        /// values.
        precision: DMatrix<f64>,
    },
}

/// Class means of rows, `classes x dim`.
fn class_means(rows: &[f32], dim: usize, labels: &[u32], classes: usize) -> Vec<Vec<f64>> {
    let mut sums = vec![vec![0.0f64; dim]; classes];
    let mut counts = vec![0usize; classes];
    for (row, &l) in rows.chunks(dim).zip(labels) {
        counts[l as usize] += 1;
        for (s, &v) in sums[l as usize].iter_mut().zip(row) {
            *s += v as f64;
        }
    }
    sums.into_iter()
        .zip(&counts)
        .map(|(s, &n)| s.into_iter().map(|v| v / n.max(1) as f64).collect())
        .collect()
}

/// [`Model::Discriminant`]: class means, and the inverse of the pooled
/// within-class correlation shrunk towards the identity by `shrinkage`.
fn fit_discriminant(
    rows: &[f32],
    dim: usize,
    labels: &[u32],
    classes: usize,
    shrinkage: f64,
) -> Result<RowModel> {
    if !(shrinkage > 0.0 && shrinkage <= 1.0) {
        return Err(invalid(format!(
            "classifier: shrinkage must be in (0, 1], got {shrinkage}"
        )));
    }
    let means = class_means(rows, dim, labels, classes);
    let n = labels.len().max(1) as f64;
    let mut covariance = DMatrix::<f64>::zeros(dim, dim);
    let mut d = DVector::<f64>::zeros(dim);
    for (row, &l) in rows.chunks(dim).zip(labels) {
        for (c, (&x, m)) in row.iter().zip(&means[l as usize]).enumerate() {
            d[c] = x as f64 - m;
        }
        covariance.syger(1.0 / n, &d, &d, 1.0);
    }
    covariance.fill_upper_triangle_with_lower_triangle();
    let scales: Vec<f64> = (0..dim)
        .map(|c| {
            let v = covariance[(c, c)];
            if v > 1e-12 {
                1.0 / v.sqrt()
            } else {
                0.0
            }
        })
        .collect();
    // R_s = (1 - s) D^-1/2 C D^-1/2 + s I; values that never vary are
    // left out by a zero scale, so their row of R is 0 and of R_s is s.
    let mut shrunk = DMatrix::<f64>::identity(dim, dim) * shrinkage;
    for i in 0..dim {
        for j in 0..dim {
            shrunk[(i, j)] += (1.0 - shrinkage) * covariance[(i, j)] * scales[i] * scales[j];
        }
    }
    let precision = shrunk
        .cholesky()
        .ok_or_else(|| invalid("classifier: the shrunk correlation is not positive definite"))?
        .inverse();
    Ok(RowModel::Discriminant {
        means,
        scales,
        precision,
    })
}

/// The class means and inverse pooled within-class variances of rows.
fn fit_nearest_mean(rows: &[f32], dim: usize, labels: &[u32], classes: usize) -> RowModel {
    let means = class_means(rows, dim, labels, classes);
    let mut variance = vec![0.0f64; dim];
    for (row, &l) in rows.chunks(dim).zip(labels) {
        for ((v, &x), m) in variance.iter_mut().zip(row).zip(&means[l as usize]) {
            *v += (x as f64 - m).powi(2);
        }
    }
    let n = labels.len().max(1) as f64;
    let weights = variance
        .into_iter()
        .map(|v| if v / n > 1e-12 { n / v } else { 0.0 })
        .collect();
    RowModel::NearestMean { means, weights }
}

impl Fitted {
    /// Adds the windows' scores for every class to `votes` (the network's
    /// probabilities, or the row model's scores of each descriptor row).
    fn add_votes(
        &self,
        descriptor: Descriptor,
        windows: &[FeatureSequence],
        fps: f64,
        votes: &mut [f32],
    ) {
        match self {
            Fitted::ConvNet(net) => net.add_votes(windows, votes),
            Fitted::Rows(model) => {
                for w in windows {
                    model.add_votes(&descriptor_row(descriptor, w, fps), votes);
                }
            }
            Fitted::Both(forest, net) => {
                for w in windows {
                    forest.add_votes(&descriptor_row(descriptor, w, fps), votes);
                }
                net.add_votes(windows, votes);
            }
        }
    }
}

impl RowModel {
    /// Adds one window row's score for every class to `votes` (the forest's
    /// histogram, or minus the squared distance to each class mean).
    fn add_votes(&self, row: &[f32], votes: &mut [f32]) {
        match self {
            RowModel::Forest(forest) => {
                for (v, h) in votes.iter_mut().zip(forest.predict(row)) {
                    *v += h;
                }
            }
            RowModel::NearestMean { means, weights } => {
                for (v, mean) in votes.iter_mut().zip(means) {
                    let d2: f64 = row
                        .iter()
                        .zip(mean)
                        .zip(weights)
                        .map(|((&x, m), w)| (x as f64 - m).powi(2) * w)
                        .sum();
                    *v -= d2 as f32;
                }
            }
            RowModel::Discriminant {
                means,
                scales,
                precision,
            } => {
                for (v, mean) in votes.iter_mut().zip(means) {
                    let z = DVector::from_iterator(
                        row.len(),
                        row.iter()
                            .zip(mean)
                            .zip(scales)
                            .map(|((&x, m), s)| (x as f64 - m) * s),
                    );
                    *v -= z.dot(&(precision * &z)) as f32;
                }
            }
        }
    }
}

impl ClipClassifier {
    /// Trains on `(clip, label)` pairs.
    pub fn train(clips: &[(&Clip, String)], config: ClassifierConfig) -> Result<ClipClassifier> {
        let mut classes: Vec<String> = clips.iter().map(|c| c.1.clone()).collect();
        classes.sort();
        classes.dedup();
        // Every training window with its frame rate, its class and whether
        // it comes from a mirror image.
        let (mut windows, mut fps, mut labels, mut from_mirror) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (clip, label) in clips {
            let class = classes.binary_search(label).expect("listed") as u32;
            let mut motions = vec![clip.motion.clone()];
            if config.mirror_training {
                motions.push(mirrored(&clip.motion)?);
            }
            for (k, m) in motions.iter().enumerate() {
                for w in feature_windows(m, config.windows)? {
                    windows.push(w);
                    fps.push(m.fps());
                    labels.push(class);
                    from_mirror.push(k > 0);
                }
            }
        }
        // The row models see one descriptor row per window (without
        // `mirrors`, only the windows of the clips as they are), with its
        // class.
        let rows = |mirrors: bool| -> (Vec<f32>, Vec<u32>) {
            let (mut rows, mut kept) = (Vec::new(), Vec::new());
            for (((w, &fps), &label), &mirror) in
                windows.iter().zip(&fps).zip(&labels).zip(&from_mirror)
            {
                if mirrors || !mirror {
                    rows.extend(descriptor_row(config.descriptor, w, fps));
                    kept.push(label);
                }
            }
            (rows, kept)
        };
        let dim = |rows: &[f32], labels: &[u32]| rows.len() / labels.len().max(1);
        let forest = |(rows, labels): (Vec<f32>, Vec<u32>)| -> Result<RowModel> {
            let samples = Samples::new(&rows, dim(&rows, &labels), &labels, classes.len())
                .map_err(invalid)?;
            let mut forest = ForestConfig {
                trees: config.trees,
                seed: config.seed,
                ..ForestConfig::default()
            };
            if let Some(c) = config.candidates {
                forest.tree.candidates_per_node = Some(c);
            }
            Ok(RowModel::Forest(Forest::train(&samples, &forest, &|| {})))
        };
        let net = || -> Result<Box<FittedNet>> {
            let net = FittedNet::train(&windows, &labels, classes.len(), &config.net, config.seed)?;
            Ok(Box::new(net))
        };
        let fitted = match config.model {
            Model::Forest => Fitted::Rows(forest(rows(true))?),
            Model::NearestMean => {
                let (rows, labels) = rows(true);
                Fitted::Rows(fit_nearest_mean(
                    &rows,
                    dim(&rows, &labels),
                    &labels,
                    classes.len(),
                ))
            }
            Model::Discriminant => {
                let (rows, labels) = rows(true);
                Fitted::Rows(fit_discriminant(
                    &rows,
                    dim(&rows, &labels),
                    &labels,
                    classes.len(),
                    config.shrinkage,
                )?)
            }
            Model::ConvNet => Fitted::ConvNet(net()?),
            // The forest on the clips as they are, the net on all windows.
            Model::ForestAndConvNet => Fitted::Both(forest(rows(false))?, net()?),
        };
        Ok(ClipClassifier {
            config,
            fitted,
            classes,
        })
    }

    /// The class of a clip: the largest summed score over its windows (forest
    /// histograms, network probabilities, or minus the distances to the class
    /// means).
    pub fn predict(&self, motion: &Motion) -> Result<String> {
        let votes = self.votes(motion)?;
        Ok(self.classes[mocap_search::argmax(&votes)].clone())
    }

    /// The summed score of every class (in the order of
    /// [`ClipClassifier::classes`]) over the clip's windows.
    pub fn votes(&self, motion: &Motion) -> Result<Vec<f32>> {
        let mut votes = vec![0.0f32; self.classes.len()];
        let windows = feature_windows(motion, self.config.windows)?;
        self.fitted
            .add_votes(self.config.descriptor, &windows, motion.fps(), &mut votes);
        Ok(votes)
    }

    pub fn classes(&self) -> &[String] {
        &self.classes
    }
}

pub(crate) fn search_error(e: mocap_search::SearchError) -> crate::StyleError {
    invalid(format!("classifier: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sequence(columns: &[Vec<f32>]) -> FeatureSequence {
        let n = columns[0].len();
        let mut values = Vec::new();
        for f in 0..n {
            for c in columns {
                values.push(c[f]);
            }
        }
        FeatureSequence {
            dim: columns.len(),
            values,
        }
    }

    #[test]
    fn step_period_and_band_of_a_sine() {
        // 1.6 Hz at 30 fps for 4 s: period 0.625 s, power in 1.5-2.5 Hz.
        let fps = 30.0;
        let x: Vec<f64> = (0..120)
            .map(|t| (2.0 * std::f64::consts::PI * 1.6 * t as f64 / fps).sin())
            .collect();
        let (period, r) = strongest_period(&x, fps, 0.25, 1.25);
        assert!((period - 0.625).abs() < 0.04, "period {period}");
        assert!(r > 0.9, "regularity {r}");
        let shares = band_shares(&x, fps);
        assert!(shares[2] > 0.8, "shares {shares:?}");
        assert!((shares.iter().sum::<f64>() - 1.0).abs() < 0.05);
    }

    #[test]
    fn nearest_mean_scales_by_the_within_class_spread() {
        // Value 0 separates the classes; value 1 is wide noise in both.
        let rows = [0.0f32, 10.0, 0.2, -10.0, 1.0, 10.0, 1.2, -10.0];
        let RowModel::NearestMean { means, weights } = fit_nearest_mean(&rows, 2, &[0, 0, 1, 1], 2)
        else {
            panic!("nearest mean");
        };
        assert!((means[0][0] - 0.1).abs() < 1e-6 && (means[1][0] - 1.1).abs() < 1e-6);
        // Pooled variance of value 0: 0.01, of value 1: 100.
        assert!((weights[0] - 100.0).abs() < 1e-3, "{weights:?}");
        assert!((weights[1] - 0.01).abs() < 1e-6, "{weights:?}");
    }

    #[test]
    fn discriminant_counts_values_that_move_together_once() {
        // Two classes whose two values have unit within-class deviation and
        // correlation 0.9: each class is the points +-(1, 1) sqrt(1.9) and
        // +-(1, -1) sqrt(0.1) about its mean, (0, 0) and (2, 0).
        let (a, b) = (1.9f32.sqrt(), 0.1f32.sqrt());
        let spread = [(a, a), (-a, -a), (b, -b), (-b, b)];
        let mut rows = Vec::new();
        let mut labels = Vec::new();
        for (class, centre) in [(0u32, 0.0f32), (1, 2.0)] {
            for (x, y) in spread {
                rows.extend([centre + x, y]);
                labels.push(class);
            }
        }
        let nearest = |fitted: &RowModel, row: &[f32]| {
            let mut votes = [0.0f32; 2];
            fitted.add_votes(row, &mut votes);
            mocap_search::argmax(&votes)
        };
        // (1.2, 1.5) lies along the shared swing from class 0's mean: the
        // Mahalanobis distances are 2.4 (class 0) and 26.6 (class 1), the
        // scaled Euclidean ones 3.7 and 2.9 (at correlation 0.9).
        let point = [1.2f32, 1.5];
        let diagonal = fit_nearest_mean(&rows, 2, &labels, 2);
        assert_eq!(nearest(&diagonal, &point), 1);
        let full = fit_discriminant(&rows, 2, &labels, 2, 0.01).unwrap();
        assert_eq!(nearest(&full, &point), 0);
        let RowModel::Discriminant { precision, .. } = &full else {
            panic!("discriminant");
        };
        // inverse of [[1, r], [r, 1]] with r = 0.99 * 0.9.
        let r = 0.99 * 0.9;
        assert!((precision[(0, 0)] - 1.0 / (1.0 - r * r)).abs() < 1e-3);
        assert!((precision[(0, 1)] + r / (1.0 - r * r)).abs() < 1e-3);
        // Shrunk all the way, it is the nearest scaled mean.
        let shrunk = fit_discriminant(&rows, 2, &labels, 2, 1.0).unwrap();
        let (mut v1, mut v2) = ([0.0f32; 2], [0.0f32; 2]);
        shrunk.add_votes(&point, &mut v1);
        diagonal.add_votes(&point, &mut v2);
        assert!((v1[0] - v2[0]).abs() < 1e-4 && (v1[1] - v2[1]).abs() < 1e-4);
        assert!(fit_discriminant(&rows, 2, &labels, 2, 0.0).is_err());
    }

    #[test]
    fn gait_row_sees_speed_but_not_its_direction() {
        let fps = 30.0;
        let n = 60;
        let mut columns = vec![vec![0.0f32; n]; 56];
        for (f, v) in columns[PELVIS_VELOCITY_Z].iter_mut().enumerate() {
            *v = 1.0 + 0.1 * (f as f32 * 0.3).sin();
        }
        let forward = gait_row(&sequence(&columns), fps);
        for v in columns[PELVIS_VELOCITY_Z].iter_mut() {
            *v = -*v;
        }
        let backward = gait_row(&sequence(&columns), fps);
        let speed = 3 * 56;
        assert!((forward[speed] - 1.0).abs() < 0.01);
        assert_eq!(forward[speed], backward[speed]);
        // The signed mean of the velocity differs.
        assert_ne!(forward[PELVIS_VELOCITY_Z], backward[PELVIS_VELOCITY_Z]);
        // Twice as fast a change doubles the rate of change.
        for v in columns[PELVIS_VELOCITY_Z].iter_mut() {
            *v *= 2.0;
        }
        let faster = gait_row(&sequence(&columns), fps);
        let rate = 2 * 56 + PELVIS_VELOCITY_Z;
        assert!((faster[rate] - 2.0 * forward[rate]).abs() < 1e-4);
    }
}
