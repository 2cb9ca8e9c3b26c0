//! `mocap cameras eval`: every triangulation method on one trial, side by
//! side, against a ground truth (a simulated trial's `truth.trc`) or
//! against another tool's triangulation of the same keypoints (Pose2Sim's
//! `pose-3d/*.trc`), and by what needs no reference at all: reprojection
//! error and bone-length spread.

use std::path::PathBuf;
use std::time::Instant;

use glam::DVec3;
use mocap_core::{Error, Result};

use crate::capture::{bone_spread, mean_of, read_trial, tracks, CaptureOptions, Trial};
use crate::keypoints::Person2d;
use crate::solve::{measure_person_by_scores, triangulate_take, Method, TriangulationOptions};
use crate::trc::{read_trc, trc_to_zup, Markers};

/// What to compare with.
#[derive(Debug, Clone)]
pub struct CameraEvalOptions {
    pub capture: CaptureOptions,
    /// The true keypoints (TRC, Pose2Sim's axes; names as the layout's).
    pub truth: Option<PathBuf>,
    /// Another tool's triangulation of the same trial (TRC, Pose2Sim's
    /// axes), compared marker by marker where names match.
    pub reference: Option<PathBuf>,
    /// Which person to measure (0: the one found in the most frames).
    pub person: usize,
}

/// One method's figures.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MethodResult {
    pub method: &'static str,
    /// Mean reprojection error over the views each keypoint used (pixels).
    pub reprojection_px: Option<f64>,
    /// Mean distance from each triangulated keypoint to where every camera
    /// that detected it (score above the threshold) saw it (pixels): the
    /// figure comparable between methods that leave views out and those
    /// that do not, and with the reference.
    pub reprojection_all_px: Option<f64>,
    /// Mean over [`crate::SPREAD_BONES`] of each bone's length spread (mm).
    pub bone_spread_mm: Option<f64>,
    /// Share of the truth's (or the layout's) keypoint-frames triangulated.
    pub coverage: f64,
    /// Mean distance to the truth over the keypoints triangulated (mm).
    pub mpjpe_mm: Option<f64>,
    /// Per keypoint name, the mean distance to the truth (mm).
    pub mpjpe_by_keypoint: Vec<(String, Option<f64>)>,
    /// Mean distance to the reference over matching markers (mm).
    pub to_reference_mm: Option<f64>,
    /// Frames triangulated a second (one core), the second pass alone.
    pub frames_per_second: f64,
}

/// The reference's own figures on the same 2D keypoints.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ReferenceResult {
    pub path: PathBuf,
    pub markers_matched: Vec<String>,
    pub reprojection_all_px: Option<f64>,
    pub bone_spread_mm: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CameraEvalReport {
    pub trial: PathBuf,
    pub cameras: usize,
    pub frames: usize,
    pub layout: &'static str,
    pub methods: Vec<MethodResult>,
    pub reference: Option<ReferenceResult>,
    /// MPJPE of the best method over plain DLT's, when there is a truth.
    pub best_over_plain: Option<f64>,
    pub notes: Vec<String>,
}

/// A TRC's markers in the calibration's world, frame `f` of the trial at
/// row `f`.
fn markers_in_world(path: &std::path::Path) -> Result<Markers> {
    let mut m = read_trc(path)?;
    for row in &mut m.positions {
        for p in row.iter_mut() {
            *p = trc_to_zup(*p);
        }
    }
    Ok(m)
}

/// The mean reprojection error of points against every sighting above
/// `min_score` of the person's detections.
fn reprojection_all(
    trial: &Trial,
    detections: &[Vec<Option<&Person2d>>],
    point: impl Fn(usize, usize) -> Option<DVec3>,
    min_score: f32,
) -> Option<f64> {
    let (mut sum, mut n) = (0.0, 0usize);
    for (f, people) in detections.iter().enumerate() {
        for (c, person) in people.iter().enumerate() {
            let Some(person) = person else { continue };
            for (k, &[x, y, s]) in person.keypoints.iter().enumerate() {
                // A NaN score is no detection either.
                if s.is_nan() || s < min_score {
                    continue;
                }
                let Some(p) = point(f, k) else { continue };
                let Some(seen) = trial.rig.cameras[c].project(p) else {
                    continue;
                };
                sum += seen.distance(glam::DVec2::new(x as f64, y as f64));
                n += 1;
            }
        }
    }
    (n > 0).then(|| sum / n as f64)
}

