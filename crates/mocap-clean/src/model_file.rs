//! The model file: what `mocap clean train` and `mocap clean fit-wiener`
//! write and every other part reads. A network's file holds its
//! [`ModelDescription`] (sizes, features, rig, base filter) in the checkpoint
//! header and its weights, with the learned Wiener filter it corrects, if
//! any, beside them; a Wiener filter's file is told apart by its kind.
//!
//! Here: the description and its kind, the base a network corrects
//! ([`Base`]) and how a window's base is made in training and in use alike,
//! loading and saving a network ([`CleanModel`]), the rig check, and
//! [`ModelFile`], either kind of file.

use std::path::{Path, PathBuf};

use burn::module::Module;
use burn::tensor::Device;
use mocap_core::Motion;
use mocap_nn::checkpoint::{
    check_parameter_count, header_from_bytes, load_weights_from_bytes, save_weights,
    CheckpointHeader,
};
use mocap_nn::device::DeviceChoice;
use serde::{Deserialize, Serialize};

use crate::features::{FeatureLayout, Recentering, Representation, RotationFrame};
use crate::filters::{filter_features, Filter};
use crate::model::{Denoiser, DenoiserConfig};
use crate::rig::ModelRig;
use crate::wiener::{LevelEstimate, WienerDescription, WienerFilter, WienerOutcome, WIENER_KIND};
use crate::{CleanError, Result};

/// The kind written in checkpoint headers.
pub(crate) const CHECKPOINT_KIND: &str = "mocap-clean/denoiser";
/// Version of [`ModelDescription`]'s layout.
pub(crate) const CHECKPOINT_KIND_VERSION: u32 = 1;

/// Everything needed to rebuild a trained denoiser, stored in its checkpoint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelDescription {
    pub network: DenoiserConfig,
    pub representation: Representation,
    /// Local rotations or rotations relative to the pelvis (models written
    /// before this field existed are local).
    #[serde(default)]
    pub frame: RotationFrame,
    /// Names of the joints whose rotations are features, in order.
    pub joints: Vec<String>,
    /// Frame rate of the training data (the loss differences use it).
    pub fps: f32,
    /// A classical filter the network's correction is added to: the model's
    /// output is `base(x) + (N(x) - x)` instead of `N(x)` (`N` has a global
    /// skip, so `N(x) - x` is its correction). At the start of training the
    /// correction is near zero and the model is as good as the filter;
    /// training learns what the filter gets wrong. `None`: the report's
    /// model.
    #[serde(default)]
    pub base_filter: Option<Filter>,
    /// How much of the take the base filter sees. `0` (models written before
    /// this field): each window alone, in training and in use alike. `N > 0`:
    /// in use the filter runs once over the whole take; in training over the
    /// window and up to `N` frames of its take on each side, so that a filter
    /// that adapts to what it sees (`butterworth-gcv`, whose cutoff chosen on
    /// a 32-frame window is poor) is trained with nearly what it sees in use.
    #[serde(default)]
    pub base_context: usize,
    /// A learned Wiener filter ([`WienerFilter`]) the network corrects
    /// instead of a classical one (same rule as `base_filter`, which is then
    /// `None`); its numbers are stored in the model's file with the
    /// network's weights.
    #[serde(default)]
    pub base_wiener: Option<WienerDescription>,
}

impl ModelDescription {
    /// Whether the network also reads its Wiener filter's output and noise
    /// level ([`crate::TrainOptions::base_input`]): it has inputs beyond the
    /// features.
    pub fn base_input(&self) -> bool {
        self.network.extra_inputs > 0
    }
}

/// The inputs a network reading its base adds to `features` channels: the
/// base's output, then the noise level ([`TrainOptions::base_input`]).
pub(crate) fn base_input_channels(features: usize) -> usize {
    features + 1
}

/// The unit of the noise-level input of a model with
/// [`TrainOptions::base_input`]: the report's largest noise, so that the
/// input is about 0 to 1.
pub(crate) const NOISE_LEVEL_UNIT_DEG: f64 = 10.0;

/// What a model's network corrects, ready to run: a classical filter at a
/// frame rate ([`ModelDescription::base_filter`]) or a learned Wiener filter
/// ([`ModelDescription::base_wiener`]).
#[derive(Debug, Clone, Copy)]
pub(crate) enum Base<'a> {
    Classical(Filter, f32),
    Wiener(&'a WienerFilter),
}

impl<'a> Base<'a> {
    /// The base of a model with `filter` at `fps` or `wiener` (at most one
    /// of them: training and loading refuse both), if any.
    pub(crate) fn of(
        filter: Option<Filter>,
        fps: f32,
        wiener: Option<&'a WienerFilter>,
    ) -> Option<Self> {
        match (filter, wiener) {
            (Some(filter), _) => Some(Base::Classical(filter, fps)),
            (None, Some(wiener)) => Some(Base::Wiener(wiener)),
            (None, None) => None,
        }
    }

