//! One frame's keypoints from every camera: the fusion report's confidence
//! applied to triangulation.
//!
//! The report fuses depth sensors joint by joint with the confidence
//! `C_kn = w(s_kn) · b(|l_pre,n − l_kn|) · r_kn`, propagated down the chain
//! (mocap-fuse's `confidence` module). A single camera has no depth, so
//! no bone length of its own; a *pair* of cameras does. Here:
//!
//! 1. every pair of cameras that sees the person triangulates a whole
//!    skeleton, which mocap-fuse's confidence model scores joint by joint
//!    against the person's bone lengths and ranges of motion (measured on a
//!    first pass over the take), exactly as it scores a depth sensor's
//!    skeleton;
//! 2. a view's weight for a keypoint is the keypoint's score (in place of the
//!    tracking state) × the mean of that confidence over the pairs the view is
//!    in: a view that makes every pair it joins grow a wrong bone is
//!    discounted, the others are not;
//! 3. the keypoint is triangulated from all views at once with these weights
//!    (weighted DLT), then views whose reprojection error stands out are left
//!    out, as Pose2Sim does.
//!
//! [`Method`] switches the steps on one after another, for the comparison
//! in `bench/results/cameras.md`.

use glam::DVec3;
use mocap_fuse::joint::{
    ANKLE_LEFT, ANKLE_RIGHT, ELBOW_LEFT, ELBOW_RIGHT, KNEE_LEFT, KNEE_RIGHT, WRIST_LEFT,
    WRIST_RIGHT,
};
use mocap_fuse::{
    confidences, BodyModel, BoneLengthFunction, ConfidenceModel, JointObservation, StateWeights,
    TrackingState, JOINT_COUNT, PARENTS,
};

use crate::camera::Camera;
use crate::keypoints::Person2d;
use crate::kinect::{kinect_joint_of, kinect_pose};
use crate::layout::Layout;
use crate::triangulate::{reprojection_error, triangulate, triangulate_robust, Sighting};

/// How views are weighted and chosen; each adds a step to the one before.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Every view that detected the keypoint, equal weights.
    Plain,
    /// Weighted by the keypoint's score.
    Scores,
    /// × the bone-length agreement of the camera pairs the view is in.
    BoneLength,
    /// × their range of motion too: the report's whole confidence.
    RangeOfMotion,
    /// The same weights, then views that disagree left out.
    Robust,
}

impl Method {
    pub const ALL: [Method; 5] = [
        Method::Plain,
        Method::Scores,
        Method::BoneLength,
        Method::RangeOfMotion,
        Method::Robust,
    ];

    /// The name used on the command line and in reports.
    pub fn label(self) -> &'static str {
        match self {
            Method::Plain => "plain",
            Method::Scores => "scores",
            Method::BoneLength => "bone-length",
            Method::RangeOfMotion => "range-of-motion",
            Method::Robust => "robust",
        }
    }

    /// Whether the method's confidence needs the person measured
    /// beforehand ([`measure_person_by_scores`]).
    pub fn needs_person(self) -> bool {
        self >= Method::BoneLength
    }

    pub fn parse(text: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.label() == text)
    }

    /// The confidence model of this method for a person whose bones vary
    /// by `bone_sigma` metres from frame to frame as a pair of cameras
    /// measures them.
    fn confidence(self, bone_sigma: f32) -> Option<ConfidenceModel> {
        // The keypoint's score stands in for the tracking state, so the state
        // weights are 1: what remains is the structural term.
        let base = ConfidenceModel {
            state_weights: StateWeights {
                not_tracked: 0.0,
                inferred: 1.0,
                tracked: 1.0,
            },
            bone_length: Some(BoneLengthFunction::Gaussian { sigma: bone_sigma }),
            // Not down the chain: a 2D estimator finds each keypoint on its
            // own, so a pair's wrong elbow says nothing of its wrist (a depth
            // sensor's tracker fits the wrist to the elbow, which is why the
            // report propagates). Propagated, the terms of a whole arm
            // multiply and the wrist's weights turn to noise
            // (docs/research/cameras.md).
            propagate: false,
            ..ConfidenceModel::default()
        };
        match self {
            Method::Plain | Method::Scores => None,
            Method::BoneLength => Some(ConfidenceModel {
                range_of_motion: None,
                ..base
            }),
            Method::RangeOfMotion | Method::Robust => Some(base),
        }
    }
}

/// Options of the triangulation.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TriangulationOptions {
    pub method: Method,
    /// Keypoints scored below this are not used (Pose2Sim's likelihood
    /// threshold).
    pub min_score: f32,
    /// Mean reprojection error (pixels) above which [`Method::Robust`] leaves
    /// out the worst view (Pose2Sim's default: 15).
    pub max_error: f64,
    /// Fewest views a keypoint is triangulated from.
    pub min_views: usize,
}

