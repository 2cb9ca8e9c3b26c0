//! Evaluation on ground truth (`mocap fuse eval`): simulate sensors watching
//! real takes, fuse with each method, compare with the truth.
//!
//! Per take, sensor count and seed: the simulator makes the recordings; the
//! person is measured ([`BodyModel::measure`]) from a *second* simulated
//! capture of the same take (another seed, so other sensor places and
//! noise), as one would measure a person beforehand; each method fuses the
//! recordings; metrics are taken against the ground truth on the fused grid:
//! - **MPJPE**: mean per-joint position error over the 25 joints (mm);
//! - **bone error**: mean `|l_fused - l_pre|` of the hip-knee and knee-ankle
//!   bones, both sides (mm), the report's own figure;
//! - **jitter**: mean norm of the second difference of joint positions
//!   between consecutive frames (mm per frame^2); the truth's is reported for
//!   reference.
//!
//! "Best single sensor" is, per run, the sensor with the lowest MPJPE
//! (an oracle choice, which favours it), over the instants it saw.

use std::path::{Path, PathBuf};

use mocap_core::ops::trim;
use mocap_core::rotation::Vec3;
use mocap_core::{Error, Motion, Result};
use serde::{Deserialize, Serialize};

use crate::body::{BodyModel, MeasureOptions};
use crate::bvh::{fit_skeleton, poses_on_skeleton, regular_poses, BoneLengthSource, BvhOptions};
use crate::calib::Calibration;
use crate::confidence::BoneLengthFunction;
use crate::fusion::{Fuser, FusionOptions, OneEuroParams};
use crate::kinect::GroundTruth;
use crate::kinect::{joint::*, JOINT_COUNT};
use crate::offline::{fuse_streams, views_at, SensorStreams};
use crate::sim::{simulate_capture, SimulatedCapture, SimulationOptions};

/// A take as the capture stage makes it: `motion` watched by the simulated
/// sensors of `options` (the person measured from a second capture), fused
/// offline by the best fusion ([`FusionOptions::best`]) and fitted as a BVH
/// as `mocap fuse run` does (bone lengths from the fused take), with the
/// truth it watched on the same skeleton (cm): `(fused, truth)`, frame for
/// frame from the first fused instant. What a denoiser of fused captures is
/// measured on (`mocap clean eval --fused`).
pub fn simulated_fused_take(
    motion: &Motion,
    options: &SimulationOptions,
) -> Result<(Motion, Motion)> {
    let SimulatedCapture {
        simulation: sim,
        body,
        ..
    } = simulate_capture(motion, None, options)?;
    let truth = &sim.truth;
    let streams = SensorStreams::new(sim.sensors.iter().flat_map(|s| s.frames.iter().cloned()));
    let mut fuser = Fuser::new(FusionOptions::best(), body.clone());
    let fused: Vec<_> = fuse_streams(
        &streams,
        &sim.calibration(),
        &mut fuser,
        truth.fps,
        Some(0.0),
    )
    .into_iter()
    .filter(|f| f.time <= truth.duration())
    .collect();
    let first = fused
        .first()
        .ok_or_else(|| Error::Invalid("the simulated sensors saw nothing to fuse".into()))?;
    // The fused motion starts at the first fused instant, a frame of the
    // truth's grid (instants are multiples of the period).
    let skip = ((first.time * truth.fps).round() as usize).min(truth.frames.len());
    let bvh = BvhOptions {
        units_per_metre: 100.0,
        fps: truth.fps,
    };
    let poses = regular_poses(&fused, truth.fps);
    let fitted = fit_skeleton(&poses, &body, BoneLengthSource::Fused, bvh.units_per_metre)?;
    let fused = poses_on_skeleton(&poses, &fitted, &bvh)?;
    let truth = poses_on_skeleton(&truth.frames[skip..], &fitted, &bvh)?;
    let n = fused.frame_count().min(truth.frame_count());
    Ok((trim(&fused, 0..n)?, trim(&truth, 0..n)?))
}

/// How the sensors' poses are known in the evaluation.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CalibrationSource {
    /// The simulator's true poses.
    Truth,
    /// Calibrated from the body in the recordings ([`crate::align::calibrate_from_body`]).
    Body,
    /// A calibration file (`mocap fuse calibrate`'s), for recordings: the
    /// simulator of BVH takes places its own sensors.
    File(PathBuf),
}

/// Options of `mocap fuse eval`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EvalOptions {
    /// BVH files, or folders whose `.bvh` files are all used.
    pub inputs: Vec<PathBuf>,
    pub sensor_counts: Vec<usize>,
    pub seeds: Vec<u64>,
    pub calibration: CalibrationSource,
    /// Template for the simulation (sensor count and seed are overridden).
    pub simulation: SimulationOptions,
    /// Length units per metre of the BVH files; guessed when `None`.
    pub units_per_metre: Option<f32>,
    /// An ASF skeleton whose joint limits give joint ranges
    /// ([`crate::body::ranges_from_asf`]): when given, two more methods use
    /// them instead of the measured ranges.
    pub limits: Option<PathBuf>,
}

impl Default for EvalOptions {
    fn default() -> Self {
        EvalOptions {
            inputs: Vec::new(),
            sensor_counts: vec![2, 3, 4],
            seeds: vec![1, 2, 3],
            calibration: CalibrationSource::Truth,
            simulation: SimulationOptions::default(),
            units_per_metre: None,
            limits: None,
        }
    }
}

