//! # mocap-py
//!
//! The Python package `mocap` (built with maturin from this crate and the
//! Python sources in `python/mocap`): motions read by the core, their
//! channels, positions and rotations as numpy arrays, and every capability.
//! A thin layer: it converts arguments and arrays and calls the library
//! entry points of `mocap-core` and the capability crates; the math lives
//! there.
//!
//! - `motion`: `mocap.Motion`, `mocap.Skeleton`, `mocap.read`;
//! - `capabilities`: `clean`, `feet`, `retarget`, `resample`, `mirror`,
//!   `mocap.search.Index` (and the steps of `mocap.batch.index`),
//!   `mocap.style.apply`, `mocap.fuse.run`;
//! - `errors`: Rust errors as `mocap.MocapError` (a `ValueError`) or
//!   `OSError`, with the Rust message (file, line and column).
//!
//! Build and install: `pip install ./crates/mocap-py` (or `maturin build
//! -m crates/mocap-py/Cargo.toml`); tests: `tests/python/run.sh`.

mod capabilities;
mod errors;
mod motion;

use pyo3::prelude::*;

/// Makes `mocap.read` and `Motion.write` read and write the formats the
/// core does not know itself (sensor recordings; glTF): the one place where
/// readers and writers are registered, once, when the module is imported.
fn register_readers() {
    mocap_fuse::register_recording_readers();
    mocap_gltf::register_formats();
}

/// The Rust extension of the `mocap` package; import `mocap`, not this.
#[pymodule]
fn _mocap(m: &Bound<'_, PyModule>) -> PyResult<()> {
    register_readers();
    m.add("MocapError", m.py().get_type::<errors::MocapError>())?;
    m.add_class::<motion::PyMotion>()?;
    m.add_class::<motion::PySkeleton>()?;
    m.add_function(wrap_pyfunction!(motion::read, m)?)?;
    m.add_function(wrap_pyfunction!(capabilities::clean, m)?)?;
    m.add_function(wrap_pyfunction!(capabilities::feet, m)?)?;
    m.add_function(wrap_pyfunction!(capabilities::retarget, m)?)?;
    m.add_function(wrap_pyfunction!(capabilities::resample, m)?)?;
    m.add_function(wrap_pyfunction!(capabilities::mirror, m)?)?;
    m.add_function(wrap_pyfunction!(capabilities::style_apply, m)?)?;
    m.add_function(wrap_pyfunction!(capabilities::fuse_run, m)?)?;
    m.add_function(wrap_pyfunction!(capabilities::search_clips, m)?)?;
    m.add_function(wrap_pyfunction!(capabilities::search_features, m)?)?;
    m.add_function(wrap_pyfunction!(capabilities::search_build_index, m)?)?;
    m.add_class::<capabilities::PyIndex>()?;
    m.add_class::<capabilities::PyQueryResult>()?;
    m.add_class::<capabilities::PyMatch>()?;
    Ok(())
}
