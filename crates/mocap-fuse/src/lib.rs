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
//! - [`offline`]: recordings put on a common clock and fused;
//! - [`net`]: the UDP datagrams, the fusion server and the sender;
//! - [`calib`], [`align`], [`ply`]: sensor poses, their file, and finding
//!   them (point pairs, ICP on room scans, the body seen by two sensors);
//! - [`bvh`]: fused joints as a BVH on a fitted skeleton;
//! - [`output`]: fused frames to JSON lines and BVH files at once;
//! - [`sim`]: a Kinect v2 simulator on ground-truth takes;
//! - [`eval`]: evaluation against ground truth, and without it
//!   (bone-length consistency of real captures).

pub mod align;
pub mod body;
pub mod bvh;
pub mod calib;
pub mod confidence;
pub mod eval;
pub mod fusion;
pub mod kinect;
pub mod net;
pub mod offline;
pub mod output;
pub mod ply;
pub mod recording;
pub mod sim;