/// The metrics of one method at one sensor count, averaged over runs.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MethodResult {
    pub method: String,
    pub sensors: usize,
    pub mpjpe_mm: f64,
    /// Hip-knee and knee-ankle length error against the measured lengths.
    pub bone_error_mm: f64,
    pub jitter_mm: f64,
    /// Mean position error of each of the 25 joints (Kinect v2 order, mm).
    #[serde(default)]
    pub per_joint_mm: Vec<f64>,
    /// Standard deviation over the runs of each joint's mean error (mm).
    #[serde(default)]
    pub per_joint_sd_mm: Vec<f64>,
    /// Runs averaged (clips x seeds).
    pub runs: usize,
}

/// The evaluation's result.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EvalReport {
    pub clips: Vec<String>,
    pub seeds: Vec<u64>,
    pub calibration: CalibrationSource,
    pub results: Vec<MethodResult>,
    /// Jitter of the ground truth itself (mm per frame^2).
    pub truth_jitter_mm: f64,
    /// Mean share of joint observations per state over all runs:
    /// NotTracked, Inferred, Tracked.
    pub state_shares: [f64; 3],
    /// Share of sensor frames with left and right swapped (seen from behind).
    pub swapped_share: f64,
    /// With calibration from the body: how far the sensors' poses are from
    /// the truth, over all calibrated (non-reference) sensors of all runs.
    pub calibration_error: Option<CalibrationError>,
}

/// How far calibrated sensor poses are from the true ones.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
pub struct CalibrationError {
    pub sensors: usize,
    pub mean_degrees: f64,
    pub max_degrees: f64,
    pub mean_metres: f64,
    pub max_metres: f64,
}

/// The methods compared, in table order. `None` is the best single sensor.
pub fn methods() -> Vec<(String, Option<FusionOptions>)> {
    let with = |f: &dyn Fn(&mut FusionOptions)| {
        let mut o = FusionOptions::state_only();
        f(&mut o);
        Some(o)
    };
    let gaussian4 = BoneLengthFunction::Gaussian { sigma: 0.04 };
    let gaussian8 = BoneLengthFunction::Gaussian { sigma: 0.08 };
    vec![
        ("best single sensor".into(), None),
        ("state only (report baseline)".into(), with(&|_| {})),
        (
            "+ bone length, linear 1-5d".into(),
            with(&|o| o.confidence.bone_length = Some(BoneLengthFunction::Linear { a: 5.0 })),
        ),
        (
            "+ bone length, inverse 1/(1+20d)".into(),
            with(&|o| o.confidence.bone_length = Some(BoneLengthFunction::Inverse { a: 20.0 })),
        ),
        (
            "+ bone length, gaussian 4 cm (report method)".into(),
            with(&|o| o.confidence.bone_length = Some(gaussian4)),
        ),
        (
            "+ range of motion (report, all terms)".into(),
            with(&|o| {
                o.confidence.bone_length = Some(gaussian4);
                o.confidence.range_of_motion = Some(Default::default());
            }),
        ),
        (
            "bone length gaussian 8 cm, not propagated".into(),
            with(&|o| {
                o.confidence.bone_length = Some(gaussian8);
                o.confidence.propagate = false;
            }),
        ),
        (
            "state only + swap repair".into(),
            with(&|o| o.swap_repair = true),
        ),
        (
            "report (all terms) + swap repair".into(),
            with(&|o| {
                o.confidence.bone_length = Some(gaussian4);
                o.confidence.range_of_motion = Some(Default::default());
                o.swap_repair = true;
            }),
        ),
        (
            "swap repair + bone 8 cm unpropagated + ROM".into(),
            with(&|o| {
                o.confidence.bone_length = Some(gaussian8);
                o.confidence.propagate = false;
                o.confidence.range_of_motion = Some(Default::default());
                o.swap_repair = true;
            }),
        ),
        (
            "previous best: + robust reweighting (c = 25 cm), swap by the feet".into(),
            Some(FusionOptions {
                knee_cue: false,
                ..FusionOptions::best()
            }),
        ),
        (
            "best: + swap repair by feet and knees".into(),
            Some(FusionOptions::best()),
        ),
        (
            "best + Savitzky-Golay smoothing (offline, 7 frames)".into(),
            Some(FusionOptions::preset("best-smooth").expect("a preset")),
        ),
        (
            "best + depth weighting, Inferred 0.07, learnt reliability".into(),
            Some({
                let mut o = FusionOptions::best();
                o.confidence.state_weights.inferred = 0.07;
                o.depth_reference = Some(3.0);
                o.adaptive_rate = Some(0.02);
                o
            }),
        ),
        (
            "best + One Euro filter".into(),
            Some(FusionOptions {
                smoothing: Some(OneEuroParams::default()),
                ..FusionOptions::best()
            }),
        ),
    ]
}

/// The `.bvh` files of the inputs (folders are listed, sorted).
pub fn collect_bvh_files(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(input)
                .map_err(|e| Error::io(input, e))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")))
                .collect();
            found.sort();
            files.extend(found);
        } else if input.exists() {
            files.push(input.clone());
        } else {
            return Err(Error::Invalid(format!(
                "{}: no such file or folder",
                input.display()
            )));
        }
    }
    if files.is_empty() {
        return Err(Error::Invalid("no BVH files in the inputs".into()));
    }
    Ok(files)
}

#[derive(Default, Clone)]
struct Sums {
    mpjpe: f64,
    bone: f64,
    jitter: f64,
    per_joint: [f64; JOINT_COUNT],
    per_joint_squares: [f64; JOINT_COUNT],
    runs: usize,
}

/// The metrics of one run (one clip, seed, sensor count and method).
#[derive(Clone, Copy)]
struct RunMetrics {
    mpjpe: f64,
    bone: f64,
    jitter: f64,
    per_joint: [f64; JOINT_COUNT],
}