impl Default for TriangulationOptions {
    fn default() -> Self {
        TriangulationOptions {
            method: Method::Robust,
            min_score: 0.3,
            max_error: 15.0,
            min_views: 2,
        }
    }
}

/// One keypoint of one frame, triangulated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Keypoint3d {
    /// Metres, in the calibration's world.
    pub position: DVec3,
    /// Mean reprojection error over the views used (pixels).
    pub error: f64,
    /// How many views it was triangulated from.
    pub views: usize,
}

/// One frame's keypoints (layout order; `None`: too few views saw it).
pub type Frame3d = Vec<Option<Keypoint3d>>;

/// The sightings of keypoint `k` in the views that saw it well enough,
/// weighted by score (or 1 for [`Method::Plain`]).
fn sightings(
    cameras: &[Camera],
    people: &[Option<&Person2d>],
    k: usize,
    options: &TriangulationOptions,
) -> Vec<Sighting> {
    let mut out = Vec::with_capacity(people.len());
    for (c, person) in people.iter().enumerate() {
        let Some(&[x, y, score]) = person.and_then(|p| p.keypoints.get(k)) else {
            continue;
        };
        if score.is_nan() || score < options.min_score || !x.is_finite() || !y.is_finite() {
            continue;
        }
        let weight = match options.method {
            Method::Plain => 1.0,
            _ => score as f64,
        };
        out.push(Sighting::new(
            c,
            &cameras[c],
            glam::DVec2::new(x as f64, y as f64),
            weight,
        ));
    }
    out
}

/// The confidence of every keypoint as each pair of cameras sees it: the
/// pair's triangulated skeleton, scored by mocap-fuse's confidence model.
/// `pair_confidence[k][c]` is the mean over the pairs camera `c` is in
/// (`None` where no pair with `c` made a skeleton).
fn view_confidences(
    cameras: &[Camera],
    layout: Layout,
    all: &[Vec<Sighting>],
    body: &BodyModel,
    model: &ConfidenceModel,
) -> Vec<Vec<Option<f64>>> {
    let n = cameras.len();
    let mut sum = vec![vec![0.0f64; n]; all.len()];
    let mut count = vec![vec![0usize; n]; all.len()];
    let names = layout.names();
    for a in 0..n {
        for b in a + 1..n {
            let points: Vec<Option<DVec3>> = all
                .iter()
                .map(|views| {
                    let pair: Vec<Sighting> = views
                        .iter()
                        .filter(|s| s.camera == a || s.camera == b)
                        .map(|s| Sighting { weight: 1.0, ..*s })
                        .collect();
                    triangulate(cameras, &pair)
                })
                .collect();
            let Some(pose) = kinect_pose(layout, &points) else {
                continue;
            };
            let observed: [JointObservation; JOINT_COUNT] =
                std::array::from_fn(|j| JointObservation {
                    position: pose.joints[j],
                    state: TrackingState::Tracked,
                });
            let c = confidences(model, body, &observed);
            for (k, point) in points.iter().enumerate() {
                let (Some(_), Some(joint)) = (point, kinect_joint_of(names[k])) else {
                    continue;
                };
                for camera in [a, b] {
                    sum[k][camera] += c[joint] as f64;
                    count[k][camera] += 1;
                }
            }
        }
    }
    sum.iter()
        .zip(&count)
        .map(|(s, c)| {
            s.iter()
                .zip(c)
                .map(|(&s, &c)| (c > 0).then(|| s / c as f64))
                .collect()
        })
        .collect()
}

/// Triangulates one frame: `people[c]` is the person camera `c` saw (or
/// `None`); `person` the person's measurements, needed from
/// [`Method::BoneLength`] on (without them those methods weigh by score).
pub fn triangulate_frame(
    cameras: &[Camera],
    layout: Layout,
    people: &[Option<&Person2d>],
    person: Option<&PersonModel>,
    options: &TriangulationOptions,
) -> Frame3d {
    let mut all: Vec<Vec<Sighting>> = (0..layout.len())
        .map(|k| sightings(cameras, people, k, options))
        .collect();
    let model = person.and_then(|p| Some((options.method.confidence(p.bone_sigma)?, &p.body)));
    if let Some((model, body)) = model {
        let pair = view_confidences(cameras, layout, &all, body, &model);
        for (k, views) in all.iter_mut().enumerate() {
            for s in views.iter_mut() {
                if let Some(c) = pair[k][s.camera] {
                    s.weight *= c.max(model.floor as f64);
                }
            }
        }
    }
    all.iter()
        .map(|views| {
            if options.method == Method::Robust {
                let t = triangulate_robust(cameras, views, options.max_error, options.min_views)?;
                return Some(Keypoint3d {
                    position: t.point,
                    error: t.error,
                    views: t.used.len(),
                });
            }
            if views.len() < options.min_views.max(2) {
                return None;
            }
            let position = triangulate(cameras, views)?;
            let error = views
                .iter()
                .map(|s| reprojection_error(cameras, s, position))
                .sum::<f64>()
                / views.len() as f64;
            // Behind a camera that saw it: no point at all.
            if !error.is_finite() {
                return None;
            }
            Some(Keypoint3d {
                position,
                error,
                views: views.len(),
            })
        })
        .collect()
}