    /// Filters `features` (frames x `channels`) in place; a Wiener filter
    /// also says the noise level it used (degrees): `level_deg` when given,
    /// else the one it estimated.
    pub(crate) fn apply(
        &self,
        features: &mut [f32],
        channels: usize,
        level_deg: Option<f64>,
    ) -> Option<f64> {
        self.apply_reporting(features, channels, level_deg)
            .map(|outcome| outcome.sigma_deg)
    }

    /// [`Base::apply`], with all a Wiener filter says of what it did (the
    /// level and, in a mixture, the component).
    pub(crate) fn apply_reporting(
        &self,
        features: &mut [f32],
        channels: usize,
        level_deg: Option<f64>,
    ) -> Option<WienerOutcome> {
        match self {
            Base::Classical(filter, fps) => {
                filter_features(features, channels, filter, *fps);
                None
            }
            Base::Wiener(wiener) => Some(wiener.filter_features(features, level_deg)),
        }
    }
}

/// The base filter's output for the recentred window `window` of
/// `channels` features, in training and in use alike (see
/// [`ModelDescription::base_context`]): `filtered_around` is the same frames
/// cut from the filter's output over a longer stretch (the take around the
/// window), brought here onto the window's branch; without it the filter
/// runs on the window itself, at noise level `level_deg` when given (else
/// the one it estimates there).
pub(crate) fn window_base(
    window: &[f32],
    filtered_around: Option<&[f32]>,
    recentering: &Recentering,
    base: &Base,
    channels: usize,
    level_deg: Option<f64>,
) -> (Vec<f32>, Option<f64>) {
    match filtered_around {
        Some(around) => {
            let mut base = around.to_vec();
            recentering.apply(&mut base);
            (base, None)
        }
        None => {
            let mut filtered = window.to_vec();
            let level = base.apply(&mut filtered, channels, level_deg);
            (filtered, level)
        }
    }
}

/// The input of a model with [`TrainOptions::base_input`]: every frame's
/// `channels` noisy features, then the base's output at that frame, then the
/// noise level the Wiener filter estimated (degrees; `None` counts as 0) over
/// [`NOISE_LEVEL_UNIT_DEG`]. Frames by rows, as `window` and `base` are.
pub(crate) fn with_base_input(
    window: &[f32],
    base: &[f32],
    level_deg: Option<f64>,
    channels: usize,
) -> Vec<f32> {
    let level = (level_deg.unwrap_or(0.0) / NOISE_LEVEL_UNIT_DEG) as f32;
    let mut input = Vec::with_capacity(window.len() * 2 + window.len() / channels.max(1));
    for (x, b) in window.chunks(channels).zip(base.chunks(channels)) {
        input.extend_from_slice(x);
        input.extend_from_slice(b);
        input.push(level);
    }
    input
}

/// Where the shipped default model lives in the source tree.
pub const DEFAULT_MODEL_PATH: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../models/clean-default.safetensors"
);

/// The shipped default model's bytes, compiled in.
pub static DEFAULT_MODEL: &[u8] = include_bytes!("../../../models/clean-default.safetensors");

/// A trained denoiser ready to clean takes.
pub struct CleanModel {
    pub description: ModelDescription,
    /// Where it was loaded from.
    pub source: PathBuf,
    pub(crate) model: Denoiser,
    pub(crate) device: Device,
    /// The learned filter the network corrects
    /// ([`ModelDescription::base_wiener`]).
    pub(crate) base_wiener: Option<WienerFilter>,
    /// The rig the model was trained on, when it is the shipped one: takes
    /// of other rigs are cleaned through it ([`crate::rig`]).
    pub(crate) rig: Option<&'static ModelRig>,
}

impl std::fmt::Debug for CleanModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CleanModel")
            .field("description", &self.description)
            .field("source", &self.source)
            .finish_non_exhaustive()
    }
}

impl CleanModel {
    /// Loads a model file written by training.
    pub fn load(path: &Path, device: DeviceChoice) -> Result<CleanModel> {
        let bytes = std::fs::read(path).map_err(|e| mocap_core::Error::io(path, e))?;
        Self::from_bytes(bytes, path, device)
    }

    /// The shipped default model, or the file named by the
    /// `MOCAP_CLEAN_MODEL` environment variable. The default model
    /// (`models/clean-default.safetensors`, about 20 MB with the Wiener mixture it corrects) is compiled into the
    /// binary, so it works wherever the binary is installed.
    pub fn load_default(device: DeviceChoice) -> Result<CleanModel> {
        if let Some(path) = std::env::var_os("MOCAP_CLEAN_MODEL") {
            return Self::load(Path::new(&path), device);
        }
        // Named as the style crate names its built-in model: the build
        // machine's source path means nothing where the binary runs.
        Self::from_bytes(
            DEFAULT_MODEL.to_vec(),
            Path::new("<built-in models/clean-default.safetensors>"),
            device,
        )
    }

