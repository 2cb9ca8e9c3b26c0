//! # mocap-gltf
//!
//! glTF 2.0 in and out: a take written as a skinned body that any viewer
//! (Blender, three.js, a web page's `<model-viewer>`) plays, and glTF files
//! from other tools (Mixamo, Blender) read as takes.
//!
//! - [`write_gltf`]: `.glb` (binary) or `.gltf` (JSON, one file): the
//!   skeleton as a skin, one animation at the take's frames, a capsule body
//!   along the bones; lengths scaled to metres and the take turned Y-up,
//!   each with a note saying so ([`take_units`] tells the unit: the rule is
//!   in its docs);
//! - [`read_gltf`]: the first skin's joints and one animation, resampled to
//!   a uniform frame time; what this crate wrote reads back as the take it
//!   was (units, channel layout, end sites and frame time are recorded in
//!   the file's `extras`);
//! - [`register_formats`]: makes `mocap_core::io::read_motion` and
//!   `write_motion` (so every `mocap` command) read and write `.glb` and
//!   `.gltf`.
//!
//! ```no_run
//! use mocap_core::io::read_motion;
//!
//! let walk = read_motion("walk.bvh".as_ref())?;
//! // e.g. "lengths scaled by 0.01: the take's units read as centimetres (rest height 134.5 cm)"
//! for note in mocap_gltf::write_gltf("walk.glb".as_ref(), &walk)? {
//!     eprintln!("note: {note}");
//! }
//! let back = mocap_gltf::read_gltf("walk.glb".as_ref(), None)?;
//! assert_eq!(back.skeleton().joint_count(), walk.skeleton().joint_count());
//! # Ok::<(), mocap_core::Error>(())
//! ```

mod mesh;
mod read;
mod record;
mod units;
mod write;

use std::path::Path;

pub use read::{read_gltf, SINGLE_KEY_FRAME_TIME};
pub use units::{take_units, LengthUnit, TakeUnits, KNOWN_UNITS, NOMINAL_HEIGHT, PLAUSIBLE_HEIGHT};
pub use write::write_gltf;

/// What `.glb` and `.gltf` files are, in the core's errors on unknown file
/// types.
const DESCRIBE: &str = "glTF 2.0";

/// Registers glTF with the core's readers and writers
/// ([`mocap_core::io::register_reader`], [`mocap_core::io::register_writer`]):
/// every later `read_motion` reads the first animation of a `.glb` or
/// `.gltf`, and every `write_motion` writes one. Registering twice is
/// harmless.
pub fn register_formats() {
    mocap_core::io::register_reader(&["glb", "gltf"], DESCRIBE, read_first_animation);
    mocap_core::io::register_writer(&["glb", "gltf"], DESCRIBE, write_gltf);
}

fn read_first_animation(path: &Path) -> mocap_core::Result<mocap_core::Motion> {
    read_gltf(path, None)
}
