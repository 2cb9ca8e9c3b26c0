//! Loss curves drawn to PNG with `plotters` (text in the embedded DejaVu Sans
//! font, so no system font is needed).

use std::path::Path;
use std::sync::Once;

use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

use crate::train::History;
use crate::{NnError, Result};

/// One curve: a label and its points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

impl Series {
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Series {
        Series {
            label: label.into(),
            points,
        }
    }
}

/// The training and validation curves of a history (x = epoch, 1-based).
pub fn history_series(history: &History, prefix: &str) -> Vec<Series> {
    let pick = |f: fn(&crate::train::EpochRecord) -> f64| {
        history
            .epochs
            .iter()
            .map(|e| ((e.epoch + 1) as f64, f(e)))
            .collect::<Vec<_>>()
    };
    vec![
        Series::new(format!("{prefix}training"), pick(|e| e.train_loss)),
        Series::new(format!("{prefix}validation"), pick(|e| e.valid_loss)),
    ]
}

fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // Registering an embedded font cannot fail for a valid TTF; if it
        // did, text would be missing but the curves still drawn.
        let _ = register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    });
}

/// Options of a line plot.
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

/// Draws `series` as lines into a PNG at `path` (written atomically).
pub fn plot_lines(path: &Path, series: &[Series], options: &PlotOptions) -> Result<()> {
    register_fonts();
    let (w, h) = (options.width, options.height);
    let mut buffer = vec![0u8; (w * h * 3) as usize];
    draw(&mut buffer, series, options).map_err(|message| NnError::Plot {
        path: path.to_path_buf(),
        message,
    })?;
    let mut png_bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut png_bytes, w, h);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let to_plot_error = |e: png::EncodingError| NnError::Plot {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        let mut writer = encoder.write_header().map_err(to_plot_error)?;
        writer.write_image_data(&buffer).map_err(to_plot_error)?;
    }
    mocap_core::io::atomic::write_bytes_atomically(path, &png_bytes)?;
    Ok(())
}

fn draw(
    buffer: &mut [u8],
    series: &[Series],
    options: &PlotOptions,
) -> std::result::Result<(), String> {
    let e = |e: &dyn std::fmt::Display| e.to_string();
    let root =
        BitMapBackend::with_buffer(buffer, (options.width, options.height)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let points = series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|p| p.0.is_finite() && p.1.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in points {
        x0 = x0.min(x);
        x1 = x1.max(x);
        if !options.log_y || y > 0.0 {
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if x0 > x1 || y0 > y1 {
        return Err("no finite points to plot".into());
    }
    if x1 <= x0 {
        x1 = x0 + 1.0;
    }
    if y1 <= y0 {
        y1 = y0 * 1.1 + 1e-9;
    }
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(&options.title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(80);
    macro_rules! finish {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_desc(&options.x_label)
                .y_desc(&options.y_label)
                .label_style(("sans-serif", 14))
                .y_label_formatter(&|v: &f64| format_tick(*v))
                .draw()
                .map_err(|x| e(&x))?;
            for (i, s) in series.iter().enumerate() {
                let color = Palette99::pick(i).to_rgba();
                chart
                    .draw_series(LineSeries::new(
                        s.points
                            .iter()
                            .copied()
                            .filter(|p| !options.log_y || p.1 > 0.0),
                        color.stroke_width(2),
                    ))
                    .map_err(|x| e(&x))?
                    .label(s.label.clone())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                    });
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 14))
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(|x| e(&x))?;
        }};
    }
    // A log axis only gets labels at powers of ten: use it for ranges of
    // more than a decade.
    if options.log_y && y0 > 0.0 && y1 / y0 > 10.0 {
        finish!(builder
            .build_cartesian_2d(x0..x1, (y0 * 0.95..y1 * 1.05).log_scale())
            .map_err(|x| e(&x))?);
    } else {
        let pad = 0.05 * (y1 - y0);
        finish!(builder
            .build_cartesian_2d(x0..x1, y0 - pad..y1 + pad)
            .map_err(|x| e(&x))?);
    }
    root.present().map_err(|x| e(&x))?;
    Ok(())
}

/// A short tick label: 3 significant digits, scientific for tiny numbers.
fn format_tick(v: f64) -> String {
    if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e5) {
        format!("{v:.2e}")
    } else {
        let digits = (2 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{v:.digits$}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_a_png() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("curves.png");
        let series = vec![
            Series::new("a", vec![(1.0, 1.0), (2.0, 0.5), (3.0, 0.2)]),
            Series::new("b", vec![(1.0, 0.9), (2.0, 0.6), (3.0, 0.3)]),
        ];
        plot_lines(&path, &series, &PlotOptions::new("test")).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        // An empty plot is an error, not a blank picture.
        assert!(plot_lines(&path, &[], &PlotOptions::new("empty")).is_err());
    }
}
