//! Reading and writing motion files.
//!
//! - [`bvh`]: Biovision Hierarchy, read and write;
//! - [`asf_amc`]: Acclaim skeleton and motion (CMU, HDM05), read;
//! - [`atomic`]: writing a file so that it is either whole or absent.

pub mod asf_amc;
pub mod atomic;
pub mod bvh;
