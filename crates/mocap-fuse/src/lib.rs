//! # mocap-fuse
//!
//! Multi-sensor skeleton capture with body-aware confidence: several depth
//! sensors (Kinect v2 style, 25 joints with a tracking state each) watch one
//! person; each is calibrated into a world frame and streams its skeletons to
//! a fusion server, which fuses each joint as a confidence-weighted mean
//!
//! ```text
//! J_n = sum_k C_kn J_kn / sum_k C_kn
//! ```
//!
//! where the confidence `C_kn` of sensor `k` for joint `n` multiplies a
//! tracking-state weight, a bone-length term propagated down the kinematic
//! chain and a range-of-motion term ([`confidence`]).
//!
//! Modules:
//! - [`kinect`]: the Kinect v2 joint layout and tracking states;
//! - [`recording`]: the recording format and the NTU RGB+D `.skeleton` reader;
//! - [`body`]: the person measured beforehand (bone lengths, joint ranges);
//! - [`confidence`]: the confidence terms;
//! - [`fusion`]: the weighted fusion and what we add to it;

pub mod align;
pub mod body;
pub mod calib;
pub mod confidence;
pub mod eval;
pub mod fusion;
pub mod kinect;
pub mod net;
pub mod offline;
pub mod recording;
pub mod sim;
