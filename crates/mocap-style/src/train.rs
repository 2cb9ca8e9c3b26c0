//! Training the autoencoder once on many styles, and loading a trained one.
//!
//! Training data: labelled clips (optionally only some contents, e.g. the
//! walks), without the held-out evaluation takes ([`crate::data::held_out`]),
//! each with its mirror image. Every eighth take (by name) is kept for the
//! validation curve. A step draws `batch` clips (weighted by length) and a
//! window of `window` frames from each, uniformly (report: 240 frames, batch
//! 16, Adam, learning rate 1e-4); when a drawn clip is shorter than the
//! window, the whole batch uses that clip's length, so short takes are not
//! padded. The loss is the mean squared error of the reconstruction, plus,
//! with [`TrainOptions::foot_loss_weight`], a loss on the feet
//! ([`crate::foot_loss`]).
//!
//! Reproducibility: the weights are initialised from `seed` and the windows
//! of epoch `e` come from a generator seeded with `(seed, e)`, so a resumed
//! run draws the windows an uninterrupted one would.

use std::path::{Path, PathBuf};
use std::time::Instant;

use burn::module::Module;
use burn::tensor::{Device, Tensor, TensorData};
use mocap_core::ops::resample_fps;
use mocap_core::rotation::Quat;
use mocap_core::Motion;
use mocap_nn::checkpoint::{
    check_parameter_count, header_from_bytes, load_weights_from_bytes, save_epoch, start_run,
    CheckpointHeader, RunStart,
};
use mocap_nn::device::{seed_device, DeviceChoice};
use mocap_nn::plot::PlotOptions;
use mocap_nn::train::{epoch_seed, optimizer_step, run_epochs, EpochPlan, History};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use serde::{Deserialize, Serialize};

use crate::convert::Latents;
use crate::data::{
    held_out, labelled_paths, list_bvh, load_clips, mirrored, ClipFilter, HeldOutTake,
};
use crate::features::{decompose, Normalization, RigLayout};
use crate::foot_loss::{contacts_tensor, flat_foot_steps, FootKinematics};
use crate::model::{AutoencoderConfig, StyleAutoencoder};
use crate::{invalid, Result};

/// The kind written in checkpoint headers.
pub const CHECKPOINT_KIND: &str = "mocap-style/autoencoder";
/// Version of [`ModelDescription`]'s layout.
pub const CHECKPOINT_KIND_VERSION: u32 = 1;

/// Everything needed to use a trained autoencoder, stored in its checkpoint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelDescription {
    pub network: AutoencoderConfig,
    /// The rig the model was trained on.
    pub rig: RigLayout,
    pub normalization: Normalization,
    /// Frame rate of the training data; clips are resampled to it.
    pub fps: f64,
}

/// Options of `mocap style train`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TrainOptions {
    /// Folders or files of labelled BVH clips.
    pub inputs: Vec<PathBuf>,
    /// The model file to write (safetensors).
    pub out: PathBuf,
    /// Which clips to train on (default: every clip).
    pub filter: ClipFilter,
    /// Leave out the held-out evaluation takes (default true).
    pub hold_out: bool,
    /// Which take of each group is held out (see [`HeldOutTake`]).
    #[serde(default)]
    pub held_out_take: HeldOutTake,
    /// Add the mirror image of every clip (default true).
    pub mirror: bool,
    /// Frames per training window (report: 240).
    pub window: usize,
    pub batch_size: usize,
    pub learning_rate: f64,
    pub epochs: usize,
    pub steps_per_epoch: usize,
    pub seed: u64,
    pub device: DeviceChoice,
    /// Loss-curve PNG; default `<out>` with extension `png`.
    pub plot: Option<PathBuf>,
    /// Folder of the resumable training state; default `<out>.state`.
    pub state_dir: Option<PathBuf>,
    /// Continue from the state folder when it holds a state.
    pub resume: bool,
    /// Hidden and latent sizes and kernel (channels come from the data).
    pub network: AutoencoderConfig,
    /// Weight of the loss on the feet (`foot_loss`) added to the
    /// reconstruction error; 0: the report's loss alone.
    #[serde(default)]
    pub foot_loss_weight: f64,
}

