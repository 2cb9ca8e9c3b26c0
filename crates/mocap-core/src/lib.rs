//! # mocap-core
//!
//! The motion core shared by every mocap capability:
//!
//! - [`skeleton`] and [`motion`]: the data model (joints, channels, frames);
//! - [`rotation`]: every rotation conversion, written once;
//! - [`kinematics`]: forward kinematics;
//! - [`bodymap`]: semantic body parts located on any humanoid rig (by joint
//!   name, else by the skeleton's shape, or from a rig file), and mirroring;
//! - [`ops`]: resample, trim, mirror, scale;
//! - [`retarget`]: a motion played by another rig of the same body map;
//! - [`metrics`]: position and rotation errors, bone-length statistics;
//! - [`io`]: BVH and ASF/AMC files, and atomic writes;
//! - [`info`] and [`convert`]: what `mocap info` reports and what `mocap
//!   convert` does, for any front end.

pub mod bodymap;
pub mod convert;
pub mod error;
pub mod info;
pub mod io;
pub mod kinematics;
pub mod metrics;
pub mod motion;
pub mod ops;
pub mod retarget;
pub mod rotation;
pub mod skeleton;

pub use error::{Error, ParseError, Result};
pub use kinematics::{forward_kinematics, GlobalPoses};
pub use motion::{Motion, FRAME_TIME_RANGE, MAX_VALUES};
pub use skeleton::{Channel, Joint, Skeleton};
