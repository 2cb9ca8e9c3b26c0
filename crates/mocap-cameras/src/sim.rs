//! A simulator of calibrated RGB cameras filming a take through a 2D pose
//! estimator: a BVH take becomes a Pose2Sim-style trial (calibration,
//! per-camera OpenPose JSON, `Config.toml`) with its ground truth, so that
//! triangulation can be measured against what it should have found.
//!
//! # The truth
//!
//! The take's 25 Kinect v2 joints ([`mocap_fuse::truth_from_motion`]) are
//! put on a treadmill when the take travels more than 2 m, as mocap-fuse's
//! Kinect simulator does ([`mocap_fuse::center_truth`]: the straight-line
//! drift of the pelvis is taken off, so that a walk across a room stays
//! within the cameras' circle rather than walking through a camera),
//! sampled at each output frame (time `frame / fps`), moved so that the
//! mean pelvis (SpineBase) over the frames stands at the origin
//! horizontally, and turned from the BVH's Y-up world to the calibration's
//! Z-up world by the rotation `(x, y, z) ↦ (x, −z, y)` (a rotation, not a
//! mirror: left stays left). The BODY_25 keypoints are then:
//!
//! - taken from a Kinect joint: shoulders, elbows, wrists, hips, knees,
//!   ankles; `MidHip` = SpineBase; big toes = Foot;
//! - `Neck` = the midpoint of the shoulders, which is how OpenPose made its
//!   neck for training (COCO has none); not the Kinect SpineShoulder, which
//!   [`mocap_fuse::truth_from_motion`] takes from the rig's chest joint (25
//!   cm above the pelvis on Bandai's rig, well below the shoulders);
//! - placed at fixed offsets in the person's frame, built from the torso:
//!   `left` = LHip − RHip and `up` = Neck − MidHip, orthonormalised (left
//!   made perpendicular to up), `forward` = left × up. From the Kinect Head
//!   joint: `Nose` = Head + 0.10 forward; eyes = Head + 0.07 forward + 0.03
//!   up ± 0.035 left (LEye +, REye −); ears = Head ± 0.075 left;
//! - for the feet, a frame that turns with each foot: `along` = Ankle →
//!   BigToe, `outward` = perpendicular to the shin (Knee → Ankle) and to
//!   `along`, away from the body, and the foot's `up` = perpendicular to both,
//!   toward the knee. Heel = Ankle − 0.05 along − 0.05 up; small toe =
//!   BigToe + 0.04 outward. For a foot flat on the floor that is the heel 5
//!   cm behind and 5 cm below the ankle; unlike the horizontal projection of
//!   the foot, it stays on the foot at toe-off, when the foot points almost
//!   straight down (Bandai's walk does).
//!
//! The simulated estimator sees exactly these points, so an error measured
//! against them (MPJPE) is what the cameras and the triangulation lose, not
//! a difference of definitions between a BVH rig and a pose estimator.
//!
//! # The cameras
//!
//! `cameras` cameras stand evenly around a circle of `radius` metres about
//! the origin, from a random start angle, each moved along the circle by up
//! to ±15° and up or down by up to 0.2 m from `height`, all looking at
//! (0, 0, 1 m). They are OpenCV cameras (x right, y down in the image) of
//! `focal` pixels, the principal point at the image centre, with a mild
//! barrel distortion (k1 = −0.05, k2 = 0.01).
//!
//! # The estimator
//!
//! For each camera and frame, each keypoint:
//!
//! - behind the camera or outside the image: not detected (score 0, at
//!   (0, 0), as OpenPose writes it);
//! - else missed with probability `miss_rate` (score 0);
//! - else occluded (with `occlusion`) when it is farther from the camera
//!   than the torso centre (mean of hips and shoulders) by more than 0.1 m
//!   and, in the image, within the torso's projected half-width of the
//!   torso's centre line (mid-hip to neck): score drawn in 0.1–0.35,
//!   Gaussian noise of 4 × `pixel_noise` on each axis. The half-width is
//!   half the wider of the shoulders and the hips in the image, but no less
//!   than 0.12 m at the torso's distance: seen from the side the shoulders
//!   overlap, and the torso's thickness still hides the far arm;
//! - else seen: score drawn in 0.6–0.95, Gaussian noise on each axis of
//!   `pixel_noise × (0.5 + (0.95 − score) / 0.35)`: from half `pixel_noise`
//!   at the best score to 1.5 × at the worst, `pixel_noise` on average;
//! - a detected keypoint is, with probability `outlier_rate`, thrown 40–150
//!   px off in a random direction with a score drawn in 0.4–0.9 instead.
//!
//! Then with probability `swap_rate` per camera and frame the estimator
//! swaps one limb's left and right keypoints, with confident scores (0.6–0.95)
//! where they were detected: an arm (elbow and wrist) or a leg (knee, ankle,
//! big toe, small toe, heel), chosen at random; shoulders and hips, which
//! frame the torso, are kept. Detected points are kept inside the image. A
//! camera that detects no keypoint in a frame reports nobody.
//!
//! Everything random comes from one generator seeded with `seed`
//! ([`StdRng::seed_from_u64`]), drawn in a fixed order: the same take and
//! options give the same trial, file for file.

use std::path::{Path, PathBuf};

use glam::{DMat3, DVec2, DVec3};
use mocap_core::{Error, Motion, Result};
use mocap_fuse::joint::*;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};

use crate::camera::{write_calibration_toml, Camera, CameraRig};
use crate::keypoints::{write_openpose_frame, Person2d};
use crate::layout::Layout;
use crate::trc::{write_trc, zup_to_trc, Markers};

