//! A trial captured by calibrated cameras, from its keypoint folders to BVH:
//! the entry point of `mocap cameras run`.
//!
//! The trial folder is laid out as Pose2Sim lays it out: one folder of
//! OpenPose JSON files per camera (`pose/cam01_json`, ..., or
//! `pose-associated/...`), the calibration in a `calibration` (or
//! `*Calib*`) folder of the trial or of a folder above it, and optionally
//! `Config.toml` files (the trial's, then its parents') giving the frame
//! rate (`[project] frame_rate`) and the layout (`[pose] pose_model`).

use std::path::{Path, PathBuf};

use glam::{DMat3, DVec3};
use mocap_core::rotation::Vec3;
use mocap_core::{Error, Motion, Result};
use mocap_fuse::{BodyModel, BvhOptions, JOINT_COUNT};

use crate::associate::{follow, people_in_frame, AssociationOptions, Track};
use crate::camera::{read_calibration, Camera, CameraRig, Format};
use crate::keypoints::{find_camera_folders, read_openpose_folder, CameraKeypoints, Person2d};
use crate::kinect::{kinect_pose, REQUIRED};
use crate::layout::Layout;
use crate::solve::{
    measure_person, measure_person_by_scores, triangulate_take, Frame3d, TriangulationOptions,
};

/// What `mocap cameras run` is asked to do.
#[derive(Debug, Clone)]
pub struct CaptureOptions {
    /// The trial folder (or a folder whose subfolders are the cameras').
    pub trial: PathBuf,
    /// The calibration file; found near the trial when `None`.
    pub calibration: Option<PathBuf>,
    /// The keypoint layout; from `Config.toml` or the keypoints themselves
    /// when `None`.
    pub layout: Option<Layout>,
    /// Frames per second; from `Config.toml` when `None`.
    pub fps: Option<f64>,
    /// How many people to write (the ones found in the most frames).
    pub people: usize,
    /// Hold each BVH's planted feet still and above the floor
    /// (mocap-feet) before it is written.
    pub feet: Option<mocap_feet::FeetOptions>,
    pub triangulation: TriangulationOptions,
    pub association: AssociationOptions,
}

impl CaptureOptions {
    pub fn new(trial: impl Into<PathBuf>) -> CaptureOptions {
        CaptureOptions {
            trial: trial.into(),
            calibration: None,
            layout: None,
            fps: None,
            people: 1,
            feet: None,
            triangulation: TriangulationOptions::default(),
            association: AssociationOptions::default(),
        }
    }
}

/// A trial's cameras and keypoints, read and checked against each other.
#[derive(Debug, Clone)]
pub struct Trial {
    pub calibration_path: PathBuf,
    pub rig: CameraRig,
    pub cameras: Vec<CameraKeypoints>,
    pub layout: Layout,
    /// Frames per second, and where that figure came from.
    pub fps: f64,
    pub fps_source: String,
    /// The first frame number of the trial and the number of frames (the
    /// union of every camera's).
    pub first_frame: usize,
    pub frames: usize,
    /// What was decided along the way, for the user.
    pub notes: Vec<String>,
}

impl Trial {
    /// The people camera `c` saw at frame `f` of the trial (counting from
    /// [`Trial::first_frame`]).
    pub fn view(&self, c: usize, f: usize) -> Option<&crate::keypoints::ViewFrame> {
        let camera = &self.cameras[c];
        let at = (self.first_frame + f).checked_sub(camera.first_frame)?;
        camera.frames.get(at)
    }
}

/// A value of `Config.toml`, looked up in the trial's folder first, then in
/// each folder above it (up to three), as Pose2Sim reads its configuration.
fn config_value(trial: &Path, table: &str, key: &str) -> Result<Option<(toml::Value, PathBuf)>> {
    for dir in trial.ancestors().take(4) {
        let path = dir.join("Config.toml");
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        let value: toml::Table = toml::from_str(&text).map_err(|e| {
            let (line, column) = e
                .span()
                .map(|s| mocap_core::error::line_column(&text, s.start))
                .unwrap_or((1, 1));
            Error::parse(&path, line, column, e.message().to_string())
        })?;
        if let Some(v) = value.get(table).and_then(|t| t.get(key)) {
            return Ok(Some((v.clone(), path)));
        }
    }
    Ok(None)
}

