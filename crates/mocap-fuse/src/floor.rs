//! The floor under a fused take, and the take stood on it.
//!
//! Fused joints live in the calibration's world: the camera frame of one
//! reference sensor when the sensors were calibrated from the body, so a
//! take can sit metres from the origin, tilted by the sensor's pitch. A BVH
//! wants its person upright at the origin, feet on `y = 0`. [`fit_floor`]
//! finds the floor from the feet alone; [`stand_on_floor`] moves the take
//! onto it. All lengths are in metres.
//!
//! # Finding the floor ([`fit_floor`])
//!
//! 1. **A provisional up**, `u0`: the mean over frames of the unit direction
//!    from the feet (the mean of both ankles) to the top of the body
//!    (the mean of head and neck). People stand roughly upright, so `u0` is
//!    the vertical within a few degrees; walking leans it forward.
//! 2. **Contacts**: for each frame and each foot joint kind (`Foot*`,
//!    `Ankle*`), the lower of the left and right joints along `u0` (the
//!    support side; comparing two joints a stride apart is barely affected
//!    by the error of `u0`), kept when its speed (central difference) is at
//!    most the median speed of these lower joints: the planted half of the
//!    support phases, without heel strikes and toe-offs. Speeds are compared
//!    with each other, not with a threshold in m/s, so the frame rate is not
//!    needed.
//! 3. **A least-squares plane** with one normal `n` shared by the two joint
//!    kinds and one offset per kind (the ankle rides a few centimetres above
//!    the foot joint): minimising `sum_i (n . (p_i - c_k(i)))^2` over unit
//!    `n`, with `c_k` the centroid of kind `k`'s contacts, is minimising
//!    `n^T C n` for the pooled scatter matrix
//!    `C = sum_i (p_i - c_k(i)) (p_i - c_k(i))^T`, so `n` is the eigenvector
//!    of `C`'s smallest eigenvalue (Rayleigh quotient); the other two
//!    eigenvectors are the directions the contacts spread along, their
//!    eigenvalues (divided by the count) the variances of that spread.
//! 4. **Robust trimming**: residuals `r_i = n . (p_i - c_k(i))`, scale
//!    `s = 1.4826 median |r|` (at least 5 mm); contacts with `|r| > 2.5 s`
//!    are dropped (a swing foot taken for a planted one, a foot tracked into
//!    the floor) and the plane is fitted again, until nothing changes (at
//!    most [`TRIM_ITERATIONS`] times).
//! 5. **Enough floor?** A plane needs the contacts to cover an area
//!    ([`FloorMethod::Plane`]: both spreads at least [`MIN_SPREAD`] and
//!    the longer one [`MIN_TRAVEL`]). When they lie along a strip (a walk in
//!    a straight line: its width, the few centimetres between the left and
//!    right footprints, cannot be told apart from a left/right bias of the
//!    sensors), the floor holds the strip's direction `e1` and takes the rest
//!    of its tilt from the body: `n = normalize(u0 - (u0 . e1) e1)`
//!    ([`FloorMethod::Line`]). When they cover neither (standing, stepping in
//!    place), the floor is `u0` itself ([`FloorMethod::Body`]).
//! 6. **Orientation and height**: `n` points the way `u0` does (toward the
//!    head); the floor's height is the mean of `n . p` over the kept `Foot*`
//!    contacts, so the planted foot joints lie on the floor.
//!
//! # Standing on it ([`stand_on_floor`])
//!
//! The rotation is the shortest arc from `n` to `+Y` (about the axis
//! `n x Y`, so no extra turn about the vertical: the take keeps its
//! heading); it takes the floor's points, `n . p = h`, to `y = h` (since
//! `(R p) . Y = p . (R^T Y) = p . n`). The translation then lowers the
//! floor to `y = 0` and brings the first frame's pelvis (`SpineBase`) to
//! `x = z = 0`.