impl Default for TrainOptions {
    /// The report's setting: 240-frame windows, batch 16, Adam, lr 1e-4.
    fn default() -> Self {
        TrainOptions {
            inputs: Vec::new(),
            out: PathBuf::from("style-ae.safetensors"),
            filter: ClipFilter::default(),
            hold_out: true,
            held_out_take: HeldOutTake::Last,
            mirror: true,
            window: 240,
            batch_size: 16,
            learning_rate: 1e-4,
            epochs: 30,
            steps_per_epoch: 100,
            seed: 1,
            device: DeviceChoice::Cpu,
            plot: None,
            state_dir: None,
            resume: false,
            network: AutoencoderConfig::report(0),
            foot_loss_weight: 0.0,
        }
    }
}

/// The data a model was trained on (stored in its header).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DataDescription {
    pub inputs: Vec<String>,
    pub filter: ClipFilter,
    pub mirror: bool,
    pub train_takes: Vec<String>,
    pub validation_takes: Vec<String>,
    /// Held-out evaluation takes left out.
    pub held_out_takes: usize,
    /// Frames of training clips (mirrors included).
    pub train_frames: usize,
}

/// What `mocap style train` reports.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TrainReport {
    pub model: PathBuf,
    pub plot: PathBuf,
    pub parameters: usize,
    pub data: DataDescription,
    pub history: History,
    pub samples_per_second: f64,
    /// Wall-clock seconds of this call (loading data included).
    pub seconds: f64,
    pub resumed_from_epoch: usize,
}

/// A trained autoencoder ready to encode and decode clips.
#[derive(Debug)]
pub struct StyleModel {
    pub description: ModelDescription,
    network: StyleAutoencoder,
    device: Device,
}

/// The bytes of the shipped default model (`models/style-default.safetensors`).
pub const DEFAULT_MODEL: &[u8] = include_bytes!("../../../models/style-default.safetensors");

impl StyleModel {
    /// Loads a model file.
    pub fn load(path: &Path, device: DeviceChoice) -> Result<StyleModel> {
        let bytes = std::fs::read(path).map_err(|e| mocap_core::Error::io(path, e))?;
        StyleModel::from_bytes(bytes, path, device)
    }

    /// The default model shipped with mocap.
    pub fn default_model(device: DeviceChoice) -> Result<StyleModel> {
        StyleModel::from_bytes(
            DEFAULT_MODEL.to_vec(),
            Path::new("<built-in models/style-default.safetensors>"),
            device,
        )
    }

    /// Loads checkpoint bytes; `origin` names them in errors.
    pub fn from_bytes(bytes: Vec<u8>, origin: &Path, device: DeviceChoice) -> Result<StyleModel> {
        let header = header_from_bytes(&bytes, origin)?;
        header.expect_kind(
            origin,
            CHECKPOINT_KIND,
            CHECKPOINT_KIND_VERSION,
            "a style autoencoder",
        )?;
        let description: ModelDescription = serde_json::from_value(header.config)
            .map_err(|e| invalid(format!("{}: bad model description: {e}", origin.display())))?;
        description.network.validate()?;
        check_parameter_count(&bytes, origin, description.network.parameter_count())?;
        let device = device.device()?;
        let network = description.network.init(&device)?;
        let network = load_weights_from_bytes(bytes, origin, network)?;
        Ok(StyleModel {
            description,
            network,
            device,
        })
    }