/// Runs the evaluation.
pub fn evaluate(options: &EvalOptions) -> Result<EvalReport> {
    evaluate_with(options, &mut |_, _| {})
}

/// Runs the evaluation, calling `progress(clips done, clips)` after each clip.
pub fn evaluate_with(
    options: &EvalOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<EvalReport> {
    let files = collect_bvh_files(&options.inputs)?;
    let limit_ranges = match &options.limits {
        Some(asf) => Some(crate::body::ranges_from_asf(asf)?),
        None => None,
    };
    let mut methods = methods();
    // Methods with the ASF ranges: marked by this prefix, run with a body
    // whose ranges are replaced.
    const ASF: &str = "ASF ranges: ";
    if limit_ranges.is_some() {
        let mut report_swap = FusionOptions::report();
        report_swap.swap_repair = true;
        methods.push((
            format!("{ASF}report (all terms) + swap repair"),
            Some(report_swap),
        ));
        methods.push((format!("{ASF}best"), Some(FusionOptions::best())));
    }
    let mut calibration_error = CalibrationError::default();
    let mut sums = vec![vec![Sums::default(); methods.len()]; options.sensor_counts.len()];
    let mut truth_jitter = (0.0, 0usize);
    let mut states = [0f64; 3];
    let (mut swapped, mut frames_seen) = (0usize, 0usize);
    let mut clips = Vec::new();
    for path in &files {
        let motion = mocap_core::io::bvh::read_bvh(path)?;
        clips.push(
            path.file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned(),
        );
        for (ki, &k) in options.sensor_counts.iter().enumerate() {
            for &seed in &options.seeds {
                let mut sim_options = options.simulation;
                sim_options.sensors = k;
                sim_options.seed = seed.wrapping_mul(1_000_003).wrapping_add(k as u64);
                let SimulatedCapture {
                    simulation: sim,
                    body,
                    ..
                } = simulate_capture(&motion, options.units_per_metre, &sim_options)?;
                let truth = &sim.truth;
                let streams =
                    SensorStreams::new(sim.sensors.iter().flat_map(|s| s.frames.iter().cloned()));
                for s in &sim.sensors {
                    for f in &s.frames {
                        for j in &f.joints {
                            states[j.state as usize] += 1.0;
                        }
                        frames_seen += 1;
                        let truth_pose = truth.at(f.timestamp);
                        let face = crate::fusion::facing_of(&truth_pose);
                        let to = ((s.pose.translation - truth_pose[SPINE_BASE])
                            * Vec3::new(1.0, 0.0, 1.0))
                        .normalize_or_zero();
                        if face.dot(to)
                            < options
                                .simulation
                                .model
                                .behind_angle_degrees
                                .to_radians()
                                .cos()
                        {
                            swapped += 1;
                        }
                    }
                }
                let calibration = match &options.calibration {
                    // A file places real sensors, not the simulator's
                    // (`evaluate_inputs` refuses it for BVH takes).
                    CalibrationSource::Truth | CalibrationSource::File(_) => sim.calibration(),
                    CalibrationSource::Body => {
                        // Relative poses from the body; the world is put where
                        // the reference sensor truly is, so that the result
                        // can be compared with the ground truth.
                        let found =
                            crate::align::calibrate_from_body(&streams, &Default::default())?;
                        let truth_calibration = sim.calibration();
                        let world_from_reference = *truth_calibration
                            .get(found.reference)
                            .expect("the simulator calibrates every sensor");
                        let mut c = found.calibration.clone();
                        for s in c.sensors.iter_mut() {
                            s.transform = world_from_reference.then_after(&s.transform);
                            if s.id != found.reference {
                                let truth = truth_calibration
                                    .get(s.id)
                                    .expect("the simulator calibrates every sensor");
                                let degrees =
                                    s.transform
                                        .rotation
                                        .angle_between(truth.rotation)
                                        .to_degrees() as f64;
                                let metres =
                                    (s.transform.translation - truth.translation).length() as f64;
                                let e = &mut calibration_error;
                                e.sensors += 1;
                                e.mean_degrees += degrees;
                                e.mean_metres += metres;
                                e.max_degrees = e.max_degrees.max(degrees);
                                e.max_metres = e.max_metres.max(metres);
                            }
                        }
                        c
                    }
                };
                if ki == 0 && seed == options.seeds[0] {
                    let poses: Vec<[Vec3; JOINT_COUNT]> =
                        (0..truth.frames.len()).map(|i| truth.frames[i]).collect();
                    truth_jitter.0 += jitter(&poses);
                    truth_jitter.1 += 1;
                }
                let asf_body = limit_ranges.as_ref().map(|ranges| BodyModel {
                    ranges: ranges.clone(),
                    ..body.clone()
                });
                for (mi, (name, method)) in methods.iter().enumerate() {
                    let body_here = match (&asf_body, name.starts_with(ASF)) {
                        (Some(b), true) => b,
                        _ => &body,
                    };
                    let m = match method {
                        Some(o) => run_method(&streams, &calibration, truth, body_here, *o),
                        None => best_single(&streams, &calibration, truth, &body),
                    };
                    let Some(m) = m else {
                        continue;
                    };
                    let s = &mut sums[ki][mi];
                    s.mpjpe += m.mpjpe;
                    s.bone += m.bone;
                    s.jitter += m.jitter;
                    for n in 0..JOINT_COUNT {
                        s.per_joint[n] += m.per_joint[n];
                        s.per_joint_squares[n] += m.per_joint[n] * m.per_joint[n];
                    }
                    s.runs += 1;
                }
            }
        }
        progress(clips.len(), files.len());
    }
    let total_states: f64 = states.iter().sum();
    let mut results = Vec::new();
    for (ki, &k) in options.sensor_counts.iter().enumerate() {
        for (mi, (name, _)) in methods.iter().enumerate() {
            let s = &sums[ki][mi];
            let n = s.runs.max(1) as f64;
            results.push(MethodResult {
                method: name.clone(),
                sensors: k,
                mpjpe_mm: s.mpjpe / n,
                bone_error_mm: s.bone / n,
                jitter_mm: s.jitter / n,
                per_joint_mm: s.per_joint.iter().map(|e| e / n).collect(),
                per_joint_sd_mm: (0..JOINT_COUNT)
                    .map(|j| {
                        let mean = s.per_joint[j] / n;
                        (s.per_joint_squares[j] / n - mean * mean).max(0.0).sqrt()
                    })
                    .collect(),
                runs: s.runs,
            });
        }
    }
    Ok(EvalReport {
        clips,
        seeds: options.seeds.clone(),
        calibration: options.calibration.clone(),
        results,
        truth_jitter_mm: truth_jitter.0 / truth_jitter.1.max(1) as f64,
        state_shares: states.map(|s| s / total_states.max(1.0)),
        swapped_share: swapped as f64 / frames_seen.max(1) as f64,
        calibration_error: (calibration_error.sensors > 0).then(|| {
            let n = calibration_error.sensors as f64;
            CalibrationError {
                mean_degrees: calibration_error.mean_degrees / n,
                mean_metres: calibration_error.mean_metres / n,
                ..calibration_error
            }
        }),
    })
}

/// What `mocap fuse eval` measured: BVH takes against their ground truth,
/// or real recordings by bone-length consistency. As JSON it is the report
/// itself.
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum Evaluation {
    /// Simulated sensors on BVH takes ([`evaluate`]).
    Truth(EvalReport),
    /// Recordings without ground truth, one report per take
    /// ([`evaluate_consistency`]).
    Consistency(Vec<ConsistencyReport>),
}

impl Evaluation {
    /// The report as Markdown, headed by the command that made it.
    pub fn markdown(&self, command: &str) -> String {
        match self {
            Evaluation::Truth(report) => report_markdown(report, command),
            Evaluation::Consistency(reports) => consistency_markdown(reports, command),
        }
    }
}

/// Whether a file is a recording (`.skeleton`, `.jsonl`) rather than a take.
fn is_recording(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("skeleton") || e.eq_ignore_ascii_case("jsonl"))
}

