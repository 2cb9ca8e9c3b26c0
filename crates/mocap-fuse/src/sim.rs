//! A simulator of Kinect v2 style sensors watching a ground-truth motion.
//!
//! It turns a BVH take into K sensor recordings (and point clouds of a simple
//! room for ICP), reproducing what makes Kinect fusion hard rather than only
//! adding Gaussian noise. Every parameter is in [`SensorModel`], with where its
//! magnitude comes from:
//!
//! - **field of view and range**: a joint outside the depth camera's 70.6 x 60
//!   degree field of view or its 0.5-4.5 m range is NotTracked (Kinect v2
//!   specification); its reported position is a guess off by
//!   `not_tracked_sigma`;
//! - **self-occlusion**: a joint whose line of sight from the sensor passes
//!   through one of the body's capsules (torso, head, limbs, radii of an adult
//!   body) is Inferred, with a large error that follows an Ornstein-Uhlenbeck
//!   process (`inferred_sigma`, `inferred_tau`): temporally correlated, as
//!   the tracker's guess drifts while the joint stays hidden;
//! - **depth-dependent error** on Tracked joints: a per-joint bias of the
//!   tracker's joint centres, a slowly varying error and a white jitter whose
//!   standard deviations grow with the square of the depth, like the depth
//!   noise of time-of-flight cameras;
//! - **seen from behind**: Kinect v2 assumes the person faces it; a sensor
//!   seeing the back (angle between the body's facing and the direction to
//!   the sensor above `behind_angle_degrees`) swaps left and right labels;
//! - **wrong bone lengths** follow from the above: a joint that is badly
//!   estimated takes its bones' lengths with it;
//! - **latency and dropped frames**: each sensor has its own latency (when the
//!   frame reaches its computer, `arrival`), jitter on it, its own capture
//!   phase (sensors are not synchronised) and clock offset, and drops frames.
//!
//! Parameter magnitudes, and their sources: Kinect v2 specification (field
//! of view, range, 30 Hz); joint position errors of a few centimetres on
//! Tracked joints and much larger ones on occluded, Inferred joints, as
//! reported when Kinect v2 skeletons are compared with marker-based capture
//! (Wang et al., "Evaluation of pose tracking accuracy in the first and second
//! generations of Microsoft Kinect", ICHI 2015; Otte et al., "Accuracy and
//! reliability of the Kinect version 2 for clinical measurement of motor
//! function", PLoS ONE 2016); depth noise growing roughly with the square of
//! the distance (Fankhauser et al., "Kinect v2 for mobile robot navigation:
//! evaluation and modeling", ICAR 2015); skeleton latency of several tens of
//! milliseconds. The values are our reading of those reports, not fitted to a
//! data set: see `docs/fuse-simulator.md`.

use mocap_core::rotation::{Quat, Vec3};
use mocap_core::{Error, Motion, Result};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use crate::body::{BodyModel, MeasureOptions};
use crate::calib::{Calibration, RigidTransform, SensorPose};
use crate::fusion::facing_of;
use crate::kinect::{joint::*, truth_from_motion, GroundTruth, TrackingState, JOINT_COUNT, MIRROR};
use crate::recording::{JointObservation, SensorFrame};

/// The sensor model; see the module documentation for the sources.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SensorModel {
    /// Horizontal and vertical field of view of the depth camera (degrees).
    pub fov_degrees: (f32, f32),
    /// Nearest and farthest tracked depth (metres).
    pub range: (f32, f32),
    /// Nearest and farthest depth of the room scans (metres): the depth
    /// camera measures beyond the body-tracking range, to 8 m.
    pub scan_range: (f32, f32),
    /// Standard deviation of the constant per-joint bias of Tracked joints (m).
    pub bias_sigma: f32,
    /// Slowly varying error of Tracked joints: `sigma = a + b z^2` (m, z in m).
    pub tracked_sigma: (f32, f32),
    /// Its correlation time (s).
    pub tracked_tau: f32,
    /// White jitter of Tracked joints: `a + b z^2` (m).
    pub jitter_sigma: (f32, f32),
    /// Error of Inferred (self-occluded) joints (m) and its correlation time (s).
    pub inferred_sigma: f32,
    pub inferred_tau: f32,
    /// Error of the guess reported for NotTracked joints (m).
    pub not_tracked_sigma: f32,
    /// Beyond this angle between the body's facing and the direction to the
    /// sensor, the sensor sees the back and swaps left and right (degrees).
    pub behind_angle_degrees: f32,
    /// Latency range (s): each sensor draws its latency from it.
    pub latency: (f32, f32),
    /// Jitter of the latency (s).
    pub latency_jitter: f32,
    /// Dropped-frame probability range: each sensor draws its rate from it.
    pub drop_rate: (f32, f32),
    /// Standard deviation of each sensor's clock offset (s).
    pub clock_offset_sigma: f32,
}

