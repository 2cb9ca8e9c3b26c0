//! # mocap-view
//!
//! Seeing motion, for people who judge it by watching it. Every picture of
//! the toolkit is drawn here (other crates hand over plain numbers and
//! motions), with the embedded DejaVu Sans so that text shows on a machine
//! without fonts.
//!
//! - [`Scene`] and [`ViewMotion`]: the data a viewer needs from motions
//!   (skeleton topology, global joint positions in metres, names,
//!   confidence, colours), from files ([`Scene::from_files`]) or from
//!   motions and captures in memory;
//! - [`ViewerServer`] (`mocap view`): a local web page (127.0.0.1 only,
//!   embedded in the binary, no network needed) that plays motions as 3D
//!   skeletons;
//! - [`render`] and [`render_files`] (`mocap render`): filmstrip PNGs and
//!   animated GIFs drawn in Rust, the motions on top of each other, side by
//!   side, or one row each ([`Layout`]);
//! - [`plot_lines`], [`plot_bars`] and [`plot_confusion`]: line, bar and
//!   confusion-matrix plots (PNG or SVG) for the evaluation reports and
//!   training curves.
//!
//! ```no_run
//! use std::path::{Path, PathBuf};
//! use mocap_view::{plot_lines, render_files, LinePlot, RenderOptions, Series};
//!
//! // A filmstrip of a take, about 8 panels.
//! render_files(&[PathBuf::from("walk.bvh")], Path::new("walk.png"), &RenderOptions::default())?;
//!
//! // A curve.
//! let plot = LinePlot::new("loss", "epoch", "loss")
//!     .with_series(Series::sampled("training", 1.0, 1.0, &[0.9, 0.5, 0.3]));
//! plot_lines(Path::new("loss.png"), &plot)?;
//! # Ok::<(), mocap_core::Error>(())
//! ```

mod fonts;
mod plots;
mod render;
mod scene;
mod server;

/// Frames to draw (`A..B`, `A..`, `..B`), on the first motion's clock.
pub use mocap_core::ops::FrameRange;
pub use plots::{
    plot_bars, plot_confusion, plot_lines, BarPlot, BarSeries, ConfusionPlot, LinePlot, Series,
};
pub use render::{confidence_colour, render, render_files, Layout, RenderOptions, RenderSummary};
pub use scene::{guess_metres_per_unit, read_capture, Scene, ViewMotion, PALETTE};
/// One connection of the viewer over any byte stream, for the fuzz target
/// `viewer_request`; not part of the API.
#[doc(hidden)]
pub use server::serve_connection;
pub use server::{serve, ViewerServer};