/// The calibration file near a trial: a `.toml`, `.yml`, `.yaml` or `.json`
/// file in a folder named like `calibration` (any case, any prefix) in the
/// trial's folder or one of the three above it.
fn find_calibration(trial: &Path) -> Result<PathBuf> {
    for dir in trial.ancestors().take(4) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            continue;
        };
        let mut folders: Vec<PathBuf> = entries
            .flatten()
            .map(|e| e.path())
            .filter(|p| {
                p.is_dir()
                    && p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| n.to_ascii_lowercase().contains("calib"))
            })
            .collect();
        folders.sort();
        for folder in folders {
            let mut files: Vec<PathBuf> = std::fs::read_dir(&folder)
                .map_err(|e| Error::io(&folder, e))?
                .flatten()
                .map(|e| e.path())
                .filter(|p| Format::of(p).is_ok())
                .collect();
            files.sort();
            if let Some(file) = files.into_iter().next() {
                return Ok(file);
            }
        }
    }
    Err(Error::Invalid(format!(
        "{}: no calibration found (a .toml, .yml or .json file in a `calibration` folder of the \
         trial or a folder above it); give one with --calib",
        trial.display()
    )))
}

/// Reads a trial: its calibration, its cameras' keypoints, its frame rate.
pub fn read_trial(options: &CaptureOptions) -> Result<Trial> {
    let mut notes = Vec::new();
    let calibration_path = match &options.calibration {
        Some(p) => p.clone(),
        None => {
            let p = find_calibration(&options.trial)?;
            notes.push(format!("calibration found: {}", p.display()));
            p
        }
    };
    let rig = read_calibration(&calibration_path)?;
    let folders = find_camera_folders(&options.trial)?;
    if folders.len() != rig.cameras.len() {
        return Err(Error::Invalid(format!(
            "{} has {} cameras but {} has {} camera keypoint folders ({}); they must match one to \
             one, in order",
            calibration_path.display(),
            rig.cameras.len(),
            options.trial.display(),
            folders.len(),
            folders
                .iter()
                .filter_map(|f| f.file_name()?.to_str())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    let configured = match options.layout {
        Some(l) => Some(l),
        None => match config_value(&options.trial, "pose", "pose_model")? {
            Some((toml::Value::String(s), path)) => {
                let layout = Layout::parse(&s).ok_or_else(|| {
                    Error::Invalid(format!(
                        "{}: pose_model '{s}' is not a layout mocap reads (BODY_25, BODY_25B, \
                         COCO_17, HALPE_26, BLAZEPOSE)",
                        path.display()
                    ))
                })?;
                notes.push(format!("layout {} from {}", layout.label(), path.display()));
                Some(layout)
            }
            _ => None,
        },
    };
    let mut cameras = Vec::with_capacity(folders.len());
    for folder in &folders {
        cameras.push(read_openpose_folder(folder, configured)?);
    }
    let layout = cameras[0].layout;
    if let Some(other) = cameras.iter().find(|c| c.layout != layout) {
        return Err(Error::Invalid(format!(
            "{} holds {} keypoints but {} holds {}; give the layout with --layout",
            cameras[0].folder.display(),
            layout.label(),
            other.folder.display(),
            other.layout.label()
        )));
    }
    if configured.is_none() {
        notes.push(format!("layout {} told from the keypoints", layout.label()));
    }
    for camera in cameras.iter().filter(|c| c.missing_files > 0) {
        notes.push(format!(
            "{}: {} frame files missing, taken as frames with nobody",
            camera.folder.display(),
            camera.missing_files
        ));
    }
    let first_frame = cameras.iter().map(|c| c.first_frame).min().unwrap_or(0);
    let end = cameras
        .iter()
        .map(|c| c.first_frame + c.frames.len())
        .max()
        .unwrap_or(0);
    let lengths: Vec<usize> = cameras.iter().map(|c| c.frames.len()).collect();
    if lengths.iter().any(|&l| l != lengths[0]) {
        notes.push(format!(
            "cameras hold different frame counts ({}): frames are matched by their number, \
             a camera's missing frames count as seeing nobody",
            lengths
                .iter()
                .map(|l| l.to_string())
                .collect::<Vec<_>>()
                .join("/")
        ));
    }
    let (fps, fps_source) = match options.fps {
        Some(fps) => (fps, "--fps".to_string()),
        None => match config_value(&options.trial, "project", "frame_rate")? {
            Some((toml::Value::Integer(i), path)) => (i as f64, path.display().to_string()),
            Some((toml::Value::Float(x), path)) => (x, path.display().to_string()),
            _ => {
                return Err(Error::Invalid(format!(
                    "{}: no frame rate (no `frame_rate` in a Config.toml of the trial or above \
                     it); give one with --fps",
                    options.trial.display()
                )))
            }
        },
    };
    if !(fps.is_finite() && fps > 0.0 && fps <= 10_000.0) {
        return Err(Error::Invalid(format!(
            "frame rate {fps} (from {fps_source}) must be between 0 and 10000"
        )));
    }
    Ok(Trial {
        calibration_path,
        rig,
        cameras,
        layout,
        fps,
        fps_source,
        first_frame,
        frames: end - first_frame,
        notes,
    })
}

/// The people found in a trial, each followed over its frames.
pub(crate) fn tracks(trial: &Trial, max_people: usize, options: &AssociationOptions) -> Vec<Track> {
    let empty = crate::keypoints::ViewFrame::default();
    let found = (0..trial.frames)
        .map(|f| {
            let views: Vec<&crate::keypoints::ViewFrame> = (0..trial.cameras.len())
                .map(|c| trial.view(c, f).unwrap_or(&empty))
                .collect();
            people_in_frame(&trial.rig.cameras, &views, max_people, options)
        })
        .collect();
    follow(found, options)
}

/// The detections of one person in one frame, per camera.
pub(crate) fn detections<'a>(
    trial: &'a Trial,
    track: &Track,
    f: usize,
) -> Vec<Option<&'a Person2d>> {
    match &track.frames[f] {
        None => vec![None; trial.cameras.len()],
        Some(choice) => choice
            .iter()
            .enumerate()
            .map(|(c, i)| i.and_then(|i| trial.view(c, f)?.people.get(i)))
            .collect(),
    }
}

/// One person triangulated over the trial.
#[derive(Debug, Clone)]
pub struct Person3d {
    /// One entry per frame of the trial.
    pub frames: Vec<Frame3d>,
    /// The person's bone lengths and ranges, measured on a first pass.
    pub body: BodyModel,
}

/// Triangulates the people of a trial (the `people` found in the most
/// frames) with `options.method`; for the methods that need the person's
/// bones, a first pass by score measures them.
pub fn triangulate_trial(
    trial: &Trial,
    people: usize,
    options: &TriangulationOptions,
    association: &AssociationOptions,
) -> Vec<Person3d> {
    let cameras: &[Camera] = &trial.rig.cameras;
    let tracks = tracks(trial, people.max(1) + 1, association);
    tracks
        .iter()
        .take(people)
        .map(|track| {
            let seen: Vec<Vec<Option<&Person2d>>> = (0..trial.frames)
                .map(|f| detections(trial, track, f))
                .collect();
            let person = options
                .method
                .needs_person()
                .then(|| measure_person_by_scores(cameras, trial.layout, &seen, options));
            let frames = triangulate_take(cameras, trial.layout, &seen, person.as_ref(), options);
            // The fitter takes bone lengths from the frames themselves; the
            // body is measured from them when no first pass was needed.
            let body =
                person.map_or_else(|| measure_person(trial.layout, &frames).body, |p| p.body);
            Person3d { frames, body }
        })
        .collect()
}

/// Each keypoint's positions over the frames with gaps filled: linear
/// between the frames around a gap, held before the first and after the
/// last. `None` for keypoints never triangulated.
pub(crate) fn fill_gaps(frames: &[Frame3d], keypoints: usize) -> Vec<Vec<Option<DVec3>>> {
    let mut out = vec![vec![None; keypoints]; frames.len()];
    for k in 0..keypoints {
        let known: Vec<(usize, DVec3)> = frames
            .iter()
            .enumerate()
            .filter_map(|(f, frame)| Some((f, frame.get(k).copied().flatten()?.position)))
            .collect();
        let (Some(&first), Some(&last)) = (known.first(), known.last()) else {
            continue;
        };
        for (f, row) in out.iter_mut().enumerate() {
            row[k] = Some(if f <= first.0 {
                first.1
            } else if f >= last.0 {
                last.1
            } else {
                let after = known.partition_point(|(g, _)| *g < f);
                let (g1, p1) = known[after];
                let (g0, p0) = known[after - 1];
                if g1 == f {
                    p1
                } else {
                    p0.lerp(p1, (f - g0) as f64 / (g1 - g0) as f64)
                }
            });
        }
    }
    out
}

/// The rotation that takes the calibration's world to a Y-up one: the
/// world axis (±x, ±y, ±z) nearest the person's mean direction from the
/// ankles to the shoulders is turned onto +y, by a proper rotation.
pub(crate) fn y_up(layout: Layout, filled: &[Vec<Option<DVec3>>]) -> (DMat3, String) {
    let mut up = DVec3::ZERO;
    for frame in filled {
        let get = |n: &str| layout.index_of(n).and_then(|i| frame[i]);
        if let (Some(a), Some(b), Some(c), Some(d)) = (
            get("LShoulder"),
            get("RShoulder"),
            get("LAnkle"),
            get("RAnkle"),
        ) {
            up += (a + b - c - d).normalize_or_zero();
        }
    }
    let axes = [
        (DVec3::X, "+x"),
        (DVec3::NEG_X, "-x"),
        (DVec3::Y, "+y"),
        (DVec3::NEG_Y, "-y"),
        (DVec3::Z, "+z"),
        (DVec3::NEG_Z, "-z"),
    ];
    let (axis, name) = axes
        .into_iter()
        .max_by(|a, b| a.0.dot(up).total_cmp(&b.0.dot(up)))
        .expect("six axes");
    let rotation = if axis == DVec3::Y {
        DMat3::IDENTITY
    } else if axis == DVec3::NEG_Y {
        DMat3::from_rotation_z(std::f64::consts::PI)
    } else {
        let q = glam::DQuat::from_rotation_arc(axis, DVec3::Y);
        DMat3::from_quat(q)
    };
    (
        rotation,
        format!("the calibration's {name} axis is up (from the person's stance)"),
    )
}

/// One person's keypoints as a BVH motion (Y up, centimetres), through
/// mocap-fuse's fitter; also the Kinect joints per frame (metres, Y up).
pub fn person_motion(
    layout: Layout,
    person: &Person3d,
    fps: f64,
) -> Result<(Motion, Vec<[Vec3; JOINT_COUNT]>, String)> {
    let filled = fill_gaps(&person.frames, layout.len());
    let (rotation, up_note) = y_up(layout, &filled);
    let mut poses = Vec::with_capacity(filled.len());
    for (f, frame) in filled.iter().enumerate() {
        let turned: Vec<Option<DVec3>> = frame.iter().map(|p| p.map(|p| rotation * p)).collect();
        let pose = kinect_pose(layout, &turned).ok_or_else(|| {
            let missing: Vec<&str> = REQUIRED
                .iter()
                .map(|(_, name)| *name)
                .filter(|n| layout.index_of(n).and_then(|i| turned[i]).is_none())
                .collect();
            Error::Invalid(format!(
                "frame {f}: no BVH can be fitted: {} never triangulated in the whole trial \
                 (seen by fewer than two cameras)",
                if missing.is_empty() {
                    "the head".to_string()
                } else {
                    missing.join(", ")
                }
            ))
        })?;
        poses.push(pose.joints);
    }
    let options = BvhOptions {
        units_per_metre: 100.0,
        fps,
    };
    let motion = mocap_fuse::poses_to_motion(&poses, &person.body, &options)?;
    Ok((motion, poses, up_note))
}

/// Bones whose length is followed over a trial, by canonical keypoint
/// names: limbs, feet, and the hip and shoulder widths. A rigid body keeps
/// them; how much they vary measures the capture without a ground truth.
pub const SPREAD_BONES: [(&str, &str); 14] = [
    ("LHip", "LKnee"),
    ("LKnee", "LAnkle"),
    ("RHip", "RKnee"),
    ("RKnee", "RAnkle"),
    ("LShoulder", "LElbow"),
    ("LElbow", "LWrist"),
    ("RShoulder", "RElbow"),
    ("RElbow", "RWrist"),
    ("LAnkle", "LHeel"),
    ("LAnkle", "LBigToe"),
    ("RAnkle", "RHeel"),
    ("RAnkle", "RBigToe"),
    ("LHip", "RHip"),
    ("LShoulder", "RShoulder"),
];

/// The standard deviation (mm) of each of [`SPREAD_BONES`] over the frames
/// where both its ends are known (`None` for bones seen in fewer than two
/// frames or absent from the layout). `point(frame, name)`: a keypoint's
/// position in metres.
pub fn bone_spread(
    frames: usize,
    point: impl Fn(usize, &str) -> Option<DVec3>,
) -> Vec<Option<f64>> {
    SPREAD_BONES
        .iter()
        .map(|(a, b)| {
            let lengths: Vec<f64> = (0..frames)
                .filter_map(|f| Some(point(f, a)?.distance(point(f, b)?)))
                .collect();
            if lengths.len() < 2 {
                return None;
            }
            let mean = lengths.iter().sum::<f64>() / lengths.len() as f64;
            let var = lengths.iter().map(|l| (l - mean).powi(2)).sum::<f64>()
                / (lengths.len() - 1) as f64;
            Some(var.sqrt() * 1000.0)
        })
        .collect()
}

/// The mean of the known values.
pub(crate) fn mean_of(values: &[Option<f64>]) -> Option<f64> {
    let known: Vec<f64> = values.iter().flatten().copied().collect();
    (!known.is_empty()).then(|| known.iter().sum::<f64>() / known.len() as f64)
}

/// How one keypoint was triangulated over a trial.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct KeypointReport {
    pub name: String,
    /// Frames it was triangulated in.
    pub frames: usize,
    /// Mean reprojection error over those frames (pixels).
    pub reprojection_px: Option<f64>,
    /// Mean number of views used.
    pub views: Option<f64>,
}

/// One person written.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PersonReport {
    pub output: PathBuf,
    /// Frames the person was found in (of the trial's).
    pub found_in: usize,
    pub keypoints: Vec<KeypointReport>,
    /// Mean reprojection error over every keypoint triangulated (pixels).
    pub reprojection_px: Option<f64>,
    /// Bone-length spread (mm) of [`SPREAD_BONES`] and their mean.
    pub bone_spread_mm: Vec<Option<f64>>,
    pub mean_bone_spread_mm: Option<f64>,
    /// What the feet stage did, when asked for.
    pub feet: Option<mocap_feet::FeetReport>,
}

