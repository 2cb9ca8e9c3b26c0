//! Pictures of an evaluation: one confusion matrix per method, drawn by
//! mocap-view.

use std::path::Path;

use crate::error::{Result, SearchError};
use crate::eval::EvalReport;

impl EvalReport {
    /// Draws one confusion matrix per method into `dir` (created if
    /// needed), as `confusion-<method>.png` and `.svg`: rows are the true
    /// classes, shown as fractions of the row, so each row's diagonal is
    /// the class's recall. Returns how many methods were drawn.
    pub fn plot_confusions(&self, dir: &Path) -> Result<usize> {
        std::fs::create_dir_all(dir).map_err(|error| SearchError::Io {
            path: dir.to_path_buf(),
            error,
        })?;
        let classes = self.classes.len();
        let side = (240 + 28 * classes as u32).min(2000);
        for method in &self.methods {
            let counts = (0..classes)
                .map(|truth| {
                    (0..classes)
                        .map(|predicted| method.confusion.count(truth, predicted) as f32)
                        .collect()
                })
                .collect();
            let plot = mocap_view::ConfusionPlot {
                title: format!("{} (accuracy {:.3})", method.method, method.accuracy),
                labels: self.classes.clone(),
                counts,
                normalise_rows: true,
                size: (side, side),
            };
            let stem: String = method
                .method
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() {
                        c.to_ascii_lowercase()
                    } else {
                        '-'
                    }
                })
                .collect();
            for extension in ["png", "svg"] {
                let path = dir.join(format!("confusion-{stem}.{extension}"));
                mocap_view::plot_confusion(&path, &plot)?;
            }
        }
        Ok(self.methods.len())
    }
}