/// What the simulated cameras and estimator are like; see the module
/// documentation for how each is used.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CameraSimOptions {
    /// Number of cameras, evenly around the person.
    pub cameras: usize,
    /// Distance of the cameras from the take's centre (metres).
    pub radius: f64,
    /// Height of the cameras above the floor (metres), ±0.2 m each.
    pub height: f64,
    /// Image width and height (pixels).
    pub image: [f64; 2],
    /// Focal length (pixels).
    pub focal: f64,
    /// Standard deviation of the pixel noise of a confident keypoint, on
    /// average (pixels).
    pub pixel_noise: f64,
    /// Share of visible keypoints the estimator does not detect (score 0).
    pub miss_rate: f64,
    /// Share of camera frames where the estimator swaps one limb's left and
    /// right keypoints (an arm or a leg), with confident scores.
    pub swap_rate: f64,
    /// Share of detected keypoints thrown 40–150 px off, with a score of
    /// 0.4–0.9.
    pub outlier_rate: f64,
    /// Whether keypoints behind the torso are occluded: low score, more
    /// noise.
    pub occlusion: bool,
    /// Frames per second of the cameras; `None`: the take's.
    pub fps: Option<f64>,
    /// Seed of the cameras' placement and of the estimator's errors.
    pub seed: u64,
}

impl Default for CameraSimOptions {
    fn default() -> Self {
        CameraSimOptions {
            cameras: 4,
            radius: 3.5,
            height: 1.6,
            image: [1920.0, 1080.0],
            focal: 1100.0,
            pixel_noise: 2.5,
            miss_rate: 0.03,
            swap_rate: 0.02,
            outlier_rate: 0.02,
            occlusion: true,
            fps: None,
            seed: 1,
        }
    }
}

/// A take filmed by simulated cameras ([`simulate_cameras`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SimulatedTrial {
    /// The cameras, as their calibration file holds them.
    pub rig: CameraRig,
    /// The keypoint layout of the views and the truth ([`Layout::Body25`]).
    pub layout: Layout,
    /// Frames per second.
    pub fps: f64,
    /// `views[camera][frame]`: the people that camera's estimator reported
    /// (the one person, or nobody when no keypoint was detected).
    pub views: Vec<Vec<Vec<Person2d>>>,
    /// The true keypoints (layout order), metres, calibration world (Z up):
    /// `truth[frame][keypoint]`.
    pub truth: Vec<Vec<DVec3>>,
}

/// The most cameras a simulation takes, and the most camera frames (cameras
/// × frames): bounds that no real use comes near, against a mistyped option
/// that would fill the memory or the disk.
const MAX_CAMERAS: usize = 100;
const MAX_CAMERA_FRAMES: usize = 2_000_000;

/// Takes that travel further than this (metres) are put on a treadmill,
/// as mocap-fuse's simulator puts them: the cameras stand 3.5 m away, and the
/// bundled walk alone crosses 8 m.
const TREADMILL_ABOVE: f32 = 2.0;

/// Mild barrel distortion of every camera (OpenCV's k1 k2 p1 p2 k3).
const DISTORTION: [f64; 5] = [-0.05, 0.01, 0.0, 0.0, 0.0];

/// Where every camera looks (metres, Z up): the body's middle.
const TARGET: DVec3 = DVec3::new(0.0, 0.0, 1.0);

/// The range of scores of a seen keypoint, of an occluded one, of an
/// outlier.
const SEEN_SCORE: (f64, f64) = (0.6, 0.95);
const OCCLUDED_SCORE: (f64, f64) = (0.1, 0.35);
const OUTLIER_SCORE: (f64, f64) = (0.4, 0.9);

/// How far an outlier is thrown (pixels).
const OUTLIER_DISTANCE: (f64, f64) = (40.0, 150.0);

/// A keypoint this much farther from the camera than the torso centre
/// (metres) can be hidden by the torso.
const OCCLUSION_DEPTH: f64 = 0.1;

/// The least half-width of the torso, whatever the side it is seen from
/// (metres): half an adult's chest depth.
const TORSO_HALF_THICKNESS: f64 = 0.12;

/// The BODY_25 keypoints that the limb swaps exchange, as (left, right) name
/// pairs: an arm, or a leg.
const SWAPPED_ARM: [(&str, &str); 2] = [("LElbow", "RElbow"), ("LWrist", "RWrist")];
const SWAPPED_LEG: [(&str, &str); 5] = [
    ("LKnee", "RKnee"),
    ("LAnkle", "RAnkle"),
    ("LBigToe", "RBigToe"),
    ("LSmallToe", "RSmallToe"),
    ("LHeel", "RHeel"),
];

/// Films `motion` with simulated cameras through a simulated 2D pose
/// estimator (see the module documentation). Errors: options out of range
/// (no camera, a rate outside 0–1, a non-positive size...), a skeleton
/// whose joints the Kinect mapping cannot find.
pub fn simulate_cameras(motion: &Motion, options: &CameraSimOptions) -> Result<SimulatedTrial> {
    let fps = options.fps.unwrap_or_else(|| motion.fps());
    check_options(options, fps)?;
    let mut kinect = mocap_fuse::truth_from_motion(motion, None)?;
    if kinect.frames.is_empty() {
        return Err(Error::Invalid("the take has no frame to film".into()));
    }
    mocap_fuse::center_truth(&mut kinect, Some(TREADMILL_ABOVE));
    let frames = frame_count(kinect.duration(), fps);
    if frames.saturating_mul(options.cameras) > MAX_CAMERA_FRAMES {
        return Err(Error::Invalid(format!(
            "{frames} frames from {} cameras is more than the simulator makes ({MAX_CAMERA_FRAMES} \
             camera frames): lower the frame rate or the number of cameras",
            options.cameras
        )));
    }
    let layout = Layout::Body25;
    let truth = body_25_truth(&kinect, fps, frames, layout);

    let mut rng = StdRng::seed_from_u64(options.seed);
    let rig = place_cameras(options, &mut rng);
    let estimator = Estimator::new(options, layout);
    let views = rig
        .cameras
        .iter()
        .map(|camera| {
            truth
                .iter()
                .map(|points| estimator.view(camera, points, &mut rng))
                .collect()
        })
        .collect();
    Ok(SimulatedTrial {
        rig,
        layout,
        fps,
        views,
        truth,
    })
}