/// What `mocap cameras run` did.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CaptureReport {
    pub trial: PathBuf,
    pub calibration: PathBuf,
    pub cameras: Vec<String>,
    pub layout: &'static str,
    pub fps: f64,
    pub fps_source: String,
    pub frames: usize,
    pub method: &'static str,
    pub people: Vec<PersonReport>,
    pub notes: Vec<String>,
}

/// The per-keypoint figures of a triangulated person.
pub fn keypoint_reports(layout: Layout, frames: &[Frame3d]) -> Vec<KeypointReport> {
    layout
        .names()
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let seen: Vec<_> = frames
                .iter()
                .filter_map(|f| f.get(k).copied().flatten())
                .collect();
            let n = seen.len();
            KeypointReport {
                name: name.to_string(),
                frames: n,
                reprojection_px: (n > 0)
                    .then(|| seen.iter().map(|k| k.error).sum::<f64>() / n as f64),
                views: (n > 0).then(|| seen.iter().map(|k| k.views as f64).sum::<f64>() / n as f64),
            }
        })
        .collect()
}

/// The output path of person `i` of `count`: the path itself for one
/// person, `NAME-2.bvh`... for the others.
fn person_output(output: &Path, i: usize) -> PathBuf {
    if i == 0 {
        return output.to_path_buf();
    }
    let stem = output
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("take");
    let ext = output.extension().and_then(|s| s.to_str()).unwrap_or("bvh");
    output.with_file_name(format!("{stem}-{}.{ext}", i + 1))
}

