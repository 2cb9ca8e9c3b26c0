//! Estimating rigid transforms: from point pairs (Kabsch/Umeyama), between
//! point clouds (ICP), and from the body itself seen by two sensors.

use std::path::{Path, PathBuf};

use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use mocap_core::rotation::{Quat, Vec3};
use mocap_core::{Error, Result};
use nalgebra::{Matrix3, Matrix6, Rotation3, UnitQuaternion, Vector3, Vector6};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};

use crate::calib::{Calibration, RigidTransform, SensorPose};
use crate::kinect::{TrackingState, JOINT_COUNT, MIRROR};
use crate::offline::{sample_stream, SensorStreams};
use crate::recording::JointObservation;

/// A fitted transform and how well it fits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Alignment {
    /// Maps source points onto target points.
    pub transform: RigidTransform,
    /// Root mean square of the pair distances after alignment (m).
    pub rms: f64,
    pub max_residual: f64,
    pub pairs: usize,
}

fn v(p: Vec3) -> Vector3<f64> {
    Vector3::new(p.x as f64, p.y as f64, p.z as f64)
}

fn to_transform(r: &Matrix3<f64>, t: &Vector3<f64>) -> RigidTransform {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r));
    RigidTransform {
        rotation: Quat::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32).normalize(),
        translation: Vec3::new(t.x as f32, t.y as f32, t.z as f32),
    }
}

/// Spread of points perpendicular to their best-fit line (m): the second
/// singular value of the centred points, per point.
fn spread_off_line(points: &[Vector3<f64>], weights: &[f64]) -> f64 {
    let total: f64 = weights.iter().sum();
    let mean = points
        .iter()
        .zip(weights)
        .map(|(p, w)| p * *w)
        .sum::<Vector3<f64>>()
        / total;
    let mut cov = Matrix3::zeros();
    for (p, w) in points.iter().zip(weights) {
        let d = p - mean;
        cov += d * d.transpose() * *w;
    }
    let mut e: Vec<f64> = cov.symmetric_eigenvalues().iter().copied().collect();
    e.sort_by(f64::total_cmp);
    (e[1].max(0.0) / total).sqrt()
}

/// The rigid transform taking `source[i]` onto `target[i]` in the weighted
/// least-squares sense (Kabsch; Umeyama's correction for reflections: when
/// the best orthogonal matrix is a reflection, the smallest singular
/// direction is flipped so the result is a rotation).
///
/// Fails with a clear message on fewer than 3 pairs or when either set is
/// collinear (spread off its best line below 1 mm), where the rotation about
/// that line is not determined.
pub fn fit_rigid(source: &[Vec3], target: &[Vec3], weights: Option<&[f64]>) -> Result<Alignment> {
    if source.len() != target.len() {
        return Err(Error::Invalid(format!(
            "point pairs: {} source points but {} target points",
            source.len(),
            target.len()
        )));
    }
    if source.len() < 3 {
        return Err(Error::Invalid(format!(
            "a rigid transform needs at least 3 point pairs, got {}",
            source.len()
        )));
    }
    let ones = vec![1.0; source.len()];
    let w = weights.unwrap_or(&ones);
    let s: Vec<Vector3<f64>> = source.iter().map(|&p| v(p)).collect();
    let t: Vec<Vector3<f64>> = target.iter().map(|&p| v(p)).collect();
    for (name, pts) in [("source", &s), ("target", &t)] {
        let spread = spread_off_line(pts, w);
        if spread.is_nan() || spread < 1e-3 {
            return Err(Error::Invalid(format!(
                "the {name} points are collinear (spread off their line {:.2} mm): \
                 the rotation about that line cannot be found; use points that span a plane",
                spread * 1000.0
            )));
        }
    }
    let total: f64 = w.iter().sum();
    let sm = s.iter().zip(w).map(|(p, w)| p * *w).sum::<Vector3<f64>>() / total;
    let tm = t.iter().zip(w).map(|(p, w)| p * *w).sum::<Vector3<f64>>() / total;
    let mut h = Matrix3::zeros();
    for ((a, b), w) in s.iter().zip(&t).zip(w) {
        h += (a - sm) * (b - tm).transpose() * *w;
    }
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
    let mut d = Matrix3::identity();
    if (vt.transpose() * u.transpose()).determinant() < 0.0 {
        d[(2, 2)] = -1.0;
    }
    let r = vt.transpose() * d * u.transpose();
    let tr = tm - r * sm;
    let residuals: Vec<f64> = s
        .iter()
        .zip(&t)
        .map(|(a, b)| (r * a + tr - b).norm())
        .collect();
    let rms = (residuals.iter().map(|x| x * x).sum::<f64>() / residuals.len() as f64).sqrt();
    Ok(Alignment {
        transform: to_transform(&r, &tr),
        rms,
        max_residual: residuals.iter().copied().fold(0.0, f64::max),
        pairs: residuals.len(),
    })
}

/// ICP error metric.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IcpMetric {
    PointToPoint,
    PointToPlane,
}

/// ICP options.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IcpOptions {
    pub metric: IcpMetric,
    pub max_iterations: usize,
    /// Pairs farther apart than this (m) are not used in the first
    /// iteration; the distance then shrinks by `distance_decay` per
    /// iteration, down to `min_distance`.
    pub max_distance: f32,
    /// Factor of the pairing distance from one iteration to the next.
    pub distance_decay: f32,
    /// The smallest pairing distance (m); about three times the depth noise.
    pub min_distance: f32,
    /// Pairs whose surface normals differ by more than this are not used
    /// (degrees): a wall point near a corner must not pair with the floor.
    pub max_normal_angle_degrees: f32,
    /// Smallest scale (m) of the Cauchy weights `1 / (1 + (r / c)^2)` of the
    /// pair residuals `r`, so that parts of one scan that the other does not
    /// cover pull little; the scale is half the pairing distance, down to
    /// this.
    pub robust_scale: f32,
    /// A direction of motion (rotation or translation) is unconstrained when
    /// the cost curves along it less than this share of the most
    /// constrained direction; ICP does not move along it (see
    /// [`IcpResult::unconstrained`]).
    pub degeneracy_ratio: f64,
    /// Stop when the transform changes by less than this (m or rad).
    pub tolerance: f64,
    /// Neighbours for the surface normals.
    pub normal_neighbours: usize,
}

impl Default for IcpOptions {
    fn default() -> Self {
        IcpOptions {
            metric: IcpMetric::PointToPlane,
            max_iterations: 80,
            max_distance: 0.5,
            distance_decay: 0.85,
            min_distance: 0.05,
            max_normal_angle_degrees: 30.0,
            robust_scale: 0.05,
            degeneracy_ratio: 0.02,
            tolerance: 1e-6,
            normal_neighbours: 12,
        }
    }
}

/// The result of ICP.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IcpResult {
    pub transform: RigidTransform,
    /// RMS distance of the pairs used in the last iteration (m; point to
    /// plane distance for that metric).
    pub rms: f64,
    pub pairs: usize,
    pub iterations: usize,
    pub converged: bool,
    /// Directions of motion the two scans do not pin down (for example
    /// sliding along the floor when the only surface both sensors see is the
    /// floor), in the target's frame. Along these the result keeps the
    /// initial transform: check it there by other means.
    pub unconstrained: Vec<String>,
}

