//! Pictures of motions drawn in Rust, without a browser: a filmstrip PNG
//! (frames side by side, or one row of frames per motion) or an animated
//! GIF, for reports and READMEs.
//!
//! The figures are drawn as in the web viewer: bones as lines, joints as
//! rings, a floor grid of 0.5 m cells, a perspective camera looking at the
//! character from the front-right and slightly above, following the
//! character so that a walk stays in the frame (the grid slides under it).
//! Pictures are drawn at twice their size and averaged down for smooth
//! edges.

use std::path::{Path, PathBuf};

use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbaImage};
use mocap_core::io::atomic::write_bytes_atomically;
use mocap_core::ops::FrameRange;
use mocap_core::rotation::Vec3;
use mocap_core::{Error, Result};
use plotters::prelude::*;

use crate::fonts::register_fonts;
use crate::scene::{Scene, ViewMotion, PALETTE};

/// How several motions share the picture.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Layout {
    /// On top of each other (noisy vs cleaned vs truth).
    #[default]
    Overlay,
    /// Next to each other along x (source vs style vs output), each kept
    /// in place under its hips so that takes that travel differently stay
    /// side by side.
    SideBySide,
    /// A filmstrip with one row per motion (source, style clip, outputs),
    /// each kept in place under its hips: the panels of a column show every
    /// motion at the same moment, so a slower pace shows. The moments span
    /// the shortest motion, and a row holds `columns` of them by default.
    /// A GIF shows the motions side by side.
    Rows,
}

/// What to draw and how big.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    /// Frames `A..B` (from 0, `B` excluded) on the clock of the first
    /// motion; `None` for the whole take (as long as the longest motion).
    pub frames: Option<FrameRange>,
    /// Draw every `N`th frame; `None` picks about 8 panels for a filmstrip
    /// and every frame (at most 50 per second) for a GIF.
    pub every: Option<usize>,
    /// Size of one panel of a filmstrip, or of the GIF, in pixels; `None`
    /// for 240 x 320 (filmstrip) or 480 x 400 per motion side by side (GIF).
    pub panel_size: Option<(u32, u32)>,
    /// Filmstrip panels per row; with [`Layout::Rows`], the moments shown
    /// when `every` is `None`.
    pub columns: usize,
    pub layout: Layout,
    /// Colour joints and bones by confidence (red 0 to green 1) where the
    /// motion has confidence.
    pub colour_by_confidence: bool,
    /// Camera direction around the vertical axis, radians from +z towards +x.
    pub yaw: f32,
    /// Camera elevation, radians above the horizon.
    pub pitch: f32,
}

impl Default for RenderOptions {
    fn default() -> RenderOptions {
        RenderOptions {
            frames: None,
            every: None,
            panel_size: None,
            columns: 8,
            layout: Layout::Overlay,
            colour_by_confidence: true,
            yaw: 0.55,
            pitch: 0.35,
        }
    }
}

/// What [`render`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderSummary {
    pub path: PathBuf,
    /// Frames drawn, on the clock of the first motion.
    pub frames: Vec<usize>,
    pub width: u32,
    pub height: u32,
}

/// The output kinds, by file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Output {
    Filmstrip,
    Gif,
}

/// Most panels in one filmstrip: beyond that the picture is too large to
/// be useful, and `--every` should be raised.
const MAX_PANELS: usize = 128;
/// Most frames in one GIF.
const MAX_GIF_FRAMES: usize = 3000;
/// Supersampling factor: draw at this scale, then average down.
const SUPER: u32 = 2;
const BACKGROUND: RGBColor = RGBColor(244, 244, 242);
const FOV: f32 = 45.0 * std::f32::consts::PI / 180.0;
const NEAR: f32 = 0.05;

/// `mocap render`: reads motion files (as [`Scene::from_files`]) and renders
/// them to `output` (see [`render`]).
pub fn render_files(
    paths: &[PathBuf],
    output: &Path,
    options: &RenderOptions,
) -> Result<RenderSummary> {
    let scene = Scene::from_files(paths)?;
    render(&scene, output, options)
}

