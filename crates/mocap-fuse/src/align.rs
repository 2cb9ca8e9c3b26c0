//! Estimating rigid transforms: from point pairs (Kabsch/Umeyama), between
//! point clouds (ICP), and from the body itself seen by two sensors.

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
    /// Pairs farther apart than this (m) are not used.
    pub max_distance: f32,
    /// Stop when the transform changes by less than this (m or rad).
    pub tolerance: f64,
    /// Neighbours for the target normals (point-to-plane).
    pub normal_neighbours: usize,
}

impl Default for IcpOptions {
    fn default() -> Self {
        IcpOptions {
            metric: IcpMetric::PointToPlane,
            max_iterations: 60,
            max_distance: 0.25,
            tolerance: 1e-6,
            normal_neighbours: 12,
        }
    }
}

/// The result of ICP.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IcpResult {
    pub transform: RigidTransform,
    /// RMS distance of the pairs used in the last iteration (m).
    pub rms: f64,
    pub pairs: usize,
    pub iterations: usize,
    pub converged: bool,
}

/// Iterative closest point: refines `initial` (taking `source` into the
/// frame of `target`). Nearest neighbours come from a k-d tree (`kiddo`).
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
    let target_points: Vec<[f64; 3]> = target
        .iter()
        .map(|p| [p.x as f64, p.y as f64, p.z as f64])
        .collect();
    let tree: ImmutableKdTree<f64, u64, 3, 32> = ImmutableKdTree::new_from_slice(&target_points);
    let normals: Vec<Vector3<f64>> = if options.metric == IcpMetric::PointToPlane {
        target_points
            .iter()
            .map(|q| {
                let nn = tree.nearest_n::<SquaredEuclidean>(
                    q,
                    std::num::NonZero::new(options.normal_neighbours).unwrap(),
                );
                let pts: Vec<Vector3<f64>> = nn
                    .iter()
                    .map(|n| Vector3::from(target_points[n.item as usize]))
                    .collect();
                let mean = pts.iter().sum::<Vector3<f64>>() / pts.len() as f64;
                let cov = pts.iter().fold(Matrix3::zeros(), |c, p| {
                    c + (p - mean) * (p - mean).transpose()
                });
                let eig = cov.symmetric_eigen();
                let i = eig.eigenvalues.imin();
                eig.eigenvectors.column(i).into_owned()
            })
            .collect()
    } else {
        Vec::new()
    };
    let mut r = {
        let q = initial.rotation;
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            q.w as f64, q.x as f64, q.y as f64, q.z as f64,
        ))
        .to_rotation_matrix()
        .into_inner()
    };
    let mut t = v(initial.translation);
    let max_d2 = (options.max_distance as f64).powi(2);
    let src: Vec<Vector3<f64>> = source.iter().map(|&p| v(p)).collect();
    let mut rms = f64::NAN;
    let mut pairs = 0;
    for iteration in 1..=options.max_iterations {
        let moved: Vec<Vector3<f64>> = src.iter().map(|p| r * p + t).collect();
        let matches: Vec<(usize, usize)> = moved
            .iter()
            .enumerate()
            .filter_map(|(i, p)| {
                let nn = tree.nearest_one::<SquaredEuclidean>(&[p.x, p.y, p.z]);
                (nn.distance <= max_d2).then_some((i, nn.item as usize))
            })
            .collect();
        pairs = matches.len();
        if pairs < 6 {
            return Err(Error::Invalid(format!(
                "ICP found only {pairs} point pairs within {} m: the clouds do not overlap under the initial transform",
                options.max_distance
            )));
        }
        let (dr, dt) = match options.metric {
            IcpMetric::PointToPoint => {
                let a: Vec<Vec3> = matches.iter().map(|&(i, _)| to_vec3(moved[i])).collect();
                let b: Vec<Vec3> = matches
                    .iter()
                    .map(|&(_, j)| to_vec3(Vector3::from(target_points[j])))
                    .collect();
                let al = fit_rigid(&a, &b, None)?;
                let q = al.transform.rotation;
                let rr = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
                    q.w as f64, q.x as f64, q.y as f64, q.z as f64,
                ))
                .to_rotation_matrix()
                .into_inner();
                (rr, v(al.transform.translation))
            }
            IcpMetric::PointToPlane => {
                // Linearised: minimise sum ((p + w x p + u - q) . n)^2 over
                // the small rotation w and translation u.
                let mut ata = Matrix6::<f64>::zeros();
                let mut atb = Vector6::<f64>::zeros();
                for &(i, j) in &matches {
                    let p = moved[i];
                    let q = Vector3::from(target_points[j]);
                    let n = normals[j];
                    let c = p.cross(&n);
                    let row = Vector6::new(c.x, c.y, c.z, n.x, n.y, n.z);
                    let res = (p - q).dot(&n);
                    ata += row * row.transpose();
                    atb -= row * res;
                }
                let x = ata.lu().solve(&atb).unwrap_or_else(Vector6::zeros);
                let w = Vector3::new(x[0], x[1], x[2]);
                let rr = Rotation3::from_scaled_axis(w).into_inner();
                (rr, Vector3::new(x[3], x[4], x[5]))
            }
        };
        r = dr * r;
        t = dr * t + dt;
        let moved_now: Vec<Vector3<f64>> = matches.iter().map(|&(i, _)| r * src[i] + t).collect();
        rms = (matches
            .iter()
            .zip(&moved_now)
            .map(|(&(_, j), p)| (p - Vector3::from(target_points[j])).norm_squared())
            .sum::<f64>()
            / pairs as f64)
            .sqrt();
        let change = (dr - Matrix3::identity()).norm() + dt.norm();
        if change < options.tolerance {
            return Ok(IcpResult {
                transform: to_transform(&r, &t),
                rms,
                pairs,
                iterations: iteration,
                converged: true,
            });
        }
    }
    Ok(IcpResult {
        transform: to_transform(&r, &t),
        rms,
        pairs,
        iterations: options.max_iterations,
        converged: false,
    })
}

