//! # mocap-view
//!
//! Seeing motion, for people who judge it by watching it:
//!
//! - [`scene`]: the data a viewer needs from motions (skeleton topology,
//!   global joint positions by forward kinematics, names, confidence,
//!   colours), as compact JSON;
//! - [`server`]: `mocap view`, a local web page (127.0.0.1 only, embedded in
//!   the binary, no network needed) that plays motions as 3D skeletons;
//! - [`render`]: `mocap render`, filmstrip PNGs and animated GIFs drawn in
//!   Rust, for reports and READMEs;
//! - [`plots`]: line, bar and confusion-matrix plots (PNG or SVG) for the
//!   evaluation reports.

pub mod plots;
pub mod render;
pub mod scene;
pub mod server;

pub use plots::{
    plot_bars, plot_confusion, plot_lines, BarPlot, BarSeries, ConfusionPlot, LinePlot, Series,
};
pub use render::{render, render_files, FrameRange, Layout, RenderOptions, RenderSummary};
pub use scene::{Scene, ViewMotion};
pub use server::{serve, ViewerServer};