impl Default for SensorModel {
    fn default() -> Self {
        SensorModel {
            fov_degrees: (70.6, 60.0),
            range: (0.5, 4.5),
            scan_range: (0.5, 8.0),
            bias_sigma: 0.015,
            tracked_sigma: (0.006, 0.0015),
            tracked_tau: 0.15,
            jitter_sigma: (0.002, 0.0005),
            inferred_sigma: 0.10,
            inferred_tau: 0.6,
            not_tracked_sigma: 0.25,
            behind_angle_degrees: 110.0,
            latency: (0.045, 0.09),
            latency_jitter: 0.004,
            drop_rate: (0.005, 0.03),
            clock_offset_sigma: 0.002,
        }
    }
}

/// Where the sensors stand and what else is simulated.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SimulationOptions {
    pub sensors: usize,
    pub seed: u64,
    /// Distance of the sensors from the centre of the capture area (m).
    pub radius: f32,
    /// Height of the sensors (m).
    pub height: f32,
    /// Sensor frame rate (Hz).
    pub fps: f64,
    /// Takes that travel further than this (m) are put on a "treadmill": the
    /// straight-line drift of the root is removed so that the person stays
    /// inside the few metres a Kinect sees. `None` keeps the take as it is.
    pub treadmill_above: Option<f32>,
    pub model: SensorModel,
}

impl Default for SimulationOptions {
    fn default() -> Self {
        SimulationOptions {
            sensors: 3,
            seed: 1,
            radius: 2.8,
            height: 1.0,
            fps: 30.0,
            treadmill_above: Some(2.0),
            model: SensorModel::default(),
        }
    }
}

/// A capsule of the body: the segment between two joints, with a radius.
const CAPSULES: [(usize, usize, f32); 17] = [
    (SPINE_BASE, SPINE_MID, 0.13),
    (SPINE_MID, SPINE_SHOULDER, 0.14),
    (NECK, HEAD, 0.06),
    (HEAD, HEAD, 0.10),
    (SHOULDER_LEFT, ELBOW_LEFT, 0.05),
    (ELBOW_LEFT, WRIST_LEFT, 0.04),
    (WRIST_LEFT, HAND_TIP_LEFT, 0.04),
    (SHOULDER_RIGHT, ELBOW_RIGHT, 0.05),
    (ELBOW_RIGHT, WRIST_RIGHT, 0.04),
    (WRIST_RIGHT, HAND_TIP_RIGHT, 0.04),
    (HIP_LEFT, KNEE_LEFT, 0.075),
    (KNEE_LEFT, ANKLE_LEFT, 0.05),
    (ANKLE_LEFT, FOOT_LEFT, 0.04),
    (HIP_RIGHT, KNEE_RIGHT, 0.075),
    (KNEE_RIGHT, ANKLE_RIGHT, 0.05),
    (ANKLE_RIGHT, FOOT_RIGHT, 0.04),
    (SHOULDER_LEFT, SHOULDER_RIGHT, 0.06),
];

