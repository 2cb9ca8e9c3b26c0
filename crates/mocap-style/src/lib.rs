//! # mocap-style
//!
//! Zero-shot motion style transfer with elastic patches: a plain walk made to
//! look proud, old or tired from one example clip of the style, with no
//! training per style, and with the style's timing carried over.
//!
//! The method:
//!
//! 1. [`features`]: every frame becomes the exponential maps (log of the
//!    unit quaternion) of the joint rotations, all joints but end sites. The
//!    pelvis keeps its tilt and roll but not its heading; the root is not
//!    style-converted: its horizontal path and heading come from the source,
//!    its height from the style clip.
//! 2. [`model`]: a tied-weight 1-D convolutional autoencoder trained once on
//!    many styles ([`train`]): encoder = convolution (kernel 15) to 256
//!    channels + ReLU, convolution (kernel 1) to 32 channels + ReLU; the
//!    decoder applies the same weights transposed, biases negated, in
//!    reverse order.
//! 3. [`convert`]: in latent space, source and style latents are whitened,
//!    the source is cut into patches that are matched by cosine similarity
//!    to style patches, swapped and coloured with the style's statistics.
//!    Elastic patches stretch each source patch by up to +-25% before
//!    matching, so the style's timing replaces the source's; a second series
//!    of patches offset by half a patch is blended in linearly so there are
//!    no seams. Strength, fade-in and a blend of two styles are latent
//!    interpolations. Beyond the report, the output keeps the part of the
//!    source's latent code that mirroring flips, averaged over two strides
//!    around each frame, so a turn stays a turn and a take that walks
//!    straight and then turns keeps both ([`convert::Asymmetry`]).
//!    [`contact`] can pin the feet during ground contacts afterwards
//!    (opt-in).
//! 4. [`apply`]: the whole thing on files (`mocap style apply`); [`eval`]
//!    measures it on labelled clips (`mocap style eval`) with independent
//!    classifiers ([`classify`]; [`classify_net`], a small conv net, is a
//!    second style judge); [`filmstrip`]
//!    draws source, style and output side by side.
//!
//! The command line is a thin layer over [`train::TrainOptions`],
//! [`apply::ApplyOptions`] and [`eval::EvalOptions`], whose reports
//! serialise to JSON.

pub mod apply;
pub mod classify;
pub mod classify_net;
pub mod contact;
pub mod convert;
pub mod data;
pub mod eval;
pub mod features;
pub mod filmstrip;
pub mod foot_loss;
pub mod linalg;
pub mod model;
pub mod train;

/// Errors of style transfer.
#[derive(Debug, thiserror::Error)]
pub enum StyleError {
    #[error(transparent)]
    Core(#[from] mocap_core::Error),
    #[error(transparent)]
    Nn(#[from] mocap_nn::NnError),
    /// A request that does not fit the data or the model.
    #[error("{0}")]
    Invalid(String),
}

pub type Result<T, E = StyleError> = std::result::Result<T, E>;

pub(crate) fn invalid(message: impl Into<String>) -> StyleError {
    StyleError::Invalid(message.into())
}
