//! Filmstrips: rows of stick figures (source, style clip, outputs) at evenly
//! spaced moments, seen from the side, drawn to PNG with `plotters`.
//!
//! Each figure is drawn in the plane of its clip's direction of travel and
//! the up axis, centred on the pelvis horizontally, so strides, posture and
//! pelvis height can be compared across rows. Left limbs are blue, right
//! limbs red, the trunk black.

use std::path::Path;
use std::sync::Once;

use mocap_core::bodymap::mirror_pairs;
use mocap_core::rotation::Vec3;
use mocap_core::{forward_kinematics, Motion};
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

use crate::features::{up_axis, RigLayout};
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

fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // An embedded TTF always registers; if it did not, labels would be
        // missing but the figures still drawn.
        let _ = register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    });
}

const CELL: u32 = 150;
const LABEL: u32 = 22;

/// Side-view 2-D points (forward, up) of every joint in `frame`, with the
/// pelvis at horizontal 0.
fn side_view(motion: &Motion, rig: &RigLayout) -> Vec<Vec<(f32, f32)>> {
    let poses = forward_kinematics(motion);
    let n = poses.joint_count;
    let up = up_axis(&poses.positions, n, rig);
    let frames = poses.frame_count;
    let travel = poses.position(frames - 1, rig.pelvis) - poses.position(0, rig.pelvis);
    let mut forward = travel - up * travel.dot(up);
    if forward.length_squared() < 1e-6 {
        // Standing still: look from the side of the first frame's hips.
        let lateral = poses.position(0, rig.left_hip) - poses.position(0, rig.right_hip);
        forward = up.cross(lateral);
    }
    let forward = if forward.length_squared() > 1e-12 {
        forward.normalize()
    } else {
        Vec3::X
    };
    (0..frames)
        .map(|f| {
            let pelvis = poses.position(f, rig.pelvis).dot(forward);
            (0..n)
                .map(|j| {
                    let p = poses.position(f, j);
                    (p.dot(forward) - pelvis, p.dot(up))
                })
                .collect()
        })
        .collect()
}

/// Draws `rows` × `columns` stick figures to a PNG at `path` (written
/// atomically). Column `k` shows every row at the same time, `k / (columns
/// - 1)` of the shortest row's duration, so a slower pace shows.
pub fn draw_filmstrip(
    path: &Path,
    rows: &[FilmstripRow],
    rig: &RigLayout,
    columns: usize,
) -> Result<()> {
    if rows.is_empty() || columns == 0 || rows.iter().any(|r| r.motion.frame_count() == 0) {
        return Err(invalid(
            "a filmstrip needs rows of non-empty motions and columns",
        ));
    }
    register_fonts();
    let width = CELL * columns as u32;
    let height = (CELL + LABEL) * rows.len() as u32;
    let views: Vec<Vec<Vec<(f32, f32)>>> = rows.iter().map(|r| side_view(r.motion, rig)).collect();
    // One scale for every cell: the tallest figure fits.
    let (mut lo, mut hi, mut reach) = (f32::MAX, f32::MIN, 0.0f32);
    // Only the joints drawn (the pelvis and below): a static world root
    // far behind the walker must not shrink the figures.
    let drawn: Vec<usize> = std::iter::once(rig.pelvis)
        .chain(rig.joints.iter().copied())
        .collect();
    for frame in views.iter().flatten() {
        for &j in &drawn {
            let v = frame[j];
            lo = lo.min(v.1);
            hi = hi.max(v.1);
            reach = reach.max(v.0.abs());
        }
    }
    lo = lo.min(0.0);
    let span = (hi - lo).max(2.0 * reach).max(1e-3) * 1.1;
    let scale = (CELL as f32 - 10.0) / span;
    let shortest = rows
        .iter()
        .map(|r| (r.motion.frame_count() - 1) as f64 * r.motion.frame_time())
        .fold(f64::INFINITY, f64::min);
    let mut buffer = vec![255u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (width, height)).into_drawing_area();
        let e =
            |x: &dyn std::fmt::Display| invalid(format!("{}: cannot draw: {x}", path.display()));
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let parents = &rig.parents;
        let pairs = mirror_pairs(rows[0].motion.skeleton());
        let colour = |j: usize| -> RGBColor {
            if pairs.iter().any(|&(l, _)| l == j) {
                RGBColor(40, 80, 220)
            } else if pairs.iter().any(|&(_, r)| r == j) {
                RGBColor(220, 50, 40)
            } else {
                BLACK
            }
        };
        for (r, (row, view)) in rows.iter().zip(&views).enumerate() {
            let top = r as u32 * (CELL + LABEL);
            root.draw(&Text::new(
                row.label.clone(),
                (6, top as i32 + 3),
                ("sans-serif", 15),
            ))
            .map_err(|x| e(&x))?;
            let frames = view.len();
            for k in 0..columns {
                // The same moment (seconds) in every row, so paces compare.
                let t = if columns == 1 {
                    0.0
                } else {
                    k as f64 * shortest / (columns - 1) as f64
                };
                let f = ((t * row.motion.fps()).round() as usize).min(frames - 1);
                let cx = (k as u32 * CELL + CELL / 2) as f32;
                let base = (top + LABEL + CELL - 5) as f32;
                let to_px = |p: (f32, f32)| {
                    (
                        (cx + p.0 * scale) as i32,
                        (base - (p.1 - lo) * scale) as i32,
                    )
                };
                let pts = &view[f];
                for (j, parent) in parents.iter().enumerate() {
                    if let Some(p) = parent {
                        // Skip bones from a static world root to the pelvis.
                        if j == rig.pelvis && !rig.joints.contains(p) {
                            continue;
                        }
                        if !(rig.joints.contains(&j) || j == rig.pelvis) {
                            continue;
                        }
                        root.draw(&PathElement::new(
                            vec![to_px(pts[*p]), to_px(pts[j])],
                            colour(j).stroke_width(2),
                        ))
                        .map_err(|x| e(&x))?;
                    }
                }
                // Ground line.
                let g = base as i32;
                root.draw(&PathElement::new(
                    vec![
                        (k as i32 * CELL as i32 + 10, g),
                        ((k as i32 + 1) * CELL as i32 - 10, g),
                    ],
                    RGBColor(180, 180, 180).stroke_width(1),
                ))
                .map_err(|x| e(&x))?;
            }
        }
        root.present().map_err(|x| e(&x))?;
    }
    let mut png_bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut png_bytes, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let to_error = |x: png::EncodingError| {
            invalid(format!("{}: cannot encode the PNG: {x}", path.display()))
        };
        let mut writer = encoder.write_header().map_err(to_error)?;
        writer.write_image_data(&buffer).map_err(to_error)?;
    }
    mocap_core::io::atomic::write_bytes_atomically(path, &png_bytes)?;
    Ok(())
}