fn check_options(options: &CameraSimOptions, fps: f64) -> Result<()> {
    let invalid = |what: String| Err(Error::Invalid(format!("camera simulation: {what}")));
    if options.cameras == 0 || options.cameras > MAX_CAMERAS {
        return invalid(format!(
            "the number of cameras should be 1 to {MAX_CAMERAS}, not {}",
            options.cameras
        ));
    }
    let positive = [
        ("the radius", options.radius),
        ("the image width", options.image[0]),
        ("the image height", options.image[1]),
        ("the focal length", options.focal),
        ("the frame rate", fps),
    ];
    for (name, value) in positive {
        if !(value.is_finite() && value > 0.0) {
            return invalid(format!("{name} should be positive, not {value}"));
        }
    }
    if !options.height.is_finite() {
        return invalid(format!("the height {} is not a number", options.height));
    }
    if !(options.pixel_noise.is_finite() && options.pixel_noise >= 0.0) {
        return invalid(format!(
            "the pixel noise should be 0 or more, not {}",
            options.pixel_noise
        ));
    }
    let rates = [
        ("the miss rate", options.miss_rate),
        ("the swap rate", options.swap_rate),
        ("the outlier rate", options.outlier_rate),
    ];
    for (name, rate) in rates {
        if !(0.0..=1.0).contains(&rate) {
            return invalid(format!("{name} should be between 0 and 1, not {rate}"));
        }
    }
    Ok(())
}

/// The frames at `fps` within a take of `duration` seconds, the first at 0.
fn frame_count(duration: f64, fps: f64) -> usize {
    // A hair of tolerance: a 30 Hz take resampled at 30 Hz keeps its last
    // frame despite rounding in `duration`.
    let last = (duration * fps + 1e-6).floor();
    if last.is_finite() && last < usize::MAX as f64 {
        last as usize + 1
    } else {
        usize::MAX
    }
}

/// The BODY_25 keypoints of the take at each output frame, centred and Z up
/// (see the module documentation).
fn body_25_truth(
    kinect: &mocap_fuse::GroundTruth,
    fps: f64,
    frames: usize,
    layout: Layout,
) -> Vec<Vec<DVec3>> {
    // Y up to Z up: (x, y, z) ↦ (x, −z, y), a rotation about x.
    let z_up = |p: glam::Vec3| DVec3::new(p.x as f64, -p.z as f64, p.y as f64);
    let joints: Vec<[DVec3; 25]> = (0..frames)
        .map(|f| kinect.at(f as f64 / fps).map(z_up))
        .collect();
    let mean_pelvis = joints.iter().map(|j| j[SPINE_BASE]).sum::<DVec3>() / frames.max(1) as f64;
    let shift = DVec3::new(mean_pelvis.x, mean_pelvis.y, 0.0);
    // The points come in one fixed order: each of the layout's names is
    // looked up once, not at every frame.
    let order: Vec<usize> = match joints.first() {
        Some(j) => {
            let points = body_25_points(j);
            layout
                .names()
                .iter()
                .map(|name| {
                    points
                        .iter()
                        .position(|(n, _)| n == name)
                        .expect("every BODY_25 keypoint is defined")
                })
                .collect()
        }
        None => Vec::new(),
    };
    joints
        .iter()
        .map(|j| {
            let points = body_25_points(&j.map(|p| p - shift));
            order.iter().map(|&k| points[k].1).collect()
        })
        .collect()
}

