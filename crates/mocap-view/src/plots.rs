//! Plots for the evaluation reports, as PNG or SVG (by the file extension):
//!
//! - [`plot_lines`]: curves over a shared x axis (training curves, a joint's
//!   rotation over time for noisy / cleaned / truth, confidence over time);
//! - [`plot_bars`]: grouped bars with optional error bars (per-joint error
//!   of several methods);
//! - [`plot_confusion`]: a confusion matrix (search: true vs found class).
//!
//! The inputs are plain numbers with labels, so any crate can plot without
//! this one knowing its types. Text uses the embedded DejaVu Sans, so PNGs
//! have captions on a machine without fonts. Files are written atomically.

use std::ops::Range;
use std::path::Path;

use mocap_core::io::atomic::write_bytes_atomically;
use mocap_core::{Error, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::fonts::register_fonts;
use crate::scene::PALETTE;

/// Draws with `$draw(&area, args...)` on a PNG or SVG drawing area (by the
/// extension of `$path`) of `$size`, then writes the file atomically. A macro
/// rather than a function because the drawing function is generic over the
/// backend.
macro_rules! draw_to {
    ($path:expr, $size:expr, $draw:ident ( $($arg:expr),* )) => {{
        let path: &Path = $path;
        let (width, height): (u32, u32) = $size;
        if width < 100 || height < 100 || width > 8192 || height > 8192 {
            return Err(Error::Invalid(format!(
                "{}: a plot of {width} x {height} is too small or too large (100 to 8192 on a side)",
                path.display()
            )));
        }
        let failed = |e: String| Error::Invalid(format!("{}: drawing failed: {e}", path.display()));
        // Text is measured with the embedded font for SVG too.
        register_fonts();
        match PlotFormat::of(path)? {
            PlotFormat::Png => {
                let mut pixels = vec![0u8; (width * height * 3) as usize];
                {
                    let area = BitMapBackend::with_buffer(&mut pixels, (width, height)).into_drawing_area();
                    area.fill(&WHITE).map_err(|e| failed(e.to_string()))?;
                    $draw(&area, $($arg),*).map_err(failed)?;
                    area.present().map_err(|e| failed(e.to_string()))?;
                }
                let picture = image::RgbImage::from_raw(width, height, pixels)
                    .expect("the buffer has width * height * 3 bytes");
                let mut bytes = Vec::new();
                picture
                    .write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png)
                    .map_err(|e| failed(e.to_string()))?;
                write_bytes_atomically(path, &bytes)
            }
            PlotFormat::Svg => {
                let mut svg = String::new();
                {
                    let area = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
                    area.fill(&WHITE).map_err(|e| failed(e.to_string()))?;
                    $draw(&area, $($arg),*).map_err(failed)?;
                    area.present().map_err(|e| failed(e.to_string()))?;
                }
                write_bytes_atomically(path, svg.as_bytes())
            }
        }
    }};
}

/// One curve: a label for the legend and its `(x, y)` points. A non-finite
/// point breaks the curve (a gap).
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f32, f32)>,
}

impl Series {
    pub fn new(label: impl Into<String>, points: Vec<(f32, f32)>) -> Series {
        Series {
            label: label.into(),
            points,
        }
    }

    /// A curve of `values` at `x = x0, x0 + step, ...` (a track sampled
    /// every frame, a loss per epoch).
    pub fn sampled(label: impl Into<String>, x0: f32, step: f32, values: &[f32]) -> Series {
        Series::new(
            label,
            values
                .iter()
                .enumerate()
                .map(|(i, &v)| (x0 + i as f32 * step, v))
                .collect(),
        )
    }
}

/// A line plot.
#[derive(Debug, Clone, PartialEq)]
pub struct LinePlot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    /// Logarithmic y axis for losses spanning decades (drawn when the values
    /// span more than a decade; a linear axis otherwise); non-positive
    /// values are left out either way.
    pub log_y: bool,
    /// Width and height in pixels (PNG) or user units (SVG).
    pub size: (u32, u32),
}