/// Renders the motions of `scene` to `output`: a filmstrip when it ends in
/// `.png`, an animated GIF (looping, at the motion's speed) when it ends in
/// `.gif`. The file is written atomically.
pub fn render(scene: &Scene, output: &Path, options: &RenderOptions) -> Result<RenderSummary> {
    let kind = match output
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .as_deref()
    {
        Some("png") => Output::Filmstrip,
        Some("gif") => Output::Gif,
        _ => {
            return Err(Error::Invalid(format!(
                "{}: the picture must end in .png (filmstrip) or .gif (animation)",
                output.display()
            )))
        }
    };
    let first = scene
        .motions
        .first()
        .ok_or_else(|| Error::Invalid("no motion to render".to_string()))?;
    if options.every == Some(0) {
        return Err(Error::Invalid("--every must be at least 1".to_string()));
    }
    if options.columns == 0 {
        return Err(Error::Invalid(
            "a filmstrip needs at least one column".to_string(),
        ));
    }
    let frames = pick_frames(scene, first, kind, options)?;
    register_fonts();
    let (bytes, width, height) = match kind {
        Output::Filmstrip if options.layout == Layout::Rows => {
            rows_filmstrip(scene, first.frame_time, &frames, options)?
        }
        Output::Filmstrip => {
            let stage = Stage::new(scene, first.frame_time, &frames, options);
            filmstrip(&stage, &frames, options)?
        }
        Output::Gif => {
            let stage = Stage::new(scene, first.frame_time, &frames, options);
            gif(&stage, &frames, first.frame_time, options)?
        }
    };
    write_bytes_atomically(output, &bytes)?;
    Ok(RenderSummary {
        path: output.to_path_buf(),
        frames,
        width,
        height,
    })
}

/// Frames on the first motion's clock: the timeline lasts as long as the
/// longest motion, or the shortest with `shortest`.
fn timeline_frames(scene: &Scene, frame_time: f64, shortest: bool) -> usize {
    let durations = scene
        .motions
        .iter()
        .map(|m| m.frame_count.saturating_sub(1) as f64 * m.frame_time);
    let span = if shortest {
        durations.fold(f64::INFINITY, f64::min)
    } else {
        durations.fold(0.0, f64::max)
    };
    if scene.motions.iter().any(|m| m.frame_count == 0)
        && (shortest || scene.motions.iter().all(|m| m.frame_count == 0))
    {
        0
    } else {
        (span / frame_time + 1e-6).floor() as usize + 1
    }
}

fn pick_frames(
    scene: &Scene,
    first: &ViewMotion,
    kind: Output,
    options: &RenderOptions,
) -> Result<Vec<usize>> {
    let rows = kind == Output::Filmstrip && options.layout == Layout::Rows;
    let total = timeline_frames(scene, first.frame_time, rows);
    if total == 0 {
        return Err(Error::Invalid(format!(
            "{}: the motion has no frames",
            first.label
        )));
    }
    let range = options.frames.unwrap_or_default().resolve(total);
    if range.start >= range.end || range.end > total {
        return Err(Error::Invalid(format!(
            "frames {}..{} are not within the take, which has frames 0..{total}",
            range.start, range.end
        )));
    }
    let count = range.end - range.start;
    let every = options.every.unwrap_or(match kind {
        Output::Filmstrip if rows => count.div_ceil(options.columns).max(1),
        Output::Filmstrip => count.div_ceil(8).max(1),
        // GIF delays are whole hundredths of a second and browsers slow
        // down delays under 0.02 s: skip frames of faster takes.
        Output::Gif => (0.02 / first.frame_time).ceil().max(1.0) as usize,
    });
    let frames: Vec<usize> = range.step_by(every).collect();
    let limit = match kind {
        Output::Filmstrip => MAX_PANELS,
        Output::Gif => MAX_GIF_FRAMES,
    };
    if frames.len() > limit {
        return Err(Error::Invalid(format!(
            "{} frames (every {every}th of {count}) is more than the {limit} a {} can hold; raise --every or narrow --frames",
            frames.len(),
            if kind == Output::Gif { "GIF" } else { "filmstrip" }
        )));
    }
    Ok(frames)
}

