//! Cleaning whole takes with a trained denoiser.
//!
//! A take of any length is cut into overlapping windows of the model's
//! length `T`, every `hop` frames (default `T / 4`). Each window's output is
//! weighted by `w(t) = sin^2(pi (t + 1/2) / T)`, which is largest in the
//! window's middle and small at its borders, and the weighted outputs are
//! summed and divided by the summed weights. A frame thus gets a smooth mix
//! of the windows that see it well, with no seam where a window ends. The
//! take is padded by repeating its first and last frames so that its own
//! first and last frames are in the middle of some window.
//!
//! Only rotations change: the output has the input's skeleton, channel
//! layout and root translation.
//!
//! Memory: the take, its copy being cleaned and (for a model on a filter of
//! the whole take) that filter's output. A window's rows are cut from the
//! take as it is fed to the network (6D features computed for its frames
//! alone), and after each batch of 256 windows the frames no later window
//! sees are blended and decoded into the output, so nothing else grows
//! with the take (`bench/results/memory.md`).

use std::borrow::Cow;
use std::path::PathBuf;
use std::time::Instant;

use burn::tensor::{Tensor, TensorData};
use mocap_core::io::bvh::write_bvh;
use mocap_core::Motion;
use mocap_feet::{plant_feet_if_asked, FeetOptions, FeetReport};
use mocap_nn::device::DeviceChoice;
use serde::{Deserialize, Serialize};

use crate::despike::{remove_spikes, DespikeOptions, FoundSpike};
use crate::features::{FeatureLayout, Representation};
use crate::filters::{filter_motion, filter_translations, Filter};
use crate::metrics::rotation_error_deg;
use crate::model_file::{window_base, with_base_input, Base, CleanModel, ModelFile};
use crate::wiener::WienerOutcome;
use crate::{CleanError, Result};

impl CleanModel {
    /// Cleans a whole take (see the module docs). `hop` defaults to `T / 4`.
    pub fn clean(&self, motion: &Motion, hop: Option<usize>) -> Result<Motion> {
        Ok(self.clean_reporting(motion, hop)?.0)
    }

    /// [`CleanModel::clean`], also returning the noise level (degrees) its
    /// Wiener filter estimated for the take, when it corrects one
    /// ([`crate::ModelDescription::base_wiener`]) and that filter sees the whole take.
    pub fn clean_reporting(
        &self,
        motion: &Motion,
        hop: Option<usize>,
    ) -> Result<(Motion, Option<f64>)> {
        self.clean_at_level(motion, hop, None)
    }

    /// [`CleanModel::clean_reporting`] with the noise level (degrees) of its
    /// Wiener filter given instead of estimated, when `level_deg` is set.
    pub fn clean_at_level(
        &self,
        motion: &Motion,
        hop: Option<usize>,
        level_deg: Option<f64>,
    ) -> Result<(Motion, Option<f64>)> {
        let (out, outcome) = self.clean_describing(motion, hop, level_deg)?;
        Ok((out, outcome.map(|o| o.sigma_deg)))
    }

    /// [`CleanModel::clean_at_level`], returning all its Wiener filter says
    /// of the take (the level and, in a mixture, the component chosen), when
    /// it corrects one that sees the whole take.
    pub fn clean_describing(
        &self,
        motion: &Motion,
        hop: Option<usize>,
        level_deg: Option<f64>,
    ) -> Result<(Motion, Option<WienerOutcome>)> {
        // A take of another rig goes through the model's own (`crate::rig`).
        let layout = match (self.layout_for(motion), self.rig) {
            (Ok(layout), _) => layout,
            (Err(_), Some(rig)) => {
                return rig.clean_through(motion, |played| {
                    let layout = self.layout_for(played)?;
                    self.clean_laid_out(played, &layout, hop, level_deg)
                })
            }
            (Err(e), None) => return Err(e),
        };
        self.clean_laid_out(motion, &layout, hop, level_deg)
    }