use mocap_core::rotation::{Quat, Vec3};
use nalgebra::{Matrix3, SymmetricEigen};
use serde::{Deserialize, Serialize};

use crate::calib::RigidTransform;
use crate::kinect::{joint::*, JOINT_COUNT};

/// The foot joints whose planted positions the floor is fitted to, by kind:
/// the feet (kind 0, which lie on the floor), then the ankles (kind 1).
const KINDS: [[usize; 2]; 2] = [[FOOT_LEFT, FOOT_RIGHT], [ANKLE_LEFT, ANKLE_RIGHT]];

/// The most times the plane is fitted again without its far contacts.
pub const TRIM_ITERATIONS: usize = 6;

/// The least spread (standard deviation, metres) of the contacts along each
/// direction of the floor for a plane fit ([`FloorMethod::Plane`]).
pub const MIN_SPREAD: f32 = 0.06;

/// The least spread (standard deviation, metres) of the contacts along their
/// longest direction for the floor to be fitted to them at all
/// ([`FloorMethod::Line`] or [`FloorMethod::Plane`]): a person stepping in
/// place spreads about 10 cm (their feet's width apart).
pub const MIN_TRAVEL: f32 = 0.15;

/// How the floor was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FloorMethod {
    /// A plane fitted to the planted feet, which covered enough of the floor.
    Plane,
    /// The planted feet lay along a strip (a walk in a straight line): the
    /// floor holds the strip, its roll about the strip is the body's.
    Line,
    /// Too little floor under the feet (standing, stepping in place): up is
    /// the direction from the feet to the head, the height the planted
    /// feet's.
    Body,
}

impl FloorMethod {
    /// A few words on the method, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            FloorMethod::Plane => "a plane fitted to the planted feet",
            FloorMethod::Line => {
                "the line the planted feet followed, tilted sideways as the body stands"
            }
            FloorMethod::Body => {
                "the body's up direction and the planted feet's height (the feet covered too little floor for a plane)"
            }
        }
    }
}

/// The floor under a take, in the take's world.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Floor {
    /// Unit normal, pointing up (toward the head).
    pub normal: Vec3,
    /// Signed offset along the normal: points `p` on the floor satisfy
    /// `normal . p = height` (metres).
    pub height: f32,
    /// The angle between the normal and the world's `+y` (degrees): the tilt
    /// that standing on the floor removes.
    pub tilt_degrees: f32,
    /// Planted foot and ankle positions the floor rests on (after trimming).
    pub contacts_used: usize,
    pub method: FloorMethod,
    /// Root mean square distance of those contacts from the floor (their
    /// kind's plane: the ankles ride above it), metres.
    pub rms_residual: f32,
    /// How far the contacts spread along the floor (standard deviations
    /// along their longest direction and across it, metres).
    pub spread: [f32; 2],
}

/// One planted foot joint: where, and its kind (index in [`KINDS`]).
#[derive(Debug, Clone, Copy)]
struct Contact {
    point: Vec3,
    kind: usize,
}

/// The provisional up: the mean unit direction from the feet to the top of
/// the body.
fn body_up(poses: &[[Vec3; JOINT_COUNT]]) -> Option<Vec3> {
    let mut sum = Vec3::ZERO;
    for p in poses {
        let top = (p[HEAD] + p[NECK]) * 0.5;
        // The ankles, not the foot joints: those lie ahead of the ankle, by
        // 10 cm or so, which would tip up forward by a few degrees.
        let feet = (p[ANKLE_LEFT] + p[ANKLE_RIGHT]) * 0.5;
        // None for a degenerate or non-finite frame: it is skipped.
        if let Some(d) = (top - feet).try_normalize() {
            sum += d;
        }
    }
    sum.try_normalize()
}