/// The motions placed for drawing, and the camera framing shared by all
/// pictures of one render.
struct Stage<'a> {
    scene: &'a Scene,
    /// Side by side: each motion is moved to its spot in the row, frame by
    /// frame (see [`Stage::place`]).
    in_place: bool,
    /// x of each motion's spot in the row.
    offsets: Vec<f32>,
    floor_y: f32,
    /// Height the camera aims at.
    aim_y: f32,
    /// Radius of the sphere around the aim that every drawn pose stays in.
    radius: f32,
    frame_time: f64,
    colour_by_confidence: bool,
    yaw: f32,
    pitch: f32,
}

impl<'a> Stage<'a> {
    fn new(
        scene: &'a Scene,
        frame_time: f64,
        frames: &[usize],
        options: &RenderOptions,
    ) -> Stage<'a> {
        let boxes: Vec<(Vec3, Vec3)> = scene
            .motions
            .iter()
            .map(|m| m.bounding_box().unwrap_or((Vec3::ZERO, Vec3::ZERO)))
            .collect();
        let in_place = options.layout != Layout::Overlay;
        let mut offsets = vec![0.0; scene.motions.len()];
        if in_place {
            // Each motion stands on its own spot of a row, its hips kept
            // over it (as on a treadmill), so that takes that travel
            // differently still stand side by side. The spacing is the
            // widest figure's span plus 0.3 m.
            let reach = scene
                .motions
                .iter()
                .map(|m| m.horizontal_reach())
                .fold(0.0, f32::max);
            let spacing = 2.0 * reach + 0.3;
            let middle = (offsets.len() as f32 - 1.0) / 2.0;
            for (i, o) in offsets.iter_mut().enumerate() {
                *o = (i as f32 - middle) * spacing;
            }
        }
        let floor_y = boxes.iter().map(|b| b.0.y).fold(f32::INFINITY, f32::min);
        let top_y = boxes
            .iter()
            .map(|b| b.1.y)
            .fold(f32::NEG_INFINITY, f32::max);
        let mut stage = Stage {
            scene,
            in_place,
            offsets,
            floor_y,
            aim_y: (floor_y + top_y) / 2.0,
            radius: 0.0,
            frame_time,
            colour_by_confidence: options.colour_by_confidence,
            yaw: options.yaw,
            pitch: options.pitch,
        };
        // The camera follows the character horizontally: frame every drawn
        // pose around its own centre, with a common zoom.
        let mut radius: f32 = 0.5;
        for &f in frames {
            let centre = stage.centre(f);
            for (i, m) in scene.motions.iter().enumerate() {
                if m.frame_count == 0 {
                    continue;
                }
                let frame = stage.motion_frame(m, f);
                let positions = m.frame_positions(frame);
                for (_, &p) in positions
                    .iter()
                    .enumerate()
                    .filter(|&(p, _)| m.point_shown(p))
                {
                    let p = stage.place(i, frame, p);
                    radius = radius.max((p - centre).length());
                }
            }
        }
        // A margin, so that the head and feet stay clear of the edges.
        stage.radius = radius * 1.15;
        stage
    }

    /// The frame of motion `m` shown at timeline frame `f`.
    fn motion_frame(&self, m: &ViewMotion, f: usize) -> usize {
        let t = f as f64 * self.frame_time;
        ((t / m.frame_time + 1e-6).floor() as usize).min(m.frame_count.saturating_sub(1))
    }

    /// Where point `p` of motion `i` in its `frame` is drawn: where it is,
    /// or, side by side, moved so that the motion's body root is over its
    /// spot in the row.
    fn place(&self, i: usize, frame: usize, p: Vec3) -> Vec3 {
        if !self.in_place {
            return p;
        }
        let m = &self.scene.motions[i];
        let root = m.frame_positions(frame)[m.body_root()];
        p - Vec3::new(root.x, 0.0, root.z) + Vec3::X * self.offsets[i]
    }

    /// Where the camera aims at timeline frame `f`: above the mean of the
    /// motions' root points.
    fn centre(&self, f: usize) -> Vec3 {
        let mut sum = Vec3::ZERO;
        let mut n = 0;
        for (i, m) in self.scene.motions.iter().enumerate() {
            if m.frame_count == 0 {
                continue;
            }
            let frame = self.motion_frame(m, f);
            sum += self.place(i, frame, m.frame_positions(frame)[m.body_root()]);
            n += 1;
        }
        let c = if n > 0 { sum / n as f32 } else { Vec3::ZERO };
        Vec3::new(c.x, self.aim_y, c.z)
    }

    fn camera(&self, f: usize, width: f32, height: f32) -> Camera {
        let fov = if width < height {
            // Fit the sphere in the narrower side.
            2.0 * ((FOV / 2.0).tan() * width / height).atan()
        } else {
            FOV
        };
        let distance = self.radius / (fov / 2.0).sin();
        Camera::looking_at(
            self.centre(f),
            self.yaw,
            self.pitch,
            distance,
            width,
            height,
        )
    }

    /// Draws timeline frame `f` into the rectangle at `origin` of `size`.
    fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, plotters::coord::Shift>,
        f: usize,
        origin: (f32, f32),
        size: (f32, f32),
        scale: f32,
    ) -> std::result::Result<(), String> {
        let camera = self.camera(f, size.0, size.1);
        let at = |(x, y): (f32, f32)| ((origin.0 + x) as i32, (origin.1 + y) as i32);
        // The floor grid around the aim point.
        let c = camera.target;
        let reach = self.radius.max(1.0).ceil();
        let (x0, x1) = ((c.x - reach).floor(), (c.x + reach).ceil());
        let (z0, z1) = ((c.z - reach).floor(), (c.z + reach).ceil());
        let steps = ((x1 - x0) * 2.0) as i32;
        let zsteps = ((z1 - z0) * 2.0) as i32;
        let mut lines = Vec::new();
        for k in 0..=steps {
            let x = x0 + k as f32 * 0.5;
            lines.push((
                Vec3::new(x, self.floor_y, z0),
                Vec3::new(x, self.floor_y, z1),
                k % 2 == 0,
            ));
        }
        for k in 0..=zsteps {
            let z = z0 + k as f32 * 0.5;
            lines.push((
                Vec3::new(x0, self.floor_y, z),
                Vec3::new(x1, self.floor_y, z),
                k % 2 == 0,
            ));
        }
        for (a, b, major) in lines {
            if let Some((a, b)) = camera.segment(a, b) {
                let colour = if major {
                    RGBColor(185, 185, 180)
                } else {
                    RGBColor(220, 220, 216)
                };
                area.draw(&PathElement::new(
                    vec![at(a), at(b)],
                    colour.stroke_width((scale * if major { 1.2 } else { 1.0 }).round() as u32),
                ))
                .map_err(|e| e.to_string())?;
            }
        }
        // Bones and joints of all motions, far ones first.
        enum Item {
            Bone((f32, f32), (f32, f32), f32, RGBColor),
            Joint((f32, f32), f32, RGBColor),
        }
        let mut items: Vec<(f32, Item)> = Vec::new();
        for (i, m) in self.scene.motions.iter().enumerate() {
            if m.frame_count == 0 {
                continue;
            }
            let frame = self.motion_frame(m, f);
            let colour = m.colour.unwrap_or(PALETTE[i % PALETTE.len()]);
            let points: Vec<Vec3> = m
                .frame_positions(frame)
                .iter()
                .map(|&p| camera.to_camera(self.place(i, frame, p)))
                .collect();
            for (p, &cam) in points.iter().enumerate() {
                let rgb = match m.joint_confidence(frame, p) {
                    Some(c) if self.colour_by_confidence => confidence_colour(c),
                    _ => colour,
                };
                let rgb = RGBColor(rgb[0], rgb[1], rgb[2]);
                if let (Some(parent), true) = (m.parents[p], m.bones[p]) {
                    if let Some((a, b, depth)) = camera.clip(points[parent], cam) {
                        let width = (0.022 * camera.focal / depth).clamp(1.5, 9.0) * scale;
                        items.push((
                            depth,
                            Item::Bone(camera.project(a), camera.project(b), width, rgb),
                        ));
                    }
                }
                if p < m.joint_count && m.point_shown(p) && cam.z >= NEAR {
                    let r = (0.022 * camera.focal / cam.z).clamp(2.0, 10.0) * scale;
                    items.push((cam.z - 1e-3, Item::Joint(camera.project(cam), r, rgb)));
                }
            }
        }
        items.sort_by(|a, b| b.0.total_cmp(&a.0));
        for (_, item) in items {
            match item {
                Item::Bone(a, b, width, rgb) => {
                    area.draw(&PathElement::new(
                        vec![at(a), at(b)],
                        rgb.stroke_width(width.round() as u32),
                    ))
                    .map_err(|e| e.to_string())?;
                    // Round ends, as the viewer's line caps.
                    for end in [a, b] {
                        area.draw(&Circle::new(at(end), (width / 2.0) as i32, rgb.filled()))
                            .map_err(|e| e.to_string())?;
                    }
                }
                Item::Joint(s, r, rgb) => {
                    let ring = (r * 0.45).max(1.5 * scale);
                    area.draw(&Circle::new(at(s), r.round() as i32, rgb.filled()))
                        .map_err(|e| e.to_string())?;
                    area.draw(&Circle::new(
                        at(s),
                        (r - ring).max(1.0).round() as i32,
                        WHITE.filled(),
                    ))
                    .map_err(|e| e.to_string())?;
                }
            }
        }
        Ok(())
    }
}