impl LinePlot {
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> LinePlot {
        LinePlot {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            log_y: false,
            size: (900, 500),
        }
    }

    pub fn with_series(mut self, series: Series) -> LinePlot {
        self.series.push(series);
        self
    }
}

/// Values of one group member for every category, with optional error bar
/// half-lengths (a standard deviation, a confidence interval).
#[derive(Debug, Clone, PartialEq)]
pub struct BarSeries {
    pub label: String,
    pub values: Vec<f32>,
    pub errors: Option<Vec<f32>>,
}

/// Grouped bars: for each category (a joint), one bar per series (a
/// method).
#[derive(Debug, Clone, PartialEq)]
pub struct BarPlot {
    pub title: String,
    pub y_label: String,
    pub categories: Vec<String>,
    pub series: Vec<BarSeries>,
    pub size: (u32, u32),
}

/// A confusion matrix: `counts[true_class][predicted_class]`.
#[derive(Debug, Clone, PartialEq)]
pub struct ConfusionPlot {
    pub title: String,
    pub labels: Vec<String>,
    pub counts: Vec<Vec<f32>>,
    /// Show each row as fractions of its total (recall per class) instead of
    /// counts.
    pub normalise_rows: bool,
    pub size: (u32, u32),
}

/// Draws a line plot to `path` (`.png` or `.svg`).
pub fn plot_lines(path: &Path, plot: &LinePlot) -> Result<()> {
    let finite = |&(x, y): &(f32, f32)| x.is_finite() && y.is_finite() && (!plot.log_y || y > 0.0);
    let points = || {
        plot.series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|p| finite(p))
    };
    if points().next().is_none() {
        return Err(Error::Invalid(format!(
            "{}: the plot \"{}\" has no finite point to draw",
            path.display(),
            plot.title
        )));
    }
    let x = padded(points().map(|p| p.0), 0.0);
    // A log axis labels only powers of ten: it is drawn when the values
    // span more than a decade, else the axis stays linear.
    let (lo, hi) = min_max(points().map(|p| p.1));
    let log_axis = plot.log_y && hi > 10.0 * lo;
    let y = if log_axis {
        lo / 1.5..hi * 1.5
    } else {
        padded(points().map(|p| p.1), 0.05)
    };
    draw_to!(path, plot.size, draw_lines(plot, x, y, log_axis))
}