/// The BODY_25 keypoints, by name, from the Kinect joints of one frame (Z
/// up, metres).
fn body_25_points(j: &[DVec3; 25]) -> [(&'static str, DVec3); 25] {
    let (mid_hip, neck) = (j[SPINE_BASE], j[SHOULDER_LEFT].midpoint(j[SHOULDER_RIGHT]));
    let up = (neck - mid_hip).normalize_or(DVec3::Z);
    let left = j[HIP_LEFT] - j[HIP_RIGHT];
    let left = (left - up * left.dot(up)).normalize_or(DVec3::NEG_X);
    let forward = left.cross(up);

    let head = j[HEAD];
    let eye = head + 0.07 * forward + 0.03 * up;
    // Each foot's own frame (see the module documentation). The shin and the
    // foot are far from parallel in any human pose; should they be, the
    // body's left stands in for the foot's side.
    let foot = |knee: usize, ankle: usize, toe: usize, side: f64| {
        let along = (j[toe] - j[ankle]).normalize_or(forward);
        let shin = j[ankle] - j[knee];
        let outward = shin.cross(along).normalize_or(left);
        let outward = if outward.dot(left) * side >= 0.0 {
            outward
        } else {
            -outward
        };
        let up = along.cross(outward);
        let up = if up.dot(shin) <= 0.0 { up } else { -up };
        let heel = j[ankle] - 0.05 * along - 0.05 * up;
        let small_toe = j[toe] + 0.04 * outward;
        (j[toe], small_toe, heel)
    };
    let (l_big, l_small, l_heel) = foot(KNEE_LEFT, ANKLE_LEFT, FOOT_LEFT, 1.0);
    let (r_big, r_small, r_heel) = foot(KNEE_RIGHT, ANKLE_RIGHT, FOOT_RIGHT, -1.0);
    [
        ("Nose", head + 0.10 * forward),
        ("Neck", neck),
        ("RShoulder", j[SHOULDER_RIGHT]),
        ("RElbow", j[ELBOW_RIGHT]),
        ("RWrist", j[WRIST_RIGHT]),
        ("LShoulder", j[SHOULDER_LEFT]),
        ("LElbow", j[ELBOW_LEFT]),
        ("LWrist", j[WRIST_LEFT]),
        ("MidHip", mid_hip),
        ("RHip", j[HIP_RIGHT]),
        ("RKnee", j[KNEE_RIGHT]),
        ("RAnkle", j[ANKLE_RIGHT]),
        ("LHip", j[HIP_LEFT]),
        ("LKnee", j[KNEE_LEFT]),
        ("LAnkle", j[ANKLE_LEFT]),
        ("REye", eye - 0.035 * left),
        ("LEye", eye + 0.035 * left),
        ("REar", head - 0.075 * left),
        ("LEar", head + 0.075 * left),
        ("LBigToe", l_big),
        ("LSmallToe", l_small),
        ("LHeel", l_heel),
        ("RBigToe", r_big),
        ("RSmallToe", r_small),
        ("RHeel", r_heel),
    ]
}

/// The cameras around the circle (see the module documentation), named
/// `cam01`, `cam02`... as their keypoint folders.
fn place_cameras(options: &CameraSimOptions, rng: &mut StdRng) -> CameraRig {
    let n = options.cameras;
    let start = rng.random_range(0.0..std::f64::consts::TAU);
    let jitter = 15f64.to_radians();
    let [width, height] = options.image;
    let cameras = (0..n)
        .map(|k| {
            let azimuth = start
                + k as f64 * std::f64::consts::TAU / n as f64
                + rng.random_range(-jitter..=jitter);
            let z = options.height + rng.random_range(-0.2..=0.2);
            let centre = DVec3::new(
                options.radius * azimuth.cos(),
                options.radius * azimuth.sin(),
                z,
            );
            let forward = (TARGET - centre).normalize();
            let right = forward.cross(DVec3::Z).normalize();
            let down = forward.cross(right);
            // Rows of R are the camera's axes in world coordinates.
            let rotation = DMat3::from_cols(right, down, forward).transpose();
            Camera {
                name: format!("cam{:02}", k + 1),
                size: options.image,
                matrix: DMat3::from_cols(
                    DVec3::new(options.focal, 0.0, 0.0),
                    DVec3::new(0.0, options.focal, 0.0),
                    DVec3::new(width / 2.0, height / 2.0, 1.0),
                ),
                distortion: DISTORTION,
                rotation,
                translation: -(rotation * centre),
            }
        })
        .collect();
    CameraRig { cameras }
}

/// The simulated 2D pose estimator's settings, with the layout's indices it
/// needs looked up once.
struct Estimator {
    options: CameraSimOptions,
    /// Torso keypoints: shoulders and hips (left, right), mid-hip, neck.
    shoulders: (usize, usize),
    hips: (usize, usize),
    mid_hip: usize,
    neck: usize,
    arm: Vec<(usize, usize)>,
    leg: Vec<(usize, usize)>,
}

impl Estimator {
    fn new(options: &CameraSimOptions, layout: Layout) -> Estimator {
        let at = |name: &str| {
            layout
                .index_of(name)
                .expect("BODY_25 has every keypoint the estimator uses")
        };
        let pairs = |names: &[(&str, &str)]| names.iter().map(|&(l, r)| (at(l), at(r))).collect();
        Estimator {
            options: options.clone(),
            shoulders: (at("LShoulder"), at("RShoulder")),
            hips: (at("LHip"), at("RHip")),
            mid_hip: at("MidHip"),
            neck: at("Neck"),
            arm: pairs(&SWAPPED_ARM),
            leg: pairs(&SWAPPED_LEG),
        }
    }

    /// What `camera`'s estimator reports of the person at `points` (the
    /// truth of one frame): one person, or nobody.
    fn view(&self, camera: &Camera, points: &[DVec3], rng: &mut StdRng) -> Vec<Person2d> {
        let o = &self.options;
        let [width, height] = o.image;
        let inside = |p: DVec2| p.x >= 0.0 && p.x < width && p.y >= 0.0 && p.y < height;
        let pixels: Vec<Option<DVec2>> = points
            .iter()
            .map(|&p| camera.project(p).filter(|&q| inside(q)))
            .collect();
        let torso = o.occlusion.then(|| self.torso(camera, points)).flatten();
        let unit = Normal::new(0.0, 1.0).expect("a unit normal");
        let mut keypoints = vec![[0.0f32; 3]; points.len()];
        for (k, pixel) in pixels.iter().enumerate() {
            let Some(pixel) = *pixel else { continue };
            if rng.random_bool(o.miss_rate) {
                continue;
            }
            let occluded = torso
                .as_ref()
                .is_some_and(|t| t.hides(camera, points[k], pixel));
            let (score, sigma) = if occluded {
                (
                    rng.random_range(OCCLUDED_SCORE.0..=OCCLUDED_SCORE.1),
                    4.0 * o.pixel_noise,
                )
            } else {
                let score = rng.random_range(SEEN_SCORE.0..=SEEN_SCORE.1);
                let sigma =
                    o.pixel_noise * (0.5 + (SEEN_SCORE.1 - score) / (SEEN_SCORE.1 - SEEN_SCORE.0));
                (score, sigma)
            };
            let noise = DVec2::new(unit.sample(rng), unit.sample(rng)) * sigma;
            let (mut seen, mut score) = (pixel + noise, score);
            if rng.random_bool(o.outlier_rate) {
                let angle = rng.random_range(0.0..std::f64::consts::TAU);
                let distance = rng.random_range(OUTLIER_DISTANCE.0..=OUTLIER_DISTANCE.1);
                seen = pixel + DVec2::from_angle(angle) * distance;
                score = rng.random_range(OUTLIER_SCORE.0..=OUTLIER_SCORE.1);
            }
            // The estimator reports points of the image only.
            let seen = seen.clamp(DVec2::ZERO, DVec2::new(width, height));
            keypoints[k] = [seen.x as f32, seen.y as f32, score as f32];
        }
        if rng.random_bool(o.swap_rate) {
            let limb = if rng.random_bool(0.5) {
                &self.arm
            } else {
                &self.leg
            };
            for &(l, r) in limb {
                keypoints.swap(l, r);
                for k in [l, r] {
                    if keypoints[k][2] > 0.0 {
                        keypoints[k][2] = rng.random_range(SEEN_SCORE.0..=SEEN_SCORE.1) as f32;
                    }
                }
            }
        }
        if keypoints.iter().all(|k| k[2] == 0.0) {
            return Vec::new();
        }
        vec![Person2d {
            id: None,
            keypoints,
        }]
    }

    /// The torso as `camera` sees it, for occlusion; `None` when a torso
    /// keypoint is behind the camera.
    fn torso(&self, camera: &Camera, points: &[DVec3]) -> Option<Torso> {
        let image = |k: usize| camera.project(points[k]);
        let (ls, rs) = (image(self.shoulders.0)?, image(self.shoulders.1)?);
        let (lh, rh) = (image(self.hips.0)?, image(self.hips.1)?);
        let centre = (points[self.shoulders.0]
            + points[self.shoulders.1]
            + points[self.hips.0]
            + points[self.hips.1])
            / 4.0;
        let depth = depth(camera, centre);
        let thickness = camera.matrix.x_axis.x * TORSO_HALF_THICKNESS / depth;
        Some(Torso {
            depth,
            line: (image(self.mid_hip)?, image(self.neck)?),
            half_width: (ls.distance(rs).max(lh.distance(rh)) / 2.0).max(thickness),
        })
    }
}

/// The torso in one camera's image.
struct Torso {
    /// Distance of the torso centre (mean of hips and shoulders) along the
    /// camera's axis (metres).
    depth: f64,
    /// The torso's centre line in the image: mid-hip to neck (pixels).
    line: (DVec2, DVec2),
    /// Half the torso's width in the image: half the wider of the shoulders
    /// and the hips, at least [`TORSO_HALF_THICKNESS`] (pixels).
    half_width: f64,
}

impl Torso {
    /// Whether the torso hides the point at `world`, seen at `pixel`.
    fn hides(&self, camera: &Camera, world: DVec3, pixel: DVec2) -> bool {
        depth(camera, world) > self.depth + OCCLUSION_DEPTH
            && segment_distance(pixel, self.line) <= self.half_width
    }
}

/// Distance of a world point along `camera`'s optical axis (metres).
fn depth(camera: &Camera, world: DVec3) -> f64 {
    camera.to_camera(world).z
}

/// Distance from `p` to the segment `a`–`b`.
fn segment_distance(p: DVec2, (a, b): (DVec2, DVec2)) -> f64 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + ab * t)
}