/// Unit normals of a point cloud from its `k` nearest neighbours (the
/// direction of least spread), or zero where the neighbourhood is a line.
fn cloud_normals(
    points: &[[f64; 3]],
    tree: &ImmutableKdTree<f64, u64, 3, 32>,
    k: usize,
) -> Vec<Vector3<f64>> {
    let k = std::num::NonZero::new(k.max(3)).expect("at least 3");
    points
        .iter()
        .map(|q| {
            let nn = tree.nearest_n::<SquaredEuclidean>(q, k);
            let pts: Vec<Vector3<f64>> = nn
                .iter()
                .map(|n| Vector3::from(points[n.item as usize]))
                .collect();
            let mean = pts.iter().sum::<Vector3<f64>>() / pts.len() as f64;
            let cov = pts.iter().fold(Matrix3::zeros(), |c, p| {
                c + (p - mean) * (p - mean).transpose()
            });
            let eig = cov.symmetric_eigen();
            let mut order = [0usize, 1, 2];
            order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
            // A neighbourhood spread along a line has no surface normal.
            if eig.eigenvalues[order[1]] < 1e-12 {
                return Vector3::zeros();
            }
            eig.eigenvectors.column(order[0]).into_owned()
        })
        .collect()
}

fn rotation_matrix(q: Quat) -> Matrix3<f64> {
    UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
        q.w as f64, q.x as f64, q.y as f64, q.z as f64,
    ))
    .to_rotation_matrix()
    .into_inner()
}

/// Describes a direction of the 6-vector (scaled rotation, translation).
fn describe_direction(v: &Vector6<f64>) -> String {
    let rot = Vector3::new(v[0], v[1], v[2]);
    let tr = Vector3::new(v[3], v[4], v[5]);
    let (kind, d) = if rot.norm() > tr.norm() {
        ("rotation about", rot.normalize())
    } else {
        ("translation along", tr.normalize())
    };
    format!("{kind} ({:.2}, {:.2}, {:.2})", d.x, d.y, d.z)
}

/// The clouds, their k-d trees and normals, shared by the ICP passes.
struct IcpClouds {
    source: Vec<Vector3<f64>>,
    source_normals: Vec<Vector3<f64>>,
    target: Vec<[f64; 3]>,
    target_normals: Vec<Vector3<f64>>,
    tree: ImmutableKdTree<f64, u64, 3, 32>,
}

/// Directions of motion held fixed in a pass: 6-vectors (rotation about
/// `centre` scaled by `radius`, translation), orthonormal.
struct Frozen {
    centre: Vector3<f64>,
    radius: f64,
    directions: Vec<Vector6<f64>>,
}

/// What one pass ends with.
struct IcpPass {
    result: IcpResult,
    /// The last iteration's centre, radius and unconstrained directions.
    frozen: Frozen,
}

/// Iterative closest point: refines `initial` (taking `source` into the
/// frame of `target`). Nearest neighbours come from a k-d tree (`kiddo`).
///
/// Two depth scans of one room overlap only in part, and sensors placed
/// around a person overlap in little more than the floor around them. Plain
/// ICP then fails in two ways, which this one guards against:
/// - points of one scan with no counterpart in the other pair with the
///   nearest wrong surface: pairs whose normals disagree are dropped, the
///   pairing distance shrinks from iteration to iteration, and residuals get
///   Cauchy weights;
/// - the overlap may not pin down every direction of motion (the floor alone
///   leaves sliding and turning on it free; one wall leaves sliding along
///   it): along such a direction every small bias moves the estimate without
///   bound, and it wanders off by a metre. As in degeneracy-aware ICP
///   (Zhang, Kaess, Singh, "On degeneracy of optimization-based state
///   estimation problems", ICRA 2016), each step is restricted to the
///   directions the point-to-plane Hessian constrains (eigenvalues above
///   `degeneracy_ratio` times the largest; rotations scaled by the pairs'
///   RMS radius so that both are in metres). Because wrong pairs in the first
///   iterations can make a free direction look constrained, a first pass
///   finds the free directions at its end, and a second pass from `initial`
///   never moves along them. Along them the result keeps the initial
///   transform; they are listed in [`IcpResult::unconstrained`].
pub fn icp(
    source: &[Vec3],
    target: &[Vec3],
    initial: RigidTransform,
    options: &IcpOptions,
) -> Result<IcpResult> {
    if source.len() < 3 || target.len() < options.normal_neighbours.max(3) {
        return Err(Error::Invalid(format!(
            "ICP needs point clouds of at least a few points (source {}, target {})",
            source.len(),
            target.len()
        )));
    }
    let as_array = |p: &Vec3| [p.x as f64, p.y as f64, p.z as f64];
    let target: Vec<[f64; 3]> = target.iter().map(as_array).collect();
    let source_points: Vec<[f64; 3]> = source.iter().map(as_array).collect();
    let tree: ImmutableKdTree<f64, u64, 3, 32> = ImmutableKdTree::new_from_slice(&target);
    let source_tree: ImmutableKdTree<f64, u64, 3, 32> =
        ImmutableKdTree::new_from_slice(&source_points);
    let clouds = IcpClouds {
        target_normals: cloud_normals(&target, &tree, options.normal_neighbours),
        source_normals: cloud_normals(&source_points, &source_tree, options.normal_neighbours),
        source: source_points.iter().map(|p| Vector3::from(*p)).collect(),
        target,
        tree,
    };
    let first = icp_pass(&clouds, initial, options, None)?;
    if first.frozen.directions.is_empty() {
        return Ok(first.result);
    }
    let unconstrained = first.result.unconstrained.clone();
    let mut second = icp_pass(&clouds, initial, options, Some(&first.frozen))?;
    second.result.unconstrained = unconstrained;
    Ok(second.result)
}

/// An orthonormal basis (columns) of the directions orthogonal to `frozen`.
fn complement(frozen: &[Vector6<f64>]) -> Vec<Vector6<f64>> {
    let projector: Matrix6<f64> = frozen.iter().map(|f| f * f.transpose()).sum();
    let eig = projector.symmetric_eigen();
    (0..6)
        .filter(|&k| eig.eigenvalues[k] < 0.5)
        .map(|k| eig.eigenvectors.column(k).into_owned())
        .collect()
}