/// Runs every method on the trial (see the module documentation).
pub fn evaluate_trial(options: &CameraEvalOptions) -> Result<CameraEvalReport> {
    let trial = read_trial(&options.capture)?;
    let names = trial.layout.names();
    let tracks = tracks(&trial, options.person + 2, &options.capture.association);
    let Some(track) = tracks.get(options.person) else {
        return Err(Error::Invalid(format!(
            "{}: {} people were seen consistently by two cameras, person {} asked for",
            options.capture.trial.display(),
            tracks.len(),
            options.person + 1
        )));
    };
    let detections: Vec<Vec<Option<&Person2d>>> = (0..trial.frames)
        .map(|f| crate::capture::detections(&trial, track, f))
        .collect();
    // The markers in the layout's order, looked up by name once.
    let in_layout_order = |m: Markers| -> Vec<Vec<Option<DVec3>>> {
        let index: Vec<Option<usize>> = names
            .iter()
            .map(|name| m.names.iter().position(|n| n == name))
            .collect();
        m.positions
            .iter()
            .map(|row| {
                index
                    .iter()
                    .map(|i| row.get((*i)?).copied().filter(|p| p.is_finite()))
                    .collect()
            })
            .collect()
    };
    let truth = options.truth.as_deref().map(markers_in_world).transpose()?;
    let reference_markers = options
        .reference
        .as_deref()
        .map(markers_in_world)
        .transpose()?;
    let matched: Vec<String> = reference_markers.as_ref().map_or_else(Vec::new, |r| {
        names
            .iter()
            .filter(|n| r.names.iter().any(|m| m == *n))
            .map(|n| n.to_string())
            .collect()
    });
    let truth = truth.map(in_layout_order);
    let reference = reference_markers.map(in_layout_order);
    let marker = |m: &[Vec<Option<DVec3>>], f: usize, k: usize| -> Option<DVec3> {
        m.get(f)?.get(k).copied().flatten()
    };
    let base = options.capture.triangulation;
    let cameras = &trial.rig.cameras;
    let person = measure_person_by_scores(cameras, trial.layout, &detections, &base);
    let mut methods = Vec::new();
    for method in Method::ALL {
        let o = TriangulationOptions { method, ..base };
        let start = Instant::now();
        let frames = triangulate_take(cameras, trial.layout, &detections, Some(&person), &o);
        let seconds = start.elapsed().as_secs_f64();
        let at = |f: usize, k: usize| Some(frames[f].get(k).copied().flatten()?.position);
        let seen: Vec<f64> = frames.iter().flatten().flatten().map(|k| k.error).collect();
        let spread = bone_spread(frames.len(), |f, name| at(f, trial.layout.index_of(name)?));
        let (coverage, mpjpe, by_keypoint);
        if let Some(truth) = &truth {
            let mut keypoints = Vec::new();
            let (mut sum, mut n, mut total) = (0.0, 0usize, 0usize);
            for (k, name) in names.iter().enumerate() {
                let (mut s, mut c) = (0.0, 0usize);
                for f in 0..frames.len() {
                    let Some(t) = marker(truth, f, k) else {
                        continue;
                    };
                    total += 1;
                    if let Some(p) = at(f, k) {
                        s += p.distance(t) * 1000.0;
                        c += 1;
                    }
                }
                sum += s;
                n += c;
                keypoints.push((name.to_string(), (c > 0).then(|| s / c as f64)));
            }
            coverage = n as f64 / total.max(1) as f64;
            mpjpe = (n > 0).then(|| sum / n as f64);
            by_keypoint = keypoints;
        } else {
            let known = frames.iter().flatten().filter(|k| k.is_some()).count();
            coverage = known as f64 / (frames.len() * names.len()).max(1) as f64;
            mpjpe = None;
            by_keypoint = Vec::new();
        }
        let to_reference = reference.as_ref().and_then(|r| {
            let d: Vec<f64> = (0..frames.len())
                .flat_map(|f| {
                    (0..names.len())
                        .filter_map(move |k| Some(at(f, k)?.distance(marker(r, f, k)?) * 1000.0))
                })
                .collect();
            (!d.is_empty()).then(|| d.iter().sum::<f64>() / d.len() as f64)
        });
        methods.push(MethodResult {
            method: method.label(),
            reprojection_px: (!seen.is_empty())
                .then(|| seen.iter().sum::<f64>() / seen.len() as f64),
            reprojection_all_px: reprojection_all(&trial, &detections, at, base.min_score),
            bone_spread_mm: mean_of(&spread),
            coverage,
            mpjpe_mm: mpjpe,
            mpjpe_by_keypoint: by_keypoint,
            to_reference_mm: to_reference,
            frames_per_second: frames.len() as f64 / seconds.max(1e-9),
        });
    }
    let reference_result = match (&reference, &options.reference) {
        (Some(r), Some(path)) => {
            let spread = bone_spread(trial.frames, |f, name| {
                marker(r, f, trial.layout.index_of(name)?)
            });
            Some(ReferenceResult {
                path: path.clone(),
                reprojection_all_px: reprojection_all(
                    &trial,
                    &detections,
                    |f, k| marker(r, f, k),
                    base.min_score,
                ),
                bone_spread_mm: mean_of(&spread),
                markers_matched: matched,
            })
        }
        _ => None,
    };
    let mpjpe_of = |m: Method| methods.iter().find(|r| r.method == m.label())?.mpjpe_mm;
    let best_over_plain = match (
        mpjpe_of(Method::Plain),
        methods.iter().filter_map(|m| m.mpjpe_mm).reduce(f64::min),
    ) {
        (Some(plain), Some(best)) if plain > 0.0 => Some(best / plain),
        _ => None,
    };
    Ok(CameraEvalReport {
        trial: options.capture.trial.clone(),
        cameras: trial.rig.cameras.len(),
        frames: trial.frames,
        layout: trial.layout.label(),
        methods,
        reference: reference_result,
        best_over_plain,
        notes: trial.notes,
    })
}