    /// [`CleanModel::clean_describing`] of a take of the model's rig, whose
    /// features are laid out by `layout`.
    fn clean_laid_out(
        &self,
        motion: &Motion,
        layout: &FeatureLayout,
        hop: Option<usize>,
        level_deg: Option<f64>,
    ) -> Result<(Motion, Option<WienerOutcome>)> {
        let c = layout.channels();
        let ci = self.description.network.input_channels();
        let t = self.description.network.window;
        let hop = hop.unwrap_or(t / 4).clamp(1, t);
        let frames = motion.frame_count();
        if frames == 0 {
            return Ok((motion.clone(), None));
        }
        // The features of the whole take, unless a window's can be computed
        // from its frames alone (6D rotations: `FeatureLayout::encode_frames`).
        let features = match layout.representation {
            Representation::Rot6d => None,
            _ => Some(layout.encode(motion)),
        };
        // A base filter that sees the whole take runs once, before the take
        // is cut into windows (see `ModelDescription::base_context`).
        let base = Base::of(
            self.description.base_filter,
            self.description.fps,
            self.base_wiener.as_ref(),
        );
        let mut outcome = None;
        let filtered_take = match &base {
            Some(base) if self.description.base_context > 0 => {
                let mut filtered = match &features {
                    Some(features) => features.clone(),
                    None => layout.encode(motion),
                };
                outcome = base.apply_reporting(&mut filtered, c, level_deg);
                Some(filtered)
            }
            _ => None,
        };
        let noise_deg = outcome.map(|o| o.sigma_deg);
        // Pad by repeating the edge frames: half a window in front, and at
        // the end enough for the last window to be whole. The padded take
        // is not made: a window's rows are cut from the take.
        let front = t / 2;
        let windows = (frames + front).div_ceil(hop).max(1);
        let padded_len = (windows - 1) * hop + t;
        let take_frames = |s: usize| {
            (s..s + t).map(|i| (i as isize - front as isize).clamp(0, frames as isize - 1) as usize)
        };
        let rows = |features: &[f32], s: usize| {
            let mut window = Vec::with_capacity(t * c);
            for f in take_frames(s) {
                window.extend_from_slice(&features[f * c..(f + 1) * c]);
            }
            window
        };
        let weight: Vec<f32> = (0..t)
            .map(|k| {
                (std::f32::consts::PI * (k as f32 + 0.5) / t as f32)
                    .sin()
                    .powi(2)
            })
            .collect();
        // The weighted sums of the windows' outputs, from padded frame
        // `done` on: the frames before the next batch's first window are
        // whole, and are decoded into the output as soon as they are.
        let mut sum: Vec<f32> = Vec::new();
        let mut weight_sum: Vec<f32> = Vec::new();
        let mut done = 0;
        let mut out = motion.clone();
        let batch = 256;
        let mut start_index = 0;
        while start_index < windows {
            let n = batch.min(windows - start_index);
            let mut x = vec![0.0; n * ci * t];
            let mut offsets = Vec::with_capacity(n);
            // Per window, base(x) - x (see `ModelDescription::base_filter`).
            let mut base_corrections = Vec::new();
            for b in 0..n {
                let s = (start_index + b) * hop;
                let mut w = match &features {
                    Some(features) => rows(features, s),
                    None => layout
                        .encode_frames(motion, take_frames(s))
                        .expect("6D features are encoded frame by frame"),
                };
                let recentering = layout.recenter(&mut w);
                let filtered = base.as_ref().map(|base| {
                    let around = filtered_take.as_deref().map(|take| rows(take, s));
                    window_base(&w, around.as_deref(), &recentering, base, c, level_deg)
                });
                offsets.push(recentering);
                if let Some((filtered, window_level)) = filtered {
                    base_corrections.push(
                        filtered
                            .iter()
                            .zip(&w)
                            .map(|(f, x)| f - x)
                            .collect::<Vec<f32>>(),
                    );
                    if self.description.base_input() {
                        w = with_base_input(&w, &filtered, noise_deg.or(window_level), c);
                    }
                }
                for f in 0..t {
                    for ch in 0..ci {
                        x[(b * ci + ch) * t + f] = w[f * ci + ch];
                    }
                }
            }
            let input = Tensor::<3>::from_data(TensorData::new(x, [n, ci, t]), &self.device);
            let output = self.model.forward(input).into_data();
            let y: Vec<f32> = output
                .try_to_vec()
                .map_err(|e| CleanError::Invalid(format!("reading the network output: {e:?}")))?;
            let end = (start_index + n - 1) * hop + t;
            sum.resize((end - done) * c, 0.0);
            weight_sum.resize(end - done, 0.0);
            let mut out_window = vec![0.0; t * c];
            for (b, recentering) in offsets.iter().enumerate() {
                for f in 0..t {
                    for ch in 0..c {
                        out_window[f * c + ch] = y[(b * c + ch) * t + f];
                    }
                }
                if let Some(correction) = base_corrections.get(b) {
                    for (o, d) in out_window.iter_mut().zip(correction) {
                        *o += d;
                    }
                }
                // Back on the take's branch before blending.
                recentering.undo(&mut out_window);
                let s = (start_index + b) * hop - done;
                for f in 0..t {
                    let w = weight[f];
                    weight_sum[s + f] += w;
                    for ch in 0..c {
                        sum[(s + f) * c + ch] += w * out_window[f * c + ch];
                    }
                }
            }
            start_index += n;
            let whole = if start_index < windows {
                start_index * hop
            } else {
                padded_len
            };
            let (first, last) = (done.max(front), whole.min(front + frames));
            if first < last {
                let mut cleaned = vec![0.0; (last - first) * c];
                for p in first..last {
                    for ch in 0..c {
                        cleaned[(p - first) * c + ch] =
                            sum[(p - done) * c + ch] / weight_sum[p - done];
                    }
                }
                layout.decode_frames_into(&cleaned, first - front, &mut out);
            }
            sum.drain(..(whole - done) * c);
            weight_sum.drain(..whole - done);
            done = whole;
        }
        Ok((out, outcome))
    }
}

