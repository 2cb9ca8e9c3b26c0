//! Training the denoiser: windows of clean takes with noise generated on the
//! fly, Adam, validation after every epoch, checkpoints, resume, and a PNG
//! of the loss curves.
//!
//! Reproducibility: the network is initialised from `seed`, and the samples
//! of epoch `e` come from a generator seeded with `(seed, e)`, so a resumed
//! run draws exactly the samples an uninterrupted one would. The validation
//! windows are drawn once from a fixed seed that does not depend on `seed`,
//! so runs with different seeds and losses are validated on the same data.
//! The validation loss is the plain mean squared error of the features, for
//! every training loss, so that curves of different losses compare.

use std::path::{Path, PathBuf};
use std::time::Instant;

use burn::module::Module;
use burn::tensor::{Device, Tensor, TensorData};
use mocap_core::io::read_motion;
use mocap_core::Motion;
use mocap_nn::checkpoint::{
    load_weights_from_bytes, save_epoch, start_run, CheckpointHeader, RunStart,
};
use mocap_nn::device::{seed_device, DeviceChoice};
use mocap_nn::plot::PlotOptions;
use mocap_nn::train::{epoch_seed, optimizer_step, run_epochs, EpochPlan, History};
use rand::rngs::ChaCha8Rng;
use rand::{Rng, RngExt, SeedableRng};
use serde::{Deserialize, Serialize};

use crate::dataset::{
    list_bvh, load_takes, looped_window, paths_in_split, window, DataDescription, Split,
    SplitFractions, Take,
};
use crate::features::{FeatureLayout, Representation, RotationFrame};
use crate::filters::Filter;
use crate::fk::FkSkeleton;
use crate::loss::{derivative_loss, position_loss, LossWeights};
use crate::model::{Denoiser, DenoiserConfig};
use crate::model_file::{
    base_input_channels, window_base, with_base_input, Base, CleanModel, ModelDescription,
    CHECKPOINT_KIND, CHECKPOINT_KIND_VERSION,
};
use crate::noise::{NoiseConfig, NoiseRigs};
use crate::wiener::WienerFilter;
use crate::{CleanError, Result};

/// The seed of the validation windows (fixed across runs).
const VALIDATION_SEED: u64 = 0x0005_eed0_fba1;

/// Options of `mocap clean train`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TrainOptions {
    /// Folders or files of clean BVH takes (split by take).
    pub inputs: Vec<PathBuf>,
    /// The model file to write (safetensors).
    pub out: PathBuf,
    /// Folder of the resumable training state; default `<out>.state`.
    pub state_dir: Option<PathBuf>,
    /// Continue from the state folder when it holds a state.
    pub resume: bool,
    pub representation: Representation,
    /// Which rotation of each joint the network sees.
    #[serde(default)]
    pub frame: RotationFrame,
    /// See [`ModelDescription::base_filter`].
    #[serde(default)]
    pub base_filter: Option<Filter>,
    /// See [`ModelDescription::base_context`].
    #[serde(default)]
    pub base_context: usize,
    /// A Wiener filter file (`mocap clean fit-wiener`) the network
    /// corrects, instead of `base_filter` (see
    /// [`ModelDescription::base_wiener`]).
    #[serde(default)]
    pub base_wiener: Option<PathBuf>,
    /// The network also reads its Wiener filter's output and the noise level
    /// the filter estimated (in units of 10 degrees, the report's largest noise; constant
    /// along the window; only a Wiener filter estimates one, so this needs
    /// `base_wiener`), after the noisy features, and its correction is
    /// multiplied by that level (see [`crate::DenoiserConfig::extra_inputs`]).
    ///
    /// Without them the network sees only the noisy window, so it cannot
    /// tell what the filter (which sees the whole take) already did, nor how
    /// noisy the take is: it then adds a correction of the average noise
    /// level to a clean take too (measured: 0.81 degrees on clean test takes
    /// for such a model). A noise-level input is how
    /// FFDNet (Zhang, Zuo and Zhang 2018) makes one denoiser serve every
    /// noise level. The inputs alone did not stop that (0.85 degrees on 40
    /// clean test takes after 4 epochs), hence the scaling: where the filter
    /// finds no noise the model gives the filter's output, which is then the
    /// take itself.
    #[serde(default)]
    pub base_input: bool,
    /// Network sizes; `channels` is set from the data.
    pub network: DenoiserConfig,
    pub epochs: usize,
    pub steps_per_epoch: usize,
    pub batch_size: usize,
    pub learning_rate: f64,
    /// Loss weights; `fps` is replaced by the data's frame rate when
    /// `derivative_loss` is set.
    pub alpha: f32,
    pub beta: f32,
    /// Use the report's `alpha = dt^2`, `beta = dt^4` (overrides alpha, beta).
    pub derivative_loss: bool,
    pub noise: NoiseConfig,
    pub split: SplitFractions,
    pub validation_windows: usize,
    pub seed: u64,
    pub device: DeviceChoice,
    /// Loss-curve PNG; default `<out>` with extension `png`.
    pub plot: Option<PathBuf>,
    /// Use at most this many training takes (quick runs and tests).
    pub max_train_takes: Option<usize>,
    /// Start from the weights of this model file (the same network on the
    /// same rig, e.g. the shipped model, to go on training it on other
    /// noise) instead of random weights. A resumed run ignores it.
    #[serde(default)]
    pub init: Option<PathBuf>,
    /// Other rigs (motion files whose skeletons are used) the noise is also
    /// put on: each window is played by one of them or by its own rig at
    /// random, the noise put on there, and the clean and the noisy window
    /// played back. What a model that cleans takes of other rigs through
    /// its own rig (`crate::rig`) sees: their noise is about their bones.
    #[serde(default)]
    pub noise_rigs: Vec<PathBuf>,
    /// Weight of the position term of the loss (forward kinematics of the
    /// 6D features on the first training take's skeleton, see `fk.rs`), per
    /// squared skeleton unit; 0 leaves it out (the report's loss).
    #[serde(default)]
    pub position_weight: f32,
}