/// Closest distance between segments `p0-p1` and `q0-q1`.
fn segment_distance(p0: Vec3, p1: Vec3, q0: Vec3, q1: Vec3) -> f32 {
    // Ericson, Real-Time Collision Detection, 5.1.9.
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.dot(d1);
    let e = d2.dot(d2);
    let f = d2.dot(r);
    let (s, t);
    if a <= 1e-12 && e <= 1e-12 {
        return r.length();
    }
    if a <= 1e-12 {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= 1e-12 {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > 1e-12 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    ((p0 + d1 * s) - (q0 + d2 * t)).length()
}

/// Whether joint `n` of `pose` is hidden from `eye` by a body capsule that
/// does not contain the joint itself. The line of sight stops 3 cm short of
/// the joint (the tracker sees the surface around it).
pub fn is_occluded(pose: &[Vec3; JOINT_COUNT], n: usize, eye: Vec3) -> bool {
    let target = pose[n];
    let to_eye = (eye - target).normalize_or_zero();
    let end = target + to_eye * 0.03;
    CAPSULES.iter().any(|&(a, b, r)| {
        if a == n || b == n {
            return false;
        }
        if segment_distance(target, target, pose[a], pose[b]) < r {
            return false;
        }
        segment_distance(eye, end, pose[a], pose[b]) < r
    })
}

/// One simulated sensor.
#[derive(Debug, Clone)]
pub struct SimulatedSensor {
    pub id: u16,
    /// `world_from_sensor`.
    pub pose: RigidTransform,
    pub latency: f64,
    pub drop_rate: f64,
    pub frames: Vec<SensorFrame>,
}

/// The result of a simulation.
#[derive(Debug, Clone)]
pub struct Simulation {
    pub truth: GroundTruth,
    pub sensors: Vec<SimulatedSensor>,
}

impl Simulation {
    /// The true calibration.
    pub fn calibration(&self) -> Calibration {
        let mut c = Calibration::default();
        for s in &self.sensors {
            c.set(SensorPose {
                id: s.id,
                transform: s.pose,
                method: Some("simulator truth".into()),
                rms_residual: None,
                pairs: None,
            });
        }
        c
    }
}

/// An Ornstein-Uhlenbeck process per joint: stationary standard deviation
/// `sigma`, correlation time `tau`.
#[derive(Debug, Clone)]
struct Drift {
    state: [Vec3; JOINT_COUNT],
}

impl Drift {
    fn new(rng: &mut StdRng) -> Drift {
        let n = Normal::new(0.0f32, 1.0).unwrap();
        Drift {
            state: std::array::from_fn(|_| Vec3::new(n.sample(rng), n.sample(rng), n.sample(rng))),
        }
    }

    /// Advances by `dt` and returns the unit-variance state of joint `j`.
    fn step(&mut self, rng: &mut StdRng, dt: f32, tau: f32) {
        let n = Normal::new(0.0f32, 1.0).unwrap();
        let a = (-dt / tau).exp();
        let b = (1.0 - a * a).sqrt();
        for s in self.state.iter_mut() {
            *s = *s * a + Vec3::new(n.sample(rng), n.sample(rng), n.sample(rng)) * b;
        }
    }
}

fn gaussian3(rng: &mut StdRng) -> Vec3 {
    let n = Normal::new(0.0f32, 1.0).unwrap();
    Vec3::new(n.sample(rng), n.sample(rng), n.sample(rng))
}

/// Removes the straight-line drift of the root when the take travels further
/// than `limit` metres (see [`SimulationOptions::treadmill_above`]), and
/// centres the take on the origin horizontally. Returns the shift taken off
/// each frame (metres): added back, it puts the take where it was.
pub fn center_truth(truth: &mut GroundTruth, treadmill_above: Option<f32>) -> Vec<Vec3> {
    let n = truth.frames.len();
    if n == 0 {
        return Vec::new();
    }
    let roots: Vec<Vec3> = truth.frames.iter().map(|f| f[SPINE_BASE]).collect();
    let (min, max) = roots.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(a, b), &p| (a.min(p), b.max(p)),
    );
    let travel = ((max - min) * Vec3::new(1.0, 0.0, 1.0)).length();
    let mean: Vec3 = roots.iter().copied().sum::<Vec3>() / n as f32;
    let velocity = match treadmill_above {
        Some(limit) if travel > limit && n > 1 => {
            // Least-squares straight line through the root's horizontal path.
            let tm = (n - 1) as f32 / 2.0;
            let mut num = Vec3::ZERO;
            let mut den = 0.0;
            for (i, &p) in roots.iter().enumerate() {
                let dt = i as f32 - tm;
                num += (p - mean) * dt;
                den += dt * dt;
            }
            (num / den) * Vec3::new(1.0, 0.0, 1.0)
        }
        _ => Vec3::ZERO,
    };
    let tm = (n - 1) as f32 / 2.0;
    let shifts: Vec<Vec3> = (0..n)
        .map(|i| mean * Vec3::new(1.0, 0.0, 1.0) + velocity * (i as f32 - tm))
        .collect();
    for (frame, shift) in truth.frames.iter_mut().zip(&shifts) {
        for p in frame.iter_mut() {
            *p -= *shift;
        }
    }
    shifts
}

/// A take watched by simulated sensors, with the person measured beforehand.
#[derive(Debug, Clone)]
pub struct SimulatedCapture {
    /// The sensors' recordings and the ground truth they watched (centred,
    /// see [`center_truth`]).
    pub simulation: Simulation,
    /// The person measured from a second capture of the take
    /// ([`measure_person`]).
    pub body: BodyModel,
    /// What [`center_truth`] took off each frame of the truth (metres):
    /// added back, a fused frame stands where the take stood.
    pub truth_shift: Vec<Vec3>,
}

/// The simulation pipeline, as `mocap fuse simulate`, `mocap fuse eval` and
/// the demo run it: the Kinect joints of `motion` ([`truth_from_motion`],
/// `units_per_metre` guessed when `None`), centred and put on a treadmill
/// when they travel far ([`center_truth`] with
/// `options.treadmill_above`), watched by `options.sensors` sensors
/// ([`simulate`]), and the person measured from a second capture
/// ([`measure_person`]).
pub fn simulate_capture(
    motion: &Motion,
    units_per_metre: Option<f32>,
    options: &SimulationOptions,
) -> Result<SimulatedCapture> {
    let mut truth = truth_from_motion(motion, units_per_metre)?;
    let truth_shift = center_truth(&mut truth, options.treadmill_above);
    let simulation = simulate(&truth, options);
    let body = measure_person(&truth, options);
    Ok(SimulatedCapture {
        simulation,
        body,
        truth_shift,
    })
}

/// The person as `mocap fuse measure` would measure them beforehand: bone
/// lengths and joint ranges from a second simulated capture of the same take
/// (other seed, so other sensor places and noise), never from the capture
/// being fused.
pub fn measure_person(truth: &GroundTruth, options: &SimulationOptions) -> BodyModel {
    let measuring = simulate(
        truth,
        &SimulationOptions {
            seed: options.seed ^ 0x5eed_5eed,
            ..*options
        },
    );
    BodyModel::measure(
        measuring
            .sensors
            .iter()
            .flat_map(|s| s.frames.iter().map(|f| &f.joints)),
        MeasureOptions::default(),
    )
}

/// Simulates `options.sensors` sensors watching `truth` (already centred,
/// see [`center_truth`]). Sensor `k` stands on a circle of radius
/// `options.radius` around the origin, evenly spaced from a random start
/// angle, at `options.height`, aimed at the body's centre height (1 m), with
/// a few degrees of random yaw.
pub fn simulate(truth: &GroundTruth, options: &SimulationOptions) -> Simulation {
    let m = options.model;
    let mut rng = StdRng::seed_from_u64(options.seed);
    let start: f32 = rng.random_range(0.0..std::f32::consts::TAU);
    let mut sensors = Vec::new();
    for k in 0..options.sensors {
        let azimuth = start + k as f32 * std::f32::consts::TAU / options.sensors as f32;
        let eye = Vec3::new(
            options.radius * azimuth.cos(),
            options.height,
            options.radius * azimuth.sin(),
        );
        let yaw_error = rng.random_range(-0.1f32..0.1);
        let target = Vec3::new(0.0, 1.0, 0.0);
        let forward = Quat::from_rotation_y(yaw_error) * (target - eye).normalize();
        // Kinect camera space: z forward, y up, x = y cross z (the sensor's left).
        let x = Vec3::Y.cross(forward).normalize();
        let y = forward.cross(x);
        let rotation = Quat::from_mat3(&mocap_core::rotation::Mat3::from_cols(x, y, forward));
        let pose = RigidTransform {
            rotation,
            translation: eye,
        };
        let latency = rng.random_range(m.latency.0..=m.latency.1) as f64;
        let drop_rate = rng.random_range(m.drop_rate.0..=m.drop_rate.1) as f64;
        let seed = rng.random::<u64>();
        let frames = simulate_sensor(truth, options, k as u16, pose, latency, drop_rate, seed);
        sensors.push(SimulatedSensor {
            id: k as u16,
            pose,
            latency,
            drop_rate,
            frames,
        });
    }
    Simulation {
        truth: truth.clone(),
        sensors,
    }
}

fn simulate_sensor(
    truth: &GroundTruth,
    options: &SimulationOptions,
    id: u16,
    pose: RigidTransform,
    latency: f64,
    drop_rate: f64,
    seed: u64,
) -> Vec<SensorFrame> {
    let m = options.model;
    let mut rng = StdRng::seed_from_u64(seed);
    let sensor_from_world = pose.inverse();
    let eye = pose.translation;
    let phase = rng.random_range(0.0..1.0 / options.fps);
    let clock_offset = Normal::new(0.0, m.clock_offset_sigma as f64)
        .unwrap()
        .sample(&mut rng);
    let bias: [Vec3; JOINT_COUNT] = std::array::from_fn(|_| gaussian3(&mut rng) * m.bias_sigma);
    let mut tracked_drift = Drift::new(&mut rng);
    let mut inferred_drift = Drift::new(&mut rng);
    let dt = (1.0 / options.fps) as f32;
    let (half_h, half_v) = (
        (m.fov_degrees.0 / 2.0).to_radians().tan(),
        (m.fov_degrees.1 / 2.0).to_radians().tan(),
    );
    let cos_behind = m.behind_angle_degrees.to_radians().cos();
    let mut frames = Vec::new();
    let mut seq = 0u64;
    loop {
        let t = phase + seq as f64 / options.fps;
        if t > truth.duration() {
            break;
        }
        tracked_drift.step(&mut rng, dt, m.tracked_tau);
        inferred_drift.step(&mut rng, dt, m.inferred_tau);
        let world = truth.at(t);
        let dropped = rng.random_bool(drop_rate.clamp(0.0, 1.0));
        let mut joints = [JointObservation::NOT_TRACKED; JOINT_COUNT];
        for n in 0..JOINT_COUNT {
            let p = sensor_from_world.apply(world[n]);
            let z = p.z;
            let in_view = z > m.range.0
                && z < m.range.1
                && (p.x / z).abs() < half_h
                && (p.y / z).abs() < half_v;
            let (state, error) = if !in_view {
                (
                    TrackingState::NotTracked,
                    gaussian3(&mut rng) * m.not_tracked_sigma,
                )
            } else if is_occluded(&world, n, eye) {
                (
                    TrackingState::Inferred,
                    bias[n] + inferred_drift.state[n] * m.inferred_sigma,
                )
            } else {
                let z2 = z * z;
                let slow = m.tracked_sigma.0 + m.tracked_sigma.1 * z2;
                let white = m.jitter_sigma.0 + m.jitter_sigma.1 * z2;
                (
                    TrackingState::Tracked,
                    bias[n] * (1.0 + 0.1 * z2)
                        + tracked_drift.state[n] * slow
                        + gaussian3(&mut rng) * white,
                )
            };
            joints[n] = JointObservation {
                position: p + error,
                state,
            };
        }
        // Seen from behind: Kinect believes the person faces it and swaps
        // left and right.
        let face = facing_of(&world);
        let to_sensor = ((eye - world[SPINE_BASE]) * Vec3::new(1.0, 0.0, 1.0)).normalize_or_zero();
        if face != Vec3::ZERO && face.dot(to_sensor) < cos_behind {
            joints = std::array::from_fn(|n| joints[MIRROR[n]]);
        }
        if !dropped && joints.iter().any(|j| j.state != TrackingState::NotTracked) {
            let jitter = Normal::new(0.0, m.latency_jitter as f64)
                .unwrap()
                .sample(&mut rng)
                .abs();
            frames.push(SensorFrame {
                sensor: id,
                seq,
                timestamp: t + clock_offset,
                arrival: Some(t + latency + jitter),
                joints,
            });
        }
        seq += 1;
    }
    frames
}

/// A point with its surface normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    pub position: Vec3,
    pub normal: Vec3,
}

