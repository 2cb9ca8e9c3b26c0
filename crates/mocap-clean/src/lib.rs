//! # mocap-clean
//!
//! Denoising of markerless motion capture. The shipped model is a 1-D
//! convolutional network over time that corrects the output of a learned
//! multichannel Wiener filter; it is trained on clean motion with synthetic
//! noise and the loss
//!
//! ```text
//! loss = E|G(x) - y|^2 + alpha E|G'(x) - y'|^2 + beta E|G''(x) - y''|^2
//! ```
//!
//! where `'` and `''` are first and second finite differences along time
//! divided by the frame interval (angular velocity and acceleration).
//! Classical filters ([`Filter`]) and rule-based spike finding
//! ([`remove_spikes`]) are here too, as baselines and as stages before a
//! model.
//!
//! The entry points, one per `mocap clean` subcommand, each with options and
//! a report that serialises to JSON:
//!
//! - [`clean_file`] ([`CleanOptions`], [`CleanReport`]): clean one take
//!   (`mocap clean apply`); [`CleanModel`] cleans a take in memory;
//! - [`train`] ([`TrainOptions`], [`TrainRecipe`], [`TrainReport`]): train a
//!   network (`mocap clean train`);
//! - [`fit_wiener`] ([`WienerFitOptions`], [`WienerFitReport`]): fit a learned
//!   Wiener filter or a mixture of them (`mocap clean fit-wiener`);
//! - [`evaluate`] ([`EvalOptions`], [`EvalReport`]): every method on held-out
//!   takes with synthetic noise (`mocap clean eval`).
//!
//! Cleaning a take with the shipped model, and with a classical filter:
//!
//! ```no_run
//! use std::path::PathBuf;
//! use mocap_clean::{clean_file, CleanModel, CleanOptions, Filter, Method};
//!
//! let report = clean_file(&CleanOptions {
//!     input: PathBuf::from("take.bvh"),
//!     output: PathBuf::from("clean.bvh"),
//!     method: Method::DefaultModel,
//!     device: Default::default(),
//!     hop: None,
//!     despike: None,
//!     root_filter: None,
//!     feet: None,
//! })?;
//! println!("{} frames, {:.2} degrees changed", report.frames, report.mean_change_deg);
//!
//! let take = mocap_core::io::read_motion("take.bvh".as_ref())?;
//! let model = CleanModel::load_default(Default::default())?;
//! let cleaned = model.clean(&take, None)?;
//! let filtered = mocap_clean::filter_motion(&take, &"butterworth-gcv:2".parse::<Filter>()?)?;
//! # let _ = (cleaned, filtered);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Fitting a Wiener filter, training a network on it, and evaluating both:
//!
//! ```no_run
//! use std::path::PathBuf;
//! use mocap_clean::{evaluate, fit_wiener, train, EvalOptions, ModelEntry, TrainOptions, WienerFitOptions};
//!
//! let data = vec![PathBuf::from("bandai")];
//! let wiener = fit_wiener(&WienerFitOptions {
//!     inputs: data.clone(),
//!     out: PathBuf::from("wiener.safetensors"),
//!     ..WienerFitOptions::default()
//! })?;
//! let trained = train(&TrainOptions {
//!     inputs: data.clone(),
//!     out: PathBuf::from("model.safetensors"),
//!     base_wiener: Some(wiener.model),
//!     base_context: 128,
//!     base_input: true,
//!     ..TrainOptions::default()
//! })?;
//! let mut options = EvalOptions { inputs: data, ..EvalOptions::default() };
//! options.models.push(ModelEntry { label: "mine".into(), path: Some(trained.model) });
//! print!("{}", evaluate(&options)?.to_markdown());
//! # Ok::<(), mocap_clean::CleanError>(())
//! ```
//!
//! The parts, from the bottom up: the take's rotations as features
//! ([`FeatureLayout`], [`Representation`], [`RotationFrame`]); the noise
//! models ([`RandomNoise`], chain-corrected like inverse kinematics on noisy
//! keypoints, and [`SpikeNoise`], a subtree swapped with another motion for
//! a while); classical filters; spike finding by the jumps of global
//! rotations at a spike's ends ([`DespikeOptions`]); the learned Wiener
//! filter ([`WienerFilter`]); the network and its model file ([`CleanModel`],
//! [`ModelFile`], [`ModelDescription`]); training with checkpoints, resume
//! and curves; cleaning whole takes with blended overlapping windows; and
//! the evaluation. Data sets are split by take ([`Split`]) so that training,
//! tuning and evaluation never share one.

mod dataset;
mod despike;
mod eval;
mod features;
mod filters;
mod fk;
mod infer;
mod loss;
mod metrics;
mod model;
mod model_file;
mod noise;
mod recipe;
mod rig;
mod training;
mod wiener;
mod wiener_fit;

#[cfg(test)]
pub(crate) mod test_support;

pub use dataset::{
    list_bvh, load_takes, looped_window, paths_in_split, DataDescription, Split, SplitFractions,
    Take,
};
pub use despike::{
    bridge_spikes, find_spikes, normalised_jumps, remove_spikes, DespikeOptions, FoundSpike,
};
pub use eval::{
    evaluate, noisy_take, parse_spike_lengths, EvalOptions, EvalReport, MethodMetrics, ModelEntry,
    SpikeSurvival, TunedFilter, CONDITIONS, FUSED,
};
pub use features::{FeatureLayout, Recentering, Representation, RotationFrame};
pub use filters::{
    filter_features, filter_motion, filter_translations, gcv_score, gcv_trace_fraction, Filter,
};
pub use infer::{clean_file, BridgedSpike, CleanOptions, CleanReport, Method};
pub use loss::LossWeights;
pub use metrics::{position_errors, rotation_error_deg};
pub use model::DenoiserConfig;
pub use model_file::{CleanModel, ModelDescription, ModelFile, DEFAULT_MODEL, DEFAULT_MODEL_PATH};
pub use noise::{
    add_random_noise, add_random_noise_sigma, add_spike_noise, add_spikes, NoiseConfig,
    RandomNoise, Spike, SpikeNoise,
};
pub use recipe::TrainRecipe;
pub use training::{train, TrainOptions, TrainReport};
pub use wiener::{
    fit_mixture, ComponentInfo, LevelEstimate, WienerDescription, WienerFilter, WienerOutcome,
};
pub use wiener_fit::{fit_wiener, WienerFitOptions, WienerFitReport};

/// Errors of the denoiser (the error every capability crate shares).
pub type CleanError = mocap_nn::CapabilityError;

pub type Result<T, E = CleanError> = std::result::Result<T, E>;