/// Red (0) through yellow to green (1), as the viewer's confidence colours
/// (`hsl(120 c, 85%, 40-45%)`).
pub fn confidence_colour(c: f32) -> [u8; 3] {
    let hue = 120.0 * c.clamp(0.0, 1.0);
    let lightness = if c > 0.5 { 0.40 } else { 0.45 };
    hsl_to_rgb(hue, 0.85, lightness)
}

fn hsl_to_rgb(hue: f32, saturation: f32, lightness: f32) -> [u8; 3] {
    let chroma = (1.0 - (2.0 * lightness - 1.0).abs()) * saturation;
    let h = hue / 60.0;
    let x = chroma * (1.0 - (h % 2.0 - 1.0).abs());
    let (r, g, b) = match h as u32 {
        0 => (chroma, x, 0.0),
        1 => (x, chroma, 0.0),
        2 => (0.0, chroma, x),
        3 => (0.0, x, chroma),
        4 => (x, 0.0, chroma),
        _ => (chroma, 0.0, x),
    };
    let m = lightness - chroma / 2.0;
    let byte = |v: f32| ((v + m) * 255.0).round().clamp(0.0, 255.0) as u8;
    [byte(r), byte(g), byte(b)]
}

/// A perspective camera: eye, an orthonormal basis, and the pixel focal
/// length for a picture of the given size.
struct Camera {
    target: Vec3,
    eye: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    focal: f32,
    centre: (f32, f32),
}