fn icp_pass(
    clouds: &IcpClouds,
    initial: RigidTransform,
    options: &IcpOptions,
    frozen: Option<&Frozen>,
) -> Result<IcpPass> {
    let min_cos = (options.max_normal_angle_degrees as f64).to_radians().cos();
    let free = frozen.map(|f| complement(&f.directions));
    let mut r = rotation_matrix(initial.rotation);
    let mut t = v(initial.translation);
    let mut max_d = options.max_distance as f64;
    let mut rms = f64::NAN;
    let mut pairs = 0;
    let mut unconstrained = Vec::new();
    let mut degenerate: Vec<Vector6<f64>> = Vec::new();
    let (mut last_centre, mut last_radius) = (Vector3::zeros(), 1.0);
    let mut converged = false;
    let mut iterations = 0;
    for iteration in 1..=options.max_iterations {
        iterations = iteration;
        let max_d2 = max_d * max_d;
        // Pairs (source index, target index, moved source point).
        let matches: Vec<(usize, usize, Vector3<f64>)> = clouds
            .source
            .iter()
            .enumerate()
            .filter_map(|(i, p)| {
                let moved = r * p + t;
                let nn = clouds
                    .tree
                    .nearest_one::<SquaredEuclidean>(&[moved.x, moved.y, moved.z]);
                let j = nn.item as usize;
                let (ns, nt) = (r * clouds.source_normals[i], clouds.target_normals[j]);
                let normals_agree = ns.dot(&nt).abs() >= min_cos;
                (nn.distance <= max_d2 && normals_agree).then_some((i, j, moved))
            })
            .collect();
        pairs = matches.len();
        if pairs < 6 {
            return Err(Error::Invalid(format!(
                "ICP found only {pairs} point pairs within {max_d:.2} m with matching surface normals: \
                 the scans do not overlap under the initial transform (give a closer start, e.g. --pairs)"
            )));
        }
        let scale = (max_d / 2.0).max(options.robust_scale as f64);
        // The motion is p -> p + w x (p - c) + u about a centre c, written
        // x = (radius * w, u). A second pass keeps the first pass's centre
        // and radius, so that its frozen directions mean the same motions.
        let (centre, radius) = match frozen {
            Some(f) => (f.centre, f.radius),
            None => {
                let c = matches.iter().map(|m| m.2).sum::<Vector3<f64>>() / pairs as f64;
                let radius = (matches
                    .iter()
                    .map(|m| (m.2 - c).norm_squared())
                    .sum::<f64>()
                    / pairs as f64)
                    .sqrt()
                    .max(1e-3);
                (c, radius)
            }
        };
        (last_centre, last_radius) = (centre, radius);
        // Point-to-plane Hessian and gradient (Gauss-Newton, Cauchy weights).
        let mut h = Matrix6::<f64>::zeros();
        let mut g = Vector6::<f64>::zeros();
        let mut residuals = Vec::with_capacity(pairs);
        for &(_, j, p) in &matches {
            let q = Vector3::from(clouds.target[j]);
            let n = clouds.target_normals[j];
            let res = match options.metric {
                IcpMetric::PointToPlane => (p - q).dot(&n),
                IcpMetric::PointToPoint => (p - q).norm(),
            };
            residuals.push(res);
            let weight = 1.0 / (1.0 + (res / scale).powi(2));
            let c = (p - centre).cross(&n) / radius;
            let row = Vector6::new(c.x, c.y, c.z, n.x, n.y, n.z);
            h += row * row.transpose() * weight;
            g -= row * ((p - q).dot(&n)) * weight;
        }
        rms = (residuals.iter().map(|x| x * x).sum::<f64>() / pairs as f64).sqrt();
        // The directions to move along: the free ones (all, or those left by
        // the first pass), restricted to those this Hessian constrains.
        let basis: Vec<Vector6<f64>> = match &free {
            Some(b) => b.clone(),
            None => (0..6).map(|k| Vector6::ith(k, 1.0)).collect(),
        };
        let m = basis.len();
        let b = nalgebra::DMatrix::from_fn(6, m, |i, k| basis[k][i]);
        let hb = b.transpose() * nalgebra::DMatrix::from_iterator(6, 6, h.iter().copied()) * &b;
        let eig = hb.symmetric_eigen();
        let largest = h.symmetric_eigenvalues().max();
        let (mut good, mut weak) = (Vec::new(), Vec::new());
        for k in 0..m {
            let direction: Vector6<f64> =
                Vector6::from_iterator((&b * eig.eigenvectors.column(k)).iter().copied());
            if eig.eigenvalues[k] > options.degeneracy_ratio * largest {
                good.push((direction, eig.eigenvalues[k]));
            } else {
                weak.push(direction);
            }
        }
        unconstrained = weak.iter().map(describe_direction).collect();
        degenerate = weak;
        // The step in scaled coordinates, within the good directions.
        let x: Vector6<f64> = match options.metric {
            IcpMetric::PointToPlane => good
                .iter()
                .map(|(d, lambda)| d * (d.dot(&g) / lambda))
                .sum(),
            IcpMetric::PointToPoint => {
                let a: Vec<Vec3> = matches.iter().map(|m| to_vec3(m.2)).collect();
                let b: Vec<Vec3> = matches
                    .iter()
                    .map(|m| to_vec3(Vector3::from(clouds.target[m.1])))
                    .collect();
                let w: Vec<f64> = residuals
                    .iter()
                    .map(|res| 1.0 / (1.0 + (res / scale).powi(2)))
                    .collect();
                let al = fit_rigid(&a, &b, Some(&w))?;
                let dr = rotation_matrix(al.transform.rotation);
                let dt = v(al.transform.translation);
                // As a motion about the centre: p -> dr (p - c) + c + u.
                let u = dr * centre + dt - centre;
                let w = Rotation3::from_matrix_unchecked(dr).scaled_axis() * radius;
                let full = Vector6::new(w.x, w.y, w.z, u.x, u.y, u.z);
                good.iter().map(|(d, _)| d * d.dot(&full)).sum()
            }
        };
        let w = Vector3::new(x[0], x[1], x[2]) / radius;
        let u = Vector3::new(x[3], x[4], x[5]);
        let dr = Rotation3::from_scaled_axis(w).into_inner();
        r = dr * r;
        t = dr * (t - centre) + centre + u;
        let annealed = max_d <= options.min_distance as f64;
        max_d = (max_d * options.distance_decay as f64).max(options.min_distance as f64);
        if annealed && w.norm() + u.norm() < options.tolerance {
            converged = true;
            break;
        }
    }
    Ok(IcpPass {
        result: IcpResult {
            transform: to_transform(&r, &t),
            rms,
            pairs,
            iterations,
            converged,
            unconstrained,
        },
        frozen: Frozen {
            centre: last_centre,
            radius: last_radius,
            directions: degenerate,
        },
    })
}

fn to_vec3(p: Vector3<f64>) -> Vec3 {
    Vec3::new(p.x as f32, p.y as f32, p.z as f32)
}

/// Point pairs picked by hand in two scans, one pair per line:
/// `x_a y_a z_a x_b y_b z_b` (metres; the same point in scan A's frame and in
/// scan B's), separated by spaces, tabs or commas. Blank lines and lines
/// starting with `#` are skipped.
pub fn read_point_pairs(path: &std::path::Path) -> Result<Vec<(Vec3, Vec3)>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let mut pairs = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|f| !f.is_empty())
            .collect();
        let bad = |column: usize, message: String| {
            Error::Parse(mocap_core::ParseError {
                location: mocap_core::error::Location {
                    path: path.to_path_buf(),
                    line: i + 1,
                    column,
                },
                message,
            })
        };
        if fields.len() != 6 {
            return Err(bad(
                1,
                format!(
                    "expected 6 numbers (x y z in scan A, x y z in scan B), found {}",
                    fields.len()
                ),
            ));
        }
        let mut xyz = [0.0f32; 6];
        for (k, f) in fields.iter().enumerate() {
            xyz[k] = f
                .parse::<f32>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    let column = line.find(f).map_or(1, |c| c + 1);
                    bad(column, format!("expected a number, found {f:?}"))
                })?;
        }
        pairs.push((
            Vec3::new(xyz[0], xyz[1], xyz[2]),
            Vec3::new(xyz[3], xyz[4], xyz[5]),
        ));
    }
    Ok(pairs)
}

