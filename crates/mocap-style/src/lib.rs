//! # mocap-style
//!
//! Zero-shot motion style transfer with elastic patches: a plain walk made to
//! look proud, old or tired from one example clip of the style, with no
//! training per style, and with the style's timing carried over.
//!
//! The method:
//!
//! 1. Features: every frame becomes the exponential maps (log of the unit
//!    quaternion) of the joint rotations, all joints but end sites
//!    ([`RigLayout`], [`Normalization`]). The pelvis keeps its tilt and roll
//!    but not its heading; the root is not style-converted: its horizontal
//!    path and heading come from the source, its height from the style clip.
//! 2. The model: a tied-weight 1-D convolutional autoencoder trained once on
//!    many styles ([`train`], [`StyleModel`]): encoder = convolution
//!    (kernel 15) to 256 channels + ReLU, convolution (kernel 1) to 32
//!    channels + ReLU; the decoder applies the same weights transposed,
//!    biases negated, in reverse order ([`AutoencoderConfig`]).
//! 3. Conversion in latent space ([`ConvertOptions`]): source and style
//!    latents are whitened, the source is cut into patches that are matched
//!    by cosine similarity to style patches, swapped and coloured with the
//!    style's statistics. Elastic patches ([`Method::ElasticPatches`])
//!    stretch each source patch by up to +-25% before matching, so the
//!    style's timing replaces the source's; a second series of patches
//!    offset by half a patch is blended in linearly so there are no seams.
//!    Strength, fade-in and a blend of two styles are latent interpolations.
//!    Beyond the report, the output keeps the part of the source's latent
//!    code that mirroring flips, averaged over two strides around each
//!    frame, so a turn stays a turn and a take that walks straight and then
//!    turns keeps both ([`Asymmetry`]). The planted feet carry the root
//!    within each stride ([`RootPath`]), and [`clean_foot_contacts`] can pin
//!    the feet during ground contacts afterwards (opt-in).
//! 4. [`apply`] does the whole thing on files (`mocap style apply`), on
//!    sources of up to [`MAX_SOURCE_SECONDS`] and style clips of up to
//!    [`MAX_STYLE_SECONDS`] (a restyle holds the whole take: a longer one is
//!    refused before it is read, with the memory it would need);
//!    [`restyle`] on motions in memory. [`evaluate`] measures it on
//!    labelled clips (`mocap style eval`) with judges independent of the
//!    model: random forests of `mocap-search` over its body-relative pose
//!    values ([`ClipClassifier`]), or a small conv net ([`StyleJudge`]).
//!
//! The command line is a thin layer over [`TrainOptions`], [`ApplyOptions`]
//! and [`EvalOptions`], whose reports serialise to JSON.
//!
//! ## Restyle a file
//!
//! ```no_run
//! use mocap_style::{apply, ApplyOptions, Method, RootPath};
//!
//! let mut options = ApplyOptions::new("walk.bvh", "proud.bvh", "walk-proud.bvh");
//! options.method = Method::ElasticPatches; // the default
//! options.root = RootPath::FeetAlongSource; // the default
//! let report = apply(&options)?;
//! println!("{} frames from {}", report.output_frames, report.source_frames);
//! # Ok::<(), mocap_style::StyleError>(())
//! ```
//!
//! ## Restyle motions in memory
//!
//! ```no_run
//! use mocap_core::io::read_motion;
//! use mocap_nn::device::DeviceChoice;
//! use mocap_style::{load_model, prepare_style, restyle, ConvertOptions, StageTimings};
//!
//! let model = load_model(None, DeviceChoice::Cpu)?; // the shipped model
//! let source = read_motion("walk.bvh".as_ref())?;
//! let mut timings = StageTimings::default();
//! let style = prepare_style(&model, &read_motion("proud.bvh".as_ref())?, "proud", &mut timings)?;
//! let restyled = restyle(&model, &source, &[(&style, 1.0)], &ConvertOptions::default(), timings)?;
//! println!("{} frames", restyled.motion.frame_count());
//! # Ok::<(), mocap_style::StyleError>(())
//! ```
//!
//! ## Train the autoencoder, and evaluate
//!
//! ```no_run
//! use mocap_style::{evaluate, train, EvalOptions, TrainOptions};
//!
//! let report = train(&TrainOptions {
//!     inputs: vec!["bandai/dataset-1".into()],
//!     out: "style.safetensors".into(),
//!     ..TrainOptions::default()
//! })?;
//! println!("{} parameters", report.parameters);
//!
//! let report = evaluate(&EvalOptions {
//!     inputs: vec!["bandai/dataset-2".into()],
//!     source_contents: vec!["walk".into()],
//!     style_contents: vec!["walk".into()],
//!     ..EvalOptions::default()
//! })?;
//! print!("{}", report.to_markdown());
//! # Ok::<(), mocap_style::StyleError>(())
//! ```

mod apply;
mod classify;
mod classify_net;
mod contact;
mod convert;
mod data;
mod eval;
mod features;
mod filmstrip;
mod foot_loss;
mod linalg;
mod model;
mod train;

// Restyling files and motions.
pub use apply::{
    apply, load_model, parse_blend, prepare_source, prepare_style, restyle, restyle_prepared,
    source_reconstruction_deg, ApplyOptions, ApplyReport, PreparedSource, Restyled, StageTimings,
    StyleClip, BUILT_IN_MODEL, MAX_SOURCE_SECONDS, MAX_STYLE_SECONDS, SOURCE_BYTES_PER_FRAME,
    STYLE_BYTES_PER_FRAME, UNFAMILIAR_SOURCE_DEG,
};
pub use contact::{clean_foot_contacts, travelled, ContactOptions, ContactReport, RootShift};
pub use convert::{
    windowed_mean, Asymmetry, Conversion, ConvertOptions, Latents, Method, PatchMatch, RootPath,
    StyleMatch,
};

// The model and its training.
pub use features::{gait_period, Normalization, RigLayout};
pub use model::AutoencoderConfig;
pub use train::{
    train, DataDescription, ModelDescription, StyleModel, TrainOptions, TrainReport, DEFAULT_MODEL,
};

// Labelled clips (`<set>_<content>_<style>_<take>.bvh`) and held-out takes.
pub use data::{
    held_out, labelled_paths, list_bvh, load_clips, Clip, ClipFilter, HeldOutTake, Labels,
    WALKING_CONTENTS,
};

// The evaluation, its judges and measures.
pub use classify::{
    clip_pose_statistics, ClassifierConfig, ClipClassifier, Descriptor, Model as ClassifierModel,
    Windows,
};
pub use classify_net::NetConfig;
pub use eval::{
    evaluate, feet_sideways_offset, foot_skating, largest_foot_reach, planted_foot_sliding,
    train_classifiers, EvalOptions, EvalReport, MethodScores, MotionMeasures, PairResult,
    SetReport, StyleClipReading, StyleJudge,
};

/// Errors of style transfer: the core's (files, rigs), the networks', and
/// requests that do not fit the data or the model.
pub type StyleError = mocap_nn::CapabilityError;

pub type Result<T, E = StyleError> = std::result::Result<T, E>;

pub(crate) fn invalid(message: impl Into<String>) -> StyleError {
    StyleError::invalid(message)
}