/// `mocap fuse eval`: BVH takes or folders (`options.inputs`) are evaluated
/// against their ground truth ([`evaluate_with`]); recordings (NTU
/// `.skeleton`, one file per camera of a take, or `.jsonl`) by bone-length
/// consistency ([`evaluate_recordings`]). Calls `progress(done, total)` after
/// each take.
pub fn evaluate_inputs(
    options: &EvalOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Evaluation> {
    // A folder without BVH takes is a folder of recordings.
    let mut inputs = Vec::new();
    for input in &options.inputs {
        let takes = input.is_dir()
            && !mocap_core::io::find_files(std::slice::from_ref(input), &["bvh"])?.is_empty();
        if input.is_dir() && !takes {
            let found =
                mocap_core::io::find_files(std::slice::from_ref(input), &["skeleton", "jsonl"])?;
            if found.is_empty() {
                return Err(Error::Invalid(format!(
                    "{}: no BVH takes and no recordings (.skeleton, .jsonl) in this folder",
                    input.display()
                )));
            }
            inputs.extend(found);
        } else {
            inputs.push(input.clone());
        }
    }
    let recordings = inputs.iter().filter(|p| is_recording(p)).count();
    if recordings == inputs.len() {
        let calibration = match &options.calibration {
            CalibrationSource::File(path) => Some(Calibration::read(path)?),
            // Recordings have no true calibration: from the body.
            CalibrationSource::Body | CalibrationSource::Truth => None,
        };
        Ok(Evaluation::Consistency(evaluate_recordings(
            &inputs,
            calibration.as_ref(),
            progress,
        )?))
    } else if recordings == 0 {
        if let CalibrationSource::File(path) = &options.calibration {
            return Err(Error::Invalid(format!(
                "{}: a calibration file applies to recordings; BVH takes are watched by simulated \
                 sensors the simulator places (truth) or that are calibrated from the body",
                path.display()
            )));
        }
        Ok(Evaluation::Truth(evaluate_with(options, progress)?))
    } else {
        Err(Error::Invalid(
            "give either BVH takes (simulated sensors, ground truth) or recordings (.skeleton, .jsonl), not both".into(),
        ))
    }
}

/// The consistency evaluation ([`evaluate_consistency`]) of each take of the
/// recordings ([`group_takes`]) with the `state`, `report` and `best`
/// fusion methods at 30 fused frames per second, the sensors placed by
/// `calibration` (or calibrated from the body of each take). Calls
/// `progress(done, total)` after each take.
pub fn evaluate_recordings(
    recordings: &[PathBuf],
    calibration: Option<&Calibration>,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Vec<ConsistencyReport>> {
    let takes = group_takes(recordings);
    let methods: Vec<(String, FusionOptions)> = ["state", "report", "best"]
        .iter()
        .map(|m| Ok((format!("fused ({m})"), FusionOptions::preset(m)?)))
        .collect::<Result<_>>()?;
    let mut reports = Vec::new();
    for (take, files) in &takes {
        let frames = crate::recording::read_recordings(files)?;
        reports.push(evaluate_consistency(
            take,
            frames,
            &methods,
            30.0,
            calibration,
        )?);
        progress(reports.len(), takes.len());
    }
    Ok(reports)
}

/// One chart of [`EvalReport::per_joint_charts`]: grouped bars of each
/// joint's mean position error, one series per method.
#[derive(Debug, Clone, PartialEq)]
pub struct PerJointChart {
    pub sensors: usize,
    pub title: String,
    /// The Kinect v2 joint names, in SDK order.
    pub joints: Vec<String>,
    pub series: Vec<PerJointSeries>,
}

/// One method's bars in a [`PerJointChart`].
#[derive(Debug, Clone, PartialEq)]
pub struct PerJointSeries {
    /// The method and its MPJPE.
    pub label: String,
    /// Mean error per joint (mm).
    pub values: Vec<f32>,
    /// Standard deviation over the runs per joint (mm).
    pub errors: Vec<f32>,
}

impl EvalReport {
    /// Per sensor count, each joint's mean position error for the best
    /// single sensor, the report's baseline and method, and the best
    /// version, with the standard deviation over runs (what `mocap fuse eval
    /// --plots` draws).
    pub fn per_joint_charts(&self) -> Vec<PerJointChart> {
        let shown = |name: &str| {
            name == "best single sensor"
                || name.starts_with("state only (")
                || name.contains("(report method)")
                || name.starts_with("best:")
        };
        let joints: Vec<String> = crate::kinect::JOINT_NAMES
            .iter()
            .map(|name| name.to_string())
            .collect();
        let mut counts: Vec<usize> = self.results.iter().map(|r| r.sensors).collect();
        counts.dedup();
        let mut charts = Vec::new();
        for k in counts {
            let series: Vec<PerJointSeries> = self
                .results
                .iter()
                .filter(|r| {
                    r.sensors == k && shown(&r.method) && r.per_joint_mm.len() == joints.len()
                })
                .map(|r| PerJointSeries {
                    label: format!("{} ({:.1} mm)", r.method, r.mpjpe_mm),
                    values: r.per_joint_mm.iter().map(|&v| v as f32).collect(),
                    errors: r.per_joint_sd_mm.iter().map(|&v| v as f32).collect(),
                })
                .collect();
            if series.is_empty() {
                continue;
            }
            charts.push(PerJointChart {
                sensors: k,
                title: format!(
                    "position error per joint, {k} sensors ({} takes x {} seeds; bars: sd over runs)",
                    self.clips.len(),
                    self.seeds.len()
                ),
                joints: joints.clone(),
                series,
            });
        }
        charts
    }
}

const LEG_BONES: [usize; 4] = [KNEE_LEFT, ANKLE_LEFT, KNEE_RIGHT, ANKLE_RIGHT];

/// (MPJPE mm, bone error mm, jitter mm) of a sequence of poses.
fn metrics(
    poses: &[(f64, [Vec3; JOINT_COUNT])],
    truth: &GroundTruth,
    body: &BodyModel,
) -> Option<RunMetrics> {
    if poses.is_empty() {
        return None;
    }
    let mut per_joint = [0.0; JOINT_COUNT];
    let mut bone = (0.0, 0usize);
    for (t, p) in poses {
        let g = truth.at(*t);
        for n in 0..JOINT_COUNT {
            per_joint[n] += p[n].distance(g[n]) as f64;
        }
        for &n in &LEG_BONES {
            if let (Some(parent), Some(l)) = (crate::kinect::PARENTS[n], body.bone_lengths[n]) {
                bone.0 += (p[n].distance(p[parent]) - l).abs() as f64;
                bone.1 += 1;
            }
        }
    }
    let frames: Vec<[Vec3; JOINT_COUNT]> = poses.iter().map(|(_, p)| *p).collect();
    let per_joint = per_joint.map(|e| 1000.0 * e / poses.len() as f64);
    Some(RunMetrics {
        mpjpe: per_joint.iter().sum::<f64>() / JOINT_COUNT as f64,
        bone: 1000.0 * bone.0 / bone.1.max(1) as f64,
        jitter: jitter(&frames),
        per_joint,
    })
}

/// Mean norm of the second difference over consecutive frames (mm).
fn jitter(frames: &[[Vec3; JOINT_COUNT]]) -> f64 {
    let mut sum = 0.0;
    let mut count = 0usize;
    for w in frames.windows(3) {
        for ((a, b), c) in w[0].iter().zip(&w[1]).zip(&w[2]) {
            sum += (*c - 2.0 * *b + *a).length() as f64;
            count += 1;
        }
    }
    1000.0 * sum / count.max(1) as f64
}

fn run_method(
    streams: &SensorStreams,
    calibration: &Calibration,
    truth: &GroundTruth,
    body: &BodyModel,
    options: FusionOptions,
) -> Option<RunMetrics> {
    let mut fuser = Fuser::new(options, body.clone());
    let fused = fuse_streams(streams, calibration, &mut fuser, truth.fps, Some(0.0));
    let poses: Vec<(f64, [Vec3; JOINT_COUNT])> = fused
        .into_iter()
        .filter(|f| f.time <= truth.duration())
        .map(|f| (f.time, f.joints))
        .collect();
    metrics(&poses, truth, body)
}

fn best_single(
    streams: &SensorStreams,
    calibration: &Calibration,
    truth: &GroundTruth,
    body: &BodyModel,
) -> Option<RunMetrics> {
    let period = 1.0 / truth.fps;
    let mut best: Option<RunMetrics> = None;
    for &sensor in streams.streams.keys() {
        let mut poses = Vec::new();
        let mut i = 0;
        loop {
            let t = i as f64 * period;
            if t > truth.duration() {
                break;
            }
            if let Some(v) = views_at(streams, calibration, t, period)
                .into_iter()
                .find(|v| v.sensor == sensor)
            {
                poses.push((t, v.joints.map(|j| j.position)));
            }
            i += 1;
        }
        // A sensor that saw less than half the take is no candidate.
        if poses.len() * 2 < truth.frames.len() {
            continue;
        }
        if let Some(m) = metrics(&poses, truth, body) {
            if best.is_none_or(|b| m.mpjpe < b.mpjpe) {
                best = Some(m);
            }
        }
    }
    best
}

/// The report as a Markdown table.
pub fn report_markdown(report: &EvalReport, command: &str) -> String {
    let mut s = String::new();
    s += &format!(
        "Command: `{command}`\n\n{} clips x {} seeds per sensor count; calibration: {:?}.\n\
         Observations: {:.1}% NotTracked, {:.1}% Inferred, {:.1}% Tracked; {:.1}% of sensor frames seen from behind (left/right swapped).\n\
         Ground-truth jitter: {:.2} mm/frame^2.\n\n",
        report.clips.len(),
        report.seeds.len(),
        report.calibration,
        100.0 * report.state_shares[0],
        100.0 * report.state_shares[1],
        100.0 * report.state_shares[2],
        100.0 * report.swapped_share,
        report.truth_jitter_mm,
    );
    if let Some(e) = report.calibration_error {
        s += &format!(
            "Calibration from the body vs the true sensor poses ({} sensors): rotation {:.2} degrees mean, {:.2} max; \
             position {:.3} m mean, {:.3} max.\n\n",
            e.sensors, e.mean_degrees, e.max_degrees, e.mean_metres, e.max_metres
        );
    }
    s += "| sensors | method | MPJPE (mm) | hip-knee/knee-ankle length error (mm) | jitter (mm/frame^2) | runs |\n";
    s += "| --- | --- | --- | --- | --- | --- |\n";
    for r in &report.results {
        s += &format!(
            "| {} | {} | {:.1} | {:.1} | {:.2} | {} |\n",
            r.sensors, r.method, r.mpjpe_mm, r.bone_error_mm, r.jitter_mm, r.runs
        );
    }
    let mut sensors: Vec<usize> = report.results.iter().map(|r| r.sensors).collect();
    sensors.dedup();
    s += "\n";
    for k in sensors {
        let get = |name: &str| {
            report
                .results
                .iter()
                .find(|r| r.sensors == k && r.method.starts_with(name))
                .map(|r| r.mpjpe_mm)
        };
        if let (Some(single), Some(best), Some(state), Some(bone)) = (
            get("best single"),
            get("best:"),
            get("state only"),
            get("+ bone length, gaussian 4 cm"),
        ) {
            s += &format!(
                "- {k} sensors: best version / best single sensor = {:.0}% of its MPJPE; report's bone-length method vs state only: {:.1} vs {:.1} mm MPJPE\n",
                100.0 * best / single,
                bone,
                state
            );
        }
    }
    s
}

/// The bones whose length consistency is reported: the torso, arms and
/// legs, without the hand tips, thumbs and feet, whose Kinect estimates are
/// too short and noisy to say much.
pub const CONSISTENCY_BONES: [usize; 16] = [
    SPINE_MID,
    SPINE_SHOULDER,
    NECK,
    HEAD,
    SHOULDER_LEFT,
    ELBOW_LEFT,
    WRIST_LEFT,
    SHOULDER_RIGHT,
    ELBOW_RIGHT,
    WRIST_RIGHT,
    HIP_LEFT,
    KNEE_LEFT,
    ANKLE_LEFT,
    HIP_RIGHT,
    KNEE_RIGHT,
    ANKLE_RIGHT,
];

/// Bone-length consistency of one skeleton stream: a real bone keeps its
/// length, so how much the lengths vary over time measures the error without
/// ground truth.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ConsistencyRow {
    /// `sensor K` (one sensor alone, in its own camera space) or the fusion
    /// method.
    pub source: String,
    /// Frames with a skeleton.
    pub frames: usize,
    /// Mean over [`CONSISTENCY_BONES`] of the standard deviation of the
    /// bone's length over the frames (mm).
    pub bone_std_mm: f64,
    /// The same as a share of the bone's mean length (%).
    pub bone_cv_percent: f64,
    /// Mean `|l - l_body|` over the same bones and frames, `l_body` the
    /// length measured from all sensors' Tracked joints (mm).
    pub bone_error_mm: f64,
    /// Mean norm of the second difference of joint positions (mm/frame^2).
    pub jitter_mm: f64,
    /// Left/right consistency: the mean difference between the lengths of
    /// each left bone of [`CONSISTENCY_BONES`] and its right mirror in the
    /// same frame (mm). People are close to symmetric, so a large value
    /// says a joint was put on the wrong side or a limb was swapped.
    #[serde(default)]
    pub left_right_mm: f64,
}

/// The consistency evaluation of one take seen by several sensors.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ConsistencyReport {
    pub take: String,
    pub sensors: Vec<u16>,
    /// Calibration from the body, per sensor (empty when a calibration
    /// file placed the sensors).
    pub calibration: Vec<crate::align::BodySensorReport>,
    pub rows: Vec<ConsistencyRow>,
    /// Each sensor's skeletons and the fused ones (best version), in the
    /// world on the fused clock: what a filmstrip of the take shows (`mocap
    /// fuse eval --plots`), for a person to judge what the figures say. Not
    /// in the JSON report.
    #[serde(skip)]
    pub poses: Vec<SourcePoses>,
}