/// `mocap cameras run`: reads a trial, triangulates its people and writes
/// each as BVH (`output`, then `output-2.bvh`... for more people).
pub fn run_capture(options: &CaptureOptions, output: &Path) -> Result<CaptureReport> {
    let mut trial = read_trial(options)?;
    let people = triangulate_trial(
        &trial,
        options.people,
        &options.triangulation,
        &options.association,
    );
    if people.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: nobody was seen consistently by two cameras in any frame (is the calibration \
             the one of this capture?)",
            options.trial.display()
        )));
    }
    if people.len() < options.people {
        trial.notes.push(format!(
            "{} people asked for, {} found",
            options.people,
            people.len()
        ));
    }
    let mut reports = Vec::new();
    for (i, person) in people.iter().enumerate() {
        let (motion, _, up_note) = person_motion(trial.layout, person, trial.fps)?;
        if i == 0 {
            trial.notes.push(up_note);
        }
        let (motion, feet) = mocap_feet::plant_feet_if_asked(motion, options.feet.as_ref())?;
        let path = person_output(output, i);
        mocap_core::io::bvh::write_bvh(&path, &motion)?;
        let keypoints = keypoint_reports(trial.layout, &person.frames);
        let all: Vec<f64> = person
            .frames
            .iter()
            .flatten()
            .flatten()
            .map(|k| k.error)
            .collect();
        let layout = trial.layout;
        let spread = bone_spread(person.frames.len(), |f, name| {
            Some(
                person.frames[f]
                    .get(layout.index_of(name)?)
                    .copied()
                    .flatten()?
                    .position,
            )
        });
        reports.push(PersonReport {
            output: path,
            found_in: person
                .frames
                .iter()
                .filter(|f| f.iter().any(|k| k.is_some()))
                .count(),
            keypoints,
            reprojection_px: (!all.is_empty()).then(|| all.iter().sum::<f64>() / all.len() as f64),
            mean_bone_spread_mm: mean_of(&spread),
            bone_spread_mm: spread,
            feet,
        });
    }
    Ok(CaptureReport {
        trial: options.trial.clone(),
        calibration: trial.calibration_path.clone(),
        cameras: trial.rig.cameras.iter().map(|c| c.name.clone()).collect(),
        layout: trial.layout.label(),
        fps: trial.fps,
        fps_source: trial.fps_source.clone(),
        frames: trial.frames,
        method: options.triangulation.method.label(),
        people: reports,
        notes: trial.notes,
    })
}