fn to_vec3(p: Vector3<f64>) -> Vec3 {
    Vec3::new(p.x as f32, p.y as f32, p.z as f32)
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
}

impl Default for BodyCalibrationOptions {
    fn default() -> Self {
        BodyCalibrationOptions {
            reference: None,
            inlier_distance: 0.10,
            ransac_iterations: 400,
            seed: 7,
        }
    }
}

/// The result of a calibration from the body, with one report per sensor.
#[derive(Debug, Clone)]
pub struct BodyCalibration {
    pub calibration: Calibration,
    pub reference: u16,
    /// Per sensor: joint pairs found, inliers kept, RMS of inliers (m).
    pub sensors: Vec<(u16, usize, usize, f64)>,
}

/// Calibrates every sensor against the reference sensor from the person
/// both see: at each frame of a sensor, its Tracked joints are paired with the
/// reference sensor's Tracked joints at the same instant (interpolated).
/// The fit is robust: RANSAC on 3-pair samples (mislabelled left/right and
/// badly estimated joints are outliers), then refinement that, frame by
/// frame, picks the labelling (as is or left/right swapped, as a sensor that
/// sees the back swaps them) that fits best, and refits on the inliers.
pub fn calibrate_from_body(
    streams: &SensorStreams,
    options: &BodyCalibrationOptions,
) -> Result<BodyCalibration> {
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
    let mut calibration = Calibration::default();
    calibration.set(SensorPose {
        id: reference,
        transform: RigidTransform::IDENTITY,
        method: Some("body (reference)".into()),
        rms_residual: Some(0.0),
        pairs: None,
    });
    let mut reports = vec![(reference, 0, 0, 0.0)];
    let mut rng = StdRng::seed_from_u64(options.seed);
    for (&sensor, frames) in &streams.streams {
        if sensor == reference {
            continue;
        }
        // Per frame: the sensor's joints and the reference's at that instant.
        let mut frame_pairs: Vec<(
            [crate::recording::JointObservation; JOINT_COUNT],
            [crate::recording::JointObservation; JOINT_COUNT],
        )> = Vec::new();
        for f in frames {
            if let Some(r) = sample_stream(ref_frames, f.timestamp, 1.0 / 30.0) {
                frame_pairs.push((f.joints, r));
            }
        }
        let tracked = |a: &crate::recording::JointObservation| a.state == TrackingState::Tracked;
        let all_pairs = |swap: &dyn Fn(usize) -> bool| -> (Vec<Vec3>, Vec<Vec3>) {
            let mut s = Vec::new();
            let mut t = Vec::new();
            for (fi, (a, b)) in frame_pairs.iter().enumerate() {
                for n in 0..JOINT_COUNT {
                    let m = if swap(fi) { MIRROR[n] } else { n };
                    if tracked(&a[m]) && tracked(&b[n]) {
                        s.push(a[m].position);
                        t.push(b[n].position);
                    }
                }
            }
            (s, t)
        };
        let (src, dst) = all_pairs(&|_| false);
        if src.len() < 30 {
            return Err(Error::Invalid(format!(
                "sensor {sensor} and reference sensor {reference} share only {} tracked joint observations; \
                 calibration from the body needs both to see the person at the same time",
                src.len()
            )));
        }
        // Which way the feet point in both sensors, frame by frame: a cue
        // that does not depend on the left/right labels. A body seen from
        // the front by one sensor and from behind by the other fits almost
        // as well turned by 180 degrees with left and right swapped; the feet
        // tell the two apart, so hypotheses that turn the feet backwards are
        // refused.
        let feet = |j: &[crate::recording::JointObservation; JOINT_COUNT]| -> Vec3 {
            use crate::kinect::joint::*;
            [(ANKLE_LEFT, FOOT_LEFT), (ANKLE_RIGHT, FOOT_RIGHT)]
                .iter()
                .filter(|(a, f)| tracked(&j[*a]) && tracked(&j[*f]))
                .map(|(a, f)| j[*f].position - j[*a].position)
                .sum()
        };
        let feet_pairs: Vec<(Vec3, Vec3)> = frame_pairs
            .iter()
            .map(|(a, b)| (feet(a), feet(b)))
            .filter(|(a, b)| *a != Vec3::ZERO && *b != Vec3::ZERO)
            .collect();
        let feet_agree = |t: &RigidTransform| -> bool {
            feet_pairs.is_empty()
                || feet_pairs
                    .iter()
                    .map(|(a, b)| (t.rotation * *a).dot(*b))
                    .sum::<f32>()
                    > 0.0
        };
        // RANSAC.
        let inlier2 = options.inlier_distance * options.inlier_distance;
        let mut best: Option<(usize, RigidTransform)> = None;
        for _ in 0..options.ransac_iterations {
            let idx: Vec<usize> = (0..3).map(|_| rng.random_range(0..src.len())).collect();
            let s3: Vec<Vec3> = idx.iter().map(|&i| src[i]).collect();
            let t3: Vec<Vec3> = idx.iter().map(|&i| dst[i]).collect();
            let Ok(a) = fit_rigid(&s3, &t3, None) else {
                continue;
            };
            let count = src
                .iter()
                .zip(&dst)
                .filter(|(p, q)| a.transform.apply(**p).distance_squared(**q) < inlier2)
                .count();
            if best.as_ref().is_none_or(|b| count > b.0) && feet_agree(&a.transform) {
                best = Some((count, a.transform));
            }
        }
        let Some((_, mut transform)) = best else {
            return Err(Error::Invalid(format!(
                "sensor {sensor}: no consistent transform found (the joints seen are degenerate)"
            )));
        };
        // Refinement with per-frame labelling and inliers.
        let mut last = (0usize, 0usize, f64::NAN);
        for _ in 0..8 {
            let swaps: Vec<bool> = frame_pairs
                .iter()
                .map(|(a, b)| {
                    let cost = |swap: bool| -> f32 {
                        (0..JOINT_COUNT)
                            .filter_map(|n| {
                                let m = if swap { MIRROR[n] } else { n };
                                (tracked(&a[m]) && tracked(&b[n])).then(|| {
                                    transform
                                        .apply(a[m].position)
                                        .distance(b[n].position)
                                        .min(0.5)
                                })
                            })
                            .sum()
                    };
                    cost(true) < cost(false)
                })
                .collect();
            let (s, t) = all_pairs(&|fi| swaps[fi]);
            let (si, ti): (Vec<Vec3>, Vec<Vec3>) = s
                .iter()
                .zip(&t)
                .filter(|(p, q)| transform.apply(**p).distance_squared(**q) < inlier2)
                .map(|(p, q)| (*p, *q))
                .unzip();
            let a = fit_rigid(&si, &ti, None)?;
            transform = a.transform;
            last = (s.len(), si.len(), a.rms);
        }
        calibration.set(SensorPose {
            id: sensor,
            transform,
            method: Some("body".into()),
            rms_residual: Some(last.2),
            pairs: Some(last.1),
        });
        reports.push((sensor, last.0, last.1, last.2));
    }
    Ok(BodyCalibration {
        calibration,
        reference,
        sensors: reports,
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

    #[test]
    fn icp_refines_a_rough_room_alignment_both_metrics() {
        let room: Vec<Vec3> = crate::sim::room_points(0.08, 1)
            .iter()
            .map(|s| s.position)
            .collect();
        let truth = RigidTransform {
            rotation: Quat::from_rotation_y(0.05) * Quat::from_rotation_x(0.02),
            translation: Vec3::new(0.06, -0.03, 0.05),
        };
        let source: Vec<Vec3> = room.iter().map(|&p| truth.inverse().apply(p)).collect();
        for metric in [IcpMetric::PointToPoint, IcpMetric::PointToPlane] {
            let r = icp(
                &source,
                &room,
                RigidTransform::IDENTITY,
                &IcpOptions {
                    metric,
                    max_iterations: 100,
                    ..Default::default()
                },
            )
            .unwrap();
            let err = (r.transform.translation - truth.translation).length();
            assert!(err < 0.01, "{metric:?}: {err} {r:?}");
            assert!(r.transform.rotation.angle_between(truth.rotation) < 0.005);
        }
    }
}