/// One source's skeletons over a take ([`ConsistencyReport::poses`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SourcePoses {
    /// "sensor 2", "fused (best)".
    pub source: String,
    /// Seconds between frames (the fused clock's).
    pub frame_time: f64,
    /// World positions (metres), Kinect v2 order, frame after frame.
    pub joints: Vec<[Vec3; JOINT_COUNT]>,
    /// How far each joint is to be trusted, 0 to 1: a sensor's tracking
    /// state (Tracked 1, Inferred 0.5, NotTracked or no frame near 0), the
    /// fused confidence capped at 1.
    pub confidence: Vec<[f32; JOINT_COUNT]>,
}

/// A sensor's skeletons at the fused frames' `times`, in the world; frames
/// where the sensor has none near hold its nearest skeleton, at confidence
/// 0. `None` for a sensor without a pose or a frame near any instant.
fn sensor_poses_at(
    sensor: u16,
    frames: &[crate::recording::SensorFrame],
    calibration: &Calibration,
    times: &[f64],
    frame_time: f64,
) -> Option<SourcePoses> {
    use crate::kinect::TrackingState;
    let pose = calibration.get(sensor)?;
    let period = crate::offline::frame_period(frames);
    let sampled: Vec<Option<[crate::recording::JointObservation; JOINT_COUNT]>> = times
        .iter()
        .map(|&t| crate::offline::sample_stream(frames, t, period))
        .collect();
    let first = sampled.iter().flatten().next()?;
    let (mut joints, mut confidence) = (Vec::new(), Vec::new());
    let mut held = *first;
    for sample in &sampled {
        match sample {
            Some(observed) => {
                held = *observed;
                confidence.push(observed.map(|j| match j.state {
                    TrackingState::Tracked => 1.0,
                    TrackingState::Inferred => 0.5,
                    TrackingState::NotTracked => 0.0,
                }));
            }
            None => confidence.push([0.0; JOINT_COUNT]),
        }
        joints.push(held.map(|j| pose.apply(j.position)));
    }
    Some(SourcePoses {
        source: format!("sensor {sensor}"),
        frame_time,
        joints,
        confidence,
    })
}