impl Camera {
    fn looking_at(
        target: Vec3,
        yaw: f32,
        pitch: f32,
        distance: f32,
        width: f32,
        height: f32,
    ) -> Camera {
        let eye = target
            + distance
                * Vec3::new(
                    pitch.cos() * yaw.sin(),
                    pitch.sin(),
                    pitch.cos() * yaw.cos(),
                );
        let forward = (target - eye).normalize();
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        Camera {
            target,
            eye,
            right,
            up,
            forward,
            focal: (height / 2.0) / (FOV / 2.0).tan(),
            centre: (width / 2.0, height / 2.0),
        }
    }

    /// Camera coordinates: right, up, depth.
    fn to_camera(&self, p: Vec3) -> Vec3 {
        let d = p - self.eye;
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.forward))
    }

    fn project(&self, c: Vec3) -> (f32, f32) {
        (
            self.centre.0 + self.focal * c.x / c.z,
            self.centre.1 - self.focal * c.y / c.z,
        )
    }

    /// A segment in camera coordinates cut at the near plane, with its mean
    /// depth; `None` when it lies behind the camera.
    fn clip(&self, a: Vec3, b: Vec3) -> Option<(Vec3, Vec3, f32)> {
        if a.z < NEAR && b.z < NEAR {
            return None;
        }
        let (a, b) = if a.z < NEAR || b.z < NEAR {
            let s = (NEAR - a.z) / (b.z - a.z);
            let m = a + (b - a) * s;
            if a.z < NEAR {
                (m, b)
            } else {
                (a, m)
            }
        } else {
            (a, b)
        };
        Some((a, b, (a.z + b.z) / 2.0))
    }

    /// A world segment projected to the picture, if in front of the camera.
    fn segment(&self, a: Vec3, b: Vec3) -> Option<((f32, f32), (f32, f32))> {
        let (a, b, _) = self.clip(self.to_camera(a), self.to_camera(b))?;
        Some((self.project(a), self.project(b)))
    }
}