/// How `mocap clean apply IN -o OUT` cleans.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub enum Method {
    /// The shipped default model.
    DefaultModel,
    /// A model file.
    Model(PathBuf),
    /// A classical filter instead of a model.
    Filter(Filter),
    /// No denoising: only the spike finding asked for (takes with little
    /// random noise, which the shipped model would make worse; see
    /// bench/results/clean.md, "Against the targets").
    SpikesOnly,
}

impl ModelFile {
    /// Cleans `motion` (`hop`: see [`CleanModel::clean`]); also says what
    /// ran, e.g. `Wiener filter (sigma 4.2 deg)`.
    pub fn clean(&self, motion: &Motion, hop: Option<usize>) -> Result<(Motion, String)> {
        let rig = self.rig_for(motion);
        let through = rig.as_ref().map_or(String::new(), |rig| {
            format!(", through the {} rig", rig.name())
        });
        match self {
            ModelFile::Network(model) => {
                let (out, outcome) = model.clean_describing(motion, hop, None)?;
                let label = match (outcome, model.base_wiener()) {
                    (Some(o), Some(wiener)) => format!("model{through} ({})", wiener.describe(&o)),
                    _ => format!("model{through}"),
                };
                Ok((out, label))
            }
            ModelFile::Wiener(filter) => {
                let (out, outcome) = match rig {
                    Some(rig) => rig.clean_through(motion, |played| filter.clean(played, None))?,
                    None => filter.clean(motion, None)?,
                };
                Ok((
                    out,
                    format!("Wiener filter{through} ({})", filter.describe(&outcome)),
                ))
            }
        }
    }
}

/// Options of `mocap clean apply IN -o OUT`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CleanOptions {
    pub input: PathBuf,
    pub output: PathBuf,
    pub method: Method,
    pub device: DeviceChoice,
    /// Frames between window starts (default: a quarter window).
    pub hop: Option<usize>,
    /// Look for spikes in the input and bridge them before cleaning
    /// ([`crate::remove_spikes`]).
    #[serde(default)]
    pub despike: Option<DespikeOptions>,
    /// Also filter the translations (the root's) with this filter
    /// ([`crate::filter_translations`]): what a fused capture needs, whose
    /// root is as noisy as its joints. `None` keeps them.
    #[serde(default)]
    pub root_filter: Option<Filter>,
    /// Then hold planted feet still and above the floor (mocap-feet).
    #[serde(default)]
    pub feet: Option<FeetOptions>,
}