fn consistency_row(
    source: String,
    poses: &[[Vec3; JOINT_COUNT]],
    seen: &dyn Fn(usize, usize) -> bool,
    body: &BodyModel,
) -> ConsistencyRow {
    let (mut std_sum, mut cv_sum, mut bones) = (0.0, 0.0, 0usize);
    let (mut err_sum, mut err_count) = (0.0, 0usize);
    for &n in &CONSISTENCY_BONES {
        let parent = crate::kinect::PARENTS[n].expect("every listed bone has a parent");
        let lengths: Vec<f64> = poses
            .iter()
            .enumerate()
            .filter(|(f, _)| seen(*f, n) && seen(*f, parent))
            .map(|(_, p)| p[n].distance(p[parent]) as f64)
            .collect();
        if lengths.len() < 2 {
            continue;
        }
        let mean = lengths.iter().sum::<f64>() / lengths.len() as f64;
        let var = lengths.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / lengths.len() as f64;
        std_sum += var.sqrt();
        cv_sum += var.sqrt() / mean.max(1e-6);
        bones += 1;
        if let Some(l) = body.bone_lengths[n] {
            err_sum += lengths.iter().map(|x| (x - l as f64).abs()).sum::<f64>();
            err_count += lengths.len();
        }
    }
    let (mut asym_sum, mut asym_count) = (0.0, 0usize);
    for &n in &CONSISTENCY_BONES {
        let m = crate::kinect::MIRROR[n];
        if m == n || !crate::kinect::JOINT_NAMES[n].ends_with("Left") {
            continue;
        }
        let (pn, pm) = (
            crate::kinect::PARENTS[n].expect("every listed bone has a parent"),
            crate::kinect::PARENTS[m].expect("mirrors have parents"),
        );
        for (f, p) in poses.iter().enumerate() {
            if [n, pn, m, pm].iter().all(|&j| seen(f, j)) {
                asym_sum += (p[n].distance(p[pn]) - p[m].distance(p[pm])).abs() as f64;
                asym_count += 1;
            }
        }
    }
    ConsistencyRow {
        left_right_mm: 1000.0 * asym_sum / asym_count.max(1) as f64,
        source,
        frames: poses.len(),
        bone_std_mm: 1000.0 * std_sum / bones.max(1) as f64,
        bone_cv_percent: 100.0 * cv_sum / bones.max(1) as f64,
        bone_error_mm: 1000.0 * err_sum / err_count.max(1) as f64,
        jitter_mm: jitter(poses),
    }
}