/// An RGB picture drawn at `SUPER` times its size, then averaged down.
struct Canvas {
    width: u32,
    height: u32,
    pixels: Vec<u8>,
}

impl Canvas {
    fn new(width: u32, height: u32) -> Canvas {
        Canvas {
            width,
            height,
            pixels: vec![0; (width * SUPER * height * SUPER * 3) as usize],
        }
    }

    fn paint(
        &mut self,
        draw: impl FnOnce(
            &DrawingArea<BitMapBackend, plotters::coord::Shift>,
        ) -> std::result::Result<(), String>,
    ) -> Result<()> {
        let size = (self.width * SUPER, self.height * SUPER);
        let area = BitMapBackend::with_buffer(&mut self.pixels, size).into_drawing_area();
        area.fill(&BACKGROUND)
            .map_err(|e| Error::Invalid(format!("drawing failed: {e}")))?;
        draw(&area).map_err(|e| Error::Invalid(format!("drawing failed: {e}")))?;
        area.present()
            .map_err(|e| Error::Invalid(format!("drawing failed: {e}")))
    }

    /// The picture at its final size: each pixel the mean of its
    /// `SUPER x SUPER` block.
    fn downsampled_rgba(&self) -> RgbaImage {
        let (w, h, s) = (self.width as usize, self.height as usize, SUPER as usize);
        let stride = w * s * 3;
        let mut out = RgbaImage::new(self.width, self.height);
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0u32; 3];
                for dy in 0..s {
                    for dx in 0..s {
                        let i = (y * s + dy) * stride + (x * s + dx) * 3;
                        for (k, total) in sum.iter_mut().enumerate() {
                            *total += self.pixels[i + k] as u32;
                        }
                    }
                }
                let n = (s * s) as u32;
                out.put_pixel(
                    x as u32,
                    y as u32,
                    image::Rgba([
                        (sum[0] / n) as u8,
                        (sum[1] / n) as u8,
                        (sum[2] / n) as u8,
                        255,
                    ]),
                );
            }
        }
        out
    }
}

/// Height of the legend strip above a filmstrip, in final pixels.
const LEGEND_HEIGHT: u32 = 26;

fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    scene: &Scene,
    origin: (i32, i32),
) -> std::result::Result<(), String> {
    let s = SUPER as i32;
    let mut x = origin.0 + 8 * s;
    let y = origin.1 + 6 * s;
    for (i, m) in scene.motions.iter().enumerate() {
        let [r, g, b] = m.colour.unwrap_or(PALETTE[i % PALETTE.len()]);
        area.draw(&Rectangle::new(
            [(x, y), (x + 12 * s, y + 12 * s)],
            RGBColor(r, g, b).filled(),
        ))
        .map_err(|e| e.to_string())?;
        let label = if m.confidence.is_some() {
            format!("{} (confidence: red 0 .. green 1)", m.label)
        } else {
            m.label.clone()
        };
        let style = ("sans-serif", 13 * s)
            .into_font()
            .color(&RGBColor(40, 40, 40));
        area.draw(&Text::new(
            label.clone(),
            (x + 16 * s, y - s),
            style.clone(),
        ))
        .map_err(|e| e.to_string())?;
        let (w, _) = area
            .estimate_text_size(&label, &style)
            .map_err(|e| e.to_string())?;
        x += 16 * s + w as i32 + 18 * s;
    }
    Ok(())
}

