//! One point from several views: weighted linear triangulation, its
//! reprojection error, and robust view selection.
//!
//! Each view sees the point at normalized, undistorted image coordinates
//! `(x, y)` through its pose `P = [R | t]` (rows `P1, P2, P3`). The direct
//! linear transform (Hartley & Zisserman, *Multiple View Geometry*, 2nd ed.,
//! §12.2) stacks two equations a view,
//!
//! ```text
//! w (x P3 - P1) · X = 0,    w (y P3 - P2) · X = 0,    X = (X, Y, Z, 1)
//! ```
//!
//! and solves them in the least-squares sense. A view's weight `w` scales
//! both of its equations, so a confident view pulls the point harder. With
//! the fourth coordinate fixed at 1 (the inhomogeneous form, §12.2: every
//! point is in front of the cameras, none at infinity) the solution is a 3×3
//! linear system `M X = v` with `M = Σ r rᵀ` over the rows' first three
//! entries, which is fast enough for thousands of frames a second.

use glam::{DMat3, DVec2, DVec3};

use crate::camera::Camera;

/// One camera's sighting of a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sighting {
    /// Index of the camera in the rig.
    pub camera: usize,
    /// Where the point is in the image, in pixels (as the pose estimator
    /// wrote it, with the lens's distortion).
    pub pixel: DVec2,
    /// The same, undistorted and normalized (`x/z, y/z` in the camera).
    pub normalized: DVec2,
    /// How much this view counts (0 leaves it out).
    pub weight: f64,
}

impl Sighting {
    /// A sighting of `pixel` by `camera` (index `index`), with `weight`.
    pub fn new(index: usize, camera: &Camera, pixel: DVec2, weight: f64) -> Sighting {
        Sighting {
            camera: index,
            pixel,
            normalized: camera.undistort(pixel),
            weight,
        }
    }
}

/// The smallest determinant of the normal matrix, relative to its scale,
/// for a solution: below it the rays are (nearly) parallel.
const DEGENERATE: f64 = 1e-12;