/// Writes a simulated trial as Pose2Sim lays a trial out, in `folder`
/// (created; refused when it exists and is not empty):
///
/// - `calibration/Calib_sim.toml`: the cameras (Pose2Sim TOML);
/// - `pose/camNN_json/<trial>_<frame:06>_keypoints.json`: each camera's
///   keypoints (OpenPose JSON), one file per frame from 0, `<trial>` being
///   the folder's name, cameras numbered from 01;
/// - `Config.toml`: `[project] frame_rate` and `[pose] pose_model =
///   "BODY_25"`;
/// - `truth.trc`: the true keypoints, on Pose2Sim's TRC axes ([`zup_to_trc`])
///   as Pose2Sim writes its triangulation, so the two compare directly.
pub fn write_simulated_trial(trial: &SimulatedTrial, folder: &Path) -> Result<()> {
    let occupied = match std::fs::read_dir(folder) {
        Ok(mut entries) => entries.next().is_some(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => false,
        Err(e) => return Err(Error::io(folder, e)),
    };
    if occupied {
        return Err(Error::Invalid(format!(
            "{}: the folder exists and is not empty; give a new or empty folder for the \
             simulated trial",
            folder.display()
        )));
    }
    if trial.views.len() != trial.rig.cameras.len() {
        return Err(Error::Invalid(format!(
            "a simulated trial with {} cameras but views from {}",
            trial.rig.cameras.len(),
            trial.views.len()
        )));
    }
    let create = |dir: &Path| std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e));
    create(folder)?;

    let calibration = folder.join("calibration");
    create(&calibration)?;
    write_calibration_toml(&trial.rig, &calibration.join("Calib_sim.toml"))?;

    let name = folder
        .file_name()
        .map_or("trial".into(), |n| n.to_string_lossy().into_owned());
    for (c, frames) in trial.views.iter().enumerate() {
        let dir = folder.join("pose").join(format!("cam{:02}_json", c + 1));
        create(&dir)?;
        for (f, people) in frames.iter().enumerate() {
            write_openpose_frame(&dir.join(format!("{name}_{f:06}_keypoints.json")), people)?;
        }
    }

    let mut project = toml::Table::new();
    project.insert("frame_rate".into(), toml::Value::Float(trial.fps));
    let mut pose = toml::Table::new();
    pose.insert(
        "pose_model".into(),
        toml::Value::String(trial.layout.label().into()),
    );
    let mut config = toml::Table::new();
    config.insert("project".into(), toml::Value::Table(project));
    config.insert("pose".into(), toml::Value::Table(pose));
    let text = format!(
        "# A trial simulated by mocap from a BVH take: {} cameras, {} frames.\n\n{}",
        trial.rig.cameras.len(),
        trial.truth.len(),
        toml::to_string(&config).map_err(|e| Error::Invalid(format!("Config.toml: {e}")))?
    );
    mocap_core::io::atomic::write_bytes_atomically(&folder.join("Config.toml"), text.as_bytes())?;

    let markers = Markers {
        names: trial.layout.names().iter().map(|n| n.to_string()).collect(),
        fps: trial.fps,
        positions: trial
            .truth
            .iter()
            .map(|frame| frame.iter().map(|&p| zup_to_trc(p)).collect())
            .collect(),
    };
    write_trc(&folder.join("truth.trc"), &markers)
}