fn frame_caption<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    text: &str,
    at: (i32, i32),
) -> std::result::Result<(), String> {
    let style = ("sans-serif", 12 * SUPER as i32)
        .into_font()
        .color(&RGBColor(90, 90, 90));
    area.draw(&Text::new(text.to_string(), at, style))
        .map_err(|e| e.to_string())
}

/// One filmstrip panel: timeline frame `f` of `stage`, with `caption` in
/// its top-left corner and, unless it is in the first column, a thin
/// separator on its left edge.
fn panel(
    stage: &Stage,
    f: usize,
    size: (u32, u32),
    caption: &str,
    first_column: bool,
) -> Result<RgbaImage> {
    let (pw, ph) = size;
    let s = SUPER as f32;
    // Each panel is drawn on its own canvas, so that nothing spills into
    // its neighbours.
    let mut canvas = Canvas::new(pw, ph);
    canvas.paint(|area| {
        stage.draw(area, f, (0.0, 0.0), (pw as f32 * s, ph as f32 * s), s)?;
        frame_caption(area, caption, (6 * SUPER as i32, 4 * SUPER as i32))
    })?;
    let mut panel = canvas.downsampled_rgba();
    if !first_column {
        for y in 0..ph {
            panel.put_pixel(0, y, image::Rgba([200, 200, 196, 255]));
        }
    }
    Ok(panel)
}

/// A picture with the legend strip of `scene` at its top, the rest in the
/// background colour.
fn picture_with_legend(scene: &Scene, width: u32, height: u32) -> Result<RgbaImage> {
    let mut picture = RgbaImage::from_pixel(width, height, image::Rgba([244, 244, 242, 255]));
    let mut legend = Canvas::new(width, LEGEND_HEIGHT);
    legend.paint(|area| draw_legend(area, scene, (0, 0)))?;
    image::imageops::replace(&mut picture, &legend.downsampled_rgba(), 0, 0);
    Ok(picture)
}

fn encode_png(picture: RgbaImage) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    image::DynamicImage::ImageRgba8(picture)
        .to_rgb8()
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .map_err(|e| Error::Invalid(format!("PNG encoding failed: {e}")))?;
    Ok(bytes)
}

fn filmstrip(
    stage: &Stage,
    frames: &[usize],
    options: &RenderOptions,
) -> Result<(Vec<u8>, u32, u32)> {
    let (pw, ph) = options.panel_size.unwrap_or((240, 320));
    check_size(pw, ph)?;
    let columns = options.columns.min(frames.len()).max(1) as u32;
    let rows = (frames.len() as u32).div_ceil(columns);
    let (width, height) = (pw * columns, LEGEND_HEIGHT + ph * rows);
    check_size(width, height)?;
    let mut picture = picture_with_legend(stage.scene, width, height)?;
    for (k, &f) in frames.iter().enumerate() {
        let (col, row) = (k as u32 % columns, k as u32 / columns);
        let caption = format!("frame {f}  {:.2} s", f as f64 * stage.frame_time);
        let panel = panel(stage, f, (pw, ph), &caption, col == 0)?;
        image::imageops::replace(
            &mut picture,
            &panel,
            (col * pw) as i64,
            (LEGEND_HEIGHT + row * ph) as i64,
        );
    }
    Ok((encode_png(picture)?, width, height))
}