impl Default for TrainOptions {
    /// The shipped default: small network, 6D rotations, derivative loss,
    /// both noise kinds, Adam with lr 1e-3 and batch 512.
    fn default() -> Self {
        TrainOptions {
            inputs: Vec::new(),
            out: PathBuf::from("clean.safetensors"),
            state_dir: None,
            resume: false,
            representation: Representation::Rot6d,
            frame: RotationFrame::Local,
            base_filter: None,
            base_context: 0,
            base_wiener: None,
            base_input: false,
            network: DenoiserConfig::small(0),
            epochs: 20,
            steps_per_epoch: 40,
            batch_size: 512,
            learning_rate: 1e-3,
            alpha: 0.0,
            beta: 0.0,
            derivative_loss: true,
            noise: NoiseConfig::default(),
            split: SplitFractions::default(),
            validation_windows: 1024,
            seed: 1,
            device: DeviceChoice::Cpu,
            plot: None,
            max_train_takes: None,
            init: None,
            noise_rigs: Vec::new(),
            position_weight: 0.0,
        }
    }
}

/// What `mocap clean train` reports.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TrainReport {
    pub model: PathBuf,
    pub plot: PathBuf,
    pub description: ModelDescription,
    pub parameters: usize,
    pub loss: LossWeights,
    pub data: DataDescription,
    pub history: History,
    /// Training samples per second (training steps only).
    pub samples_per_second: f64,
    /// Wall-clock seconds of this call (loading data included).
    pub seconds: f64,
    pub resumed_from_epoch: usize,
    /// Seconds per step spent drawing windows and making noise (part of
    /// the training time above).
    pub data_seconds_per_step: f64,
    /// Validation MSE of the noisy input itself (what the curves start from).
    pub validation_input_mse: f64,
}

/// Draws training pairs (noisy, clean) of features from takes.
pub struct WindowSampler<'a> {
    takes: Vec<&'a Take>,
    /// Cumulative count of window starts, to pick a window uniformly.
    cumulative: Vec<usize>,
    layout: &'a FeatureLayout,
    frames: usize,
    noise: NoiseConfig,
    /// What the network corrects (see [`ModelDescription::base_filter`]).
    base: Option<Base<'a>>,
    /// Frames of the take the noise and the base filter see on each side of
    /// the window ([`ModelDescription::base_context`]).
    context: usize,
    /// The input also holds the base's output and noise level
    /// ([`TrainOptions::base_input`]).
    base_input: bool,
    /// Other rigs the noise is put on ([`TrainOptions::noise_rigs`]).
    rigs: NoiseRigs,
}

impl<'a> WindowSampler<'a> {
    /// A sampler of windows of `frames` frames; takes shorter than that are
    /// skipped.
    pub fn new(
        takes: &'a [Take],
        layout: &'a FeatureLayout,
        frames: usize,
        noise: NoiseConfig,
    ) -> Result<Self> {
        let takes: Vec<&Take> = takes
            .iter()
            .filter(|t| t.motion.frame_count() >= frames)
            .collect();
        let mut cumulative = Vec::with_capacity(takes.len());
        let mut total = 0;
        for t in &takes {
            total += t.motion.frame_count() - frames + 1;
            cumulative.push(total);
        }
        if takes.len() < 2 {
            return Err(CleanError::Invalid(format!(
                "need at least two takes of {frames} frames or more (spikes are taken from another take)"
            )));
        }
        Ok(WindowSampler {
            takes,
            cumulative,
            layout,
            frames,
            noise,
            base: None,
            context: 0,
            base_input: false,
            rigs: NoiseRigs::default(),
        })
    }

    /// Samples whose noise is also put on other rigs
    /// ([`TrainOptions::noise_rigs`]).
    pub(crate) fn with_noise_rigs(mut self, rigs: NoiseRigs) -> Self {
        self.rigs = rigs;
        self
    }

    /// Targets for a model whose output is added to `base` run on its
    /// input, with `context` frames of the take on each side of the window
    /// (see [`ModelDescription::base_filter`] and
    /// [`ModelDescription::base_context`]). The noise is then added to the
    /// window with its context, as it is added to whole takes in use.
    pub(crate) fn with_base(mut self, base: Option<Base<'a>>, context: usize) -> Self {
        self.base = base;
        self.context = if self.base.is_some() { context } else { 0 };
        self
    }

    /// Inputs that also hold the base's output and the noise level it
    /// estimated ([`TrainOptions::base_input`]; needs a base, which training
    /// checks is a Wiener filter).
    pub(crate) fn with_base_input(mut self, on: bool) -> Self {
        self.base_input = on && self.base.is_some();
        self
    }

    /// Rows of an input window: the features, then with
    /// [`TrainOptions::base_input`] the base's output and the noise level.
    pub fn input_channels(&self) -> usize {
        let c = self.layout.channels();
        if self.base_input {
            c + base_input_channels(c)
        } else {
            c
        }
    }

    fn pick<R: Rng + ?Sized>(&self, rng: &mut R) -> (usize, usize) {
        let total = *self.cumulative.last().expect("at least two takes");
        let u = rng.random_range(0..total);
        let t = self.cumulative.partition_point(|&c| c <= u);
        let before = if t == 0 { 0 } else { self.cumulative[t - 1] };
        (t, u - before)
    }

    /// A window with up to `context` frames of its take on each side (as
    /// many as the take has), clean and noisy.
    fn sample_stretch<R: Rng + ?Sized>(&self, rng: &mut R) -> Result<Stretch> {
        let (t, start) = self.pick(rng);
        let take = &self.takes[t].motion;
        let first = start.saturating_sub(self.context);
        let end = (start + self.frames + self.context).min(take.frame_count());
        let clean = window(take, first, end - first);
        // Spike donors: stretches of other takes, as long as this one.
        let mut donors = Vec::new();
        for _ in 0..self.noise.spikes.map_or(0, |s| s.max_spikes.max(1)) {
            let (mut d, mut s) = self.pick(rng);
            while d == t {
                (d, s) = self.pick(rng);
            }
            donors.push(looped_window(&self.takes[d].motion, s, end - first));
        }
        let donor_refs: Vec<&Motion> = donors.iter().collect();
        let (clean, noisy) = self.rigs.add_noise(&clean, &donor_refs, &self.noise, rng)?;
        Ok(Stretch {
            noisy,
            clean,
            window_start: start - first,
        })
    }