    /// Loads checkpoint bytes; `origin` names them in errors.
    pub fn from_bytes(bytes: Vec<u8>, origin: &Path, device: DeviceChoice) -> Result<CleanModel> {
        let header = header_from_bytes(&bytes, origin)?;
        let bad = |m: String| CleanError::Invalid(format!("{}: {m}", origin.display()));
        header.expect_kind(
            origin,
            CHECKPOINT_KIND,
            CHECKPOINT_KIND_VERSION,
            "a denoiser",
        )?;
        let description: ModelDescription = serde_json::from_value(header.config)
            .map_err(|e| bad(format!("bad model description: {e}")))?;
        // A network reading more than its features reads its Wiener filter's
        // output and noise level, and only a Wiener filter estimates one.
        let extra = description.network.extra_inputs;
        let expected = base_input_channels(description.network.channels);
        if extra > 0 && (extra != expected || description.base_wiener.is_none()) {
            return Err(bad(format!(
                "the network reads {extra} inputs besides its features; a model reading its base \
                 reads {expected}, and needs a base Wiener filter{}",
                if description.base_wiener.is_some() {
                    ""
                } else {
                    " (it has none)"
                }
            )));
        }
        description.network.validate()?;
        if let Some(wiener) = &description.base_wiener {
            WienerFilter::check_description(wiener).map_err(bad)?;
        }
        let base_values = description
            .base_wiener
            .as_ref()
            .map_or(0, WienerFilter::stored_value_count);
        let wanted = description
            .network
            .parameter_count()
            .saturating_add(base_values);
        check_parameter_count(&bytes, origin, wanted)?;
        let device = device.device()?;
        let mut model = description.network.init(&device)?;
        if let Some(wiener) = &description.base_wiener {
            if description.base_filter.is_some() {
                return Err(bad("a base filter and a base Wiener filter at once".into()));
            }
            model.base = Some(WienerFilter::empty_tensors(wiener));
        }
        let mut model = load_weights_from_bytes(bytes, origin, model)?;
        let base_wiener = match (model.base.take(), &description.base_wiener) {
            (Some(tensors), Some(wiener)) => {
                Some(WienerFilter::from_tensors(wiener.clone(), tensors).map_err(bad)?)
            }
            _ => None,
        };
        Ok(CleanModel {
            rig: ModelRig::shipped_for(&description.joints),
            description,
            source: origin.to_path_buf(),
            model,
            device,
            base_wiener,
        })
    }

    /// The features of `motion`'s rig, or an error when the model was
    /// trained on another rig.
    pub(crate) fn layout_for(&self, motion: &Motion) -> Result<FeatureLayout> {
        let layout = FeatureLayout::new(motion.skeleton(), self.description.representation)?
            .in_frame(self.description.frame)?;
        let c = layout.channels();
        if c != self.description.network.channels {
            return Err(CleanError::Invalid(format!(
                "the model was trained on a rig of {} joints with rotations ({}, ...), this take \
                 has {} ({c} features against {}): clean it with --filter butterworth-gcv:2, or \
                 train a model on this rig with `mocap clean train`",
                self.description.joints.len(),
                self.description.joints[..self.description.joints.len().min(3)].join(", "),
                layout.joints.len(),
                self.description.network.channels,
            )));
        }
        // As many joints is not the same rig: the network reads each
        // joint's features in its place, so they must be the same joints
        // in the same order.
        let names = layout.joint_names(motion.skeleton());
        let known = &self.description.joints;
        if let Some(k) = (0..names.len()).find(|&k| known.get(k) != Some(&names[k])) {
            return Err(CleanError::Invalid(format!(
                "the model was trained on a rig of {} joints with rotations ({}, ...), this take's \
                 {} joints with rotations are others: joint {} is {:?} where the model has {:?}. \
                 Clean it with --filter butterworth-gcv:2, play it by the model's rig first \
                 (`mocap convert IN OUT --retarget-to samples/dataset-1_walk_normal_001.bvh`, \
                 with --rig FILE for joint names of its own), or train a model on this rig with \
                 `mocap clean train`",
                known.len(),
                known[..known.len().min(3)].join(", "),
                names.len(),
                k + 1,
                names[k],
                known.get(k).map_or("", String::as_str),
            )));
        }
        Ok(layout)
    }

    /// The learned filter the network corrects, if it corrects one
    /// ([`ModelDescription::base_wiener`]).
    pub fn base_wiener(&self) -> Option<&WienerFilter> {
        self.base_wiener.as_ref()
    }