/// Points of a simple room around the capture area (world space): a floor
/// 7 x 7 m, four walls 2.6 m high, a table, a cabinet and a pillar (boxes
/// break the sliding symmetry of plain walls), sampled every `spacing`
/// metres.
///
/// Note: sensors placed around the person look inwards, so each sees the
/// part of the room behind the others; what two such sensors both see is
/// little more than the floor around the person. Their scans leave sliding
/// and turning on the floor free, which ICP reports rather than guesses
/// ([`crate::align::IcpResult::unconstrained`]).
pub fn room_points(spacing: f32, seed: u64) -> Vec<SurfacePoint> {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut out = Vec::new();
    // Axis-aligned box faces (centre, half sizes), outward normals, only the
    // faces listed.
    let mut plane = |centre: Vec3, u: Vec3, v: Vec3, normal: Vec3, rng: &mut StdRng| {
        let (lu, lv) = (u.length(), v.length());
        let (nu, nv) = ((2.0 * lu / spacing) as i32, (2.0 * lv / spacing) as i32);
        for i in 0..=nu {
            for j in 0..=nv {
                let a = -1.0 + 2.0 * (i as f32 + rng.random_range(0.0..0.5)) / nu.max(1) as f32;
                let b = -1.0 + 2.0 * (j as f32 + rng.random_range(0.0..0.5)) / nv.max(1) as f32;
                out.push(SurfacePoint {
                    position: centre + u * a.clamp(-1.0, 1.0) + v * b.clamp(-1.0, 1.0),
                    normal,
                });
            }
        }
    };
    let (x, y, z) = (Vec3::X, Vec3::Y, Vec3::Z);
    plane(Vec3::ZERO, x * 3.5, z * 3.5, y, &mut rng);
    plane(Vec3::new(0.0, 1.3, -3.5), x * 3.5, y * 1.3, z, &mut rng);
    plane(Vec3::new(0.0, 1.3, 3.5), x * 3.5, y * 1.3, -z, &mut rng);
    plane(Vec3::new(-3.5, 1.3, 0.0), z * 3.5, y * 1.3, x, &mut rng);
    plane(Vec3::new(3.5, 1.3, 0.0), z * 3.5, y * 1.3, -x, &mut rng);
    let boxes = [
        (Vec3::new(2.2, 0.375, -1.8), Vec3::new(0.6, 0.375, 0.4)),
        (Vec3::new(-2.6, 0.9, 2.3), Vec3::new(0.3, 0.9, 0.5)),
        (Vec3::new(-2.0, 1.3, -2.5), Vec3::new(0.2, 1.3, 0.2)),
    ];
    for (c, h) in boxes {
        plane(c + y * h.y, x * h.x, z * h.z, y, &mut rng);
        plane(c + x * h.x, z * h.z, y * h.y, x, &mut rng);
        plane(c - x * h.x, z * h.z, y * h.y, -x, &mut rng);
        plane(c + z * h.z, x * h.x, y * h.y, z, &mut rng);
        plane(c - z * h.z, x * h.x, y * h.y, -z, &mut rng);
    }
    out
}