/// The result of calibrating one scan against another.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointCalibration {
    /// `a_from_b`: takes scan B's points into scan A's frame.
    pub transform: RigidTransform,
    /// The rough start from the point pairs, when given.
    pub pairs_fit: Option<Alignment>,
    pub icp: IcpResult,
}

/// Calibrates scan `b` against scan `a`: a rough start from hand-picked
/// point pairs (`(point in a, point in b)`, at least 3 spanning a plane) or
/// from `initial` (an `a_from_b` transform, for example from the body), then
/// ICP.
pub fn calibrate_from_points(
    a: &[Vec3],
    b: &[Vec3],
    pairs: &[(Vec3, Vec3)],
    initial: Option<RigidTransform>,
    options: &IcpOptions,
) -> Result<PointCalibration> {
    let pairs_fit = if pairs.is_empty() {
        None
    } else {
        let (in_a, in_b): (Vec<Vec3>, Vec<Vec3>) = pairs.iter().copied().unzip();
        Some(fit_rigid(&in_b, &in_a, None)?)
    };
    let start = match (&pairs_fit, initial) {
        (Some(fit), _) => fit.transform,
        (None, Some(t)) => t,
        (None, None) => RigidTransform::IDENTITY,
    };
    let icp = icp(b, a, start, options)?;
    Ok(PointCalibration {
        transform: icp.transform,
        pairs_fit,
        icp,
    })
}

/// Options of calibration from the body.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BodyCalibrationOptions {
    /// The sensor whose camera frame is the world; the lowest id when `None`.
    pub reference: Option<u16>,
    /// Pairs farther apart than this after alignment are outliers (m).
    pub inlier_distance: f32,
    pub ransac_iterations: usize,
    pub seed: u64,
    /// Rounds of refinement against the fused skeleton of the other sensors
    /// (see [`calibrate_from_body`]); 0 keeps the pairwise fit.
    #[serde(default)]
    pub consensus_rounds: usize,
}

impl Default for BodyCalibrationOptions {
    fn default() -> Self {
        BodyCalibrationOptions {
            reference: None,
            inlier_distance: 0.10,
            ransac_iterations: 400,
            seed: 7,
            consensus_rounds: 2,
        }
    }
}

/// How one sensor was calibrated from the body.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BodySensorReport {
    pub sensor: u16,
    /// Joint pairs (this sensor and the reference, same instant, both
    /// Tracked, labels settled) the fit could use.
    pub pairs: usize,
    /// Pairs within `inlier_distance` of the fitted transform.
    pub inliers: usize,
    /// RMS distance of the inliers (m).
    pub rms: f64,
    /// Frames whose left/right labels were settled (`settle_labels`) in
    /// this sensor and in the reference, out of the frames paired.
    pub settled_frames: usize,
    pub paired_frames: usize,
    /// Inliers of the best fit with this sensor's labels all mirrored, the
    /// hypothesis kept if it had had more.
    pub mirrored_inliers: usize,
    /// A rough standard error of the fitted turn about the vertical (degrees):
    /// `rms / (spread * sqrt(25))`, with `spread` the RMS horizontal distance
    /// of the inlier joints from their mean. The errors that matter are each
    /// joint's constant bias, repeated in every frame, so only the 25 joints
    /// count as independent, not the frames. A person standing still (a bow)
    /// spreads little and gives several degrees; capture a calibration take
    /// in which the person walks and turns.
    pub yaw_uncertainty_degrees: f64,
    /// Standard deviations of the fitted rotation (degrees) and translation
    /// (metres) when the 25 joints are drawn again with replacement
    /// ([`joint_bootstrap`]): what the joints' own biases leave uncertain.
    /// They, like `yaw_uncertainty_degrees`, describe the fit to the
    /// reference, before the consensus refinement (`refined`).
    pub rotation_uncertainty_degrees: f64,
    pub translation_uncertainty: f64,
    /// Whether the consensus refinement replaced the first fit (`pairs`,
    /// `inliers` and `rms` are then the refit's, as in the calibration file).
    pub refined: bool,
}

/// The result of a calibration from the body, with one report per sensor.
#[derive(Debug, Clone)]
pub struct BodyCalibration {
    pub calibration: Calibration,
    pub reference: u16,
    pub sensors: Vec<BodySensorReport>,
}

/// Settles the left/right labels of one sensor's frames (in time order) in
/// its own camera space.
///
/// A Kinect seeing a person from behind still labels the skeleton as if the
/// person faced it, so its labelled skeleton always seems to face the camera.
/// Where the labelled facing and [`crate::fusion::label_free_forward`]
/// disagree, the labels are swapped. One frame's cues are noisy (a foot in
/// swing points down, a straight knee says nothing), but whether a sensor
/// sees the back changes only as the person turns, so the agreement is
/// summed over the frames within `window` seconds. `None` for frames where
/// the sum does not clearly say (below `margin` of its largest possible
/// value).
pub fn settle_labels(
    frames: &[crate::recording::SensorFrame],
    window: f64,
    margin: f32,
) -> Vec<Option<[JointObservation; JOINT_COUNT]>> {
    let cues: Vec<(f64, f32, f32)> = frames
        .iter()
        .map(|f| {
            let forward = crate::fusion::label_free_forward(&f.joints);
            let labelled = crate::fusion::facing_of(&f.joints.map(|j| j.position));
            (f.timestamp, labelled.dot(forward), forward.length())
        })
        .collect();
    let mut out = Vec::with_capacity(frames.len());
    let (mut lo, mut hi) = (0usize, 0usize);
    let (mut sum, mut size) = (0.0f32, 0.0f32);
    for f in frames {
        let t = f.timestamp;
        while hi < cues.len() && cues[hi].0 <= t + window {
            sum += cues[hi].1;
            size += cues[hi].2;
            hi += 1;
        }
        while cues[lo].0 < t - window {
            sum -= cues[lo].1;
            size -= cues[lo].2;
            lo += 1;
        }
        out.push(if size <= 0.0 || sum.abs() < margin * size {
            None
        } else if sum < 0.0 {
            Some(crate::fusion::swap_left_right(&f.joints))
        } else {
            Some(f.joints)
        });
    }
    out
}

type Joints = [JointObservation; JOINT_COUNT];

/// Joint pairs `(sensor point, reference point)` of frame pairs, with the
/// sensor's labels mirrored when `mirror` says so for that frame.
fn joint_pairs(
    frames: &[(Joints, Joints)],
    mirror: &dyn Fn(usize) -> bool,
) -> (Vec<Vec3>, Vec<Vec3>) {
    let tracked = |a: &JointObservation| a.state == TrackingState::Tracked;
    let mut s = Vec::new();
    let mut t = Vec::new();
    for (fi, (a, b)) in frames.iter().enumerate() {
        for n in 0..JOINT_COUNT {
            let m = if mirror(fi) { MIRROR[n] } else { n };
            if tracked(&a[m]) && tracked(&b[n]) {
                s.push(a[m].position);
                t.push(b[n].position);
            }
        }
    }
    (s, t)
}