/// Evaluates fusion on a real multi-sensor capture without ground truth:
/// the sensors are calibrated from the body ([`crate::align::calibrate_from_body`]),
/// fused with each method, and the bone-length consistency of each single
/// sensor and each fused result is compared ([`ConsistencyRow`]). The person's
/// bone lengths come from all sensors' Tracked joints.
pub fn evaluate_consistency(
    take: &str,
    frames: Vec<crate::recording::SensorFrame>,
    methods: &[(String, FusionOptions)],
    fps: f64,
    calibration: Option<&Calibration>,
) -> Result<ConsistencyReport> {
    let streams = SensorStreams::new(frames);
    streams.check_span(fps)?;
    if streams.streams.len() < 2 {
        return Err(Error::Invalid(format!(
            "{take}: fusion needs at least two sensors, found {}",
            streams.streams.len()
        )));
    }
    let body = BodyModel::measure(
        streams
            .streams
            .values()
            .flat_map(|s| s.iter().map(|f| &f.joints)),
        MeasureOptions::default(),
    );
    let (calibration, calibration_report) = match calibration {
        Some(given) => {
            crate::offline::check_calibrated(&streams, given)
                .map_err(|e| Error::Invalid(format!("{take}: {e}")))?;
            (given.clone(), Vec::new())
        }
        None => {
            let found = crate::align::calibrate_from_body(&streams, &Default::default())?;
            (found.calibration, found.sensors)
        }
    };
    let mut rows = Vec::new();
    for (&sensor, frames) in &streams.streams {
        let poses: Vec<[Vec3; JOINT_COUNT]> = frames
            .iter()
            .map(|f| f.joints.map(|j| j.position))
            .collect();
        let seen = |f: usize, n: usize| {
            frames[f].joints[n].state != crate::kinect::TrackingState::NotTracked
        };
        rows.push(consistency_row(
            format!("sensor {sensor}"),
            &poses,
            &seen,
            &body,
        ));
    }
    let mut shown = Vec::new();
    for (name, options) in methods {
        let mut fuser = Fuser::new(*options, body.clone());
        let fused = fuse_streams(&streams, &calibration, &mut fuser, fps, None);
        let poses: Vec<[Vec3; JOINT_COUNT]> = fused.iter().map(|f| f.joints).collect();
        rows.push(consistency_row(name.clone(), &poses, &|_, _| true, &body));
        // The last method (the best version) is the one shown.
        shown = vec![SourcePoses {
            source: name.clone(),
            frame_time: 1.0 / fps,
            joints: poses,
            confidence: fused
                .iter()
                .map(|f| f.confidence.map(|c| c.min(1.0)))
                .collect(),
        }];
        let times: Vec<f64> = fused.iter().map(|f| f.time).collect();
        shown.splice(
            0..0,
            streams.streams.iter().filter_map(|(&sensor, frames)| {
                sensor_poses_at(sensor, frames, &calibration, &times, 1.0 / fps)
            }),
        );
    }
    Ok(ConsistencyReport {
        take: take.to_string(),
        sensors: streams.streams.keys().copied().collect(),
        calibration: calibration_report,
        rows,
        poses: shown,
    })
}