    /// A batch as `[batch, channels, frames]` tensor data (noisy, clean).
    ///
    /// Each sample has its own generator seeded from `rng`, so the batch is
    /// the same whatever the number of threads that make it.
    pub fn batch<R: Rng + ?Sized>(&self, rng: &mut R, size: usize) -> Result<(Vec<f32>, Vec<f32>)> {
        use rayon::prelude::*;
        let c = self.layout.channels();
        let ci = self.input_channels();
        let t = self.frames;
        let seeds: Vec<u64> = (0..size).map(|_| rng.random::<u64>()).collect();
        let samples = seeds
            .par_iter()
            .map(|&seed| {
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                let stretch = self.sample_stretch(&mut rng)?;
                let xs = self.layout.encode(&stretch.noisy);
                let mut ys = self.layout.encode(&stretch.clean);
                // Euler angles and exponential maps: the target on the
                // input's branch, then both brought to the canonical range
                // the same way (see `FeatureLayout::align_target`).
                self.layout.align_target(&xs, &mut ys);
                let crop = |v: &[f32]| {
                    v[stretch.window_start * c..(stretch.window_start + t) * c].to_vec()
                };
                let (mut xf, mut yf) = (crop(&xs), crop(&ys));
                let recentering = self.layout.recenter(&mut xf);
                recentering.apply(&mut yf);
                if let Some(base) = &self.base {
                    // With a context the filter sees the whole stretch, as
                    // it sees the whole take in use.
                    let mut stretch_level = None;
                    let around = (self.context > 0).then(|| {
                        let mut filtered = xs.clone();
                        stretch_level = base.apply(&mut filtered, c, None);
                        crop(&filtered)
                    });
                    let (base, window_level) =
                        window_base(&xf, around.as_deref(), &recentering, base, c, None);
                    // The network's output N(x) stands for y - base(x) + x,
                    // so that the model's output N(x) - x + base(x) is y.
                    for ((y, x), b) in yf.iter_mut().zip(&xf).zip(&base) {
                        *y += x - b;
                    }
                    if self.base_input {
                        xf = with_base_input(&xf, &base, stretch_level.or(window_level), c);
                    }
                }
                Ok((xf, yf))
            })
            .collect::<Result<Vec<_>>>()?;
        let mut x = vec![0.0; size * ci * t];
        let mut y = vec![0.0; size * c * t];
        for (b, (xf, yf)) in samples.iter().enumerate() {
            for f in 0..t {
                for ch in 0..ci {
                    x[(b * ci + ch) * t + f] = xf[f * ci + ch];
                }
                for ch in 0..c {
                    y[(b * c + ch) * t + f] = yf[f * c + ch];
                }
            }
        }
        Ok((x, y))
    }
}

/// A window of a take with its context, clean and noisy (see
/// [`WindowSampler::sample_stretch`]).
struct Stretch {
    noisy: Motion,
    clean: Motion,
    /// Where the window starts in the stretch.
    window_start: usize,
}

fn tensor(data: Vec<f32>, shape: [usize; 3], device: &Device) -> Tensor<3> {
    Tensor::from_data(TensorData::new(data, shape), device)
}

/// The mean squared error of `model` on fixed validation batches.
fn validation_loss(
    model: &Denoiser,
    batches: &[(Vec<f32>, Vec<f32>)],
    shape: [usize; 3],
    target_shape: [usize; 3],
    device: &Device,
) -> f64 {
    let model = model.valid();
    let mut sum = 0.0;
    for (x, y) in batches {
        let pred = model.forward(tensor(x.clone(), shape, device));
        let target = tensor(y.clone(), target_shape, device);
        let loss: f32 = (pred - target).powi_scalar(2).mean().into_scalar();
        sum += loss as f64;
    }
    sum / batches.len().max(1) as f64
}

/// The network training starts from: random weights, or those of the model
/// file `init` (which must have the same network, rig and base).
fn initial_network(
    network: &DenoiserConfig,
    description: &ModelDescription,
    init: Option<&Path>,
    device: &Device,
) -> Result<Denoiser> {
    let fresh = network.init(device)?;
    let Some(path) = init else {
        return Ok(fresh);
    };
    let model = CleanModel::load(path, Default::default())?;
    let given = &model.description;
    if given.network != *network
        || given.joints != description.joints
        || given.representation != description.representation
        || given.frame != description.frame
        || given.base_input() != description.base_input()
    {
        return Err(CleanError::Invalid(format!(
            "{}: its network, rig or inputs are not those of this training (train with its \
             recipe, rig and base options)",
            path.display()
        )));
    }
    let bytes = std::fs::read(path).map_err(|e| mocap_core::Error::io(path, e))?;
    let mut fresh = fresh;
    // The weights ride with the base filter the file also holds.
    fresh.base = given.base_wiener.as_ref().map(WienerFilter::empty_tensors);
    let mut loaded = load_weights_from_bytes(bytes, path, fresh)?;
    loaded.base = None;
    Ok(loaded)
}