/// The planted foot joints (step 2 of the module documentation).
fn planted_contacts(poses: &[[Vec3; JOINT_COUNT]], up: Vec3) -> Vec<Contact> {
    let last = poses.len().saturating_sub(1);
    let speed = |f: usize, j: usize| {
        let (a, b) = (f.saturating_sub(1), (f + 1).min(last));
        if b > a {
            poses[b][j].distance(poses[a][j]) / (b - a) as f32
        } else {
            0.0
        }
    };
    let mut contacts = Vec::new();
    for (kind, [left, right]) in KINDS.iter().copied().enumerate() {
        // The lower side of each frame, with its speed.
        let lower: Vec<(Vec3, f32)> = poses
            .iter()
            .enumerate()
            .filter_map(|(f, p)| {
                let j = if up.dot(p[left]) <= up.dot(p[right]) {
                    left
                } else {
                    right
                };
                let s = speed(f, j);
                (p[j].is_finite() && s.is_finite()).then_some((p[j], s))
            })
            .collect();
        if lower.is_empty() {
            continue;
        }
        let mut speeds: Vec<f32> = lower.iter().map(|&(_, s)| s).collect();
        let median = median(&mut speeds);
        contacts.extend(
            lower
                .into_iter()
                .filter(|&(_, s)| s <= median)
                .map(|(point, _)| Contact { point, kind }),
        );
    }
    contacts
}

fn median(values: &mut [f32]) -> f32 {
    crate::body::percentile(values, 0.5)
}

/// The kept contacts' centroid per kind (`None` for a kind with none).
fn centroids(contacts: &[Contact], keep: &[bool]) -> [Option<Vec3>; 2] {
    let mut sum = [Vec3::ZERO; 2];
    let mut count = [0usize; 2];
    for (c, _) in contacts.iter().zip(keep).filter(|(_, &k)| k) {
        sum[c.kind] += c.point;
        count[c.kind] += 1;
    }
    std::array::from_fn(|k| (count[k] > 0).then(|| sum[k] / count[k] as f32))
}

/// The pooled least-squares fit of the kept contacts (step 3): the plane's
/// normal (smallest eigenvector), the direction of the longest spread and
/// the spreads along it and across it.
struct PlaneFit {
    normal: Vec3,
    along: Vec3,
    spread: [f32; 2],
}

fn fit_plane(contacts: &[Contact], keep: &[bool], centre: &[Option<Vec3>; 2]) -> Option<PlaneFit> {
    let mut scatter = Matrix3::<f64>::zeros();
    let mut count = 0usize;
    for (c, _) in contacts.iter().zip(keep).filter(|(_, &k)| k) {
        let d = c.point - centre[c.kind]?;
        let d = nalgebra::Vector3::new(d.x as f64, d.y as f64, d.z as f64);
        scatter += d * d.transpose();
        count += 1;
    }
    if count < 3 {
        return None;
    }
    scatter /= count as f64;
    let eigen = SymmetricEigen::new(scatter);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
    let vector = |i: usize| {
        let v = eigen.eigenvectors.column(order[i]);
        Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
    };
    let spread = |i: usize| eigen.eigenvalues[order[i]].max(0.0).sqrt() as f32;
    let normal = vector(2).try_normalize()?;
    let along = vector(0).try_normalize()?;
    Some(PlaneFit {
        normal,
        along,
        spread: [spread(0), spread(1)],
    })
}

/// The floor's normal by the method the spread allows (step 5), pointing
/// the way `up` does.
fn choose_normal(fit: &PlaneFit, up: Vec3) -> (Vec3, FloorMethod) {
    let [length, width] = fit.spread;
    if length >= MIN_TRAVEL && width >= MIN_SPREAD {
        let n = if fit.normal.dot(up) < 0.0 {
            -fit.normal
        } else {
            fit.normal
        };
        (n, FloorMethod::Plane)
    } else if length >= MIN_TRAVEL {
        // The floor holds the strip's direction: up with its component along
        // the strip taken out.
        match (up - fit.along * up.dot(fit.along)).try_normalize() {
            Some(n) => (n, FloorMethod::Line),
            None => (up, FloorMethod::Body),
        }
    } else {
        (up, FloorMethod::Body)
    }
}