/// RANSAC on 3-pair samples, then refits on the inliers until they settle.
/// Returns the transform, the inlier count and their RMS.
fn robust_fit(
    src: &[Vec3],
    dst: &[Vec3],
    options: &BodyCalibrationOptions,
    rng: &mut StdRng,
) -> Option<(RigidTransform, usize, f64)> {
    if src.len() < 3 {
        return None;
    }
    let inlier2 = options.inlier_distance * options.inlier_distance;
    let count = |t: &RigidTransform| {
        src.iter()
            .zip(dst)
            .filter(|(p, q)| t.apply(**p).distance_squared(**q) < inlier2)
            .count()
    };
    let mut best: Option<(usize, RigidTransform)> = None;
    for _ in 0..options.ransac_iterations {
        let idx: Vec<usize> = (0..3).map(|_| rng.random_range(0..src.len())).collect();
        let s3: Vec<Vec3> = idx.iter().map(|&i| src[i]).collect();
        let t3: Vec<Vec3> = idx.iter().map(|&i| dst[i]).collect();
        let Ok(a) = fit_rigid(&s3, &t3, None) else {
            continue;
        };
        let c = count(&a.transform);
        if best.as_ref().is_none_or(|b| c > b.0) {
            best = Some((c, a.transform));
        }
    }
    let (_, mut transform) = best?;
    let mut result = None;
    for _ in 0..8 {
        let (si, ti): (Vec<Vec3>, Vec<Vec3>) = src
            .iter()
            .zip(dst)
            .filter(|(p, q)| transform.apply(**p).distance_squared(**q) < inlier2)
            .map(|(p, q)| (*p, *q))
            .unzip();
        let Ok(a) = fit_rigid(&si, &ti, None) else {
            break;
        };
        transform = a.transform;
        result = Some((transform, si.len(), a.rms));
    }
    result.map(|(t, _, rms)| (t, count(&t), rms))
}

/// Calibrates every sensor against the reference sensor from the person
/// both see: at each frame of a sensor, its Tracked joints are paired with
/// the reference sensor's Tracked joints at the same instant (interpolated),
/// and a rigid transform is fitted robustly (RANSAC on 3-pair samples, then
/// refits on the inliers).
///
/// The trap is the left/right swap of a sensor that sees the person's back:
/// pairing its labelled left hand with the reference's left hand pairs two
/// different hands, and since a body is nearly mirror-symmetric, the fit
/// finds the sensor turned by about 180 degrees, with many inliers. So the
/// labels are first settled frame by frame in each sensor's own view, by
/// the feet and knees (`settle_labels`); only frames settled in both sensors
/// are paired. As a check, the fit is also made with this sensor's labels
/// all mirrored, and the hypothesis with more inliers is kept (reported in
/// [`BodySensorReport::mirrored_inliers`]).
pub fn calibrate_from_body(
    streams: &SensorStreams,
    options: &BodyCalibrationOptions,
) -> Result<BodyCalibration> {
    // Cues summed over half a second on either side; a sum below a third of
    // its largest value says nothing reliable about the labels.
    const WINDOW: f64 = 0.5;
    const MARGIN: f32 = 0.3;
    let reference = match options.reference {
        Some(r) => r,
        None => *streams
            .streams
            .keys()
            .next()
            .ok_or_else(|| Error::Invalid("no sensor frames to calibrate from".into()))?,
    };
    let ref_frames = streams
        .streams
        .get(&reference)
        .ok_or_else(|| Error::Invalid(format!("the reference sensor {reference} has no frames")))?;
    // The reference's frames with settled labels only (unsettled frames are
    // dropped, so interpolation never mixes two labellings).
    let settled_reference: Vec<crate::recording::SensorFrame> = ref_frames
        .iter()
        .zip(settle_labels(ref_frames, WINDOW, MARGIN))
        .filter_map(|(f, joints)| {
            joints.map(|joints| crate::recording::SensorFrame {
                joints,
                ..f.clone()
            })
        })
        .collect();
    let mut calibration = Calibration::default();
    calibration.set(SensorPose {
        id: reference,
        transform: RigidTransform::IDENTITY,
        method: Some("body (reference)".into()),
        rms_residual: Some(0.0),
        pairs: None,
    });
    let mut reports = Vec::new();
    let mut rng = StdRng::seed_from_u64(options.seed);
    for (&sensor, frames) in &streams.streams {
        if sensor == reference {
            continue;
        }
        // Pairs are made on the reference's clock, at its own frame rate.
        let period = crate::offline::frame_period(ref_frames);
        let mut paired_frames = 0;
        let mut settled: Vec<(Joints, Joints)> = Vec::new();
        let mut as_labelled: Vec<(Joints, Joints)> = Vec::new();
        for (f, own) in frames.iter().zip(settle_labels(frames, WINDOW, MARGIN)) {
            let Some(reference_joints) = sample_stream(ref_frames, f.timestamp, period) else {
                continue;
            };
            paired_frames += 1;
            as_labelled.push((f.joints, reference_joints));
            let (Some(a), Some(b)) = (own, sample_stream(&settled_reference, f.timestamp, period))
            else {
                continue;
            };
            settled.push((a, b));
        }
        // Too few frames where both could tell left from right (a person
        // standing still, seen from the side with one foot hidden): fall back
        // to the labels as reported, and let the two global hypotheses (as
        // labelled, all mirrored) decide below.
        let settled_frames = settled.len();
        if joint_pairs(&settled, &|_| false).0.len() < 30 {
            settled = as_labelled;
        }
        let (src, dst) = joint_pairs(&settled, &|_| false);
        if src.len() < 30 {
            return Err(Error::Invalid(format!(
                "sensor {sensor} and reference sensor {reference} share only {} tracked joint \
                 observations: calibration from the body needs both to see the whole person at \
                 the same time ({paired_frames} frames at the same instants)",
                src.len()
            )));
        }
        let fit = robust_fit(&src, &dst, options, &mut rng);
        let (msrc, mdst) = joint_pairs(&settled, &|_| true);
        let mirrored = robust_fit(&msrc, &mdst, options, &mut rng);
        let mirrored_inliers = mirrored.as_ref().map_or(0, |m| m.1);
        let (best, mirrored_won) = match (fit, mirrored) {
            (Some(f), Some(m)) if m.1 > f.1 => ((m, msrc.len()), true),
            (Some(f), _) => ((f, src.len()), false),
            (None, Some(m)) => ((m, msrc.len()), true),
            (None, None) => {
                return Err(Error::Invalid(format!(
                "sensor {sensor}: no consistent transform found (the joints seen are degenerate)"
            )))
            }
        };
        let ((transform, inliers, rms), pairs) = best;
        let (rotation_uncertainty_degrees, translation_uncertainty) = joint_bootstrap(
            &settled,
            mirrored_won,
            &transform,
            options.inlier_distance,
            // Its own draws: a figure of the report must not change the
            // RANSAC draws of the sensors after this one.
            &mut StdRng::seed_from_u64(options.seed ^ (u64::from(sensor) << 32)),
        );
        let yaw_uncertainty_degrees = {
            let inlier2 = options.inlier_distance * options.inlier_distance;
            let kept: Vec<Vec3> = src
                .iter()
                .zip(&dst)
                .filter(|(p, q)| transform.apply(**p).distance_squared(**q) < inlier2)
                .map(|(_, q)| *q)
                .collect();
            let n = kept.len().max(1) as f32;
            let mean = kept.iter().copied().sum::<Vec3>() / n;
            let spread = (kept
                .iter()
                .map(|q| (*q - mean).with_y(0.0).length_squared())
                .sum::<f32>()
                / n)
                .sqrt() as f64;
            (rms / (spread.max(1e-3) * (JOINT_COUNT as f64).sqrt())).to_degrees()
        };
        calibration.set(SensorPose {
            id: sensor,
            transform,
            method: Some("body".into()),
            rms_residual: Some(rms),
            pairs: Some(inliers),
        });
        reports.push(BodySensorReport {
            sensor,
            pairs,
            inliers,
            rms,
            settled_frames,
            paired_frames,
            mirrored_inliers,
            yaw_uncertainty_degrees,
            rotation_uncertainty_degrees,
            translation_uncertainty,
            refined: false,
        });
    }
    for _ in 0..options.consensus_rounds {
        for (sensor, pairs, inliers, rms) in
            refine_by_consensus(streams, &mut calibration, reference, options, &mut rng)
        {
            // The report says what the calibration file holds.
            if let Some(r) = reports.iter_mut().find(|r| r.sensor == sensor) {
                (r.pairs, r.inliers, r.rms, r.refined) = (pairs, inliers, rms, true);
            }
        }
    }
    Ok(BodyCalibration {
        calibration,
        reference,
        sensors: reports,
    })
}