fn draw_lines<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: &LinePlot,
    x: Range<f32>,
    y: Range<f32>,
    log_axis: bool,
) -> std::result::Result<(), String> {
    let finite = |&(x, y): &(f32, f32)| x.is_finite() && y.is_finite() && (!plot.log_y || y > 0.0);
    {
        let mut builder = ChartBuilder::on(area);
        builder
            .caption(&plot.title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(70);
        macro_rules! curves {
            ($chart:expr) => {{
                let mut chart = $chart;
                chart
                    .configure_mesh()
                    .x_desc(&plot.x_label)
                    .y_desc(&plot.y_label)
                    .label_style(("sans-serif", 13))
                    .light_line_style(RGBColor(235, 235, 235))
                    .draw()
                    .map_err(|e| e.to_string())?;
                for (i, series) in plot.series.iter().enumerate() {
                    let colour = palette(i);
                    // Split at non-finite points so a gap shows as a gap.
                    let mut pieces: Vec<Vec<(f32, f32)>> = vec![Vec::new()];
                    for p in &series.points {
                        if finite(p) {
                            pieces.last_mut().expect("never empty").push(*p);
                        } else if !pieces.last().expect("never empty").is_empty() {
                            pieces.push(Vec::new());
                        }
                    }
                    let mut first = true;
                    for piece in pieces.into_iter().filter(|p| !p.is_empty()) {
                        let drawn = if piece.len() == 1 {
                            chart
                                .draw_series(std::iter::once(Circle::new(
                                    piece[0],
                                    3,
                                    colour.filled(),
                                )))
                                .map_err(|e| e.to_string())?
                        } else {
                            chart
                                .draw_series(LineSeries::new(piece, colour.stroke_width(2)))
                                .map_err(|e| e.to_string())?
                        };
                        if first && !series.label.is_empty() {
                            drawn.label(series.label.clone()).legend(move |(x, y)| {
                                PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
                            });
                        }
                        first = false;
                    }
                }
                if plot.series.iter().any(|s| !s.label.is_empty()) {
                    chart
                        .configure_series_labels()
                        .background_style(WHITE.mix(0.85))
                        .border_style(RGBColor(200, 200, 200))
                        .label_font(("sans-serif", 13))
                        .position(SeriesLabelPosition::UpperRight)
                        .draw()
                        .map_err(|e| e.to_string())?;
                }
            }};
        }
        if log_axis {
            curves!(builder
                .build_cartesian_2d(x.clone(), y.clone().log_scale())
                .map_err(|e| e.to_string())?);
        } else {
            curves!(builder
                .build_cartesian_2d(x.clone(), y.clone())
                .map_err(|e| e.to_string())?);
        }
        Ok(())
    }
}

/// Draws grouped bars with error bars to `path` (`.png` or `.svg`).
pub fn plot_bars(path: &Path, plot: &BarPlot) -> Result<()> {
    let n = plot.categories.len();
    if n == 0 || plot.series.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: the bar plot \"{}\" has no {} to draw",
            path.display(),
            plot.title,
            if n == 0 { "category" } else { "series" }
        )));
    }
    for s in &plot.series {
        let errors_len = s.errors.as_ref().map_or(n, |e| e.len());
        if s.values.len() != n || errors_len != n {
            return Err(Error::Invalid(format!(
                "{}: series \"{}\" of the bar plot \"{}\" has {} values and {errors_len} errors for {n} categories",
                path.display(),
                s.label,
                plot.title,
                s.values.len()
            )));
        }
    }
    // The bars start at zero; the axis spans every bar and error bar.
    let tops = plot.series.iter().flat_map(|s| {
        s.values.iter().enumerate().flat_map(move |(i, &v)| {
            let e = s.errors.as_ref().map_or(0.0, |e| e[i].abs());
            [v + e, v - e, 0.0]
        })
    });
    let (lo, hi) = min_max(tops.filter(|v| v.is_finite()));
    let pad = (hi - lo).max(1e-6) * 0.08;
    // Room above the bars for the legend.
    let y = if lo < 0.0 { lo - pad } else { 0.0 }..hi + 2.5 * pad;
    let x = -0.5f32..n as f32 - 0.5;
    let longest = plot
        .categories
        .iter()
        .map(|c| c.chars().count())
        .max()
        .unwrap_or(1);
    let rotate = n > 8 || longest * n > 80;
    draw_to!(path, plot.size, draw_bars(plot, x, y, rotate, longest))
}

fn draw_bars<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: &BarPlot,
    x: Range<f32>,
    y: Range<f32>,
    rotate: bool,
    longest: usize,
) -> std::result::Result<(), String> {
    let n = plot.categories.len();
    {
        let mut chart = ChartBuilder::on(area)
            .caption(&plot.title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(if rotate {
                20 + 7 * longest.min(24) as u32
            } else {
                36
            })
            .y_label_area_size(70)
            .build_cartesian_2d(x.clone(), y.clone())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(n + 1)
            .x_label_formatter(&|v: &f32| {
                let i = v.round();
                if !rotate && (v - i).abs() < 1e-3 && i >= 0.0 && (i as usize) < n {
                    plot.categories[i as usize].clone()
                } else {
                    String::new()
                }
            })
            .label_style(("sans-serif", 13))
            .y_desc(&plot.y_label)
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(|e| e.to_string())?;
        if rotate {
            let ticks: Vec<(i32, i32)> = (0..n)
                .map(|c| chart.backend_coord(&(c as f32, y.start)))
                .collect();
            vertical_labels(area, &ticks, &plot.categories)?;
        }
        let groups = plot.series.len() as f32;
        let width = 0.8 / groups;
        for (s, series) in plot.series.iter().enumerate() {
            let colour = palette(s);
            let left = |i: usize| i as f32 - 0.4 + s as f32 * width;
            let bars = series
                .values
                .iter()
                .enumerate()
                .filter(|(_, v)| v.is_finite())
                .map(|(i, &v)| {
                    Rectangle::new(
                        [(left(i), 0.0), (left(i) + width * 0.92, v)],
                        colour.filled(),
                    )
                });
            chart
                .draw_series(bars)
                .map_err(|e| e.to_string())?
                .label(series.label.clone())
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 12, y + 5)], colour.filled())
                });
            if let Some(errors) = &series.errors {
                let bars = series
                    .values
                    .iter()
                    .zip(errors)
                    .enumerate()
                    .filter(|(_, (v, e))| v.is_finite() && e.is_finite())
                    .map(|(i, (&v, &e))| {
                        let centre = left(i) + width * 0.46;
                        ErrorBar::new_vertical(
                            centre,
                            v - e.abs(),
                            v,
                            v + e.abs(),
                            BLACK.stroke_width(1),
                            6,
                        )
                    });
                chart.draw_series(bars).map_err(|e| e.to_string())?;
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(200, 200, 200))
            .label_font(("sans-serif", 13))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| e.to_string())?;
        Ok(())
    }
}