/// The floor under the feet of `poses` (metres, Kinect order, frames at a
/// regular rate): see the module documentation. `None` when there are no
/// frames or the body has no direction (every frame degenerate).
pub fn fit_floor(poses: &[[Vec3; JOINT_COUNT]]) -> Option<Floor> {
    let up = body_up(poses)?;
    let contacts = planted_contacts(poses, up);
    if contacts.is_empty() {
        return None;
    }
    let mut keep = vec![true; contacts.len()];
    let (mut normal, mut method, mut spread) = (up, FloorMethod::Body, [0.0f32; 2]);
    for _ in 0..TRIM_ITERATIONS {
        let centre = centroids(&contacts, &keep);
        (normal, method) = match fit_plane(&contacts, &keep, &centre) {
            Some(fit) => {
                spread = fit.spread;
                choose_normal(&fit, up)
            }
            None => (up, FloorMethod::Body),
        };
        let residual = |c: &Contact| {
            centre[c.kind]
                .map_or(0.0, |m| normal.dot(c.point - m))
                .abs()
        };
        let mut kept: Vec<f32> = contacts
            .iter()
            .zip(&keep)
            .filter(|(_, &k)| k)
            .map(|(c, _)| residual(c))
            .collect();
        let scale = (1.4826 * median(&mut kept)).max(0.005);
        let next: Vec<bool> = contacts
            .iter()
            .map(|c| residual(c) <= 2.5 * scale)
            .collect();
        if next == keep || next.iter().filter(|&&k| k).count() < 3 {
            break;
        }
        keep = next;
    }
    let centre = centroids(&contacts, &keep);
    let kept = || {
        contacts
            .iter()
            .zip(&keep)
            .filter(|(_, &k)| k)
            .map(|(c, _)| c)
    };
    // The feet's plane, or the ankles' when no foot contact was kept.
    let floor_kind = if centre[0].is_some() { 0 } else { 1 };
    let on_floor: Vec<f32> = kept()
        .filter(|c| c.kind == floor_kind)
        .map(|c| normal.dot(c.point))
        .collect();
    let height = on_floor.iter().sum::<f32>() / on_floor.len().max(1) as f32;
    let squares: f32 = kept()
        .map(|c| {
            centre[c.kind]
                .map_or(0.0, |m| normal.dot(c.point - m))
                .powi(2)
        })
        .sum();
    let used = kept().count();
    Some(Floor {
        normal,
        height,
        tilt_degrees: normal.angle_between(Vec3::Y).to_degrees(),
        contacts_used: used,
        method,
        rms_residual: (squares / used.max(1) as f32).sqrt(),
        spread,
    })
}

/// The rigid transform that stands `poses` on `floor` (see the module
/// documentation): the floor's normal turned to `+y` by the shortest arc,
/// the floor at `y = 0`, the first frame's pelvis at `x = z = 0`. The
/// identity for no poses.
pub fn floor_transform(poses: &[[Vec3; JOINT_COUNT]], floor: &Floor) -> RigidTransform {
    let rotation = Quat::from_rotation_arc(floor.normal.normalize(), Vec3::Y);
    let pelvis = poses
        .first()
        .map_or(Vec3::ZERO, |p| rotation * p[SPINE_BASE]);
    RigidTransform {
        rotation,
        translation: Vec3::new(-pelvis.x, -floor.height, -pelvis.z),
    }
}

/// Stands `poses` on `floor` ([`floor_transform`]) in place; returns the
/// transform applied (`new = rotation * old + translation`).
pub fn stand_on_floor(poses: &mut [[Vec3; JOINT_COUNT]], floor: &Floor) -> RigidTransform {
    let transform = floor_transform(poses, floor);
    for pose in poses.iter_mut() {
        for p in pose.iter_mut() {
            *p = transform.apply(*p);
        }
    }
    transform
}