    /// Sets how the Wiener filter the network corrects estimates a take's
    /// noise level (nothing to set for a model without one).
    pub fn set_level_estimate(&mut self, estimate: LevelEstimate) {
        if let Some(wiener) = &mut self.base_wiener {
            wiener.set_level_estimate(estimate);
        }
    }

    /// The same network correcting another Wiener filter: one with the same
    /// rig, segment and noise covariance as its own (e.g. a mixture made from
    /// it by [`crate::wiener::fit_mixture`]), so the noise level it reads
    /// means the same. The network is not retrained.
    pub fn with_base_wiener(mut self, wiener: WienerFilter) -> Result<CleanModel> {
        let own = self.base_wiener.as_ref().ok_or_else(|| {
            CleanError::Invalid("this model corrects no Wiener filter to replace".into())
        })?;
        if !own.same_noise_model(&wiener) {
            return Err(CleanError::Invalid(
                "the new Wiener filter differs from the model's in rig, segment or noise \
                 covariance"
                    .into(),
            ));
        }
        self.description.base_wiener = Some(wiener.description.clone());
        self.base_wiener = Some(wiener);
        Ok(self)
    }

    /// Writes the model (the network and the Wiener filter it corrects) to
    /// `path`, atomically, with `data` and `training` in its header (e.g.
    /// those of the file it was loaded from, [`CleanModel::header_of`]).
    pub fn save(
        &self,
        path: &Path,
        data: serde_json::Value,
        training: serde_json::Value,
    ) -> Result<()> {
        let mut module = self.model.clone();
        module.base = self.base_wiener.as_ref().map(WienerFilter::to_tensors);
        let header = CheckpointHeader {
            kind: CHECKPOINT_KIND.into(),
            kind_version: CHECKPOINT_KIND_VERSION,
            config: serde_json::to_value(&self.description)
                .map_err(|e| CleanError::Invalid(format!("describing the model: {e}")))?,
            data,
            training,
        };
        save_weights(path, &module, &header)?;
        Ok(())
    }

    /// The `data` and `training` records of a model file's header.
    pub fn header_of(path: &Path) -> Result<(serde_json::Value, serde_json::Value)> {
        let bytes = std::fs::read(path).map_err(|e| mocap_core::Error::io(path, e))?;
        let header = header_from_bytes(&bytes, path)?;
        Ok((header.data, header.training))
    }

    /// Number of trainable numbers of the network.
    pub fn parameter_count(&self) -> usize {
        self.model.num_params()
    }
}

/// A file written by `mocap clean train` (a network) or `mocap clean
/// fit-wiener` (a Wiener filter), told apart by the kind in its header.
pub enum ModelFile {
    Network(Box<CleanModel>),
    Wiener(WienerFilter),
}

impl ModelFile {
    pub fn load(path: &Path, device: DeviceChoice) -> Result<ModelFile> {
        let bytes = std::fs::read(path).map_err(|e| mocap_core::Error::io(path, e))?;
        if header_from_bytes(&bytes, path)?.kind == WIENER_KIND {
            Ok(ModelFile::Wiener(WienerFilter::from_bytes(bytes, path)?))
        } else {
            Ok(ModelFile::Network(Box::new(CleanModel::from_bytes(
                bytes, path, device,
            )?)))
        }
    }

    /// `Ok` when this model can clean `motion` (it was trained or fitted on
    /// `motion`'s rig, or cleans other rigs through its own and finds
    /// `motion`'s body parts), else the error [`ModelFile::clean`] would
    /// give.
    pub fn check_rig(&self, motion: &Motion) -> Result<()> {
        match (self.rig_for(motion), self) {
            (Some(rig), _) => rig.check(motion),
            (None, ModelFile::Network(model)) => model.layout_for(motion).map(|_| ()),
            (None, ModelFile::Wiener(filter)) => filter.layout_for(motion).map(|_| ()),
        }
    }

    /// The model's rig, when `motion` is of another rig and the model
    /// cleans such takes through its own ([`crate::rig`]).
    pub(crate) fn rig_for(&self, motion: &Motion) -> Option<&'static ModelRig> {
        match self {
            ModelFile::Network(model) => model.layout_for(motion).is_err().then_some(model.rig)?,
            ModelFile::Wiener(filter) => filter
                .layout_for(motion)
                .is_err()
                .then(|| ModelRig::shipped_for(&filter.description.joints))?,
        }
    }
}

#[cfg(test)]
impl CleanModel {
    /// Zeroes the network's output layer, so that the model gives its base
    /// filter's output (tests of what is around the network).
    pub(crate) fn zero_output(&mut self) {
        self.model.zero_output();
    }
}