    /// Checks the clip's rig and brings it to the model's frame rate.
    pub fn prepare(&self, motion: &Motion, what: &str) -> Result<Motion> {
        self.description
            .rig
            .check_skeleton(motion.skeleton(), what)?;
        require_two_frames(motion, what)?;
        if (motion.fps() - self.description.fps).abs() > 1e-3 * self.description.fps {
            Ok(resample_fps(motion, self.description.fps)?)
        } else {
            Ok(motion.clone())
        }
    }

    /// Standardised features of a clip of the model's rig (frame after frame).
    pub fn features(&self, rotations: &[Quat]) -> Vec<f32> {
        self.description.normalization.features(rotations)
    }

    /// Latent codes of features (`channels` per frame, frame after frame).
    pub fn encode(&self, features: &[f32]) -> Result<Latents> {
        let c = self.description.network.channels;
        let frames = features.len() / c;
        let x = to_tensor(features, frames, c, &self.device);
        let z = self.network.encode(x);
        from_tensor(z, frames)
    }

    /// Features of latent codes (frame after frame).
    pub fn decode(&self, latents: &Latents) -> Result<Vec<f32>> {
        let z = to_tensor(&latents.data, latents.frames, latents.dim, &self.device);
        let x = self.network.decode(z);
        Ok(from_tensor(x, latents.frames)?.data)
    }
}

/// A clip to encode needs at least two frames; `what` names it in the error
/// (a file path where the caller has one).
pub(crate) fn require_two_frames(motion: &Motion, what: &str) -> Result<()> {
    if motion.frame_count() < 2 {
        return Err(invalid(format!(
            "{what}: {} frame(s); needs at least 2 frames",
            motion.frame_count()
        )));
    }
    Ok(())
}

/// `[1, channels, frames]` tensor of frame-major values.
pub(crate) fn to_tensor(
    values: &[f32],
    frames: usize,
    channels: usize,
    device: &Device,
) -> Tensor<3> {
    let mut t = vec![0.0; values.len()];
    for f in 0..frames {
        for c in 0..channels {
            t[c * frames + f] = values[f * channels + c];
        }
    }
    Tensor::from_data(TensorData::new(t, [1, channels, frames]), device)
}

/// Frame-major values of a `[1, channels, frames]` tensor.
fn from_tensor(tensor: Tensor<3>, frames: usize) -> Result<Latents> {
    let [_, channels, _] = tensor.dims();
    let data = tensor
        .into_data()
        .try_into_vec::<f32>()
        .map_err(|e| invalid(format!("internal: cannot read a tensor: {e:?}")))?;
    let mut out = vec![0.0; data.len()];
    for c in 0..channels {
        for f in 0..frames {
            out[f * channels + c] = data[c * frames + f];
        }
    }
    Latents::new(frames, channels, out)
}

/// A training clip: standardised features, frame after frame.
struct FeatureClip {
    frames: usize,
    features: Vec<f32>,
    /// [`crate::foot_loss::flat_foot_steps`] of the clip (empty without a
    /// loss on the feet).
    contacts: Vec<f32>,
}

/// Draws training batches.
struct WindowSampler<'a> {
    clips: &'a [FeatureClip],
    cumulative: Vec<usize>,
    channels: usize,
    window: usize,
    /// Foot joints per contact step.
    feet: usize,
}