/// Triangulates every frame of one person: `detections[f][c]` is the
/// person camera `c` saw at frame `f` ([`triangulate_frame`]).
pub fn triangulate_take(
    cameras: &[Camera],
    layout: Layout,
    detections: &[Vec<Option<&Person2d>>],
    person: Option<&PersonModel>,
    options: &TriangulationOptions,
) -> Vec<Frame3d> {
    detections
        .iter()
        .map(|seen| triangulate_frame(cameras, layout, seen, person, options))
        .collect()
}

/// The person measured on a first pass triangulated by score alone, for
/// the methods whose confidence needs the person's bones.
pub fn measure_person_by_scores(
    cameras: &[Camera],
    layout: Layout,
    detections: &[Vec<Option<&Person2d>>],
    options: &TriangulationOptions,
) -> PersonModel {
    let by_score = TriangulationOptions {
        method: Method::Scores,
        ..*options
    };
    measure_person(
        layout,
        &triangulate_take(cameras, layout, detections, None, &by_score),
    )
}

/// What the confidence needs to know of the person.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PersonModel {
    /// Bone lengths and ranges of motion.
    pub body: BodyModel,
    /// The width (metres) of the bone-length term's Gaussian: how far a
    /// bone as one pair of cameras sees it may differ from the person's
    /// length before the pair is distrusted. It is six times the limb
    /// bones' typical spread over the first pass (their median robust
    /// standard deviation, 1.4826 × MAD): three for a three-sigma band, two
    /// because one pair measures a bone about twice as noisily as all the
    /// cameras together; within 3 to 15 cm. Cameras' triangulation noise
    /// depends on their distance, resolution and the estimator, so a fixed
    /// width (the depth sensors' 4 cm) would distrust every pair of a noisy
    /// rig or none of a precise one.
    pub bone_sigma: f32,
}

/// The person's bone lengths and ranges of motion, measured from frames
/// triangulated by score alone (Kinect joints made from keypoints count;
/// joints made up from nothing, such as a hand beyond the wrist, do too,
/// since their confidence only follows their parents').
pub fn measure_person(layout: Layout, frames: &[Frame3d]) -> PersonModel {
    let observed: Vec<[JointObservation; JOINT_COUNT]> = frames
        .iter()
        .filter_map(|f| {
            let points: Vec<Option<DVec3>> = f.iter().map(|k| k.map(|k| k.position)).collect();
            let pose = kinect_pose(layout, &points)?;
            Some(std::array::from_fn(|j| JointObservation {
                position: pose.joints[j],
                state: TrackingState::Tracked,
            }))
        })
        .collect();
    let body = BodyModel::measure(observed.iter(), mocap_fuse::MeasureOptions::default());
    // The limbs' bones: both their ends are keypoints (the made joints'
    // bones keep their lengths by construction).
    let limbs = [
        ELBOW_LEFT,
        WRIST_LEFT,
        ELBOW_RIGHT,
        WRIST_RIGHT,
        KNEE_LEFT,
        ANKLE_LEFT,
        KNEE_RIGHT,
        ANKLE_RIGHT,
    ];
    let mut spreads: Vec<f32> = limbs
        .into_iter()
        .filter_map(|n| {
            let parent = PARENTS[n]?;
            let mut lengths: Vec<f32> = observed
                .iter()
                .map(|o| o[n].position.distance(o[parent].position))
                .collect();
            (lengths.len() >= 10).then(|| 1.4826 * median_absolute_deviation(&mut lengths))
        })
        .collect();
    let bone_sigma = if spreads.is_empty() {
        0.05
    } else {
        (6.0 * median(&mut spreads)).clamp(0.03, 0.15)
    };
    PersonModel { body, bone_sigma }
}

fn median(values: &mut [f32]) -> f32 {
    values.sort_by(f32::total_cmp);
    values[values.len() / 2]
}

fn median_absolute_deviation(values: &mut [f32]) -> f32 {
    let m = median(values);
    let mut deviations: Vec<f32> = values.iter().map(|v| (v - m).abs()).collect();
    median(&mut deviations)
}
