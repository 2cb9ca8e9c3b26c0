//! # mocap-nn
//!
//! The neural-network glue shared by the learned mocap capabilities (the
//! denoiser of `mocap-clean` and the autoencoder of `mocap-style`), so that each of them
//! only writes its model and its data:
//!
//! - [`device`]: which device runs the network (the pure-Rust `flex` CPU
//!   backend by default, CUDA behind this crate's `cuda` feature), and seeding;
//! - [`checkpoint`]: weights in a safetensors file whose header carries a
//!   versioned description of the model configuration and of the data it was
//!   trained on; resumable training state;
//! - [`train`]: an epoch loop with a progress bar (hidden when stderr is not a
//!   terminal), loss history, and one Adam step;
//! - [`plot`]: loss curves as PNG (drawn by mocap-view);
//! - [`kinematics`]: forward kinematics on tensors, for losses on joint
//!   positions.
//!
//! `burn` is re-exported so that dependent crates use the very same version.

pub mod checkpoint;
pub mod device;
pub mod kinematics;
pub mod plot;
pub mod train;

pub use burn;

/// Errors of the neural-network glue.
#[derive(Debug, thiserror::Error)]
pub enum NnError {
    /// Reading or writing a file failed.
    #[error(transparent)]
    Core(#[from] mocap_core::Error),
    /// A checkpoint file that cannot be used: wrong format, version, kind or
    /// tensors that do not fit the model.
    #[error("{path}: {message}")]
    Checkpoint {
        path: std::path::PathBuf,
        message: String,
    },
    /// A device that this build cannot use.
    #[error("{0}")]
    Device(String),
    /// The training loss stopped being a number: training diverged.
    #[error("the training loss became {loss} at epoch {epoch}: lower the learning rate")]
    Diverged { loss: f64, epoch: usize },
}

pub type Result<T, E = NnError> = std::result::Result<T, E>;

/// Errors of a learned capability (`mocap-clean`, `mocap-style`): reading
/// the data, the networks, or a request that does not fit the data or the
/// model. Each capability names it as its own (`CleanError`, `StyleError`).
#[derive(Debug, thiserror::Error)]
pub enum CapabilityError {
    #[error(transparent)]
    Core(#[from] mocap_core::Error),
    #[error(transparent)]
    Nn(#[from] NnError),
    /// A request that does not fit the data or the model.
    #[error("{0}")]
    Invalid(String),
}

impl CapabilityError {
    /// A request that does not fit the data or the model.
    pub fn invalid(message: impl Into<String>) -> Self {
        Self::Invalid(message.into())
    }
}