/// What sensor `pose` sees of the room: points in its field of view and
/// scan range, on surfaces facing it, in its camera space, with depth noise along
/// the line of sight (`0.0015 z^2` m). Occlusion between room objects is not
/// modelled.
pub fn sensor_point_cloud(
    room: &[SurfacePoint],
    pose: &RigidTransform,
    model: &SensorModel,
    seed: u64,
) -> Vec<Vec3> {
    let mut rng = StdRng::seed_from_u64(seed);
    let inverse = pose.inverse();
    let (half_h, half_v) = (
        (model.fov_degrees.0 / 2.0).to_radians().tan(),
        (model.fov_degrees.1 / 2.0).to_radians().tan(),
    );
    let n = Normal::new(0.0f32, 1.0).unwrap();
    room.iter()
        .filter(|s| s.normal.dot(pose.translation - s.position) > 0.0)
        .filter_map(|s| {
            let p = inverse.apply(s.position);
            let ok = p.z > model.scan_range.0
                && p.z < model.scan_range.1
                && (p.x / p.z).abs() < half_h
                && (p.y / p.z).abs() < half_v;
            ok.then(|| p * (1.0 + n.sample(&mut rng) * 0.0015 * p.z))
        })
        .collect()
}

/// The files [`write_simulation`] wrote.
#[derive(Debug, Clone, Serialize)]
pub struct SimulationFiles {
    /// One recording per sensor (`sensor-K.jsonl`).
    pub recordings: Vec<std::path::PathBuf>,
    /// The same as NTU `.skeleton` files, when asked for.
    pub ntu: Vec<std::path::PathBuf>,
    /// The true sensor poses (`truth.calib.toml`).
    pub calibration: std::path::PathBuf,
    /// The person measured from a second simulated capture (`body.json`).
    pub body: std::path::PathBuf,
    /// The ground-truth joints in the fused-frame JSON lines format
    /// (`truth.jsonl`).
    pub truth: std::path::PathBuf,
    /// Each sensor's scan of the room in its camera space (`sensor-K.ply`).
    pub scans: Vec<std::path::PathBuf>,
    /// Floor marks picked in the scans of sensor 0 and sensor K
    /// (`pairs-0-K.txt`), for `mocap fuse calibrate --points`.
    pub pairs: Vec<std::path::PathBuf>,
}