/// One round of refinement: each sensor but the reference is fitted again,
/// this time to the fused skeleton of all the other sensors (with the best
/// fusion, left/right repaired) instead of to the reference alone. The
/// consensus of several sensors has smaller joint biases than one sensor,
/// and frames the reference could not settle still count. Each frame of the
/// sensor takes the labelling (as reported or mirrored) closer to the
/// consensus under the current transform. The pose is kept when the refit
/// has fewer inliers than the current one.
/// Returns, for each sensor whose refit was kept, its pairs, inliers and RMS.
fn refine_by_consensus(
    streams: &SensorStreams,
    calibration: &mut Calibration,
    reference: u16,
    options: &BodyCalibrationOptions,
    rng: &mut StdRng,
) -> Vec<(u16, usize, usize, f64)> {
    let mut kept = Vec::new();
    let body = crate::body::BodyModel::measure(
        streams
            .streams
            .values()
            .flat_map(|s| s.iter().map(|f| &f.joints)),
        crate::body::MeasureOptions::default(),
    );
    let inlier2 = options.inlier_distance * options.inlier_distance;
    let ids: Vec<u16> = streams.streams.keys().copied().collect();
    for &sensor in ids.iter().filter(|&&s| s != reference) {
        let Some(current) = calibration.get(sensor).copied() else {
            continue;
        };
        let others = SensorStreams {
            streams: streams
                .streams
                .iter()
                .filter(|(id, _)| **id != sensor)
                .map(|(id, f)| (*id, f.clone()))
                .collect(),
        };
        let mut fuser =
            crate::fusion::Fuser::new(crate::fusion::FusionOptions::best(), body.clone());
        let tracked = |a: &JointObservation| a.state == TrackingState::Tracked;
        let (mut src, mut dst) = (Vec::new(), Vec::new());
        // The others are sampled at this sensor's instants, at its rate.
        let period = crate::offline::frame_period(&streams.streams[&sensor]);
        for f in &streams.streams[&sensor] {
            let views = crate::offline::views_at(&others, calibration, f.timestamp, period);
            let Some(fused) = fuser.fuse(f.timestamp, &views) else {
                continue;
            };
            let cost = |mirror: bool| -> f32 {
                (0..JOINT_COUNT)
                    .filter_map(|n| {
                        let m = if mirror { MIRROR[n] } else { n };
                        (tracked(&f.joints[m]) && fused.confidence[n] > 0.0).then(|| {
                            current
                                .apply(f.joints[m].position)
                                .distance(fused.joints[n])
                                .min(0.5)
                        })
                    })
                    .sum()
            };
            let mirror = cost(true) < cost(false);
            for (n, &mirrored) in MIRROR.iter().enumerate() {
                let m = if mirror { mirrored } else { n };
                if tracked(&f.joints[m]) && fused.confidence[n] > 0.0 {
                    src.push(f.joints[m].position);
                    dst.push(fused.joints[n]);
                }
            }
        }
        let inliers_now = src
            .iter()
            .zip(&dst)
            .filter(|(p, q)| current.apply(**p).distance_squared(**q) < inlier2)
            .count();
        if let Some((transform, inliers, rms)) = robust_fit(&src, &dst, options, rng) {
            if inliers >= inliers_now {
                calibration.set(SensorPose {
                    id: sensor,
                    transform,
                    method: Some("body (refined on the fused skeleton)".into()),
                    rms_residual: Some(rms),
                    pairs: Some(inliers),
                });
                kept.push((sensor, src.len(), inliers, rms));
            }
        }
    }
    kept
}

/// Standard deviations of a body calibration's rotation (degrees) and
/// translation (metres) by a bootstrap over joints: 50 times, 25 joints are
/// drawn with replacement and the transform refitted (Kabsch, on the pairs
/// of the drawn joints that are inliers of `transform`, over every frame).
/// Joints, not frames, are the independent samples: a sensor's error at a
/// joint is mostly a bias that repeats in every frame (see
/// [`BodySensorReport::yaw_uncertainty_degrees`]); resampling frames would
/// call a calibration sure that a second take moves by centimetres.
fn joint_bootstrap(
    frames: &[(Joints, Joints)],
    mirrored: bool,
    transform: &RigidTransform,
    inlier_distance: f32,
    rng: &mut StdRng,
) -> (f64, f64) {
    const ROUNDS: usize = 50;
    let inlier2 = inlier_distance * inlier_distance;
    let tracked = |a: &JointObservation| a.state == TrackingState::Tracked;
    // Each joint's inlier pairs over the frames.
    let by_joint: Vec<(Vec<Vec3>, Vec<Vec3>)> = (0..JOINT_COUNT)
        .map(|n| {
            let m = if mirrored { MIRROR[n] } else { n };
            frames
                .iter()
                .filter(|(a, b)| tracked(&a[m]) && tracked(&b[n]))
                .map(|(a, b)| (a[m].position, b[n].position))
                .filter(|(p, q)| transform.apply(*p).distance_squared(*q) < inlier2)
                .unzip()
        })
        .collect();
    let (mut angle2, mut shift2, mut rounds) = (0.0f64, 0.0f64, 0usize);
    for _ in 0..ROUNDS {
        let (mut src, mut dst) = (Vec::new(), Vec::new());
        for _ in 0..JOINT_COUNT {
            let (s, d) = &by_joint[rng.random_range(0..JOINT_COUNT)];
            src.extend_from_slice(s);
            dst.extend_from_slice(d);
        }
        let Ok(fit) = fit_rigid(&src, &dst, None) else {
            continue;
        };
        let turn = fit.transform.rotation * transform.rotation.inverse();
        // The shorter way round (q and -q are one rotation).
        let angle = 2.0 * (turn.normalize().w.abs().min(1.0) as f64).acos();
        angle2 += angle.to_degrees().powi(2);
        shift2 += (fit.transform.translation - transform.translation).length_squared() as f64;
        rounds += 1;
    }
    if rounds == 0 {
        return (f64::NAN, f64::NAN);
    }
    (
        (angle2 / rounds as f64).sqrt(),
        (shift2 / rounds as f64).sqrt(),
    )
}