impl<'a> WindowSampler<'a> {
    fn new(
        clips: &'a [FeatureClip],
        channels: usize,
        window: usize,
        feet: usize,
    ) -> WindowSampler<'a> {
        let mut total = 0;
        let cumulative = clips
            .iter()
            .map(|c| {
                total += c.frames;
                total
            })
            .collect();
        WindowSampler {
            clips,
            cumulative,
            channels,
            window,
            feet,
        }
    }

    /// A batch `[size, channels, frames]`, its frame count, and the contact
    /// steps of its windows (`frames - 1` steps of `feet` values each).
    fn batch(&self, rng: &mut ChaCha8Rng, size: usize) -> (Vec<f32>, usize, Vec<f32>) {
        let total = *self.cumulative.last().expect("training clips");
        let picked: Vec<usize> = (0..size)
            .map(|_| {
                let u = rng.random_range(0..total);
                self.cumulative.partition_point(|&c| c <= u)
            })
            .collect();
        let frames = picked
            .iter()
            .map(|&i| self.clips[i].frames)
            .min()
            .unwrap_or(0)
            .min(self.window);
        let c = self.channels;
        let mut x = vec![0.0; size * c * frames];
        let mut contacts = Vec::with_capacity(size * frames.saturating_sub(1) * self.feet);
        for (b, &i) in picked.iter().enumerate() {
            let clip = &self.clips[i];
            let start = rng.random_range(0..=clip.frames - frames);
            for f in 0..frames {
                for ch in 0..c {
                    x[(b * c + ch) * frames + f] = clip.features[(start + f) * c + ch];
                }
            }
            // Step k of the clip goes from frame k to k + 1 (none are kept
            // without a loss on the feet).
            if !clip.contacts.is_empty() {
                let steps = frames.saturating_sub(1) * self.feet;
                contacts.extend_from_slice(&clip.contacts[start * self.feet..][..steps]);
            }
        }
        (x, frames, contacts)
    }
}