/// What standing a take on its floor did: the floor found (in the
/// calibration's world) and the transform applied.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FloorReport {
    pub floor: Floor,
    /// From the calibration's world to the output's
    /// (`new = rotation * old + translation`, metres).
    pub transform: RigidTransform,
    /// How far the take moved along the floor to bring its first pelvis to
    /// `x = z = 0` (metres).
    pub moved_along_floor: f32,
}

impl FloorReport {
    pub fn new(floor: Floor, transform: RigidTransform) -> FloorReport {
        FloorReport {
            floor,
            transform,
            moved_along_floor: transform.translation.with_y(0.0).length(),
        }
    }
}

/// Which world the BVH outputs are written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BvhWorld {
    /// Upright on the floor found under the feet ([`fit_floor`],
    /// [`stand_on_floor`]): `+y` up, the floor at `y = 0`, the first pelvis
    /// at `x = z = 0`.
    #[default]
    Floor,
    /// The calibration's world, as the fused joints (and the JSON lines
    /// outputs) are.
    Calibration,
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The tilt of the tests' worlds: 17 degrees about x, then 30 about z,
    /// and 3.6 m away.
    fn tilt() -> RigidTransform {
        RigidTransform {
            rotation: Quat::from_rotation_z(30f32.to_radians())
                * Quat::from_rotation_x(17f32.to_radians()),
            translation: Vec3::new(0.5, 1.2, 3.36),
        }
    }

    /// What sensors watching `truth` (y up, floor at y = 0) report, fused
    /// with their true calibration moved into the tilted world: the fused
    /// poses in that world.
    fn fused_in_tilted_world(
        truth: &crate::kinect::GroundTruth,
        seed: u64,
        body: Option<crate::body::BodyModel>,
    ) -> Vec<[Vec3; JOINT_COUNT]> {
        use crate::offline::{fuse_streams, SensorStreams};
        let options = crate::sim::SimulationOptions {
            sensors: 3,
            seed,
            ..Default::default()
        };
        let simulation = crate::sim::simulate(truth, &options);
        let body = body.unwrap_or_else(|| crate::sim::measure_person(truth, &options));
        let mut calibration = simulation.calibration();
        for s in &mut calibration.sensors {
            s.transform = tilt().then_after(&s.transform);
        }
        let streams = SensorStreams::new(
            simulation
                .sensors
                .iter()
                .flat_map(|s| s.frames.iter().cloned()),
        );
        let mut fuser = crate::fusion::Fuser::new(crate::fusion::FusionOptions::best(), body);
        let fused = fuse_streams(&streams, &calibration, &mut fuser, truth.fps, None);
        crate::bvh::regular_poses(&fused, truth.fps)
    }

    /// The bundled walk, centred and on the simulator's treadmill, as
    /// `simulate_capture` makes it.
    fn walk() -> crate::kinect::GroundTruth {
        let motion = mocap_core::io::bvh::read_bvh(&mocap_testdata::sample_walk()).unwrap();
        let mut truth = crate::kinect::truth_from_motion(&motion, None).unwrap();
        crate::sim::center_truth(
            &mut truth,
            crate::sim::SimulationOptions::default().treadmill_above,
        );
        truth
    }

    /// The lowest foot joint of each frame whose lower foot is planted (at
    /// most the median speed of the lower feet): the heights feet rest at.
    fn resting_feet(poses: &[[Vec3; JOINT_COUNT]]) -> Vec<f32> {
        let lower: Vec<(f32, f32)> = (1..poses.len() - 1)
            .map(|f| {
                let j = if poses[f][FOOT_LEFT].y <= poses[f][FOOT_RIGHT].y {
                    FOOT_LEFT
                } else {
                    FOOT_RIGHT
                };
                (poses[f][j].y, poses[f + 1][j].distance(poses[f - 1][j]))
            })
            .collect();
        let mut speeds: Vec<f32> = lower.iter().map(|l| l.1).collect();
        let median = median(&mut speeds);
        lower
            .into_iter()
            .filter(|l| l.1 <= median)
            .map(|l| l.0)
            .collect()
    }

    #[test]
    fn a_tilted_and_shifted_capture_of_a_walk_is_stood_upright_on_its_floor() {
        let truth = walk();
        let up = tilt().rotation * Vec3::Y;
        for seed in 1..=4 {
            let mut poses = fused_in_tilted_world(&truth, seed, None);
            let floor = fit_floor(&poses).unwrap();
            let off = floor.normal.angle_between(up).to_degrees();
            let true_tilt = up.angle_between(Vec3::Y).to_degrees();
            eprintln!(
                "seed {seed}: {:?} floor, {off:.2} degrees off, tilt {:.1} (true {true_tilt:.1}), {} contacts, spread {:?}, rms {:.1} mm",
                floor.method, floor.tilt_degrees, floor.contacts_used, floor.spread, floor.rms_residual * 1000.0
            );
            assert!(off < 2.0, "seed {seed}: {off} degrees, {floor:?}");
            // A walk in a straight line (on the simulator's treadmill): the
            // feet cover a strip a few centimetres wide.
            assert_eq!(floor.method, FloorMethod::Line, "{floor:?}");
            assert!(floor.contacts_used > 100, "{floor:?}");

            let transform = stand_on_floor(&mut poses, &floor);
            assert!((transform.rotation * floor.normal).distance(Vec3::Y) < 1e-5);
            // The body stands along +y as it did in the simulator's world
            // (where its mean up is 0.8 degrees from the vertical).
            let body = body_up(&poses).unwrap().angle_between(Vec3::Y).to_degrees();
            assert!(body < 3.0, "{body} degrees");
            let first = poses[0][SPINE_BASE];
            assert!(first.x.abs() < 1e-4 && first.z.abs() < 1e-4, "{first}");
            assert!(first.y > 0.8 && first.y < 1.2, "{first}");
            let mut resting = resting_feet(&poses);
            let median = median(&mut resting);
            let within =
                resting.iter().filter(|h| h.abs() <= 0.03).count() as f32 / resting.len() as f32;
            eprintln!(
                "  resting feet: median {:.1} mm, {:.0}% within 3 cm, lowest {:.1} mm, highest {:.1} mm",
                median * 1000.0,
                within * 100.0,
                resting[0] * 1000.0,
                resting[resting.len() - 1] * 1000.0
            );
            assert!(median.abs() < 0.01, "{median}");
            assert!(within > 0.9, "{within}");
            // Upright: the head above the feet along +y in every frame.
            let clearance = poses
                .iter()
                .map(|p| p[HEAD].y - p[FOOT_LEFT].y.max(p[FOOT_RIGHT].y))
                .fold(f32::MAX, f32::min);
            eprintln!("  head above the higher foot by at least {clearance:.2} m");
            assert!(clearance > 1.0, "{clearance}");
        }
    }

    /// A synthetic person who stands still at twelve places on a circle of
    /// 1 m (steps between them), on a floor tilted and shifted away, with a
    /// centimetre of noise.
    fn wandering(rng: &mut rand::rngs::StdRng) -> Vec<[Vec3; JOINT_COUNT]> {
        let base = crate::body::tests::standing_pose();
        let mut poses = Vec::new();
        for place in 0..12 {
            let a = place as f32 * std::f32::consts::TAU / 12.0;
            let turn = Quat::from_rotation_y(a);
            let at = Vec3::new(a.cos(), 0.0, a.sin());
            for _ in 0..15 {
                poses.push(base.map(|p| {
                    let noise = Vec3::new(
                        rng.random_range(-0.01..0.01),
                        rng.random_range(-0.01..0.01),
                        rng.random_range(-0.01..0.01),
                    );
                    tilt().apply(turn * p + at + noise)
                }));
            }
        }
        poses
    }

    #[test]
    fn feet_all_over_the_floor_give_a_plane() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let mut poses = wandering(&mut rng);
        let floor = fit_floor(&poses).unwrap();
        let up = tilt().rotation * Vec3::Y;
        let off = floor.normal.angle_between(up).to_degrees();
        assert_eq!(floor.method, FloorMethod::Plane, "{floor:?}");
        assert!(off < 0.5, "{off} degrees: {floor:?}");
        // The feet of the standing pose are 3 cm above its floor.
        let truth_height = up.dot(tilt().translation) + 0.03;
        assert!(
            (floor.height - truth_height).abs() < 0.005,
            "{floor:?} vs {truth_height}"
        );
        stand_on_floor(&mut poses, &floor);
        let feet = poses.iter().map(|p| p[FOOT_LEFT].y.min(p[FOOT_RIGHT].y));
        assert!(feet.clone().all(|y| y.abs() < 0.03));
        assert!(poses.iter().all(|p| (p[HEAD].y - 1.62).abs() < 0.05));
    }

    #[test]
    fn a_person_standing_still_gets_the_floor_of_the_body_and_says_so() {
        // Watched by the simulated sensors: a person standing on both feet,
        // swaying a little and moving their arms, four seconds.
        let base = crate::body::tests::standing_pose();
        let frames: Vec<[Vec3; JOINT_COUNT]> = (0..120)
            .map(|i| {
                let t = i as f32 / 30.0;
                let sway = Quat::from_rotation_z(0.03 * (1.3 * t).sin());
                let arm = Quat::from_rotation_x(0.5 * (2.0 * t).sin());
                let mut p = base;
                for j in [ELBOW_LEFT, WRIST_LEFT, HAND_LEFT, HAND_TIP_LEFT, THUMB_LEFT] {
                    p[j] = base[SHOULDER_LEFT] + arm * (base[j] - base[SHOULDER_LEFT]);
                }
                // Swaying about the ankles: the feet stay.
                for (j, q) in p.iter_mut().enumerate() {
                    if ![ANKLE_LEFT, ANKLE_RIGHT, FOOT_LEFT, FOOT_RIGHT].contains(&j) {
                        *q = sway * (*q - Vec3::new(0.0, 0.1, 0.0)) + Vec3::new(0.0, 0.1, 0.0);
                    }
                }
                p
            })
            .collect();
        let truth = crate::kinect::GroundTruth { fps: 30.0, frames };
        let body = crate::body::BodyModel::from_positions(
            truth.frames.iter(),
            crate::body::MeasureOptions::default(),
        );
        let up = tilt().rotation * Vec3::Y;
        let mut poses = fused_in_tilted_world(&truth, 5, Some(body));
        let floor = fit_floor(&poses).unwrap();
        let off = floor.normal.angle_between(up).to_degrees();
        eprintln!(
            "standing: {:?}, {off:.2} degrees off, spread {:?}, {} contacts",
            floor.method, floor.spread, floor.contacts_used
        );
        assert_eq!(floor.method, FloorMethod::Body, "{floor:?}");
        assert!(floor.method.describe().contains("too little floor"));
        assert!(off < 3.0, "{off} degrees: {floor:?}");
        stand_on_floor(&mut poses, &floor);
        let mut resting = resting_feet(&poses);
        let median = median(&mut resting);
        assert!(median.abs() < 0.02, "{median}");

        // The synthetic pose without sensors: exactly level, feet on the floor.
        let still = vec![base; 10];
        let floor = fit_floor(&still).unwrap();
        assert_eq!(floor.method, FloorMethod::Body, "{floor:?}");
        assert!(floor.tilt_degrees < 0.5, "{floor:?}");
        assert!((floor.height - 0.03).abs() < 0.002, "{floor:?}");
        assert!(fit_floor(&[]).is_none());
    }
}