/// What `mocap fuse calibrate` reports of a calibration from the body.
#[derive(Debug, Clone, Serialize)]
pub struct BodyCalibrationReport {
    /// The calibration file written.
    pub calibration: PathBuf,
    /// The sensor whose camera frame is the world.
    pub reference: u16,
    pub sensors: Vec<BodySensorReport>,
    /// Whether every sensor's body is the same person once calibrated
    /// ([`crate::check_same_person`]).
    pub same_person: crate::offline::SamePersonReport,
}

impl BodyCalibrationReport {
    /// Share of a sensor's joint pairs that fit below which the calibration
    /// is suspect: the sensor may follow another person, or see the person
    /// from a side the reference never sees.
    pub const LOW_INLIER_SHARE: f64 = 0.5;

    /// Warnings for the user: sensors whose body is another person, sensors
    /// few of whose joint pairs fit.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = self.same_person.notes();
        for s in &self.sensors {
            let share = s.inliers as f64 / s.pairs.max(1) as f64;
            if share < Self::LOW_INLIER_SHARE {
                out.push(format!(
                    "sensor {}: only {:.0}% of its joint pairs fit the reference's: it may follow \
                     another person (check the bodies kept) or see a side the reference never sees",
                    s.sensor,
                    100.0 * share
                ));
            }
        }
        out
    }

    /// Degrees of doubt about a sensor's turn about the vertical beyond which
    /// the person moved too little for a sure calibration.
    pub const UNSURE_DEGREES: f64 = 5.0;

    /// Whether some sensor's turn is known only to more than
    /// [`Self::UNSURE_DEGREES`].
    pub fn is_unsure(&self) -> bool {
        self.sensors
            .iter()
            .any(|s| s.yaw_uncertainty_degrees > Self::UNSURE_DEGREES)
    }
}

/// `mocap fuse calibrate REC...`: calibrates the sensors of the recordings
/// from the person all of them see ([`calibrate_from_body`]) and writes the
/// calibration to `output`.
pub fn calibrate_recordings(
    recordings: &[PathBuf],
    options: &BodyCalibrationOptions,
    output: &Path,
) -> Result<BodyCalibrationReport> {
    let reading = crate::recording::ReadOptions::default();
    Ok(calibrate_recordings_with(recordings, &reading, options, output)?.0)
}

/// [`calibrate_recordings`], the recordings read as `reading` says (the
/// input frame rate of NTU files, time offsets:
/// [`crate::read_recordings_with`]); also returns how they were read.
pub fn calibrate_recordings_with(
    recordings: &[PathBuf],
    reading: &crate::recording::ReadOptions,
    options: &BodyCalibrationOptions,
    output: &Path,
) -> Result<(BodyCalibrationReport, crate::recording::RecordingsReport)> {
    let read = crate::recording::read_recordings_with(recordings, reading)?;
    let streams = SensorStreams::new(read.frames);
    let found = calibrate_from_body(&streams, options)?;
    found.calibration.write(output)?;
    let same_person =
        crate::offline::check_same_person(&streams, &found.calibration, 1.0 / reading.input_fps);
    let report = BodyCalibrationReport {
        calibration: output.to_path_buf(),
        reference: found.reference,
        sensors: found.sensors,
        same_person,
    };
    Ok((report, read.report))
}

/// Two room scans to calibrate one against the other
/// ([`calibrate_scans`]).
#[derive(Debug, Clone, Default)]
pub struct ScanPair {
    /// The reference's scan and the scan of the sensor to place (PLY, camera
    /// space, metres).
    pub scans: [PathBuf; 2],
    /// Point pairs picked in both scans ([`read_point_pairs`]) for the rough
    /// start.
    pub pairs: Option<PathBuf>,
    /// A calibration holding both sensors (for example from the body) for
    /// the rough start.
    pub initial: Option<PathBuf>,
    /// The sensor ids of the two scans; by default the last number in each
    /// file name (`sensor-2.ply` is 2).
    pub ids: Option<[u16; 2]>,
}

/// The result of [`calibrate_scans`].
#[derive(Debug, Clone)]
pub struct ScanCalibration {
    /// The reference's id and the id of the sensor placed.
    pub ids: [u16; 2],
    /// ICP started from the identity (neither point pairs nor an initial
    /// calibration): it works only for scans taken from nearly the same
    /// place.
    pub from_identity: bool,
    pub fit: PointCalibration,
}

/// The sensor id in a file name: its last number (`sensor-2.ply` is 2).
fn id_in_name(path: &Path) -> Option<u16> {
    let stem = path.file_stem()?.to_str()?;
    let digits: String = stem
        .chars()
        .rev()
        .skip_while(|c| !c.is_ascii_digit())
        .take_while(|c| c.is_ascii_digit())
        .collect();
    digits.chars().rev().collect::<String>().parse().ok()
}