/// [`Layout::Rows`]: one row of panels per motion, each motion alone on its
/// stage in its own colour, all at one zoom so that sizes compare.
fn rows_filmstrip(
    scene: &Scene,
    frame_time: f64,
    frames: &[usize],
    options: &RenderOptions,
) -> Result<(Vec<u8>, u32, u32)> {
    let (pw, ph) = options.panel_size.unwrap_or((240, 320));
    check_size(pw, ph)?;
    let alone: Vec<Scene> = scene
        .motions
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let colour = m.colour.unwrap_or(PALETTE[i % PALETTE.len()]);
            Scene::new(vec![m.clone().with_colour(colour)])
        })
        .collect();
    let mut stages: Vec<Stage> = alone
        .iter()
        .map(|one| Stage::new(one, frame_time, frames, options))
        .collect();
    let radius = stages.iter().map(|s| s.radius).fold(0.0, f32::max);
    for stage in &mut stages {
        stage.radius = radius;
    }
    let (width, height) = (
        pw * frames.len() as u32,
        LEGEND_HEIGHT + ph * stages.len() as u32,
    );
    check_size(width, height)?;
    let mut picture = picture_with_legend(scene, width, height)?;
    for (row, stage) in stages.iter().enumerate() {
        for (col, &f) in frames.iter().enumerate() {
            let seconds = f as f64 * frame_time;
            let caption = if col == 0 {
                format!("{}  {seconds:.2} s", stage.scene.motions[0].label)
            } else {
                format!("{seconds:.2} s")
            };
            let panel = panel(stage, f, (pw, ph), &caption, col == 0)?;
            image::imageops::replace(
                &mut picture,
                &panel,
                (col as u32 * pw) as i64,
                (LEGEND_HEIGHT + row as u32 * ph) as i64,
            );
        }
    }
    Ok((encode_png(picture)?, width, height))
}

fn gif(
    stage: &Stage,
    frames: &[usize],
    frame_time: f64,
    options: &RenderOptions,
) -> Result<(Vec<u8>, u32, u32)> {
    let side_by_side = if options.layout != Layout::Overlay {
        stage.scene.motions.len().clamp(1, 3) as u32
    } else {
        1
    };
    let (width, height) = options.panel_size.unwrap_or((480 * side_by_side, 400));
    check_size(width, height)?;
    let s = SUPER as f32;
    let mut bytes = Vec::new();
    {
        // NeuQuant's fastest setting (30; 1 is best and slowest): the
        // figures are flat colours on a plain background, and a frame of
        // the sample looks the same at 10 while encoding takes 1.5 times as
        // long (see RESULTS.md).
        let mut encoder = GifEncoder::new_with_speed(&mut bytes, 30);
        encoder
            .set_repeat(Repeat::Infinite)
            .map_err(|e| Error::Invalid(format!("GIF encoding failed: {e}")))?;
        // GIF delays are whole hundredths of a second: give each frame the
        // rounding of its end time minus that of its start, so the loop keeps
        // the take's real speed (3, 3, 4, 3, 3, 4 ... for 30 fps).
        let step = frames.get(1).map_or(1, |&b| b - frames[0]) as f64 * frame_time * 100.0;
        for (k, &f) in frames.iter().enumerate() {
            let mut canvas = Canvas::new(width, height);
            canvas.paint(|area| {
                // The figure below the legend strip; then the strip, which
                // covers whatever of the floor reached into it.
                let top = LEGEND_HEIGHT as f32 * s;
                stage.draw(
                    area,
                    f,
                    (0.0, top),
                    (width as f32 * s, height as f32 * s - top),
                    s,
                )?;
                area.draw(&Rectangle::new(
                    [(0, 0), ((width * SUPER) as i32, top as i32)],
                    BACKGROUND.filled(),
                ))
                .map_err(|e| e.to_string())?;
                draw_legend(area, stage.scene, (0, 0))?;
                let caption = format!("frame {f}  {:.2} s", f as f64 * stage.frame_time);
                frame_caption(
                    area,
                    &caption,
                    (6 * SUPER as i32, (height as i32 - 20) * SUPER as i32),
                )
            })?;
            let delay = ((k + 1) as f64 * step).round() - (k as f64 * step).round();
            let delay = Delay::from_numer_denom_ms((delay.max(2.0) * 10.0) as u32, 1);
            encoder
                .encode_frame(Frame::from_parts(canvas.downsampled_rgba(), 0, 0, delay))
                .map_err(|e| Error::Invalid(format!("GIF encoding failed: {e}")))?;
        }
    }
    Ok((bytes, width, height))
}

fn check_size(width: u32, height: u32) -> Result<()> {
    if width == 0 || height == 0 || width > 8192 || height > 8192 {
        return Err(Error::Invalid(format!(
            "a picture of {width} x {height} pixels is empty or too large (at most 8192 on a side)"
        )));
    }
    Ok(())
}