/// Draws a confusion matrix to `path` (`.png` or `.svg`): true classes down,
/// predicted classes across, each cell shaded by its value (or its share of
/// the row) and labelled with it.
pub fn plot_confusion(path: &Path, plot: &ConfusionPlot) -> Result<()> {
    let n = plot.labels.len();
    if n == 0 {
        return Err(Error::Invalid(format!(
            "{}: the confusion matrix \"{}\" has no class",
            path.display(),
            plot.title
        )));
    }
    if plot.counts.len() != n || plot.counts.iter().any(|row| row.len() != n) {
        return Err(Error::Invalid(format!(
            "{}: the confusion matrix \"{}\" must be {n} x {n} for {n} classes",
            path.display(),
            plot.title
        )));
    }
    if plot
        .counts
        .iter()
        .flatten()
        .any(|v| !v.is_finite() || *v < 0.0)
    {
        return Err(Error::Invalid(format!(
            "{}: the confusion matrix \"{}\" holds a negative or non-finite count",
            path.display(),
            plot.title
        )));
    }
    let shown: Vec<Vec<f32>> = plot
        .counts
        .iter()
        .map(|row| {
            let total: f32 = row.iter().sum();
            if plot.normalise_rows {
                row.iter()
                    .map(|v| if total > 0.0 { v / total } else { 0.0 })
                    .collect()
            } else {
                row.clone()
            }
        })
        .collect();
    let max = shown
        .iter()
        .flatten()
        .copied()
        .fold(0.0f32, f32::max)
        .max(1e-9);
    let longest = plot
        .labels
        .iter()
        .map(|c| c.chars().count())
        .max()
        .unwrap_or(1)
        .min(24) as u32;
    let cell_font = (13.0f32).min(260.0 / n as f32).max(7.0) as u32;
    draw_to!(
        path,
        plot.size,
        draw_confusion(plot, &shown, max, longest, cell_font)
    )
}