/// Writes a simulation to the folder `dir` (created if needed): see
/// [`SimulationFiles`]. The room scans sample [`room_points`] every 5 cm.
/// The pairs files hold five marks on the floor around the capture area (as
/// tape marks one would pick by hand in both scans), with 1 cm of picking
/// error.
pub fn write_simulation(
    dir: &std::path::Path,
    sim: &Simulation,
    body: &crate::body::BodyModel,
    seed: u64,
    ntu: bool,
) -> Result<SimulationFiles> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let mut files = SimulationFiles {
        recordings: Vec::new(),
        ntu: Vec::new(),
        calibration: dir.join("truth.calib.toml"),
        body: dir.join("body.json"),
        truth: dir.join("truth.jsonl"),
        scans: Vec::new(),
        pairs: Vec::new(),
    };
    for s in &sim.sensors {
        let path = dir.join(format!("sensor-{}.jsonl", s.id));
        crate::recording::write_recording(&path, &s.frames)?;
        files.recordings.push(path);
        if ntu {
            let path = dir.join(format!("S001C{:03}P001R001A001.skeleton", s.id));
            crate::recording::write_ntu_skeleton(
                &path,
                &s.frames,
                72057594037927936 + s.id as u64,
            )?;
            files.ntu.push(path);
        }
    }
    sim.calibration().write(&files.calibration)?;
    body.write(&files.body)?;
    mocap_core::io::atomic::write_atomically(&files.truth, |w| {
        for (i, joints) in sim.truth.frames.iter().enumerate() {
            let frame = crate::fusion::FusedFrame {
                time: i as f64 / sim.truth.fps,
                joints: *joints,
                confidence: [1.0; JOINT_COUNT],
                sensors: Vec::new(),
                swapped: Vec::new(),
            };
            writeln!(w, "{}", crate::output::fused_frame_json(&frame))?;
        }
        Ok(())
    })?;
    let model = SensorModel::default();
    let room = room_points(0.05, seed);
    for s in &sim.sensors {
        let path = dir.join(format!("sensor-{}.ply", s.id));
        let cloud = sensor_point_cloud(&room, &s.pose, &model, seed.wrapping_add(s.id as u64));
        crate::ply::write_ply_points(
            &path,
            &cloud,
            crate::ply::PlyEncoding::BinaryLittleEndian,
            &format!(
                "room scan of simulated sensor {}, camera space, metres",
                s.id
            ),
        )?;
        files.scans.push(path);
    }
    let marks = [
        Vec3::ZERO,
        Vec3::new(0.8, 0.0, 0.8),
        Vec3::new(-0.8, 0.0, 0.8),
        Vec3::new(0.8, 0.0, -0.8),
        Vec3::new(-0.8, 0.0, -0.8),
    ];
    let mut rng = StdRng::seed_from_u64(seed ^ 0x7a11);
    if let Some(first) = sim.sensors.first() {
        for s in &sim.sensors[1..] {
            let path = dir.join(format!("pairs-{}-{}.txt", first.id, s.id));
            let mut text = format!(
                "# floor marks picked in the scans of sensor {} (x y z) and sensor {} (x y z), metres, camera space\n",
                first.id, s.id
            );
            for &m in &marks {
                let a = first.pose.inverse().apply(m + gaussian3(&mut rng) * 0.01);
                let b = s.pose.inverse().apply(m + gaussian3(&mut rng) * 0.01);
                text += &format!(
                    "{:.4} {:.4} {:.4} {:.4} {:.4} {:.4}\n",
                    a.x, a.y, a.z, b.x, b.y, b.z
                );
            }
            mocap_core::io::atomic::write_bytes_atomically(&path, text.as_bytes())?;
            files.pairs.push(path);
        }
    }
    Ok(files)
}