/// The point seen by `sightings` (weighted DLT, see the module
/// documentation); `None` when fewer than two views have a weight or their
/// rays are parallel.
pub fn triangulate(cameras: &[Camera], sightings: &[Sighting]) -> Option<DVec3> {
    let mut m = DMat3::ZERO;
    let mut v = DVec3::ZERO;
    let mut views = 0;
    for s in sightings {
        if s.weight <= 0.0 || !s.weight.is_finite() {
            continue;
        }
        views += 1;
        let p = cameras[s.camera].pose_matrix();
        for (coordinate, row) in [(s.normalized.x, p[0]), (s.normalized.y, p[1])] {
            // r = w (c P3 - Pi), split into its first three entries and the
            // constant, which moves to the right-hand side.
            let r = [
                s.weight * (coordinate * p[2][0] - row[0]),
                s.weight * (coordinate * p[2][1] - row[1]),
                s.weight * (coordinate * p[2][2] - row[2]),
                s.weight * (coordinate * p[2][3] - row[3]),
            ];
            let a = DVec3::new(r[0], r[1], r[2]);
            m += outer(a, a);
            v -= a * r[3];
        }
    }
    if views < 2 {
        return None;
    }
    let scale = m.x_axis.length() * m.y_axis.length() * m.z_axis.length();
    let det = m.determinant();
    // (NaN fails this test too.)
    if det.is_nan() || det.abs() <= DEGENERATE * scale {
        return None;
    }
    let x = m.inverse() * v;
    x.is_finite().then_some(x)
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Distance in pixels between where `point` projects in the sighting's
/// camera and where it was seen; infinite when the point is behind it.
pub fn reprojection_error(cameras: &[Camera], sighting: &Sighting, point: DVec3) -> f64 {
    cameras[sighting.camera]
        .project(point)
        .map_or(f64::INFINITY, |p| p.distance(sighting.pixel))
}

/// A triangulated point and how well it fits its views.
#[derive(Debug, Clone, PartialEq)]
pub struct Triangulated {
    pub point: DVec3,
    /// Mean reprojection error (pixels) over the views used.
    pub error: f64,
    /// The views used, as indices into the sightings given.
    pub used: Vec<usize>,
}

/// The most views a keypoint is triangulated from by trying every subset
/// of them ([`triangulate_robust`]); above it, views are left out one at a
/// time.
const MAX_EXHAUSTIVE_VIEWS: usize = 8;

/// Triangulates from every view; when the mean reprojection error is above
/// `max_error` pixels, tries every subset of the views, the largest first,
/// and keeps the subset of the most views that meets `max_error`, the one
/// with the smallest error among those (Pose2Sim tries leaving out cameras
/// the same way). A view that drags the first estimate off is thus judged
/// against the others, not against a point it has already pulled toward
/// itself. Sightings of zero weight never take part. `None` when fewer
/// than `min_views` (at least 2) views are left or they do not meet; when
/// no subset meets `max_error`, the subset of `min_views` views that fits
/// best.
pub fn triangulate_robust(
    cameras: &[Camera],
    sightings: &[Sighting],
    max_error: f64,
    min_views: usize,
) -> Option<Triangulated> {
    let min_views = min_views.max(2);
    let views: Vec<usize> = (0..sightings.len())
        .filter(|&i| sightings[i].weight > 0.0)
        .collect();
    if views.len() < min_views {
        return None;
    }
    let mut subset: Vec<Sighting> = Vec::with_capacity(views.len());
    let mut fit = |used: &[usize]| -> Option<Triangulated> {
        subset.clear();
        subset.extend(used.iter().map(|&i| sightings[i]));
        let point = triangulate(cameras, &subset)?;
        let error = subset
            .iter()
            .map(|s| reprojection_error(cameras, s, point))
            .sum::<f64>()
            / subset.len() as f64;
        // Behind one of its views: no point at all.
        error.is_finite().then(|| Triangulated {
            point,
            error,
            used: used.to_vec(),
        })
    };
    let all = fit(&views);
    if all.as_ref().is_some_and(|t| t.error <= max_error) || views.len() == min_views {
        return all;
    }
    if views.len() > MAX_EXHAUSTIVE_VIEWS {
        return leave_out_one_at_a_time(views, fit, max_error, min_views);
    }
    let mut best_of_size: Option<Triangulated> = None;
    for size in (min_views..views.len()).rev() {
        best_of_size = None;
        for mask in 0u32..(1 << views.len()) {
            if mask.count_ones() as usize != size {
                continue;
            }
            let used: Vec<usize> = (0..views.len())
                .filter(|b| mask & (1 << b) != 0)
                .map(|b| views[b])
                .collect();
            if let Some(t) = fit(&used) {
                if best_of_size.as_ref().is_none_or(|b| t.error < b.error) {
                    best_of_size = Some(t);
                }
            }
        }
        if best_of_size.as_ref().is_some_and(|t| t.error <= max_error) {
            return best_of_size;
        }
    }
    best_of_size
}

/// For many views: leaves out the view that fits worst, one at a time,
/// while the mean error is above `max_error`.
fn leave_out_one_at_a_time(
    mut used: Vec<usize>,
    mut fit: impl FnMut(&[usize]) -> Option<Triangulated>,
    max_error: f64,
    min_views: usize,
) -> Option<Triangulated> {
    loop {
        let t = fit(&used)?;
        if t.error <= max_error || used.len() == min_views {
            return Some(t);
        }
        // Each view's own error decides which goes: fit without each, keep
        // the best.
        let (worst, _) = (0..used.len())
            .filter_map(|k| {
                let mut without = used.clone();
                without.remove(k);
                Some((k, fit(&without)?.error))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        used.remove(worst);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A camera at `centre` looking at `target`, y down in the image as
    /// OpenCV's cameras are, 1000 px focal length, 1000×1000 image.
    pub(crate) fn looking_at(name: &str, centre: DVec3, target: DVec3) -> Camera {
        let forward = (target - centre).normalize();
        let right = forward.cross(DVec3::Z).normalize();
        let down = forward.cross(right);
        // Rows of R are the camera axes in world coordinates.
        let rotation = DMat3::from_cols(right, down, forward).transpose();
        Camera {
            name: name.into(),
            size: [1000.0, 1000.0],
            matrix: DMat3::from_cols(
                DVec3::new(1000.0, 0.0, 0.0),
                DVec3::new(0.0, 1000.0, 0.0),
                DVec3::new(500.0, 500.0, 1.0),
            ),
            distortion: [0.0; 5],
            rotation,
            translation: -(rotation * centre),
        }
    }

    pub(crate) fn four_cameras() -> Vec<Camera> {
        let target = DVec3::new(0.0, 0.0, 1.0);
        (0..4)
            .map(|i| {
                let a = i as f64 * std::f64::consts::FRAC_PI_2 + 0.3;
                looking_at(
                    &format!("cam{i}"),
                    DVec3::new(3.0 * a.cos(), 3.0 * a.sin(), 1.5),
                    target,
                )
            })
            .collect()
    }

    fn seen(cameras: &[Camera], point: DVec3, weight: f64) -> Vec<Sighting> {
        cameras
            .iter()
            .enumerate()
            .map(|(i, c)| Sighting::new(i, c, c.project(point).unwrap(), weight))
            .collect()
    }

    #[test]
    fn exact_sightings_give_the_point_back() {
        let cameras = four_cameras();
        for point in [
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(0.4, -0.3, 1.8),
            DVec3::new(-0.5, 0.2, 0.05),
        ] {
            let x = triangulate(&cameras, &seen(&cameras, point, 1.0)).unwrap();
            assert!(x.distance(point) < 1e-9, "{x} against {point}");
            let t = triangulate(&cameras, &seen(&cameras[..2], point, 0.5)).unwrap();
            assert!(t.distance(point) < 1e-9);
        }
    }

    #[test]
    fn one_view_or_parallel_rays_give_nothing() {
        let cameras = four_cameras();
        let point = DVec3::new(0.1, 0.1, 1.0);
        assert!(triangulate(&cameras, &seen(&cameras[..1], point, 1.0)).is_none());
        let mut two = seen(&cameras[..2], point, 1.0);
        two[1].weight = 0.0;
        assert!(triangulate(&cameras, &two).is_none());
        // The same camera twice: the same ray.
        let same = [cameras[0].clone(), cameras[0].clone()];
        assert!(triangulate(&same, &seen(&same, point, 1.0)).is_none());
    }

    #[test]
    fn a_weight_pulls_the_point_toward_the_confident_views() {
        let cameras = four_cameras();
        let point = DVec3::new(0.0, 0.0, 1.0);
        let mut views = seen(&cameras, point, 1.0);
        views[3].pixel += DVec2::new(40.0, 0.0);
        views[3].normalized = cameras[3].undistort(views[3].pixel);
        let equal = triangulate(&cameras, &views).unwrap();
        views[3].weight = 0.1;
        let weighted = triangulate(&cameras, &views).unwrap();
        assert!(
            weighted.distance(point) < 0.2 * equal.distance(point),
            "{} against {}",
            weighted.distance(point),
            equal.distance(point)
        );
    }

    #[test]
    fn the_view_that_disagrees_is_left_out() {
        let cameras = four_cameras();
        let point = DVec3::new(0.2, 0.1, 1.2);
        let mut views = seen(&cameras, point, 1.0);
        views[1].pixel += DVec2::new(0.0, 80.0);
        views[1].normalized = cameras[1].undistort(views[1].pixel);
        let all = triangulate_robust(&cameras, &views, f64::INFINITY, 2).unwrap();
        assert_eq!(all.used, vec![0, 1, 2, 3]);
        assert!(all.error > 10.0);
        let robust = triangulate_robust(&cameras, &views, 5.0, 2).unwrap();
        assert_eq!(robust.used, vec![0, 2, 3]);
        assert!(robust.point.distance(point) < 1e-9);
        assert!(robust.error < 1e-6);
        assert_eq!(
            reprojection_error(&cameras, &views[1], robust.point).round(),
            80.0
        );
    }

    #[test]
    fn with_many_views_the_one_that_disagrees_is_left_out_one_at_a_time() {
        // Nine cameras: more than the subset search takes on.
        let target = DVec3::new(0.0, 0.0, 1.0);
        let cameras: Vec<Camera> = (0..=MAX_EXHAUSTIVE_VIEWS)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / (MAX_EXHAUSTIVE_VIEWS + 1) as f64;
                looking_at(
                    &format!("cam{i}"),
                    DVec3::new(3.0 * a.cos(), 3.0 * a.sin(), 1.5),
                    target,
                )
            })
            .collect();
        let point = DVec3::new(0.2, -0.1, 1.1);
        let mut views = seen(&cameras, point, 1.0);
        views[4].pixel += DVec2::new(200.0, -150.0);
        views[4].normalized = cameras[4].undistort(views[4].pixel);
        let robust = triangulate_robust(&cameras, &views, 5.0, 2).unwrap();
        assert_eq!(robust.used, vec![0, 1, 2, 3, 5, 6, 7, 8]);
        assert!(robust.point.distance(point) < 1e-9);
    }

    #[test]
    fn two_views_that_disagree_of_four_are_both_left_out() {
        let cameras = four_cameras();
        let point = DVec3::new(-0.1, 0.3, 0.9);
        let mut views = seen(&cameras, point, 1.0);
        for (k, shift) in [(0, DVec2::new(60.0, -30.0)), (2, DVec2::new(-45.0, 70.0))] {
            views[k].pixel += shift;
            views[k].normalized = cameras[k].undistort(views[k].pixel);
        }
        let robust = triangulate_robust(&cameras, &views, 5.0, 2).unwrap();
        assert_eq!(robust.used, vec![1, 3]);
        assert!(robust.point.distance(point) < 1e-9);
    }
}
