//! Filmstrips: one row of stick figures per motion (source, style clip,
//! outputs), the panels of a column at the same moment, drawn by
//! mocap-view's renderer ([`mocap_view::Layout::Rows`]).

use std::path::Path;

use mocap_core::Motion;
use mocap_view::{render, Layout, RenderOptions, Scene, ViewMotion};

use crate::{invalid, Result};

/// One row of a filmstrip.
pub struct FilmstripRow<'a> {
    pub label: String,
    pub motion: &'a Motion,
}

impl<'a> FilmstripRow<'a> {
    pub fn new(label: impl Into<String>, motion: &'a Motion) -> FilmstripRow<'a> {
        FilmstripRow {
            label: label.into(),
            motion,
        }
    }
}

/// Draws one row of `columns` stick figures per row of `rows` to a PNG at
/// `path` (written atomically). Column `k` shows every row at the same
/// moment, evenly spaced over the shortest row's duration, so a slower pace
/// shows.
pub fn draw_filmstrip(path: &Path, rows: &[FilmstripRow], columns: usize) -> Result<()> {
    if rows.is_empty() || columns == 0 || rows.iter().any(|r| r.motion.frame_count() == 0) {
        return Err(invalid(
            "a filmstrip needs rows of non-empty motions and columns",
        ));
    }
    let scene = Scene::new(
        rows.iter()
            .map(|r| ViewMotion::from_motion(r.label.clone(), r.motion))
            .collect(),
    );
    let options = RenderOptions {
        layout: Layout::Rows,
        columns,
        ..RenderOptions::default()
    };
    render(&scene, path, &options)?;
    Ok(())
}