/// What `mocap clean apply IN -o OUT` reports.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CleanReport {
    pub input: PathBuf,
    pub output: PathBuf,
    pub method: String,
    pub frames: usize,
    pub seconds: f64,
    /// Frames cleaned per second (reading and writing excluded).
    pub frames_per_second: f64,
    /// Mean change of the joint rotations, in degrees.
    pub mean_change_deg: f64,
    /// The spikes found and bridged (with `despike`).
    #[serde(default)]
    pub spikes: Vec<BridgedSpike>,
    /// What the feet stage did (with `feet`).
    #[serde(default)]
    pub feet: Option<FeetReport>,
    /// What the user should know of the result (a take of another rig than
    /// the model's).
    #[serde(default)]
    pub notes: Vec<String>,
}

/// A spike that was bridged, as reported: its joint by name (the joints
/// below it were bridged too) and its frames `start..start + frames`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BridgedSpike {
    pub joint: String,
    pub start: usize,
    pub frames: usize,
    /// `start` in seconds from the take's first frame.
    pub start_seconds: f64,
    /// `frames` in seconds.
    pub seconds: f64,
}

impl BridgedSpike {
    fn new(motion: &Motion, spike: &FoundSpike) -> BridgedSpike {
        let frame_time = motion.frame_time();
        BridgedSpike {
            joint: motion.skeleton().joint(spike.joint).name.clone(),
            start: spike.start,
            frames: spike.frames,
            start_seconds: spike.start as f64 * frame_time,
            seconds: spike.frames as f64 * frame_time,
        }
    }
}