/// Trains a denoiser (see the module docs).
pub fn train(options: &TrainOptions) -> Result<TrainReport> {
    let started = Instant::now();
    let paths = list_bvh(&options.inputs)?;
    let mut train_paths = paths_in_split(&paths, Split::Train, &options.split);
    if let Some(max) = options.max_train_takes {
        train_paths.truncate(max);
    }
    let valid_paths = paths_in_split(&paths, Split::Validation, &options.split);
    let train_takes = load_takes(&train_paths)?;
    let valid_takes = load_takes(&valid_paths)?;
    let first = train_takes
        .first()
        .ok_or_else(|| CleanError::Invalid("no training takes".into()))?;
    let fps = first.motion.fps() as f32;
    let layout = FeatureLayout::new(first.motion.skeleton(), options.representation)?
        .in_frame(options.frame)?;
    let joints = layout.joint_names(first.motion.skeleton());
    let mut network = options.network;
    network.channels = layout.channels();
    // Any base: a classical filter or a Wiener filter.
    let any_base = options.base_filter.is_some() || options.base_wiener.is_some();
    network.validate()?;
    // A learned Wiener filter as the base: fitted to this rig's 6D local
    // rotations, which the network must then read too.
    let base_wiener = match &options.base_wiener {
        None => None,
        Some(path) => {
            let wiener = WienerFilter::load(path)?;
            let why = if options.base_filter.is_some() {
                Some("give a base filter or a base Wiener filter, not both".to_string())
            } else if options.representation != Representation::Rot6d
                || options.frame != RotationFrame::Local
            {
                Some("a Wiener filter works on 6D local rotations (--representation rot6d --rotations local)".to_string())
            } else if wiener.description.joints != joints {
                Some(format!(
                    "{} was fitted to another rig ({} joints with rotations, the data has {})",
                    path.display(),
                    wiener.description.joints.len(),
                    joints.len()
                ))
            } else if (wiener.description.fps - fps).abs() > 1e-3 {
                Some(format!(
                    "{} was fitted at {} fps, the data is at {fps}",
                    path.display(),
                    wiener.description.fps
                ))
            } else {
                None
            };
            if let Some(why) = why {
                return Err(CleanError::Invalid(why));
            }
            Some(wiener)
        }
    };
    if options.base_input && options.base_wiener.is_none() {
        // The correction is scaled by the noise level the base estimates,
        // and only a Wiener filter estimates one.
        return Err(CleanError::Invalid(
            "--base-input needs a base Wiener filter (the noise level it estimates is an input)"
                .into(),
        ));
    }
    // What the network reads besides the features follows from the options
    // alone (a configuration copied from another model may say otherwise).
    network.extra_inputs = if options.base_input {
        base_input_channels(layout.channels())
    } else {
        0
    };
    if options.base_context > 0 && !any_base {
        return Err(CleanError::Invalid(
            "a base context needs a base filter (the context is what that filter sees)".into(),
        ));
    }
    let description = ModelDescription {
        network,
        representation: options.representation,
        frame: options.frame,
        joints,
        fps,
        base_filter: options.base_filter,
        base_context: options.base_context,
        base_wiener: base_wiener.as_ref().map(|w| w.description.clone()),
    };
    let base = Base::of(options.base_filter, fps, base_wiener.as_ref());
    let loss = if options.derivative_loss {
        LossWeights::derivative(fps)
    } else {
        LossWeights {
            alpha: options.alpha,
            beta: options.beta,
            fps,
        }
    };
    let data = DataDescription {
        train_takes: train_takes.len(),
        train_frames: train_takes.iter().map(|t| t.motion.frame_count()).sum(),
        validation_takes: valid_takes.len(),
        validation_frames: valid_takes.iter().map(|t| t.motion.frame_count()).sum(),
        ..DataDescription::new(&options.inputs, &paths, options.split, fps as f64)
    };

    if options.position_weight > 0.0 && any_base {
        return Err(CleanError::Invalid(
            "the position term and a base filter do not go together (the term reads the network's output as rotations)".into(),
        ));
    }
    let fk = if options.position_weight > 0.0 {
        Some(FkSkeleton::new(first.motion.skeleton(), &layout)?)
    } else {
        None
    };
    let others = options
        .noise_rigs
        .iter()
        .map(|path| Ok(read_motion(path)?.skeleton().clone()))
        .collect::<Result<Vec<_>>>()?;
    let rigs = NoiseRigs::new(first.motion.skeleton(), &others)?;
    let train_sampler = WindowSampler::new(&train_takes, &layout, network.window, options.noise)?
        .with_base(base, options.base_context)
        .with_base_input(options.base_input)
        .with_noise_rigs(rigs.clone());
    let valid_sampler = WindowSampler::new(&valid_takes, &layout, network.window, options.noise)?
        .with_base(base, options.base_context)
        .with_base_input(options.base_input)
        .with_noise_rigs(rigs);
    let shape = [options.batch_size, network.input_channels(), network.window];
    let target_shape = [
        options.batch_size,
        network.output_channels(),
        network.window,
    ];
    let mut valid_rng = ChaCha8Rng::seed_from_u64(VALIDATION_SEED);
    let valid_batches = (0..options
        .validation_windows
        .div_ceil(options.batch_size)
        .max(1))
        .map(|_| valid_sampler.batch(&mut valid_rng, options.batch_size))
        .collect::<Result<Vec<_>>>()?;

    // The validation MSE of doing nothing (the noisy input itself), for
    // scale. The features are the first rows of every sample's input.
    let validation_input_mse = {
        let (ci, c, t) = (network.input_channels(), network.channels, network.window);
        valid_batches
            .iter()
            .map(|(x, y)| {
                x.chunks(ci * t)
                    .zip(y.chunks(c * t))
                    .flat_map(|(x, y)| x[..c * t].iter().zip(y))
                    .map(|(a, b)| ((a - b) * (a - b)) as f64)
                    .sum::<f64>()
                    / y.len() as f64
            })
            .sum::<f64>()
            / valid_batches.len() as f64
    };
    let device = options.device.training_device()?;
    let plain_device = options.device.device()?;
    seed_device(&device, options.seed);
    let RunStart {
        state,
        plot,
        model,
        optimizer,
        mut history,
    } = start_run(
        &options.out,
        options.state_dir.as_deref(),
        options.plot.as_deref(),
        options.resume,
        initial_network(&network, &description, options.init.as_deref(), &device)?,
    )?;
    let resumed_from_epoch = history.epochs.len();
    let header = |history: &History| CheckpointHeader {
        kind: CHECKPOINT_KIND.into(),
        kind_version: CHECKPOINT_KIND_VERSION,
        config: serde_json::to_value(&description).expect("serialisable"),
        data: serde_json::json!({ "data": data, "noise": options.noise }),
        training: serde_json::json!({
            "loss": loss,
            "epochs": history.epochs.len(),
            "steps_per_epoch": options.steps_per_epoch,
            "batch_size": options.batch_size,
            "learning_rate": options.learning_rate,
            "seed": options.seed,
            "position_weight": options.position_weight,
            "history": history,
        }),
    };

    let plan = EpochPlan {
        epochs: options.epochs,
        steps_per_epoch: options.steps_per_epoch,
        batch_size: options.batch_size,
    };
    struct Run {
        model: Option<Denoiser>,
        optimizer: burn::optim::ModuleOptimizer,
        rng: ChaCha8Rng,
        rng_epoch: usize,
        data_seconds: f64,
    }
    let mut run = Run {
        model: Some(model),
        optimizer,
        rng: ChaCha8Rng::seed_from_u64(0),
        rng_epoch: usize::MAX,
        data_seconds: 0.0,
    };
    run_epochs(
        &mut run,
        &mut history,
        plan,
        |run, epoch, _step| -> Result<f64> {
            if run.rng_epoch != epoch {
                run.rng = ChaCha8Rng::seed_from_u64(epoch_seed(options.seed, epoch));
                run.rng_epoch = epoch;
            }
            let data_start = Instant::now();
            let (x, y) = train_sampler.batch(&mut run.rng, options.batch_size)?;
            run.data_seconds += data_start.elapsed().as_secs_f64();
            let model = run.model.take().expect("model present");
            let pred = model.forward(tensor(x, shape, &device));
            let target = tensor(y, target_shape, &device);
            let mut l = derivative_loss(pred.clone(), target.clone(), &loss);
            if let Some(fk) = &fk {
                l = l + position_loss(fk, pred, target) * options.position_weight;
            }
            let (model, value) =
                optimizer_step(model, &mut run.optimizer, l, options.learning_rate);
            run.model = Some(model);
            Ok(value)
        },
        |run, _epoch| {
            Ok(validation_loss(
                run.model.as_ref().expect("model"),
                &valid_batches,
                shape,
                target_shape,
                &plain_device,
            ))
        },
        |run, history| {
            let model = run.model.as_ref().expect("model");
            // The written model carries its Wiener filter (not the training
            // state, which only the network's weights and Adam's need).
            let mut written = model.valid();
            written.base = base_wiener.as_ref().map(WienerFilter::to_tensors);
            save_epoch(
                &state,
                model,
                &run.optimizer,
                history,
                &options.out,
                &written,
                &header(history),
                &plot,
                &PlotOptions {
                    y_label: "loss (training: chosen loss; validation: MSE)".into(),
                    ..PlotOptions::new(format!(
                        "mocap-clean training ({})",
                        if loss.is_mse() {
                            "MSE"
                        } else {
                            "derivative loss"
                        }
                    ))
                },
            )?;
            Ok(())
        },
    )?;
    if history.epochs.is_empty() {
        return Err(CleanError::Invalid("no epoch was run (epochs = 0)".into()));
    }
    let samples_per_second = history.samples_per_second();
    let steps_run = (history.epochs.len() - resumed_from_epoch) * options.steps_per_epoch;
    Ok(TrainReport {
        model: options.out.clone(),
        plot,
        parameters: network.parameter_count(),
        description,
        loss,
        data,
        samples_per_second,
        seconds: started.elapsed().as_secs_f64(),
        resumed_from_epoch,
        history,
        data_seconds_per_step: run.data_seconds / steps_run.max(1) as f64,
        validation_input_mse,
    })
}