/// What `mocap cameras simulate` wrote.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SimulationReport {
    pub folder: PathBuf,
    pub cameras: usize,
    pub frames: usize,
    pub fps: f64,
    pub layout: &'static str,
}

/// `mocap cameras simulate`: a take filmed by simulated cameras, written as
/// a trial folder.
pub fn simulate_to_folder(
    take: &std::path::Path,
    folder: &std::path::Path,
    options: &CameraSimOptions,
) -> Result<SimulationReport> {
    let motion = mocap_core::io::read_motion(take)?;
    let trial = simulate_cameras(&motion, options)?;
    write_simulated_trial(&trial, folder)?;
    Ok(SimulationReport {
        folder: folder.to_path_buf(),
        cameras: trial.rig.cameras.len(),
        frames: trial.truth.len(),
        fps: trial.fps,
        layout: trial.layout.label(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trc::{read_trc, trc_to_zup};

    fn walk() -> Motion {
        mocap_core::io::bvh::read_bvh(&mocap_testdata::sample_walk()).unwrap()
    }

    /// Options with no estimator error at all.
    fn exact() -> CameraSimOptions {
        CameraSimOptions {
            pixel_noise: 0.0,
            miss_rate: 0.0,
            swap_rate: 0.0,
            outlier_rate: 0.0,
            occlusion: false,
            ..CameraSimOptions::default()
        }
    }

    fn index(name: &str) -> usize {
        Layout::Body25.index_of(name).unwrap()
    }

    /// Every keypoint of every view, with its camera, frame and index.
    fn keypoints(
        trial: &SimulatedTrial,
    ) -> impl Iterator<Item = (usize, usize, usize, [f32; 3])> + '_ {
        trial.views.iter().enumerate().flat_map(|(c, frames)| {
            frames.iter().enumerate().flat_map(move |(f, people)| {
                people.iter().flat_map(move |p| {
                    p.keypoints
                        .iter()
                        .enumerate()
                        .map(move |(k, &kp)| (c, f, k, kp))
                })
            })
        })
    }

    /// Where keypoint `k` of frame `f` falls in camera `c`'s image, when it
    /// does.
    fn true_pixel(trial: &SimulatedTrial, c: usize, f: usize, k: usize) -> Option<DVec2> {
        let [w, h] = trial.rig.cameras[c].size;
        trial.rig.cameras[c]
            .project(trial.truth[f][k])
            .filter(|p| p.x >= 0.0 && p.x < w && p.y >= 0.0 && p.y < h)
    }

    #[test]
    fn the_truth_is_a_person_standing_on_the_floor_of_a_z_up_world_facing_their_walk() {
        let trial = simulate_cameras(&walk(), &exact()).unwrap();
        assert_eq!(trial.layout, Layout::Body25);
        assert!((trial.fps - 30.0).abs() < 0.01, "{}", trial.fps);
        // 6.5 s at 30 Hz.
        assert!(
            (190..=200).contains(&trial.truth.len()),
            "{}",
            trial.truth.len()
        );
        let mid_hip = index("MidHip");
        let mean = trial.truth.iter().map(|f| f[mid_hip]).sum::<DVec3>() / trial.truth.len() as f64;
        assert!(mean.x.abs() < 1e-9 && mean.y.abs() < 1e-9, "{mean}");
        assert!((0.7..1.2).contains(&mean.z), "pelvis height {}", mean.z);
        // A foot on the floor, the nose above the neck above the hips, and
        // the person within the cameras' circle (on the treadmill).
        for frame in &trial.truth {
            let lowest = ["LHeel", "RHeel", "LBigToe", "RBigToe"]
                .map(|n| frame[index(n)].z)
                .into_iter()
                .fold(f64::INFINITY, f64::min);
            assert!(
                (0.0..0.1).contains(&lowest),
                "lowest foot point at {lowest}"
            );
            assert!(frame[index("Nose")].z > frame[index("Neck")].z);
            assert!(frame[index("Neck")].z > frame[mid_hip].z + 0.3);
            assert!(frame[mid_hip].truncate().length() < 1.0);
        }
        // Not mirrored: the person's forward (left × up, from their own left
        // hip) is the way the take walks, turned Z up.
        let take = mocap_fuse::truth_from_motion(&walk(), None).unwrap();
        let walked = take.frames.last().unwrap()[SPINE_BASE] - take.frames[0][SPINE_BASE];
        let walked = DVec3::new(walked.x as f64, -walked.z as f64, walked.y as f64);
        assert!(walked.length() > 1.0, "walked {walked}");
        let facing = trial
            .truth
            .iter()
            .filter(|f| {
                let left = f[index("LHip")] - f[index("RHip")];
                let forward = left.cross(DVec3::Z);
                forward.dot(walked) > 0.0
            })
            .count();
        assert!(facing > trial.truth.len() * 9 / 10, "{facing}");
        // The feet: the heel a rigid point of the foot, behind the ankle
        // and the toes, the small toe outside the big toe.
        let heel_to_toe = |f: &[DVec3], side: &str| {
            f[index(&format!("{side}BigToe"))] - f[index(&format!("{side}Heel"))]
        };
        let length = heel_to_toe(&trial.truth[0], "L").length();
        for f in &trial.truth {
            let left = f[index("LHip")] - f[index("RHip")];
            for side in ["L", "R"] {
                assert!((heel_to_toe(f, side).length() - length).abs() < 0.01);
                let ankle = f[index(&format!("{side}Ankle"))];
                let toe = f[index(&format!("{side}BigToe"))];
                assert!(heel_to_toe(f, side).dot(toe - ankle) > 0.0);
            }
            assert!((f[index("LSmallToe")] - f[index("LBigToe")]).dot(left) > 0.0);
            assert!((f[index("RSmallToe")] - f[index("RBigToe")]).dot(left) < 0.0);
        }
    }

    #[test]
    fn without_errors_every_visible_keypoint_is_the_truths_projection() {
        let trial = simulate_cameras(&walk(), &exact()).unwrap();
        assert_eq!(trial.rig.cameras.len(), 4);
        let (mut visible, mut total) = (0, 0);
        for c in 0..4 {
            let camera = &trial.rig.cameras[c];
            // Upright in the image (y down): the nose above the ankles.
            let p = |k: usize| camera.project(trial.truth[0][k]).unwrap();
            assert!(p(index("Nose")).y < p(index("LAnkle")).y - 200.0);
            for f in 0..trial.truth.len() {
                for k in 0..25 {
                    total += 1;
                    let reported = trial.views[c][f].first().map(|p| p.keypoints[k]);
                    match true_pixel(&trial, c, f, k) {
                        Some(pixel) => {
                            visible += 1;
                            let [x, y, s] = reported.expect("a person where keypoints show");
                            assert!(s >= 0.6, "score {s}");
                            let d = pixel.distance(DVec2::new(x as f64, y as f64));
                            assert!(d < 1e-3, "camera {c} frame {f} keypoint {k}: {d} px");
                        }
                        None => assert!(reported.is_none_or(|kp| kp[2] == 0.0)),
                    }
                }
            }
        }
        // Most of the person is in view of most cameras.
        assert!(visible > total * 8 / 10, "{visible} of {total}");
    }

    #[test]
    fn the_written_trial_reads_back_as_it_was_simulated() {
        let trial = simulate_cameras(&walk(), &exact()).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let folder = dir.path().join("walk");
        write_simulated_trial(&trial, &folder).unwrap();

        // The files: a calibration, a Config.toml, the truth, and a frame
        // file per camera and frame.
        let frames = trial.truth.len();
        let mut files = Vec::new();
        let mut stack = vec![folder.clone()];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    stack.push(path);
                } else {
                    files.push(path.strip_prefix(&folder).unwrap().to_path_buf());
                }
            }
        }
        assert_eq!(files.len(), 4 * frames + 3, "{files:?}");
        for f in ["calibration/Calib_sim.toml", "Config.toml", "truth.trc"] {
            assert!(files.contains(&f.into()), "{f} missing");
        }
        assert!(files.contains(&"pose/cam04_json/walk_000000_keypoints.json".into()));
        let last = format!("pose/cam01_json/walk_{:06}_keypoints.json", frames - 1);
        assert!(files.contains(&last.into()));

        let config: toml::Table =
            toml::from_str(&std::fs::read_to_string(folder.join("Config.toml")).unwrap()).unwrap();
        assert_eq!(config["project"]["frame_rate"].as_float(), Some(trial.fps));
        assert_eq!(config["pose"]["pose_model"].as_str(), Some("BODY_25"));

        // The truth, through Pose2Sim's axes and back.
        let markers = read_trc(&folder.join("truth.trc")).unwrap();
        assert_eq!(markers.names, Layout::Body25.names());
        assert_eq!(markers.positions.len(), frames);
        for (read, truth) in markers.positions.iter().zip(&trial.truth) {
            for (p, q) in read.iter().zip(truth) {
                assert_eq!(trc_to_zup(*p), *q);
            }
        }
        // Y up in the file, as Pose2Sim writes it.
        assert!(markers.positions[0][index("Nose")].y > 1.3);

        // The keypoints and the calibration: the truth projects through the
        // calibration read back onto the keypoints read back.
        let rig =
            crate::camera::read_calibration(&folder.join("calibration/Calib_sim.toml")).unwrap();
        assert_eq!(rig.cameras.len(), 4);
        for c in 0..4 {
            let read = crate::keypoints::read_openpose_folder(
                &folder.join(format!("pose/cam{:02}_json", c + 1)),
                Some(Layout::Body25),
            )
            .unwrap();
            assert_eq!(read.frames.len(), frames);
            for (f, frame) in read.frames.iter().enumerate() {
                assert_eq!(frame.people, trial.views[c][f]);
                for person in &frame.people {
                    for (k, &[x, y, s]) in person.keypoints.iter().enumerate() {
                        if s > 0.0 {
                            let p = rig.cameras[c].project(trial.truth[f][k]).unwrap();
                            let d = p.distance(DVec2::new(x as f64, y as f64));
                            assert!(d < 1e-3, "camera {c} frame {f} keypoint {k}: {d} px");
                        }
                    }
                }
            }
        }

        // Never over an earlier trial.
        let e = write_simulated_trial(&trial, &folder).unwrap_err();
        assert!(e.to_string().contains("not empty"), "{e}");
    }

    #[test]
    fn the_same_seed_gives_the_same_trial_and_another_seed_another() {
        let motion = walk();
        let options = CameraSimOptions::default();
        let a = simulate_cameras(&motion, &options).unwrap();
        let b = simulate_cameras(&motion, &options).unwrap();
        assert_eq!(a, b);
        let c = simulate_cameras(&motion, &CameraSimOptions { seed: 2, ..options }).unwrap();
        assert_eq!(a.truth, c.truth);
        assert_ne!(a.rig, c.rig);
        assert_ne!(a.views, c.views);
    }

    /// The share of `hit` among `of`, with the counts for messages.
    fn rate(hit: usize, of: usize) -> f64 {
        assert!(of > 500, "too few to measure a rate: {of}");
        hit as f64 / of as f64
    }

    #[test]
    fn the_error_rates_come_out_as_asked() {
        let motion = walk();
        // Measured with this seed: misses 2.83%, outliers 2.10%, swaps 9.6%:
        // within a fifth of what was asked (a binomial's spread over these
        // counts is 4-11% of the rate).
        let near = |measured: f64, asked: f64| (measured - asked).abs() < 0.2 * asked;

        // Misses: visible keypoints reported undetected.
        let options = CameraSimOptions {
            miss_rate: 0.03,
            ..exact()
        };
        let trial = simulate_cameras(&motion, &options).unwrap();
        let (mut missed, mut visible) = (0, 0);
        for (c, f, k, kp) in keypoints(&trial) {
            if true_pixel(&trial, c, f, k).is_some() {
                visible += 1;
                missed += usize::from(kp[2] == 0.0);
            }
        }
        let measured = rate(missed, visible);
        assert!(near(measured, 0.03), "miss rate {measured}");

        // Outliers: detected keypoints 40 px or more off.
        let trial = simulate_cameras(
            &motion,
            &CameraSimOptions {
                outlier_rate: 0.02,
                ..exact()
            },
        )
        .unwrap();
        let (mut thrown, mut detected) = (0, 0);
        for (c, f, k, [x, y, s]) in keypoints(&trial) {
            if s > 0.0 {
                detected += 1;
                let d = true_pixel(&trial, c, f, k)
                    .unwrap()
                    .distance(DVec2::new(x as f64, y as f64));
                if d > 1e-3 {
                    // Clamped to the image, an outlier may land nearer.
                    assert!(d < 150.01 && (0.4..=0.9).contains(&s), "{d} px, score {s}");
                    thrown += 1;
                }
            }
        }
        let measured = rate(thrown, detected);
        assert!(near(measured, 0.02), "outlier rate {measured}");

        // Swaps: camera frames whose one limb shows the other side (fewer
        // camera frames than keypoints: a higher rate to measure it).
        let trial = simulate_cameras(
            &motion,
            &CameraSimOptions {
                swap_rate: 0.1,
                ..exact()
            },
        )
        .unwrap();
        let (mut swapped, mut views) = (0, 0);
        let pairs = [("LWrist", "RWrist"), ("LAnkle", "RAnkle")];
        for (c, frames) in trial.views.iter().enumerate() {
            for (f, people) in frames.iter().enumerate() {
                let Some(person) = people.first() else {
                    continue;
                };
                views += 1;
                let crossed = pairs.iter().any(|&(l, r)| {
                    let (l, r) = (index(l), index(r));
                    let (Some(tl), Some(tr)) =
                        (true_pixel(&trial, c, f, l), true_pixel(&trial, c, f, r))
                    else {
                        return false;
                    };
                    let at = |k: usize| {
                        DVec2::new(person.keypoints[k][0] as f64, person.keypoints[k][1] as f64)
                    };
                    tl.distance(tr) > 1.0 && at(l).distance(tr) < 1e-3 && at(r).distance(tl) < 1e-3
                });
                swapped += usize::from(crossed);
            }
        }
        let measured = rate(swapped, views);
        assert!(near(measured, 0.1), "swap rate {measured}");

        // Occlusion: some keypoints, not most, hidden behind the torso, and
        // noisier than the rest.
        let trial = simulate_cameras(
            &motion,
            &CameraSimOptions {
                occlusion: true,
                pixel_noise: 2.5,
                ..exact()
            },
        )
        .unwrap();
        let (mut hidden, mut seen) = (Vec::new(), Vec::new());
        for (c, f, k, [x, y, s]) in keypoints(&trial) {
            if s > 0.0 {
                let d = true_pixel(&trial, c, f, k)
                    .unwrap()
                    .distance(DVec2::new(x as f64, y as f64));
                if s < 0.5 { &mut hidden } else { &mut seen }.push(d);
            }
        }
        let share = rate(hidden.len(), hidden.len() + seen.len());
        // 3.2% measured with the default cameras on the bundled walk:
        // mostly the far shoulder and the far arm seen from the side.
        assert!((0.02..0.05).contains(&share), "occluded share {share}");
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        // Mean distance of a 2D Gaussian of s.d. σ per axis: σ √(π/2).
        let expected = 2.5 * (std::f64::consts::PI / 2.0).sqrt();
        assert!(
            (mean(&seen) - expected).abs() < 0.15 * expected,
            "{}",
            mean(&seen)
        );
        assert!(
            mean(&hidden) > 3.0 * mean(&seen),
            "{} {}",
            mean(&hidden),
            mean(&seen)
        );
    }

    #[test]
    fn bad_options_are_refused() {
        let motion = walk();
        for options in [
            CameraSimOptions {
                cameras: 0,
                ..CameraSimOptions::default()
            },
            CameraSimOptions {
                miss_rate: 1.5,
                ..CameraSimOptions::default()
            },
            CameraSimOptions {
                focal: 0.0,
                ..CameraSimOptions::default()
            },
            CameraSimOptions {
                fps: Some(f64::NAN),
                ..CameraSimOptions::default()
            },
            CameraSimOptions {
                fps: Some(1e9),
                ..CameraSimOptions::default()
            },
        ] {
            assert!(simulate_cameras(&motion, &options).is_err(), "{options:?}");
        }
    }
}