/// What `mocap fuse simulate` reports of one simulated sensor.
#[derive(Debug, Clone, Serialize)]
pub struct SimulatedSensorReport {
    pub id: u16,
    pub frames: usize,
    pub latency_seconds: f64,
    pub drop_rate: f64,
}

/// What [`simulate_to_folder`] made.
#[derive(Debug, Clone, Serialize)]
pub struct SimulationReport {
    pub sensors: Vec<SimulatedSensorReport>,
    /// Frames of the ground truth, and their rate.
    pub truth_frames: usize,
    pub fps: f64,
    pub files: SimulationFiles,
}

/// `mocap fuse simulate`: `options.sensors` sensors watching the BVH take at
/// `take` ([`simulate_capture`], `units_per_metre` guessed when `None`),
/// written to the folder `output` ([`write_simulation`], with NTU
/// `.skeleton` files when `ntu`).
pub fn simulate_to_folder(
    take: &std::path::Path,
    output: &std::path::Path,
    options: &SimulationOptions,
    units_per_metre: Option<f32>,
    ntu: bool,
) -> Result<SimulationReport> {
    if options.sensors == 0 {
        return Err(Error::Invalid(
            "a simulation needs at least one sensor".into(),
        ));
    }
    let motion = mocap_core::io::bvh::read_bvh(take)?;
    let capture = simulate_capture(&motion, units_per_metre, options)?;
    let simulation = &capture.simulation;
    let files = write_simulation(output, simulation, &capture.body, options.seed, ntu)?;
    Ok(SimulationReport {
        sensors: simulation
            .sensors
            .iter()
            .map(|s| SimulatedSensorReport {
                id: s.id,
                frames: s.frames.len(),
                latency_seconds: s.latency,
                drop_rate: s.drop_rate,
            })
            .collect(),
        truth_frames: simulation.truth.frames.len(),
        fps: simulation.truth.fps,
        files,
    })
}

