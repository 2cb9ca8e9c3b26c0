//! # mocap-clean
//!
//! Learned denoising of markerless motion capture: a 1-D convolutional
//! autoencoder over time, trained on clean motion with synthetic noise and
//! the loss
//!
//! ```text
//! loss = E|G(x) - y|^2 + alpha E|G'(x) - y'|^2 + beta E|G''(x) - y''|^2
//! ```
//!
//! where `'` and `''` are first and second finite differences along time
//! divided by the frame interval (angular velocity and acceleration).
//!
//! - [`noise`]: the two noise models (chain-corrected random noise, spikes);
//! - [`features`]: rotation representations fed to the network;
//! - [`despike`]: finding spikes by the jumps of global rotations at their
//!   ends and bridging them, a classical stage before a filter or denoiser;
//! - [`spikes`]: a learned spike detector (the network with one output per
//!   joint and frame) and bridging of what it marks, a stage before a
//!   denoiser;
//! - [`filters`]: classical baselines (zero-phase Butterworth,
//!   Savitzky-Golay, median, One Euro);
//! - [`wiener`]: a learned multichannel Wiener filter (the spectra of clean
//!   motion and the noise covariance, fitted to training takes);
//! - [`dataset`]: BVH takes split by take, windows;
//! - [`model`]: the autoencoder and its configuration;
//! - [`loss`]: the derivative loss and the optional position term;
//! - [`fk`]: forward kinematics of 6D features in burn tensors (position term);
//! - [`training`]: training with checkpoints, resume and curves;
//! - [`infer`]: cleaning whole takes with blended overlapping windows;
//! - [`eval`]: the evaluation of every method on held-out takes.
//!
//! The command line (`mocap clean`) is a thin layer over
//! [`infer::CleanOptions`], [`training::TrainOptions`] and
//! [`eval::EvalOptions`], whose reports serialise to JSON.

pub mod dataset;
pub mod despike;
pub mod eval;
pub mod features;
pub mod filters;
pub mod fk;
pub mod infer;
pub mod loss;
pub mod model;
pub mod noise;
pub mod spikes;
pub mod training;
pub mod wiener;

#[cfg(test)]
pub(crate) mod test_support;

/// Errors of the denoiser.
#[derive(Debug, thiserror::Error)]
pub enum CleanError {
    #[error(transparent)]
    Core(#[from] mocap_core::Error),
    #[error(transparent)]
    Nn(#[from] mocap_nn::NnError),
    /// A request that does not fit the data or the model.
    #[error("{0}")]
    Invalid(String),
}

pub type Result<T, E = CleanError> = std::result::Result<T, E>;