fn draw_confusion<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: &ConfusionPlot,
    shown: &[Vec<f32>],
    max: f32,
    longest: u32,
    cell_font: u32,
) -> std::result::Result<(), String> {
    let n = plot.labels.len();
    let rotate = n > 6 || longest as usize * n > 60;
    {
        let mut chart = ChartBuilder::on(area)
            .caption(&plot.title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(if rotate { 24 + 7 * longest } else { 40 })
            .y_label_area_size(24 + 7 * longest)
            .build_cartesian_2d(-0.5f32..n as f32 - 0.5, -0.5f32..n as f32 - 0.5)
            .map_err(|e| e.to_string())?;
        // Row 0 at the top: y = n - 1 - row.
        let name = |v: f32, flip: bool| {
            let i = v.round();
            if (v - i).abs() < 1e-3 && i >= 0.0 && (i as usize) < n {
                let i = if flip { n - 1 - i as usize } else { i as usize };
                plot.labels[i].clone()
            } else {
                String::new()
            }
        };
        chart
            .configure_mesh()
            .disable_mesh()
            .x_labels(n + 1)
            .y_labels(n + 1)
            .x_label_formatter(&|v| {
                if rotate {
                    String::new()
                } else {
                    name(*v, false)
                }
            })
            .y_label_formatter(&|v| name(*v, true))
            // The general label style first: it sets the x labels' too.
            .label_style(("sans-serif", 12))
            .x_desc("found")
            .y_desc("true")
            .draw()
            .map_err(|e| e.to_string())?;
        let mut cells = Vec::new();
        let mut labels = Vec::new();
        for (row, values) in shown.iter().enumerate() {
            for (col, &v) in values.iter().enumerate() {
                let y = (n - 1 - row) as f32;
                let x = col as f32;
                let shade = v / max;
                cells.push(Rectangle::new(
                    [(x - 0.5, y - 0.5), (x + 0.5, y + 0.5)],
                    blues(shade).filled(),
                ));
                let text = if plot.normalise_rows {
                    format!("{:.2}", v)
                } else if v.fract() == 0.0 {
                    format!("{v:.0}")
                } else {
                    format!("{v:.2}")
                };
                let colour = if shade > 0.55 {
                    WHITE
                } else {
                    RGBColor(30, 30, 30)
                };
                labels.push(Text::new(
                    text,
                    (x, y),
                    ("sans-serif", cell_font)
                        .into_font()
                        .color(&colour)
                        .pos(Pos::new(HPos::Center, VPos::Center)),
                ));
            }
        }
        if rotate {
            let ticks: Vec<(i32, i32)> = (0..n)
                .map(|c| chart.backend_coord(&(c as f32, -0.5)))
                .collect();
            vertical_labels(area, &ticks, &plot.labels)?;
        }
        chart.draw_series(cells).map_err(|e| e.to_string())?;
        if n <= 30 {
            chart.draw_series(labels).map_err(|e| e.to_string())?;
        }
        Ok(())
    }
}

/// Category names written downwards under their ticks (`ticks` in pixels,
/// on the x axis): many joint names side by side would overlap. Drawn here
/// because plotters' axis labels keep their own anchor, which rotated text
/// needs changed.
fn vertical_labels<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    ticks: &[(i32, i32)],
    names: &[String],
) -> std::result::Result<(), String> {
    let style = ("sans-serif", 12)
        .into_font()
        .transform(FontTransform::Rotate90)
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    for (&(x, y), name) in ticks.iter().zip(names) {
        let name: String = name.chars().take(24).collect();
        area.draw(&Text::new(name, (x, y + 8), style.clone()))
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// White (0) to dark blue (1).
fn blues(t: f32) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    let mix = |a: f32, b: f32| (a + (b - a) * t).round() as u8;
    RGBColor(mix(247.0, 8.0), mix(251.0, 48.0), mix(255.0, 107.0))
}

fn palette(i: usize) -> RGBColor {
    let [r, g, b] = PALETTE[i % PALETTE.len()];
    RGBColor(r, g, b)
}

fn min_max(values: impl Iterator<Item = f32>) -> (f32, f32) {
    values.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

/// The range of `values` widened by `margin` of its span (and to a unit
/// span when all values are equal).
fn padded(values: impl Iterator<Item = f32>, margin: f32) -> Range<f32> {
    let (lo, hi) = min_max(values);
    if hi - lo <= f32::EPSILON * lo.abs().max(1.0) {
        return lo - 0.5..hi + 0.5;
    }
    let pad = (hi - lo) * margin;
    lo - pad..hi + pad
}

enum PlotFormat {
    Png,
    Svg,
}

impl PlotFormat {
    fn of(path: &Path) -> Result<PlotFormat> {
        match path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .as_deref()
        {
            Some("png") => Ok(PlotFormat::Png),
            Some("svg") => Ok(PlotFormat::Svg),
            _ => Err(Error::Invalid(format!(
                "{}: a plot must end in .png or .svg",
                path.display()
            ))),
        }
    }
}