/// Reads a take, cleans it and writes it (atomically).
pub fn clean_file(options: &CleanOptions) -> Result<CleanReport> {
    let original = mocap_core::io::read_motion(&options.input)?;
    let in_file = |e: CleanError| match e {
        CleanError::Invalid(m) => CleanError::Invalid(format!("{}: {m}", options.input.display())),
        other => other,
    };
    let start = Instant::now();
    // The take the method cleans: the input, or its copy with the spikes
    // found bridged.
    let (motion, spikes) = match &options.despike {
        Some(despike) => {
            let (bridged, found) = remove_spikes(&original, despike);
            (Cow::Owned(bridged), found)
        }
        None => (Cow::Borrowed(&original), Vec::new()),
    };
    let detect_seconds = start.elapsed().as_secs_f64();
    let mut notes = Vec::new();
    let (cleaned, method, seconds) = match &options.method {
        Method::SpikesOnly => {
            if options.despike.is_none() {
                return Err(CleanError::Invalid(
                    "spike finding only, but no spike finding asked for (despike)".into(),
                ));
            }
            (
                motion.as_ref().clone(),
                "spike finding only".to_string(),
                0.0,
            )
        }
        Method::Filter(filter) => {
            let start = Instant::now();
            let out = filter_motion(&motion, filter)?;
            (out, filter.label(), start.elapsed().as_secs_f64())
        }
        Method::Model(_) | Method::DefaultModel => {
            let (model, source) = match &options.method {
                Method::Model(path) => (ModelFile::load(path, options.device)?, path.clone()),
                _ => {
                    let model = CleanModel::load_default(options.device)?;
                    let source = model.source.clone();
                    (ModelFile::Network(Box::new(model)), source)
                }
            };
            let start = Instant::now();
            if model.rig_for(&motion).is_some() {
                notes.push(format!(
                    "{} is not of the model's rig: it was cleaned through the model's rig \
                     (its body parts played there, the change carried back); on real takes of \
                     other rigs the model measured worse than `--filter butterworth-gcv:2` \
                     (bench/results/clean.md, \"Other rigs\"): compare the two",
                    options.input.display()
                ));
            }
            let (out, label) = model.clean(&motion, options.hop).map_err(in_file)?;
            (
                out,
                format!("{label} {}", source.display()),
                start.elapsed().as_secs_f64(),
            )
        }
    };
    let (cleaned, method) = match &options.root_filter {
        Some(filter) => (
            filter_translations(&cleaned, filter)?,
            format!("{method}; root: {}", filter.label()),
        ),
        None => (cleaned, method),
    };
    let (cleaned, feet) =
        plant_feet_if_asked(cleaned, options.feet.as_ref()).map_err(|e| match e {
            mocap_core::Error::Invalid(m) => {
                CleanError::Invalid(format!("{}: --feet: {m}", options.input.display()))
            }
            other => other.into(),
        })?;
    write_bvh(&options.output, &cleaned)?;
    let frames = motion.frame_count();
    let seconds = seconds + detect_seconds;
    Ok(CleanReport {
        input: options.input.clone(),
        output: options.output.clone(),
        method,
        frames,
        seconds,
        frames_per_second: frames as f64 / seconds.max(1e-9),
        mean_change_deg: rotation_error_deg(&original, &cleaned),
        spikes: spikes
            .iter()
            .map(|s| BridgedSpike::new(&original, s))
            .collect(),
        feet,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    use crate::despike::bridge_spikes;
    use crate::features::Representation;
    use crate::model::{Denoiser, DenoiserConfig};
    use crate::model_file::{ModelDescription, CHECKPOINT_KIND, CHECKPOINT_KIND_VERSION};
    use crate::test_support::synthetic_motion;
    use burn::tensor::Device;
    use mocap_core::io::bvh::read_bvh;
    use mocap_nn::checkpoint::{weights_to_bytes, CheckpointHeader};

    fn model_bytes(representation: Representation, joints: usize) -> Vec<u8> {
        let device = Device::flex();
        device.seed(5);
        let mut network = DenoiserConfig::small(joints * representation.dim());
        network.width = 8;
        let model = network.init(&device).unwrap();
        let description = ModelDescription {
            network,
            representation,
            frame: Default::default(),
            joints: (0..joints).map(|j| format!("j{j}")).collect(),
            fps: 30.0,
            base_filter: None,
            base_context: 0,
            base_wiener: None,
        };
        description_bytes(&model, &description)
    }

    fn description_bytes(model: &Denoiser, description: &ModelDescription) -> Vec<u8> {
        let header = CheckpointHeader {
            kind: CHECKPOINT_KIND.into(),
            kind_version: CHECKPOINT_KIND_VERSION,
            config: serde_json::to_value(description).unwrap(),
            data: serde_json::Value::Null,
            training: serde_json::Value::Null,
        };
        weights_to_bytes(model, &header).unwrap()
    }

    /// Cleaning as it was written before the blend was decoded batch by
    /// batch: the padded take and the weighted sums of the whole take.
    fn whole_take_blend(
        model: &CleanModel,
        motion: &Motion,
        hop: Option<usize>,
        level_deg: Option<f64>,
    ) -> Result<(Motion, Option<WienerOutcome>)> {
        let layout = model.layout_for(motion)?;
        let c = layout.channels();
        let ci = model.description.network.input_channels();
        let t = model.description.network.window;
        let hop = hop.unwrap_or(t / 4).clamp(1, t);
        let frames = motion.frame_count();
        if frames == 0 {
            return Ok((motion.clone(), None));
        }
        let features = layout.encode(motion);
        // A base filter that sees the whole take runs once, before the take
        // is cut into windows (see `ModelDescription::base_context`).
        let base = Base::of(
            model.description.base_filter,
            model.description.fps,
            model.base_wiener.as_ref(),
        );
        let mut outcome = None;
        let filtered_take = match &base {
            Some(base) if model.description.base_context > 0 => {
                let mut filtered = features.clone();
                outcome = base.apply_reporting(&mut filtered, c, level_deg);
                Some(filtered)
            }
            _ => None,
        };
        let noise_deg = outcome.map(|o| o.sigma_deg);
        // Pad by repeating the edge frames: half a window in front, and at
        // the end enough for the last window to be whole.
        let front = t / 2;
        let windows = (frames + front).div_ceil(hop).max(1);
        let padded_len = (windows - 1) * hop + t;
        let pad = |features: &[f32]| {
            let mut padded = Vec::with_capacity(padded_len * c);
            for i in 0..padded_len {
                let f = (i as isize - front as isize).clamp(0, frames as isize - 1) as usize;
                padded.extend_from_slice(&features[f * c..(f + 1) * c]);
            }
            padded
        };
        let padded = pad(&features);
        let padded_filtered = filtered_take.as_deref().map(pad);
        let weight: Vec<f32> = (0..t)
            .map(|k| {
                (std::f32::consts::PI * (k as f32 + 0.5) / t as f32)
                    .sin()
                    .powi(2)
            })
            .collect();
        let mut sum = vec![0.0f32; padded_len * c];
        let mut weight_sum = vec![0.0f32; padded_len];
        let batch = 256;
        let mut start_index = 0;
        while start_index < windows {
            let n = batch.min(windows - start_index);
            let mut x = vec![0.0; n * ci * t];
            let mut offsets = Vec::with_capacity(n);
            // Per window, base(x) - x (see `ModelDescription::base_filter`).
            let mut base_corrections = Vec::new();
            for b in 0..n {
                let s = (start_index + b) * hop;
                let mut w = padded[s * c..(s + t) * c].to_vec();
                let recentering = layout.recenter(&mut w);
                let filtered = base.as_ref().map(|base| {
                    let around = padded_filtered
                        .as_deref()
                        .map(|take| &take[s * c..(s + t) * c]);
                    window_base(&w, around, &recentering, base, c, level_deg)
                });
                offsets.push(recentering);
                if let Some((filtered, window_level)) = filtered {
                    base_corrections.push(
                        filtered
                            .iter()
                            .zip(&w)
                            .map(|(f, x)| f - x)
                            .collect::<Vec<f32>>(),
                    );
                    if model.description.base_input() {
                        w = with_base_input(&w, &filtered, noise_deg.or(window_level), c);
                    }
                }
                for f in 0..t {
                    for ch in 0..ci {
                        x[(b * ci + ch) * t + f] = w[f * ci + ch];
                    }
                }
            }
            let input = Tensor::<3>::from_data(TensorData::new(x, [n, ci, t]), &model.device);
            let output = model.model.forward(input).into_data();
            let y: Vec<f32> = output
                .try_to_vec()
                .map_err(|e| CleanError::Invalid(format!("reading the network output: {e:?}")))?;
            let mut out_window = vec![0.0; t * c];
            for (b, recentering) in offsets.iter().enumerate() {
                for f in 0..t {
                    for ch in 0..c {
                        out_window[f * c + ch] = y[(b * c + ch) * t + f];
                    }
                }
                if let Some(correction) = base_corrections.get(b) {
                    for (o, d) in out_window.iter_mut().zip(correction) {
                        *o += d;
                    }
                }
                // Back on the take's branch before blending.
                recentering.undo(&mut out_window);
                let s = (start_index + b) * hop;
                for f in 0..t {
                    let w = weight[f];
                    weight_sum[s + f] += w;
                    for ch in 0..c {
                        sum[(s + f) * c + ch] += w * out_window[f * c + ch];
                    }
                }
            }
            start_index += n;
        }
        let mut cleaned = vec![0.0; frames * c];
        for f in 0..frames {
            let p = f + front;
            for ch in 0..c {
                cleaned[f * c + ch] = sum[p * c + ch] / weight_sum[p];
            }
        }
        let mut out = motion.clone();
        layout.decode_into(&cleaned, &mut out);
        Ok((out, outcome))
    }

    /// The blend decoded batch by batch gives the bits of blending the
    /// whole take at once, on a real take long enough for several batches
    /// of windows (the sample walk played 12 times: 2,340 frames).
    #[test]
    fn batches_give_the_bits_of_the_whole_take() {
        let walk = read_bvh(&mocap_testdata::sample_walk()).unwrap();
        let mut take = walk.clone();
        for _ in 1..12 {
            take.append(&walk).unwrap();
        }
        let model = CleanModel::load_default(DeviceChoice::Cpu).unwrap();
        for hop in [None, Some(5)] {
            let (expected, expected_outcome) = whole_take_blend(&model, &take, hop, None).unwrap();
            let (got, outcome) = model.clean_describing(&take, hop, None).unwrap();
            assert_eq!(outcome, expected_outcome);
            let same = got
                .values()
                .iter()
                .zip(expected.values())
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "hop {hop:?}: other values");
        }
    }

    #[test]
    fn a_base_context_model_corrects_the_filter_run_over_the_whole_take() {
        // With its output layer zeroed the network corrects nothing, so
        // cleaning must give exactly the base filter over the whole take:
        // this checks the cutting, padding, recentering and blending around
        // the network. Filtering each window on its own gives another answer.
        let joints = 5;
        let device = Device::flex();
        device.seed(5);
        let mut network = DenoiserConfig::small(joints * Representation::Rot6d.dim());
        network.width = 8;
        let mut model = network.init(&device).unwrap();
        model.zero_output();
        let filter = Filter::ButterworthGcv { order: 2 };
        let mut description = ModelDescription {
            network,
            representation: Representation::Rot6d,
            frame: Default::default(),
            joints: (0..joints).map(|j| format!("j{j}")).collect(),
            fps: 30.0,
            base_filter: Some(filter),
            base_context: 64,
            base_wiener: None,
        };
        let clean = crate::test_support::synthetic_motion_phase(150, joints, 0.3);
        let noise = crate::noise::RandomNoise::default();
        let mut rng = <rand::rngs::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(3);
        let noisy = crate::noise::add_random_noise_sigma(&clean, 6.0, &noise, &mut rng);
        let whole_take = filter_motion(&noisy, &filter).unwrap();
        let cleaned_by = |description: &ModelDescription| {
            let bytes = description_bytes(&model, description);
            CleanModel::from_bytes(bytes, Path::new("t"), DeviceChoice::Cpu)
                .unwrap()
                .clean_reporting(&noisy, None)
                .unwrap()
        };
        let (with_context, noise) = cleaned_by(&description);
        // A classical base estimates no noise level.
        assert_eq!(noise, None);
        let off = crate::metrics::rotation_error_deg(&whole_take, &with_context);
        assert!(off < 1e-3, "{off} degrees from the whole-take filter");
        for f in 0..noisy.frame_count() {
            assert_eq!(with_context.root_translation(f), noisy.root_translation(f));
        }
        description.base_context = 0;
        let (per_window, _) = cleaned_by(&description);
        let off = crate::metrics::rotation_error_deg(&whole_take, &per_window);
        assert!(off > 0.05, "per-window filtering is only {off} degrees off");
    }

    #[test]
    fn cleans_takes_of_any_length_and_keeps_the_layout() {
        let bytes = model_bytes(Representation::Rot6d, 5);
        let model = CleanModel::from_bytes(bytes, Path::new("test.safetensors"), DeviceChoice::Cpu)
            .unwrap();
        for frames in [1, 7, 16, 33, 100] {
            let motion = synthetic_motion(frames, 5);
            let out = model.clean(&motion, None).unwrap();
            assert_eq!(out.frame_count(), frames);
            assert_eq!(out.skeleton(), motion.skeleton());
            for f in 0..frames {
                assert_eq!(out.root_translation(f), motion.root_translation(f));
            }
        }
    }

    #[test]
    fn the_blend_has_no_seams() {
        // The output of overlapping windows is a weighted mean; changing the
        // hop moves the window borders, and with smooth weights the result
        // must stay close (an unweighted cut would jump at borders).
        let bytes = model_bytes(Representation::Rot6d, 5);
        let model = CleanModel::from_bytes(bytes, Path::new("t"), DeviceChoice::Cpu).unwrap();
        let motion = synthetic_motion(120, 5);
        let a = model.clean(&motion, Some(4)).unwrap();
        let b = model.clean(&motion, Some(2)).unwrap();
        let diff = crate::metrics::rotation_error_deg(&a, &b);
        let change = crate::metrics::rotation_error_deg(&motion, &a);
        assert!(
            diff < 0.25 * change.max(0.1),
            "hop changes the result by {diff} (model changes {change})"
        );
    }

    #[test]
    fn spikes_are_found_in_the_input_and_bridged_before_the_model_runs() {
        use crate::noise::RandomNoise;
        use crate::test_support::synthetic_motion_phase;
        use crate::wiener::WienerFilter;
        let dir = tempfile::tempdir().unwrap();
        let takes: Vec<Motion> = (0..8)
            .map(|k| synthetic_motion_phase(240, 5, 0.7 * k as f32))
            .collect();
        let refs: Vec<&Motion> = takes.iter().collect();
        let wiener = WienerFilter::fit(&refs, &RandomNoise::default(), 5.0, 32, 1).unwrap();
        let model_path = dir.path().join("wiener.safetensors");
        wiener.save(&model_path, serde_json::Value::Null).unwrap();
        // A take whose joint 2 and the joints below it turn 60 degrees
        // away for frames 100-139.
        let mut spiked = synthetic_motion_phase(240, 5, 0.35);
        let turn = mocap_core::rotation::Quat::from_rotation_x(60f32.to_radians());
        for f in 100..140 {
            let q = spiked.local_rotation(f, 2);
            spiked.set_local_rotation(f, 2, q * turn);
        }
        let input = dir.path().join("spiked.bvh");
        mocap_core::io::bvh::write_bvh(&input, &spiked).unwrap();
        let despike = DespikeOptions::default();
        let output = dir.path().join("out.bvh");
        let report = clean_file(&CleanOptions {
            input: input.clone(),
            output: output.clone(),
            method: Method::Model(model_path),
            device: DeviceChoice::Cpu,
            hop: None,
            despike: Some(despike),
            root_filter: None,
            feet: None,
        })
        .unwrap();
        assert_eq!(report.spikes.len(), 1, "{:?}", report.spikes);
        let spike = &report.spikes[0];
        // Reported by name and in seconds too.
        let spiked = read_bvh(&input).unwrap();
        assert_eq!(spike.joint, spiked.skeleton().joint(2).name);
        assert!(spike.start.abs_diff(100) <= 2 && (spike.start + spike.frames).abs_diff(140) <= 2);
        let frame_time = spiked.frame_time();
        assert!((spike.start_seconds - spike.start as f64 * frame_time).abs() < 1e-9);
        assert!((spike.seconds - spike.frames as f64 * frame_time).abs() < 1e-9);
        // What was written: the filter run on the input with the spike
        // bridged, not its output with the spike bridged.
        let found = [FoundSpike {
            joint: 2,
            start: spike.start,
            frames: spike.frames,
        }];
        let written = read_bvh(&output).unwrap();
        let (again, _) = wiener.clean(&bridge_spikes(&spiked, &found), None).unwrap();
        assert!(crate::metrics::rotation_error_deg(&again, &written) < 1e-3);
        let (first, _) = wiener.clean(&spiked, None).unwrap();
        let bridged_after = bridge_spikes(&first, &found);
        assert!(crate::metrics::rotation_error_deg(&bridged_after, &written) > 0.01);
    }

    #[test]
    fn checkpoints_round_trip_and_reject_other_files() {
        let bytes = model_bytes(Representation::Euler, 5);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.safetensors");
        std::fs::write(&path, &bytes).unwrap();
        let a = CleanModel::load(&path, DeviceChoice::Cpu).unwrap();
        let b = CleanModel::from_bytes(bytes.clone(), &path, DeviceChoice::Cpu).unwrap();
        let motion = synthetic_motion(40, 5);
        assert_eq!(
            a.clean(&motion, None).unwrap().values(),
            b.clean(&motion, None).unwrap().values()
        );
        assert_eq!(a.description.representation, Representation::Euler);
        // A file that is not a checkpoint is an error naming it.
        std::fs::write(&path, b"not a model").unwrap();
        let e = CleanModel::load(&path, DeviceChoice::Cpu)
            .unwrap_err()
            .to_string();
        assert!(e.contains("m.safetensors"), "{e}");
        // A model for another skeleton is an error, not a panic.
        let other = synthetic_motion(20, 7);
        assert!(a.clean(&other, None).is_err());
        // A description whose network does not read what it says is refused:
        // a base input without a base, or without the inputs for it.
        let refused = |description: &ModelDescription| {
            let bytes = description_bytes(&a.model, description);
            match CleanModel::from_bytes(bytes, &path, DeviceChoice::Cpu) {
                Ok(_) => panic!("a model reading what it has not was accepted"),
                Err(e) => e.to_string(),
            }
        };
        let mut description = a.description.clone();
        description.network.extra_inputs = description.network.channels + 1;
        let e = refused(&description);
        assert!(
            e.contains("needs a base Wiener filter (it has none)"),
            "{e}"
        );
        description.base_filter = Some(Filter::ButterworthGcv { order: 2 });
        description.network.extra_inputs = 1;
        let e = refused(&description);
        assert!(e.contains("reads 1 inputs besides its features"), "{e}");
    }
}
