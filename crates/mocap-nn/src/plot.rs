//! Loss curves of a training run, drawn as a PNG by mocap-view's line plots.

use std::path::Path;

use mocap_view::{plot_lines, LinePlot};

/// One curve of a loss plot (mocap-view's).
pub use mocap_view::Series;

use crate::train::{EpochRecord, History};
use crate::Result;

/// Title, axis labels and size of a loss plot.
#[derive(Debug, Clone)]
pub struct PlotOptions {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    /// Logarithmic y axis (loss curves span decades).
    pub log_y: bool,
    pub width: u32,
    pub height: u32,
}

impl PlotOptions {
    pub fn new(title: impl Into<String>) -> PlotOptions {
        PlotOptions {
            title: title.into(),
            x_label: "epoch".into(),
            y_label: "loss".into(),
            log_y: true,
            width: 900,
            height: 600,
        }
    }
}

/// The training and validation curves of a history (x = epoch, 1-based),
/// their labels starting with `prefix`.
pub fn history_series(history: &History, prefix: &str) -> Vec<Series> {
    let pick = |f: fn(&EpochRecord) -> f64| {
        history
            .epochs
            .iter()
            .map(|e| ((e.epoch + 1) as f32, f(e) as f32))
            .collect::<Vec<_>>()
    };
    vec![
        Series::new(format!("{prefix}training"), pick(|e| e.train_loss)),
        Series::new(format!("{prefix}validation"), pick(|e| e.valid_loss)),
    ]
}

/// Draws the training and validation curves of `history` into a PNG at
/// `path` (written atomically).
pub fn plot_history(path: &Path, history: &History, options: &PlotOptions) -> Result<()> {
    plot_curves(path, &history_series(history, ""), options)
}

/// Draws `series` (several runs' curves) into a PNG at `path` (written
/// atomically).
pub fn plot_curves(path: &Path, series: &[Series], options: &PlotOptions) -> Result<()> {
    let plot = LinePlot {
        series: series.to_vec(),
        log_y: options.log_y,
        size: (options.width, options.height),
        ..LinePlot::new(&options.title, &options.x_label, &options.y_label)
    };
    plot_lines(path, &plot)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_a_png() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("curves.png");
        let record = |epoch: usize, train_loss: f64, valid_loss: f64| EpochRecord {
            epoch,
            train_loss,
            valid_loss,
            samples: 0,
            train_seconds: 0.0,
        };
        let history = History {
            epochs: vec![
                record(0, 1.0, 0.9),
                record(1, 0.5, 0.6),
                record(2, 0.2, 0.3),
            ],
        };
        plot_history(&path, &history, &PlotOptions::new("test")).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        // An empty plot is an error, not a blank picture.
        let empty = History { epochs: Vec::new() };
        assert!(plot_history(&path, &empty, &PlotOptions::new("empty")).is_err());
    }
}