/// For tests of other modules: the sample walk seen by three simulated
/// sensors (seed 2), written with its NTU files (cameras C000-C002, 194
/// frames) into a temporary folder that lives as long as the first value.
#[cfg(test)]
pub(crate) fn simulated_walk_files() -> (tempfile::TempDir, SimulationFiles) {
    let dir = tempfile::tempdir().unwrap();
    let options = SimulationOptions {
        sensors: 3,
        seed: 2,
        ..Default::default()
    };
    let report = simulate_to_folder(
        &mocap_testdata::sample_walk(),
        dir.path(),
        &options,
        None,
        true,
    )
    .unwrap();
    (dir, report.files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_distance_matches_simple_cases() {
        let d = segment_distance(
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.5, 1.0, -1.0),
            Vec3::new(0.5, 1.0, 1.0),
        );
        assert!((d - 1.0).abs() < 1e-6);
        let d = segment_distance(
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0),
        );
        assert!((d - 1.0).abs() < 1e-6);
    }

    #[test]
    fn a_hand_behind_the_back_is_occluded_from_the_front_only() {
        let mut pose = crate::body::tests::standing_pose();
        // The person faces +z; put the left hand behind the back.
        pose[HAND_LEFT] = Vec3::new(0.0, 1.1, -0.2);
        let front = Vec3::new(0.0, 1.0, 3.0);
        let back = Vec3::new(0.0, 1.0, -3.0);
        assert!(is_occluded(&pose, HAND_LEFT, front));
        assert!(!is_occluded(&pose, HAND_LEFT, back));
        assert!(!is_occluded(&pose, HEAD, front));
        assert!(
            !is_occluded(&pose, HIP_LEFT, front),
            "joints inside the torso capsule"
        );
        assert!(facing_of(&pose).dot(Vec3::Z) > 0.9, "{}", facing_of(&pose));
    }
}