/// `mocap fuse calibrate --points A.ply B.ply`: places the second scan's
/// sensor in the world of the calibration file `output`
/// ([`calibrate_from_points`]). An existing `output` is updated; a new one
/// takes the first scan's sensor as the world.
pub fn calibrate_scans(scans: &ScanPair, output: &Path) -> Result<ScanCalibration> {
    let [a_path, b_path] = &scans.scans;
    let (a_id, b_id) = match scans.ids {
        Some([a, b]) => (a, b),
        None => match (id_in_name(a_path), id_in_name(b_path)) {
            (Some(a), Some(b)) => (a, b),
            _ => {
                return Err(Error::Invalid(format!(
                    "cannot tell the sensor ids from the names {} and {}: give --ids A B",
                    a_path.display(),
                    b_path.display()
                )))
            }
        },
    };
    if a_id == b_id {
        return Err(Error::Invalid(format!(
            "both scans are of sensor {a_id}: give --ids A B"
        )));
    }
    let a = crate::ply::read_ply_points(a_path)?;
    let b = crate::ply::read_ply_points(b_path)?;
    let pairs = match &scans.pairs {
        Some(p) => read_point_pairs(p)?,
        None => Vec::new(),
    };
    let initial = match &scans.initial {
        Some(path) => {
            let c = Calibration::read(path)?;
            let (Some(wa), Some(wb)) = (c.get(a_id), c.get(b_id)) else {
                return Err(Error::Invalid(format!(
                    "{}: --initial must hold both sensor {a_id} and sensor {b_id}",
                    path.display()
                )));
            };
            Some(wa.inverse().then_after(wb))
        }
        None => None,
    };
    let from_identity = pairs.is_empty() && initial.is_none();
    let fit = calibrate_from_points(&a, &b, &pairs, initial, &Default::default())?;
    // Place B in the world of the output file (A's pose there, or A as the
    // world when the file is new).
    let mut calibration = if output.exists() {
        Calibration::read(output)?
    } else {
        Calibration::default()
    };
    let world_from_a = match calibration.get(a_id) {
        Some(t) => *t,
        None => {
            calibration.set(SensorPose {
                id: a_id,
                transform: RigidTransform::IDENTITY,
                method: Some("reference".into()),
                rms_residual: None,
                pairs: None,
            });
            RigidTransform::IDENTITY
        }
    };
    calibration.set(SensorPose {
        id: b_id,
        transform: world_from_a.then_after(&fit.transform),
        method: Some("icp".into()),
        rms_residual: Some(fit.icp.rms),
        pairs: Some(fit.icp.pairs),
    });
    calibration.write(output)?;
    Ok(ScanCalibration {
        ids: [a_id, b_id],
        from_identity,
        fit,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn transform() -> RigidTransform {
        RigidTransform {
            rotation: Quat::from_euler(glam::EulerRot::YXZ, 1.1, 0.2, -0.3),
            translation: Vec3::new(0.5, -1.0, 2.0),
        }
    }

    #[test]
    fn kabsch_recovers_a_transform() {
        let src = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.3, 0.2, 1.0),
        ];
        let t = transform();
        let dst: Vec<Vec3> = src.iter().map(|&p| t.apply(p)).collect();
        let a = fit_rigid(&src, &dst, None).unwrap();
        assert!(a.rms < 1e-5);
        assert!(a.transform.rotation.angle_between(t.rotation) < 1e-4);
    }

    #[test]
    fn planar_points_give_a_rotation_not_a_reflection() {
        // Three points: the SVD may give a reflection; the result must not.
        let src = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let t = transform();
        let dst: Vec<Vec3> = src.iter().map(|&p| t.apply(p)).collect();
        let a = fit_rigid(&src, &dst, None).unwrap();
        let m = mocap_core::rotation::Mat3::from_quat(a.transform.rotation);
        assert!((m.determinant() - 1.0).abs() < 1e-4);
        assert!(a.rms < 1e-5);
        // A mirrored target: the best rotation leaves a residual.
        let mirrored: Vec<Vec3> = src
            .iter()
            .map(|p| Vec3::new(-p.x, p.y, p.z + 0.5 * p.x * p.y))
            .collect();
        let m = fit_rigid(
            &[src.clone(), vec![Vec3::new(1.0, 1.0, 1.0)]].concat(),
            &[mirrored, vec![Vec3::new(-1.0, 1.0, 1.0)]].concat(),
            None,
        )
        .unwrap();
        let det = mocap_core::rotation::Mat3::from_quat(m.transform.rotation).determinant();
        assert!((det - 1.0).abs() < 1e-4);
    }

    #[test]
    fn collinear_points_are_refused() {
        let src: Vec<Vec3> = (0..5)
            .map(|i| Vec3::new(i as f32, 2.0 * i as f32, 0.0))
            .collect();
        let err = fit_rigid(&src, &src, None).unwrap_err().to_string();
        assert!(err.contains("collinear"), "{err}");
        assert!(fit_rigid(&src[..2], &src[..2], None).is_err());
    }

    fn looking_at(eye: Vec3, target: Vec3) -> RigidTransform {
        let forward = (target - eye).normalize();
        let x = Vec3::Y.cross(forward).normalize();
        let y = forward.cross(x);
        RigidTransform {
            rotation: Quat::from_mat3(&mocap_core::rotation::Mat3::from_cols(x, y, forward)),
            translation: eye,
        }
    }

    /// `truth` (a `target_from_source` transform) made rough: tilted by
    /// `tilt` about x and z, turned by `yaw` about y, moved by `shift`.
    fn rough(truth: RigidTransform, tilt: f32, yaw: f32, shift: Vec3) -> RigidTransform {
        RigidTransform {
            rotation: (Quat::from_rotation_y(yaw)
                * Quat::from_rotation_x(tilt)
                * Quat::from_rotation_z(-tilt)
                * truth.rotation)
                .normalize(),
            translation: truth.translation + shift,
        }
    }

    #[test]
    fn icp_aligns_two_scans_of_the_room_from_a_rough_start() {
        // Two sensors 1.2 m apart both looking into the room: their scans
        // share walls, the floor and furniture. Start 3 degrees and 15 cm off
        // (what hand-picked point pairs or the body calibration give).
        let room = crate::sim::room_points(0.06, 1);
        let model = crate::sim::SensorModel::default();
        for seed in 1..=3u64 {
            let angle = seed as f32;
            let eye = Vec3::new(2.8 * angle.cos(), 1.0, 2.8 * angle.sin());
            let side = Vec3::new(-angle.sin(), 0.0, angle.cos()) * 1.2;
            let a = looking_at(eye, Vec3::new(0.0, 1.0, 0.0));
            let b = looking_at(eye + side, Vec3::new(0.3, 1.0, 0.2));
            let cloud_a = crate::sim::sensor_point_cloud(&room, &a, &model, seed);
            let cloud_b = crate::sim::sensor_point_cloud(&room, &b, &model, seed + 100);
            let truth = a.inverse().then_after(&b);
            let start = rough(truth, 0.05, 0.05, Vec3::new(0.075, 0.15, -0.075));
            let r = icp(&cloud_b, &cloud_a, start, &IcpOptions::default()).unwrap();
            let err = (r.transform.translation - truth.translation).length();
            let angle = r
                .transform
                .rotation
                .angle_between(truth.rotation)
                .to_degrees();
            assert!(err < 0.03, "seed {seed}: {err} m {r:?}");
            assert!(angle < 0.5, "seed {seed}: {angle} degrees");
            assert!(r.unconstrained.is_empty(), "{:?}", r.unconstrained);
        }
    }

    #[test]
    fn icp_on_scans_that_share_only_the_floor_fixes_height_and_tilt_and_does_not_drift() {
        // Sensors around the person look inwards: two of them see little of
        // the same room but the floor. Height and tilt must come out right;
        // sliding and turning on the floor are not determined, must be
        // reported, and must stay where the start put them (plain ICP
        // wandered off by a metre here).
        let room = crate::sim::room_points(0.06, 1);
        let model = crate::sim::SensorModel::default();
        let still = crate::kinect::GroundTruth {
            fps: 30.0,
            frames: vec![[Vec3::new(0.0, 1.0, 0.0); JOINT_COUNT]; 2],
        };
        for seed in 1..=2u64 {
            let sim = crate::sim::simulate(
                &still,
                &crate::sim::SimulationOptions {
                    sensors: 3,
                    seed,
                    ..Default::default()
                },
            );
            let (a, b) = (sim.sensors[0].pose, sim.sensors[1].pose);
            let cloud_a = crate::sim::sensor_point_cloud(&room, &a, &model, seed);
            let cloud_b = crate::sim::sensor_point_cloud(&room, &b, &model, seed + 100);
            let truth = a.inverse().then_after(&b);
            let start = rough(truth, 0.035, 0.01, Vec3::new(0.04, 0.08, -0.04));
            let r = icp(&cloud_b, &cloud_a, start, &IcpOptions::default()).unwrap();
            // In the world: where b is and where its up axis points.
            let found = a.then_after(&r.transform);
            let height = (found.translation.y - b.translation.y).abs();
            let tilt = (found.rotation * Vec3::Y)
                .angle_between(b.rotation * Vec3::Y)
                .to_degrees();
            assert!(height < 0.005, "seed {seed}: height off by {height} m");
            assert!(tilt < 0.1, "seed {seed}: tilted by {tilt} degrees");
            // How far the scan's points are from their true place along the
            // floor (mean over the points, a's frame is level).
            let slide = |t: &RigidTransform| {
                cloud_b
                    .iter()
                    .map(|&p| (t.apply(p) - truth.apply(p)).with_y(0.0).length())
                    .sum::<f32>()
                    / cloud_b.len() as f32
            };
            let (found, began) = (r.transform, start);
            assert!(
                slide(&found) < slide(&began) + 0.02,
                "seed {seed}: slid from {} to {} m",
                slide(&began),
                slide(&found)
            );
            assert!(
                r.unconstrained.len() >= 2,
                "seed {seed}: {:?}",
                r.unconstrained
            );
        }
    }
}