/// Trains an autoencoder (see the module docs).
pub fn train(options: &TrainOptions) -> Result<TrainReport> {
    let started = Instant::now();
    if !(options.foot_loss_weight >= 0.0 && options.foot_loss_weight.is_finite()) {
        return Err(invalid(format!(
            "the foot loss weight must be a number >= 0 (got {})",
            options.foot_loss_weight
        )));
    }
    if options.batch_size == 0 || options.window < 16 || options.steps_per_epoch == 0 {
        return Err(invalid(
            "batch size, steps per epoch must be positive and the window at least 16 frames",
        ));
    }
    let files = labelled_paths(&list_bvh(&options.inputs)?, &options.filter)?;
    let held = if options.hold_out {
        held_out(&files, options.held_out_take)
    } else {
        Default::default()
    };
    let mut kept: Vec<_> = files
        .into_iter()
        .filter(|(p, _)| !held.contains(&stem(p)))
        .collect();
    kept.sort_by_key(|(p, _)| stem(p));
    if kept.len() < 2 {
        return Err(invalid("need at least two training clips"));
    }
    let (mut train_files, mut valid_files) = (Vec::new(), Vec::new());
    for (i, f) in kept.into_iter().enumerate() {
        if i % 8 == 7 {
            valid_files.push(f);
        } else {
            train_files.push(f);
        }
    }
    let train_clips = load_clips(&train_files)?;
    let valid_clips = load_clips(&valid_files)?;
    let first = &train_clips[0];
    let rig = RigLayout::from_skeleton(first.motion.skeleton())?;
    let fps = first.motion.fps();

    // Slot rotations of every clip (and mirror), at the first clip's rate,
    // with the frame steps where its feet are flat on the ground.
    let rotations_of = |clips: &[crate::data::Clip]| -> Result<Vec<(Vec<Quat>, Vec<f32>)>> {
        let mut out = Vec::new();
        for clip in clips {
            rig.check_skeleton(clip.motion.skeleton(), &clip.path.display().to_string())?;
            let motion = if (clip.motion.fps() - fps).abs() > 1e-3 * fps {
                resample_fps(&clip.motion, fps)?
            } else {
                clip.motion.clone()
            };
            let mut motions = vec![motion.clone()];
            if options.mirror {
                motions.push(mirrored(&motion)?);
            }
            for m in motions {
                // Contact steps only for the loss on the feet: finding them
                // runs forward kinematics over every clip.
                let contacts = if options.foot_loss_weight > 0.0 {
                    flat_foot_steps(&m, &rig)
                } else {
                    Vec::new()
                };
                out.push((decompose(&m, &rig).0, contacts));
            }
        }
        Ok(out)
    };
    let train_rotations = rotations_of(&train_clips)?;
    let valid_rotations = rotations_of(&valid_clips)?;
    let slots = rig.slots();
    let normalization = Normalization::fit(
        &train_rotations
            .iter()
            .map(|(r, _)| r.as_slice())
            .collect::<Vec<_>>(),
        slots,
    )?;
    let to_features = |rotations: &[(Vec<Quat>, Vec<f32>)]| -> Vec<FeatureClip> {
        rotations
            .iter()
            .map(|(r, contacts)| FeatureClip {
                frames: r.len() / slots,
                features: normalization.features(r),
                contacts: contacts.clone(),
            })
            .collect()
    };
    let train_features = to_features(&train_rotations);
    let valid_features = to_features(&valid_rotations);
    let mut network = options.network;
    network.channels = rig.channels();
    network.validate()?;
    let description = ModelDescription {
        network,
        rig,
        normalization,
        fps,
    };
    let data = DataDescription {
        inputs: options
            .inputs
            .iter()
            .map(|p| p.display().to_string())
            .collect(),
        filter: options.filter.clone(),
        mirror: options.mirror,
        train_takes: train_clips.iter().map(|c| c.name.clone()).collect(),
        validation_takes: valid_clips.iter().map(|c| c.name.clone()).collect(),
        held_out_takes: held.len(),
        train_frames: train_features.iter().map(|c| c.frames).sum(),
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
        network.init(&device)?,
    )?;
    let resumed_from_epoch = history.epochs.len();
    let header = |history: &History| CheckpointHeader {
        kind: CHECKPOINT_KIND.into(),
        kind_version: CHECKPOINT_KIND_VERSION,
        config: serde_json::to_value(&description).expect("serialisable"),
        data: serde_json::to_value(&data).expect("serialisable"),
        training: serde_json::json!({
            "loss": if options.foot_loss_weight > 0.0 { "mse + feet" } else { "mse" },
            "foot_loss_weight": options.foot_loss_weight,
            "epochs": history.epochs.len(),
            "steps_per_epoch": options.steps_per_epoch,
            "batch_size": options.batch_size,
            "window": options.window,
            "learning_rate": options.learning_rate,
            "optimizer": "adam",
            "seed": options.seed,
            "device": options.device.to_string(),
            "history": history,
        }),
    };

    let feet = FootKinematics::new(
        train_clips[0].motion.skeleton(),
        &description.rig,
        &description.normalization,
    );
    let sampler = WindowSampler::new(
        &train_features,
        network.channels,
        options.window,
        feet.feet(),
    );
    struct Run {
        model: Option<StyleAutoencoder>,
        optimizer: burn::optim::ModuleOptimizer,
        rng: ChaCha8Rng,
        rng_epoch: usize,
    }
    let mut run = Run {
        model: Some(model),
        optimizer,
        rng: ChaCha8Rng::seed_from_u64(0),
        rng_epoch: usize::MAX,
    };
    let plan = EpochPlan {
        epochs: options.epochs,
        steps_per_epoch: options.steps_per_epoch,
        batch_size: options.batch_size,
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
            let (x, frames, contacts) = sampler.batch(&mut run.rng, options.batch_size);
            let shape = [options.batch_size, network.channels, frames];
            let x = Tensor::<3>::from_data(TensorData::new(x, shape), &device);
            let model = run.model.take().expect("model present");
            let output = model.forward(x.clone());
            let mut loss = (output.clone() - x.clone()).powi_scalar(2).mean();
            if options.foot_loss_weight > 0.0 && frames > 1 {
                let contacts = contacts_tensor(
                    &contacts,
                    options.batch_size,
                    feet.feet(),
                    frames - 1,
                    &device,
                );
                loss = loss + feet.loss(output, x, contacts) * options.foot_loss_weight;
            }
            let (model, value) =
                optimizer_step(model, &mut run.optimizer, loss, options.learning_rate);
            run.model = Some(model);
            Ok(value)
        },
        |run, _epoch| {
            let model = run.model.as_ref().expect("model").valid();
            Ok(validation_mse(
                &model,
                &valid_features,
                network.channels,
                &plain_device,
            ))
        },
        |run, history| -> Result<()> {
            let model = run.model.as_ref().expect("model");
            save_epoch(
                &state,
                model,
                &run.optimizer,
                history,
                &options.out,
                &model.valid(),
                &header(history),
                &plot,
                &PlotOptions {
                    y_label: "mean squared error (standardised features)".into(),
                    ..PlotOptions::new("mocap-style autoencoder training")
                },
            )?;
            Ok(())
        },
    )?;
    if history.epochs.is_empty() {
        return Err(invalid("no epoch was run (epochs = 0)"));
    }
    Ok(TrainReport {
        model: options.out.clone(),
        plot,
        parameters: network.parameter_count(),
        data,
        samples_per_second: history.samples_per_second(),
        seconds: started.elapsed().as_secs_f64(),
        resumed_from_epoch,
        history,
    })
}