/// Groups recordings into takes: NTU files whose names differ only in the
/// camera (`S001C001P001R001A001` and `S001C002P001R001A001`) are one take
/// seen by several sensors; a `.jsonl` recording is a take of its own (it
/// may hold several sensors).
pub fn group_takes(paths: &[PathBuf]) -> Vec<(String, Vec<PathBuf>)> {
    let mut takes: Vec<(String, Vec<PathBuf>)> = Vec::new();
    for p in paths {
        let stem = p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let is_ntu = p
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("skeleton"));
        let key = match (is_ntu, stem.find('C')) {
            (true, Some(at)) => {
                let digits = stem[at + 1..]
                    .chars()
                    .take_while(|c| c.is_ascii_digit())
                    .count();
                format!("{}C*{}", &stem[..at], &stem[at + 1 + digits..])
            }
            _ => p.display().to_string(),
        };
        match takes.iter_mut().find(|(k, _)| *k == key) {
            Some((_, files)) => files.push(p.clone()),
            None => takes.push((key, vec![p.clone()])),
        }
    }
    takes
}

/// A consistency report as a Markdown table.
pub fn consistency_markdown(reports: &[ConsistencyReport], command: &str) -> String {
    let mut s = format!(
        "Command: `{command}`\n\nNo ground truth: sensors calibrated from the body (or a given file); bone-length consistency over the take \
         (mean over {} bones of the standard deviation of each bone's length), its share of the mean length, the mean \
         difference to the person's lengths measured from all sensors' Tracked joints, the mean difference between left and \
         right bones in the same frame, and jitter.\n",
        CONSISTENCY_BONES.len()
    );
    for r in reports {
        s += &format!(
            "\n### {}\n\nSensors {:?}; calibration from the body: ",
            r.take, r.sensors
        );
        for c in &r.calibration {
            s += &format!(
                "sensor {} {} inliers of {} pairs (RMS {:.1} mm; mirrored hypothesis {} inliers; pose known to about {:.1} degrees and {:.1} cm); ",
                c.sensor,
                c.inliers,
                c.pairs,
                c.rms * 1000.0,
                c.mirrored_inliers,
                c.rotation_uncertainty_degrees,
                c.translation_uncertainty * 100.0
            );
        }
        if r.calibration.is_empty() {
            s += "given as a file";
        }
        s += "\n\n| source | frames | bone length std (mm) | std / length (%) | length error (mm) | left - right (mm) | jitter (mm/frame^2) |\n";
        s += "| --- | --- | --- | --- | --- | --- | --- |\n";
        for row in &r.rows {
            s += &format!(
                "| {} | {} | {:.1} | {:.2} | {:.1} | {:.1} | {:.2} |\n",
                row.source,
                row.frames,
                row.bone_std_mm,
                row.bone_cv_percent,
                row.bone_error_mm,
                row.left_right_mm,
                row.jitter_mm
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shin_longer_on_one_side_shows_in_the_left_right_figure_only_there() {
        let pose = crate::body::tests::standing_pose();
        let body = BodyModel::from_positions([&pose; 10], MeasureOptions::default());
        let all = |_: usize, _: usize| true;
        let even = consistency_row("even".into(), &[pose; 4], &all, &body);
        assert!(even.left_right_mm < 1e-3, "{}", even.left_right_mm);
        // The left ankle 8 cm further from its knee in every frame: no
        // spread over time, 8 cm between the sides.
        let mut uneven = pose;
        let shin = (uneven[ANKLE_LEFT] - uneven[KNEE_LEFT]).normalize();
        uneven[ANKLE_LEFT] += shin * 0.08;
        uneven[FOOT_LEFT] += shin * 0.08;
        let row = consistency_row("uneven".into(), &[uneven; 4], &all, &body);
        // One of the six left bones differs: 80 mm over six.
        assert!(
            (row.left_right_mm - 80.0 / 6.0).abs() < 0.5,
            "{}",
            row.left_right_mm
        );
        assert!(row.bone_std_mm < 1e-3);
    }
}
