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

use mocap_core::rotation::Vec3;
use mocap_core::{Error, Result};
use serde::{Deserialize, Serialize};

use crate::body::{BodyModel, MeasureOptions};
use crate::calib::Calibration;
use crate::confidence::BoneLengthFunction;
use crate::fusion::{Fuser, FusionOptions, OneEuroParams};
use crate::kinect::{joint::*, JOINT_COUNT};
use crate::offline::{fuse_streams, views_at, SensorStreams};
use crate::sim::{center_truth, simulate, truth_from_motion, GroundTruth, SimulationOptions};

/// How the sensors' poses are known in the evaluation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CalibrationSource {
    /// The simulator's true poses.
    Truth,
    /// Calibrated from the body in the recordings ([`crate::align::calibrate_from_body`]).
    Body,
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
            "best: + robust reweighting (c = 25 cm)".into(),
            Some(FusionOptions::best()),
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
    runs: usize,
}

/// Runs the evaluation.
pub fn evaluate(options: &EvalOptions) -> Result<EvalReport> {
    let files = collect_bvh_files(&options.inputs)?;
    let methods = methods();
    let mut sums = vec![vec![Sums::default(); methods.len()]; options.sensor_counts.len()];
    let mut truth_jitter = (0.0, 0usize);
    let mut states = [0f64; 3];
    let (mut swapped, mut frames_seen) = (0usize, 0usize);
    let mut clips = Vec::new();
    for path in &files {
        let motion = mocap_core::io::bvh::read_bvh(path)?;
        let mut truth = truth_from_motion(&motion, options.units_per_metre)?;
        center_truth(&mut truth, options.simulation.treadmill_above);
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
                let sim = simulate(&truth, &sim_options);
                // The person, measured from another capture of the take.
                let mut measuring = sim_options;
                measuring.seed = sim_options.seed ^ 0x5eed_5eed;
                let measure_sim = simulate(&truth, &measuring);
                let body = BodyModel::measure(
                    measure_sim
                        .sensors
                        .iter()
                        .flat_map(|s| s.frames.iter().map(|f| &f.joints)),
                    MeasureOptions::default(),
                );
                let streams =
                    SensorStreams::new(sim.sensors.iter().flat_map(|s| s.frames.iter().cloned()));
                for s in &sim.sensors {
                    for f in &s.frames {
                        for j in &f.joints {
                            states[j.state as usize] += 1.0;
                        }
                        frames_seen += 1;
                        let truth_pose = truth.at(f.timestamp);
                        let face = crate::sim::facing(&truth_pose);
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
                let calibration = match options.calibration {
                    CalibrationSource::Truth => sim.calibration(),
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
                for (mi, (_, method)) in methods.iter().enumerate() {
                    let m = match method {
                        Some(o) => run_method(&streams, &calibration, &truth, &body, *o),
                        None => best_single(&streams, &calibration, &truth, &body),
                    };
                    let Some((mpjpe, bone, jit)) = m else {
                        continue;
                    };
                    let s = &mut sums[ki][mi];
                    s.mpjpe += mpjpe;
                    s.bone += bone;
                    s.jitter += jit;
                    s.runs += 1;
                }
            }
        }
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
                runs: s.runs,
            });
        }
    }
    Ok(EvalReport {
        clips,
        seeds: options.seeds.clone(),
        calibration: options.calibration,
        results,
        truth_jitter_mm: truth_jitter.0 / truth_jitter.1.max(1) as f64,
        state_shares: states.map(|s| s / total_states.max(1.0)),
        swapped_share: swapped as f64 / frames_seen.max(1) as f64,
    })
}

const LEG_BONES: [usize; 4] = [KNEE_LEFT, ANKLE_LEFT, KNEE_RIGHT, ANKLE_RIGHT];

/// (MPJPE mm, bone error mm, jitter mm) of a sequence of poses.
fn metrics(
    poses: &[(f64, [Vec3; JOINT_COUNT])],
    truth: &GroundTruth,
    body: &BodyModel,
) -> Option<(f64, f64, f64)> {
    if poses.is_empty() {
        return None;
    }
    let mut error = 0.0;
    let mut bone = (0.0, 0usize);
    for (t, p) in poses {
        let g = truth.at(*t);
        error += (0..JOINT_COUNT)
            .map(|n| p[n].distance(g[n]) as f64)
            .sum::<f64>()
            / JOINT_COUNT as f64;
        for &n in &LEG_BONES {
            if let (Some(parent), Some(l)) = (crate::kinect::PARENTS[n], body.bone_lengths[n]) {
                bone.0 += (p[n].distance(p[parent]) - l).abs() as f64;
                bone.1 += 1;
            }
        }
    }
    let frames: Vec<[Vec3; JOINT_COUNT]> = poses.iter().map(|(_, p)| *p).collect();
    Some((
        1000.0 * error / poses.len() as f64,
        1000.0 * bone.0 / bone.1.max(1) as f64,
        jitter(&frames),
    ))
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
) -> Option<(f64, f64, f64)> {
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
) -> Option<(f64, f64, f64)> {
    let period = 1.0 / truth.fps;
    let mut best: Option<(f64, f64, f64)> = None;
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
            if best.is_none_or(|b| m.0 < b.0) {
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

/// Writes the report's Markdown to `path` atomically.
pub fn write_report(path: &Path, report: &EvalReport, command: &str) -> Result<()> {
    mocap_core::io::atomic::write_bytes_atomically(
        path,
        report_markdown(report, command).as_bytes(),
    )
}