fn stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Mean squared reconstruction error over whole validation clips (a clip
/// with no validation clips gives NaN, shown as a gap in the plot).
fn validation_mse(
    model: &StyleAutoencoder,
    clips: &[FeatureClip],
    channels: usize,
    device: &Device,
) -> f64 {
    let mut sum = 0.0;
    let mut count = 0usize;
    for clip in clips {
        let x = to_tensor(&clip.features, clip.frames, channels, device);
        let se: f32 = (model.forward(x.clone()) - x)
            .powi_scalar(2)
            .sum()
            .into_scalar();
        sum += se as f64;
        count += clip.frames * channels;
    }
    if count == 0 {
        f64::NAN
    } else {
        sum / count as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shipped model with `edit` applied to its header's configuration,
    /// resealed, as a file damaged before it was written would be.
    fn with_config(edit: impl Fn(&mut serde_json::Value)) -> Vec<u8> {
        let n = u64::from_le_bytes(DEFAULT_MODEL[..8].try_into().unwrap()) as usize;
        let mut outer: serde_json::Value =
            serde_json::from_slice(&DEFAULT_MODEL[8..8 + n]).unwrap();
        let metadata = &mut outer["__metadata__"];
        let mut header: serde_json::Value =
            serde_json::from_str(metadata["mocap.header"].as_str().unwrap()).unwrap();
        edit(&mut header["config"]);
        metadata["mocap.header"] = header.to_string().into();
        let text = outer.to_string();
        let mut bytes = (text.len() as u64).to_le_bytes().to_vec();
        bytes.extend_from_slice(text.as_bytes());
        bytes.extend_from_slice(&DEFAULT_MODEL[8 + n..]);
        mocap_nn::checkpoint::seal(&bytes).unwrap()
    }

    #[test]
    fn a_configuration_larger_than_the_weights_in_the_file_is_refused_before_allocating() {
        let origin = Path::new("big.safetensors");
        // The shipped configuration loads.
        StyleModel::from_bytes(with_config(|_| {}), origin, DeviceChoice::Cpu).unwrap();
        let hidden = with_config(|config| config["network"]["hidden"] = (1u64 << 40).into());
        let e = StyleModel::from_bytes(hidden, origin, DeviceChoice::Cpu)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("big.safetensors: the model configuration asks for"),
            "{e}"
        );
        let huge = with_config(|config| {
            config["network"]["channels"] = u64::MAX.into();
            config["network"]["kernel"] = (u64::MAX - 2).into();
        });
        let e = StyleModel::from_bytes(huge, origin, DeviceChoice::Cpu)
            .unwrap_err()
            .to_string();
        assert!(e.contains("asks for 18446744073709551615 weights"), "{e}");
    }
}