fn cell(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.digits$}"))
}

/// The report's tables as Markdown.
pub fn eval_markdown(report: &CameraEvalReport) -> String {
    let mut out = format!(
        "{}: {} cameras, {} frames, {}\n\n| method | reprojection, views used (px) | reprojection, every view (px) | bone-length spread (mm) | coverage | MPJPE (mm) | to reference (mm) | frames/s |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n",
        report.trial.display(),
        report.cameras,
        report.frames,
        report.layout
    );
    for m in &report.methods {
        out += &format!(
            "| {} | {} | {} | {} | {:.1}% | {} | {} | {:.0} |\n",
            m.method,
            cell(m.reprojection_px, 2),
            cell(m.reprojection_all_px, 2),
            cell(m.bone_spread_mm, 1),
            100.0 * m.coverage,
            cell(m.mpjpe_mm, 1),
            cell(m.to_reference_mm, 1),
            m.frames_per_second
        );
    }
    if let Some(r) = &report.reference {
        out += &format!(
            "| reference ({}) | - | {} | {} | - | - | - | - |\n",
            r.path.file_name().and_then(|n| n.to_str()).unwrap_or("?"),
            cell(r.reprojection_all_px, 2),
            cell(r.bone_spread_mm, 1)
        );
    }
    if let Some(ratio) = report.best_over_plain {
        out += &format!("\nBest MPJPE over plain DLT's: {:.2}\n", ratio);
    }
    out
}