#[cfg(test)]
impl<'a> WindowSampler<'a> {
    /// The sampler with a classical filter at `fps` as its base (see `with_base`).
    fn with_base_filter(self, base: Option<Filter>, fps: f32, context: usize) -> Self {
        self.with_base(base.map(|f| Base::Classical(f, fps)), context)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filters::filter_features;
    use crate::test_support::synthetic_motion_phase;
    use mocap_core::io::bvh::write_bvh;
    use std::path::Path;

    /// Training seeds the device's global generator: runs in parallel tests
    /// would draw from it in turn and lose their reproducibility.
    static ONE_RUN_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

    /// A folder of small synthetic takes and options for a tiny run.
    fn tiny_setup(dir: &Path) -> TrainOptions {
        let data = dir.join("data");
        std::fs::create_dir_all(&data).unwrap();
        for i in 0..30 {
            let m = synthetic_motion_phase(40, 4, i as f32 * 0.37);
            write_bvh(&data.join(format!("take_{i:02}.bvh")), &m).unwrap();
        }
        TrainOptions {
            inputs: vec![data],
            network: DenoiserConfig {
                channels: 0,
                width: 4,
                levels: 1,
                blocks: 1,
                kernel: 3,
                window: 8,
                extra_inputs: 0,
            },
            epochs: 2,
            steps_per_epoch: 2,
            batch_size: 8,
            validation_windows: 8,
            split: SplitFractions {
                validation: 0.3,
                test: 0.0,
            },
            ..TrainOptions::default()
        }
    }

    #[test]
    fn a_run_started_from_a_model_starts_where_that_model_ended() {
        let _one = ONE_RUN_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
        let dir = tempfile::tempdir().unwrap();
        let base = tiny_setup(dir.path());
        let first = TrainOptions {
            out: dir.path().join("a.safetensors"),
            epochs: 1,
            ..base.clone()
        };
        let a = train(&first).unwrap();
        // Not one step taken (a zero learning rate): the weights, and so
        // the validation loss, are the first model's; from random weights
        // they are not.
        let still = |init: Option<PathBuf>, out: &str| TrainOptions {
            out: dir.path().join(out),
            epochs: 1,
            learning_rate: 0.0,
            init,
            ..base.clone()
        };
        let b = train(&still(Some(a.model.clone()), "b.safetensors")).unwrap();
        let fresh = train(&still(None, "c.safetensors")).unwrap();
        let loss = |r: &TrainReport| r.history.epochs[0].valid_loss;
        assert!(
            (loss(&a) - loss(&b)).abs() < 1e-6 * loss(&a),
            "{} {}",
            loss(&a),
            loss(&b)
        );
        assert!((loss(&a) - loss(&fresh)).abs() > 1e-3 * loss(&a));
        // Another network: refused, naming the file.
        let wider = TrainOptions {
            network: DenoiserConfig {
                width: 8,
                ..base.network
            },
            ..still(Some(a.model.clone()), "d.safetensors")
        };
        let error = train(&wider).unwrap_err().to_string();
        assert!(error.contains("a.safetensors"), "{error}");
    }

    #[test]
    fn a_resumed_run_matches_an_uninterrupted_one() {
        let _one = ONE_RUN_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
        let dir = tempfile::tempdir().unwrap();
        let base = tiny_setup(dir.path());
        let straight = TrainOptions {
            out: dir.path().join("a.safetensors"),
            ..base.clone()
        };
        let a = train(&straight).unwrap();
        let first_half = TrainOptions {
            out: dir.path().join("b.safetensors"),
            epochs: 1,
            ..base.clone()
        };
        train(&first_half).unwrap();
        let resumed = TrainOptions {
            epochs: 2,
            resume: true,
            ..first_half
        };
        let b = train(&resumed).unwrap();
        assert_eq!(b.resumed_from_epoch, 1);
        assert_eq!(a.history.epochs.len(), 2);
        assert_eq!(b.history.epochs.len(), 2);
        for (x, y) in a.history.epochs.iter().zip(&b.history.epochs) {
            let tol = 1e-5 * x.valid_loss.abs().max(1e-3);
            assert!((x.valid_loss - y.valid_loss).abs() < tol, "{x:?} vs {y:?}");
            assert!((x.train_loss - y.train_loss).abs() < 1e-5 * x.train_loss.abs().max(1e-3));
        }
        // The model file says what it is and what it was trained on.
        let header = mocap_nn::checkpoint::read_header(&b.model).unwrap();
        assert_eq!(header.kind, CHECKPOINT_KIND);
        assert_eq!(header.data["data"]["train_takes"], b.data.train_takes);
        assert!(b.plot.is_file());
    }

    /// Three synthetic 40-frame takes of 4 joints.
    fn three_takes() -> Vec<Take> {
        (0..3)
            .map(|i| Take {
                name: format!("take_{i}"),
                path: PathBuf::new(),
                motion: synthetic_motion_phase(40, 4, i as f32),
            })
            .collect()
    }

    const TWO_HERTZ: Filter = Filter::Butterworth {
        order: 2,
        cutoff_hz: 2.0,
    };

    /// Sample `b` of a `[sample, channel, frame]` batch, frame after frame
    /// (as features and filters take it).
    fn frame_major(batch: &[f32], b: usize, c: usize, t: usize) -> Vec<f32> {
        (0..t)
            .flat_map(|f| (0..c).map(move |ch| (f, ch)))
            .map(|(f, ch)| batch[(b * c + ch) * t + f])
            .collect()
    }

    #[test]
    fn a_base_filter_moves_the_target_by_what_the_filter_changes() {
        let takes = three_takes();
        let layout = FeatureLayout::new(takes[0].motion.skeleton(), Representation::Rot6d).unwrap();
        let filter = TWO_HERTZ;
        let plain = WindowSampler::new(&takes, &layout, 16, NoiseConfig::default()).unwrap();
        let based = WindowSampler::new(&takes, &layout, 16, NoiseConfig::default())
            .unwrap()
            .with_base_filter(Some(filter), 30.0, 0);
        let (x1, y1) = plain.batch(&mut ChaCha8Rng::seed_from_u64(1), 4).unwrap();
        let (x2, y2) = based.batch(&mut ChaCha8Rng::seed_from_u64(1), 4).unwrap();
        assert_eq!(x1, x2);
        let (c, t) = (layout.channels(), 16);
        let mut moved = 0.0f32;
        for b in 0..4 {
            let x = frame_major(&x1, b, c, t);
            let mut filtered = x.clone();
            filter_features(&mut filtered, c, &filter, 30.0);
            let (plain_y, based_y) = (frame_major(&y1, b, c, t), frame_major(&y2, b, c, t));
            for i in 0..x.len() {
                let expected = plain_y[i] + x[i] - filtered[i];
                assert!((based_y[i] - expected).abs() < 1e-5);
                moved = moved.max((based_y[i] - plain_y[i]).abs());
            }
        }
        // The filter did change the noisy windows.
        assert!(moved > 1e-3);
    }

    /// With a context the base filter runs on the window's take around it,
    /// as in use on the whole take; without one on the window alone.
    #[test]
    fn a_base_context_filters_the_take_around_the_window() {
        let takes = three_takes();
        let layout = FeatureLayout::new(takes[0].motion.skeleton(), Representation::Rot6d).unwrap();
        let filter = TWO_HERTZ;
        // No noise: the input window is a window of a take, and the target
        // is y + x - base = 2x - base.
        let no_noise = NoiseConfig {
            random: None,
            spikes: None,
            spike_probability: 0.0,
        };
        let (c, t) = (layout.channels(), 16);
        let encoded: Vec<Vec<f32>> = takes.iter().map(|t| layout.encode(&t.motion)).collect();
        let filtered_takes: Vec<Vec<f32>> = encoded
            .iter()
            .map(|features| {
                let mut f = features.clone();
                filter_features(&mut f, c, &filter, 30.0);
                f
            })
            .collect();
        // The largest gap between the implied base of each sample and the
        // filtered take at the same frames.
        let gap_to_the_filtered_take = |context: usize| {
            let sampler = WindowSampler::new(&takes, &layout, t, no_noise)
                .unwrap()
                .with_base_filter(Some(filter), 30.0, context);
            let (x, y) = sampler.batch(&mut ChaCha8Rng::seed_from_u64(3), 8).unwrap();
            let mut gap = 0.0f32;
            for b in 0..8 {
                let (xw, yw) = (frame_major(&x, b, c, t), frame_major(&y, b, c, t));
                let (take, start) = (0..takes.len())
                    .flat_map(|k| (0..=40 - t).map(move |s| (k, s)))
                    .find(|&(k, s)| {
                        encoded[k][s * c..(s + t) * c]
                            .iter()
                            .zip(&xw)
                            .all(|(a, b)| (a - b).abs() < 1e-6)
                    })
                    .expect("a noiseless window is a window of a take");
                let base = &filtered_takes[take][start * c..(start + t) * c];
                for i in 0..xw.len() {
                    gap = gap.max((2.0 * xw[i] - yw[i] - base[i]).abs());
                }
            }
            gap
        };
        assert!(gap_to_the_filtered_take(40) < 1e-5);
        // Filtering the window alone differs at its borders.
        assert!(gap_to_the_filtered_take(0) > 1e-3);
    }

    #[test]
    fn a_model_with_a_base_filter_trains_and_cleans() {
        let _one = ONE_RUN_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
        let dir = tempfile::tempdir().unwrap();
        let options = TrainOptions {
            out: dir.path().join("based.safetensors"),
            base_filter: Some(Filter::SavitzkyGolay {
                window: 5,
                polyorder: 2,
            }),
            ..tiny_setup(dir.path())
        };
        let report = train(&options).unwrap();
        let model = crate::model_file::CleanModel::load(&report.model, Default::default()).unwrap();
        assert_eq!(model.description.base_filter, options.base_filter);
        let motion = synthetic_motion_phase(50, 4, 0.5);
        let cleaned = model.clean(&motion, None).unwrap();
        assert!(cleaned.values().iter().all(|v| v.is_finite()));
        assert_eq!(cleaned.frame_count(), 50);
    }

    #[test]
    fn a_model_with_a_base_context_filters_whole_takes() {
        let _one = ONE_RUN_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
        let dir = tempfile::tempdir().unwrap();
        let options = TrainOptions {
            out: dir.path().join("context.safetensors"),
            base_filter: Some(Filter::ButterworthGcv { order: 2 }),
            base_context: 16,
            ..tiny_setup(dir.path())
        };
        let report = train(&options).unwrap();
        let mut model =
            crate::model_file::CleanModel::load(&report.model, Default::default()).unwrap();
        assert_eq!(model.description.base_context, 16);
        let mut motion = synthetic_motion_phase(50, 4, 0.5);
        let noise = NoiseConfig {
            spikes: None,
            ..NoiseConfig::default()
        };
        motion = crate::noise::add_noise(&motion, &[], &noise, &mut ChaCha8Rng::seed_from_u64(2))
            .unwrap();
        let whole_take = model.clean(&motion, None).unwrap();
        assert!(whole_take.values().iter().all(|v| v.is_finite()));
        // The same weights with the filter run per window give another
        // answer: the context is used in cleaning.
        model.description.base_context = 0;
        let per_window = model.clean(&motion, None).unwrap();
        let most = whole_take
            .values()
            .iter()
            .zip(per_window.values())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        assert!(most > 1e-3, "{most}");
        // A context without a base filter is an error, not silently dropped.
        let error = train(&TrainOptions {
            base_filter: None,
            ..options
        })
        .unwrap_err()
        .to_string();
        assert!(error.contains("base filter"), "{error}");
    }

    /// [`tiny_setup`] on a Wiener filter fitted to its takes (written to
    /// `wiener.safetensors` in `dir`), the filter seeing 16 frames around
    /// each window; the model is written to `out` in `dir`.
    fn tiny_setup_on_wiener(dir: &Path, out: &str) -> (TrainOptions, PathBuf) {
        let setup = tiny_setup(dir);
        let wiener_path = dir.join("wiener.safetensors");
        crate::wiener_fit::fit_wiener(&crate::wiener_fit::WienerFitOptions {
            inputs: setup.inputs.clone(),
            out: wiener_path.clone(),
            split: setup.split,
            ..Default::default()
        })
        .unwrap();
        let options = TrainOptions {
            out: dir.join(out),
            base_wiener: Some(wiener_path.clone()),
            base_context: 16,
            ..setup
        };
        (options, wiener_path)
    }

    /// A synthetic take of the tiny setups' rig with 4 degrees of noise.
    fn noisy_four_joint_take() -> Motion {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        crate::noise::add_random_noise_sigma(
            &synthetic_motion_phase(90, 4, 0.2),
            4.0,
            &crate::noise::RandomNoise::default(),
            &mut rng,
        )
    }

    #[test]
    fn a_model_on_a_wiener_filter_carries_it_and_corrects_it() {
        let _one = ONE_RUN_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
        let dir = tempfile::tempdir().unwrap();
        let (options, wiener_path) = tiny_setup_on_wiener(dir.path(), "on-wiener.safetensors");
        let report = train(&options).unwrap();
        // The model's file alone is enough: the filter rides in it.
        let kept = dir.path().join("kept.safetensors");
        std::fs::rename(&wiener_path, &kept).unwrap();
        let mut model =
            crate::model_file::CleanModel::load(&report.model, Default::default()).unwrap();
        let stored = model.description.base_wiener.clone().unwrap();
        assert_eq!(stored.joints.len(), 4);
        let noisy = noisy_four_joint_take();
        let (trained, noise) = model.clean_reporting(&noisy, None).unwrap();
        assert!(trained.values().iter().all(|v| v.is_finite()));
        // It says the noise level its filter found (4 degrees were added).
        let noise = noise.expect("a Wiener filter estimates the noise");
        assert!((1.0..16.0).contains(&noise), "{noise}");
        // With no correction the model is its Wiener filter over the take.
        model.zero_output();
        let zeroed = model.clean(&noisy, None).unwrap();
        let wiener = crate::wiener::WienerFilter::from_bytes(
            std::fs::read(dir.path().join("on-wiener.safetensors")).unwrap(),
            Path::new("t"),
        );
        assert!(wiener.is_err(), "a model file is not a Wiener filter file");
        let (filtered, _) = model_base(&model).clean(&noisy, None).unwrap();
        let off = crate::metrics::rotation_error_deg(&filtered, &zeroed);
        assert!(off < 1e-3, "{off} degrees from the Wiener filter");
        assert!(crate::metrics::rotation_error_deg(&filtered, &noisy) > 0.1);
        // A noise level given instead of estimated reaches the filter.
        let (at_level, level) = model.clean_at_level(&noisy, None, Some(1.0)).unwrap();
        assert_eq!(level, Some(1.0));
        let (filtered_at_level, _) = model_base(&model).clean(&noisy, Some(1.0)).unwrap();
        let off = crate::metrics::rotation_error_deg(&filtered_at_level, &at_level);
        assert!(
            off < 1e-3,
            "{off} degrees from the Wiener filter at 1 degree"
        );
        assert!(crate::metrics::rotation_error_deg(&filtered_at_level, &filtered) > 0.01);
        // So it does when the filter runs on each window alone.
        model.description.base_context = 0;
        let per_window = |level: f64| model.clean_at_level(&noisy, None, Some(level)).unwrap();
        let ((low, _), (high, _)) = (per_window(1.0), per_window(8.0));
        assert!(crate::metrics::rotation_error_deg(&low, &high) > 0.01);
        // Not both bases, and not on features a Wiener filter cannot read.
        std::fs::rename(&kept, &wiener_path).unwrap();
        for (wrong, why) in [
            (
                TrainOptions {
                    base_filter: Some(Filter::ButterworthGcv { order: 2 }),
                    ..options.clone()
                },
                "not both",
            ),
            (
                TrainOptions {
                    representation: Representation::ExpMap,
                    ..options.clone()
                },
                "6D local rotations",
            ),
        ] {
            let error = train(&wrong).unwrap_err().to_string();
            assert!(error.contains(why), "{error}");
        }
    }

    #[test]
    fn a_network_is_rebased_on_a_mixture_of_its_own_filter() {
        let _one = ONE_RUN_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
        let dir = tempfile::tempdir().unwrap();
        let (options, wiener_path) = tiny_setup_on_wiener(dir.path(), "to-rebase.safetensors");
        let report = train(&options).unwrap();
        let rebased_path = dir.path().join("rebased.safetensors");
        let fit = crate::wiener_fit::WienerFitOptions {
            inputs: options.inputs.clone(),
            out: rebased_path.clone(),
            split: options.split,
            mixture_min_segments: Some(1),
            rebase: Some(report.model.clone()),
            ..Default::default()
        };
        let fitted = crate::wiener_fit::fit_wiener(&fit).unwrap();
        // The synthetic take names carry no content: the rest and all.
        let names: Vec<&str> = fitted
            .description
            .components
            .iter()
            .map(|c| c.name.as_str())
            .collect();
        assert_eq!(names, ["other", "all"]);
        let original =
            crate::model_file::CleanModel::load(&report.model, Default::default()).unwrap();
        let rebased =
            crate::model_file::CleanModel::load(&rebased_path, Default::default()).unwrap();
        assert_eq!(rebased.description.network, original.description.network);
        assert_eq!(model_base(&rebased).description.component_count(), 2);
        // The same network on a filter whose components both come from the
        // same takes: nearly the same output.
        let noisy = noisy_four_joint_take();
        let off = crate::metrics::rotation_error_deg(
            &original.clean(&noisy, None).unwrap(),
            &rebased.clean(&noisy, None).unwrap(),
        );
        assert!(off < 0.5, "{off} degrees apart");
        // The header keeps the network's training record and says what was done.
        let (data, training) = crate::model_file::CleanModel::header_of(&rebased_path).unwrap();
        assert!(data["rebased"]["mixture_min_segments"] == 1, "{data}");
        assert!(!training.is_null());
        // A filter with another noise covariance is refused, and so is a
        // rebase without a mixture or of a file that is no network.
        let takes = load_takes(&list_bvh(&options.inputs).unwrap()).unwrap();
        let refs: Vec<&Motion> = takes.iter().map(|t| &t.motion).collect();
        let other =
            WienerFilter::fit(&refs, &crate::noise::RandomNoise::default(), 3.0, 32, 9).unwrap();
        assert!(original.with_base_wiener(other).is_err());
        let error = crate::wiener_fit::fit_wiener(&crate::wiener_fit::WienerFitOptions {
            mixture_min_segments: None,
            ..fit.clone()
        })
        .unwrap_err()
        .to_string();
        assert!(error.contains("needs a mixture"), "{error}");
        let error = crate::wiener_fit::fit_wiener(&crate::wiener_fit::WienerFitOptions {
            rebase: Some(wiener_path),
            ..fit
        })
        .unwrap_err()
        .to_string();
        assert!(error.contains(crate::wiener::WIENER_KIND), "{error}");
    }

    #[test]
    fn a_model_reading_its_base_gets_the_filter_output_and_the_noise_level() {
        let _one = ONE_RUN_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
        let dir = tempfile::tempdir().unwrap();
        let (on_wiener, _) = tiny_setup_on_wiener(dir.path(), "reads-base.safetensors");
        let options = TrainOptions {
            base_input: true,
            ..on_wiener
        };
        let report = train(&options).unwrap();
        let mut model =
            crate::model_file::CleanModel::load(&report.model, Default::default()).unwrap();
        let c = model.description.network.channels;
        assert!(model.description.base_input());
        assert_eq!(model.description.network.input_channels(), 2 * c + 1);

        // The training windows: features, the filter's output, the level.
        let takes = load_takes(&list_bvh(&options.inputs).unwrap()).unwrap();
        let layout = FeatureLayout::new(takes[0].motion.skeleton(), Representation::Rot6d).unwrap();
        let wiener = model_base(&model).clone();
        let t = model.description.network.window;
        let sampler = WindowSampler::new(&takes, &layout, t, NoiseConfig::default())
            .unwrap()
            .with_base(Some(Base::Wiener(&wiener)), 16)
            .with_base_input(true);
        assert_eq!(sampler.input_channels(), 2 * c + 1);
        let (x, y) = sampler.batch(&mut ChaCha8Rng::seed_from_u64(3), 6).unwrap();
        assert_eq!((x.len(), y.len()), (6 * (2 * c + 1) * t, 6 * c * t));
        let row = |b: usize, ch: usize| &x[(b * (2 * c + 1) + ch) * t..][..t];
        let mut levels = Vec::new();
        let roughness = |v: &[f32]| v.windows(2).map(|w| (w[1] - w[0]).abs()).sum::<f32>();
        let (mut noisy_roughness, mut filtered_roughness) = (0.0, 0.0);
        for b in 0..6 {
            // One level per window, the same on every frame.
            let level = row(b, 2 * c);
            assert!(level.iter().all(|&v| v == level[0]), "{level:?}");
            assert!(level[0].is_finite() && level[0] >= 0.0, "{}", level[0]);
            levels.push(level[0]);
            // Then the filter's output: smoother than the noisy features.
            for ch in 0..c {
                noisy_roughness += roughness(row(b, ch));
                filtered_roughness += roughness(row(b, c + ch));
            }
        }
        assert!(levels.iter().any(|&l| l > 0.05), "{levels:?}");
        assert!(
            filtered_roughness < 0.8 * noisy_roughness,
            "{filtered_roughness} against {noisy_roughness}"
        );

        // With no correction the model is still its Wiener filter.
        let noisy = noisy_four_joint_take();
        model.zero_output();
        let zeroed = model.clean(&noisy, None).unwrap();
        let (filtered, _) = model_base(&model).clean(&noisy, None).unwrap();
        let off = crate::metrics::rotation_error_deg(&filtered, &zeroed);
        assert!(off < 1e-3, "{off} degrees from the Wiener filter");

        // It needs a base to read.
        let error = train(&TrainOptions {
            base_wiener: None,
            base_context: 0,
            ..options
        })
        .unwrap_err()
        .to_string();
        assert!(error.contains("--base-input needs"), "{error}");
    }

    /// The Wiener filter a loaded model corrects.
    fn model_base(model: &crate::model_file::CleanModel) -> &crate::wiener::WienerFilter {
        model.base_wiener().expect("a model on a Wiener filter")
    }
}
