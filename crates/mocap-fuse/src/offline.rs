//! Offline fusion of recordings (`mocap fuse run`): sensor frames are put on
//! a common clock and fused instant by instant.
//!
//! Sensors are not synchronised: each captures at its own phase. The fused
//! skeleton is made on a regular grid of instants (the sensors' frame rate);
//! at each instant a sensor contributes its skeleton linearly interpolated
//! between its two frames around the instant (if they are at most
//! `max_gap` apart: one dropped frame is bridged), with the worse of the two
//! tracking states, or its nearest frame within half a period.

use std::collections::BTreeMap;
use std::path::PathBuf;

use mocap_core::{Error, Result};
use serde::{Deserialize, Serialize};

use crate::body::{BodyModel, MeasureOptions};
use crate::calib::Calibration;
use crate::fusion::{FusedFrame, Fuser, FusionOptions, SensorView};
use crate::kinect::JOINT_COUNT;
use crate::output::{FrameSink, FusedOutputs, OutputFiles, OutputReport};
use crate::recording::{
    read_recordings_with, JointObservation, ReadOptions, Recordings, RecordingsReport, SensorFrame,
};

/// The most instants one fusion may have: as many as the channel values a
/// motion may hold allow for the 25 joints' positions
/// ([`mocap_core::MAX_VALUES`]), 33 hours at 30 frames per second.
pub const MAX_FUSED_FRAMES: usize = mocap_core::MAX_VALUES / (3 * JOINT_COUNT);

/// Each sensor's frames in time order (duplicates removed).
#[derive(Debug, Clone, Default)]
pub struct SensorStreams {
    pub streams: BTreeMap<u16, Vec<SensorFrame>>,
}

impl SensorStreams {
    /// Sorts the frames into streams. Every frame is screened for outliers
    /// first ([`SensorFrame::screen_implausible_joints`], as the fusion
    /// server does): joints beyond [`crate::MAX_JOINT_DISTANCE`] from their
    /// sensor are NotTracked, and a frame with no plausible joint is dropped.
    pub fn new(frames: impl IntoIterator<Item = SensorFrame>) -> SensorStreams {
        let mut streams: BTreeMap<u16, Vec<SensorFrame>> = BTreeMap::new();
        for mut f in frames {
            if f.screen_implausible_joints() == JOINT_COUNT {
                continue;
            }
            streams.entry(f.sensor).or_default().push(f);
        }
        for s in streams.values_mut() {
            s.sort_by(|a, b| a.timestamp.total_cmp(&b.timestamp).then(a.seq.cmp(&b.seq)));
            s.dedup_by(|a, b| a.seq == b.seq && a.timestamp == b.timestamp);
        }
        SensorStreams { streams }
    }

    /// First and last timestamp over all sensors.
    pub fn span(&self) -> Option<(f64, f64)> {
        let first = self
            .streams
            .values()
            .filter_map(|s| s.first())
            .map(|f| f.timestamp)
            .min_by(f64::total_cmp)?;
        let last = self
            .streams
            .values()
            .filter_map(|s| s.last())
            .map(|f| f.timestamp)
            .max_by(f64::total_cmp)?;
        Some((first, last))
    }
}

impl SensorStreams {
    /// Checks that fusing the streams at `fps` from their first to their
    /// last timestamp makes at most [`MAX_FUSED_FRAMES`] instants: a
    /// timestamp far from the others (`t` = 1e30 on one line) would
    /// otherwise ask for an endless take.
    pub fn check_span(&self, fps: f64) -> Result<()> {
        let Some((first, last)) = self.span() else {
            return Ok(());
        };
        let instants = (last - first) * fps;
        if instants.is_finite() && instants < MAX_FUSED_FRAMES as f64 {
            return Ok(());
        }
        let at = |t: f64| {
            self.streams
                .values()
                .flatten()
                .find(|f| f.timestamp == t)
                .map_or(String::new(), |f| {
                    format!(" (sensor {} frame {})", f.sensor, f.seq)
                })
        };
        Err(Error::Invalid(format!(
            "the recordings' times run from {first} s{} to {last} s{}: at {fps} frames per second \
             that is more than the {MAX_FUSED_FRAMES} fused frames a take may have; \
             is a timestamp wrong?",
            at(first),
            at(last)
        )))
    }
}

/// How close (a fraction of the frame period) an instant and a frame's
/// time must be to count as the same instant: [`sample_stream`] then takes
/// the frame as it is, and the fused grid ([`fuse_streams`],
/// [`fuse_recordings`]) starts and ends on the frame. 1% of a period is
/// a third of a millisecond at 30 frames per second: far below what a
/// sensor's clock says, far above the rounding of a time written as text.
pub const SAME_INSTANT: f64 = 0.01;

/// A stream's frame period (s): the median step between its frames' times,
/// so that a recording at 15 or 60 frames per second is paired at its own
/// rate; 1/30 s (Kinect v2) for a stream of fewer than two frames. Gaps
/// (dropped frames) are rare enough not to move the median.
pub fn frame_period(frames: &[SensorFrame]) -> f64 {
    let mut steps: Vec<f64> = frames
        .windows(2)
        .map(|w| w[1].timestamp - w[0].timestamp)
        .filter(|d| *d > 0.0 && d.is_finite())
        .collect();
    crate::body::median(&mut steps).unwrap_or(1.0 / 30.0)
}

/// A sensor's skeleton at instant `t` (camera space), interpolated between
/// its frames; `None` when it has no frame close enough. A frame within
/// [`SAME_INSTANT`] of a period of `t` gives its own tracking states;
/// between two frames each joint has the worse of their two states.
pub fn sample_stream(
    frames: &[SensorFrame],
    t: f64,
    period: f64,
) -> Option<[JointObservation; JOINT_COUNT]> {
    let max_gap = 2.5 * period;
    let same_instant = SAME_INSTANT * period;
    let i = frames.partition_point(|f| f.timestamp <= t);
    let before = i.checked_sub(1).map(|k| &frames[k]);
    let after = frames.get(i);
    match (before, after) {
        (Some(a), Some(b)) if b.timestamp - a.timestamp <= max_gap => {
            let span = b.timestamp - a.timestamp;
            let w = if span > 0.0 {
                ((t - a.timestamp) / span) as f32
            } else {
                0.0
            };
            // A frame at the instant (to within SAME_INSTANT of a period)
            // is taken as it is, states included: whether the instant falls
            // a hair before or after it (a time read from text, a clock a
            // microsecond off) must not decide which neighbour's state it
            // is judged by. Between frames, the worse of the two states.
            let state_of = |n: usize| {
                if t - a.timestamp <= same_instant {
                    a.joints[n].state
                } else if b.timestamp - t <= same_instant {
                    b.joints[n].state
                } else {
                    a.joints[n].state.min(b.joints[n].state)
                }
            };
            Some(std::array::from_fn(|n| JointObservation {
                position: a.joints[n].position.lerp(b.joints[n].position, w),
                state: state_of(n),
            }))
        }
        (a, b) => [a, b]
            .into_iter()
            .flatten()
            .filter(|f| (f.timestamp - t).abs() <= (0.5 + SAME_INSTANT) * period)
            .min_by(|x, y| (x.timestamp - t).abs().total_cmp(&(y.timestamp - t).abs()))
            .map(|f| f.joints),
    }
}

/// Every sensor's view of instant `t`, in world space.
pub fn views_at(
    streams: &SensorStreams,
    calibration: &Calibration,
    t: f64,
    period: f64,
) -> Vec<SensorView> {
    streams
        .streams
        .iter()
        .filter_map(|(&sensor, frames)| {
            let pose = calibration.get(sensor)?;
            let joints = sample_stream(frames, t, period)?;
            Some(SensorView {
                sensor,
                origin: pose.translation,
                joints: joints.map(|j| JointObservation {
                    position: pose.apply(j.position),
                    state: j.state,
                }),
            })
        })
        .collect()
}

/// Checks that every sensor in the recordings is calibrated.
pub fn check_calibrated(streams: &SensorStreams, calibration: &Calibration) -> Result<()> {
    let missing: Vec<String> = streams
        .streams
        .keys()
        .filter(|s| calibration.get(**s).is_none())
        .map(|s| s.to_string())
        .collect();
    if missing.is_empty() {
        Ok(())
    } else {
        Err(Error::Invalid(format!(
            "the calibration has no pose for sensor(s) {}; calibrate them first (mocap fuse calibrate)",
            missing.join(", ")
        )))
    }
}

/// Fuses recordings on a grid of `fps` instants from the first timestamp
/// (or from `start` when given) to the last, at most [`MAX_FUSED_FRAMES`]
/// instants (check longer streams with [`SensorStreams::check_span`]).
pub fn fuse_streams(
    streams: &SensorStreams,
    calibration: &Calibration,
    fuser: &mut Fuser,
    fps: f64,
    start: Option<f64>,
) -> Vec<FusedFrame> {
    let Some((first, last)) = streams.span() else {
        return Vec::new();
    };
    let period = 1.0 / fps;
    let t0 = start.unwrap_or(first);
    // The last frame's instant is fused even when rounding puts it a hair
    // short of a whole number of periods from the start.
    let count = (((last - t0) * fps + SAME_INSTANT).floor().max(-1.0) as i64 + 1)
        .min(MAX_FUSED_FRAMES as i64);
    let mut out = Vec::with_capacity(count.max(0) as usize);
    for i in 0..count {
        let t = t0 + i as f64 / fps;
        let views = views_at(streams, calibration, t, period);
        if let Some(f) = fuser.fuse(t, &views) {
            out.push(f);
        }
    }
    if let Some(half) = fuser.options().centered_smoothing {
        savitzky_golay(&mut out, half);
    }
    out
}

/// Quadratic Savitzky-Golay smoothing of the joints over `2 half + 1`
/// frames (Savitzky and Golay, Analytical Chemistry 1964): each value is
/// replaced by the value at the centre of the least-squares parabola
/// through its neighbours, so peaks of the motion are kept better than by a
/// moving average. The weights are `(3(3m^2 + 3m - 1) - 15 i^2) / ((2m +
/// 1)(4m^2 + 4m - 3))` for `i` in `-m..=m`. Frames nearer the ends than
/// `half` are left as they are.
pub fn savitzky_golay(frames: &mut [FusedFrame], half: usize) {
    let m = half as i64;
    if half == 0 || frames.len() < 2 * half + 1 {
        return;
    }
    let denominator = ((2 * m + 1) * (4 * m * m + 4 * m - 3)) as f32;
    let weights: Vec<f32> = (-m..=m)
        .map(|i| (3 * (3 * m * m + 3 * m - 1) - 15 * i * i) as f32 / denominator)
        .collect();
    let original: Vec<[mocap_core::rotation::Vec3; JOINT_COUNT]> =
        frames.iter().map(|f| f.joints).collect();
    for c in half..frames.len() - half {
        for (n, joint) in frames[c].joints.iter_mut().enumerate() {
            *joint = weights
                .iter()
                .enumerate()
                .map(|(k, w)| original[c + k - half][n] * *w)
                .sum();
        }
    }
}

/// `mocap fuse run`: fuses recorded frames into `sink`. Every sensor must be
/// in the calibration. Returns how many fused frames were written.
pub fn fuse_recordings(
    frames: Vec<SensorFrame>,
    calibration: &Calibration,
    fuser: &mut Fuser,
    fps: f64,
    sink: &mut dyn FrameSink,
) -> Result<usize> {
    fuse_stream_set(&SensorStreams::new(frames), calibration, fuser, fps, sink)
}

/// [`fuse_recordings`] on frames already sorted into streams.
fn fuse_stream_set(
    streams: &SensorStreams,
    calibration: &Calibration,
    fuser: &mut Fuser,
    fps: f64,
    sink: &mut dyn FrameSink,
) -> Result<usize> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(Error::Invalid(format!(
            "the fused frame rate must be positive, got {fps}"
        )));
    }
    if streams.streams.is_empty() {
        return Err(Error::Invalid(
            "the recordings hold no sensor frames".into(),
        ));
    }
    check_calibrated(streams, calibration)?;
    streams.check_span(fps)?;
    // Instants on multiples of the period, as the server fuses them, so that
    // offline and live outputs (and ground truth) share their times; the
    // first frame's own instant when it is on one (to within SAME_INSTANT:
    // a time a microsecond late must not lose the frame).
    let start = streams
        .span()
        .map(|(first, _)| (first * fps - SAME_INSTANT).ceil() / fps);
    let fused = fuse_streams(streams, calibration, fuser, fps, start);
    for f in &fused {
        sink.write(f)?;
    }
    sink.finish()?;
    Ok(fused.len())
}

/// The median pelvis distance (metres) between a sensor's body and the
/// nearest other sensor's beyond which the sensor follows another person
/// ([`check_same_person`]).
pub const OTHER_PERSON_DISTANCE: f64 = 0.5;

/// How far one frame's pelvis is from the nearest other sensor's.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PelvisDistance {
    /// The frame's time (s).
    pub time: f64,
    /// Metres, in the world of the calibration.
    pub distance: f64,
}

/// One sensor's body against the others' ([`check_same_person`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorAgreement {
    pub sensor: u16,
    /// Per frame with a pelvis seen here and by another sensor at that
    /// instant: the distance to the nearest other sensor's pelvis. Left
    /// out of the JSON reports (one entry a frame), which give the median.
    #[serde(skip)]
    pub per_frame: Vec<PelvisDistance>,
    /// Their median (`None`: no frame to compare).
    pub median_distance: Option<f64>,
    /// The median is beyond [`OTHER_PERSON_DISTANCE`]: this sensor's body
    /// is another person (or its calibration is wrong).
    pub other_person: bool,
}

/// Whether every sensor's body is the same person in the world
/// ([`check_same_person`]).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SamePersonReport {
    pub sensors: Vec<SensorAgreement>,
}

impl SamePersonReport {
    /// The sensors whose body is another person.
    pub fn other_people(&self) -> Vec<u16> {
        self.sensors
            .iter()
            .filter(|s| s.other_person)
            .map(|s| s.sensor)
            .collect()
    }

    /// One sentence per sensor that follows another person; empty when all
    /// agree.
    pub fn notes(&self) -> Vec<String> {
        let flagged: Vec<&SensorAgreement> =
            self.sensors.iter().filter(|s| s.other_person).collect();
        if flagged.len() > 1 && flagged.len() == self.sensors.len() {
            let each: Vec<String> = flagged
                .iter()
                .map(|s| {
                    format!(
                        "sensor {} {:.2} m",
                        s.sensor,
                        s.median_distance.unwrap_or(f64::NAN)
                    )
                })
                .collect();
            return vec![format!(
                "the sensors' bodies are not the same person: each is far from the others' (median pelvis distance: {}); which one follows the performer cannot be told",
                each.join(", ")
            )];
        }
        flagged
            .iter()
            .map(|s| {
                format!(
                    "sensor {}'s body is {:.2} m (median over {} frames) from the other sensors' bodies: it follows another person than they do (or its calibration is wrong)",
                    s.sensor,
                    s.median_distance.unwrap_or(f64::NAN),
                    s.per_frame.len()
                )
            })
            .collect()
    }
}

/// Checks that every calibrated sensor's body is the same person: per frame
/// of each sensor, the distance in the world between its pelvis
/// (`SpineBase`, when not NotTracked) and the nearest pelvis of the other
/// sensors at that instant ([`sample_stream`], frame period `period`). A
/// sensor whose median distance is beyond [`OTHER_PERSON_DISTANCE`] follows
/// another person; with two sensors, both are then far from each other and
/// which one is wrong cannot be told. Uncalibrated sensors are left out.
///
/// For NTU files this checks the per-file choice of the performer
/// ([`crate::choose_ntu_body`]) across the cameras, once they are
/// calibrated.
pub fn check_same_person(
    streams: &SensorStreams,
    calibration: &Calibration,
    period: f64,
) -> SamePersonReport {
    use crate::kinect::{joint::SPINE_BASE, TrackingState};
    let calibrated: Vec<(u16, &Vec<SensorFrame>, &crate::calib::RigidTransform)> = streams
        .streams
        .iter()
        .filter_map(|(&s, frames)| Some((s, frames, calibration.get(s)?)))
        .collect();
    let seen = |j: &JointObservation| j.state != TrackingState::NotTracked;
    let sensors = calibrated
        .iter()
        .map(|&(sensor, frames, pose)| {
            let per_frame: Vec<PelvisDistance> = frames
                .iter()
                .filter(|f| seen(&f.joints[SPINE_BASE]))
                .filter_map(|f| {
                    let here = pose.apply(f.joints[SPINE_BASE].position);
                    let distance = calibrated
                        .iter()
                        .filter(|(other, _, _)| *other != sensor)
                        .filter_map(|(_, others, other_pose)| {
                            let joints = sample_stream(others, f.timestamp, period)?;
                            let pelvis = joints[SPINE_BASE];
                            seen(&pelvis)
                                .then(|| other_pose.apply(pelvis.position).distance(here) as f64)
                        })
                        .min_by(f64::total_cmp)?;
                    Some(PelvisDistance {
                        time: f.timestamp,
                        distance,
                    })
                })
                .collect();
            let mut distances: Vec<f64> = per_frame.iter().map(|d| d.distance).collect();
            let median_distance = crate::body::median(&mut distances);
            SensorAgreement {
                sensor,
                per_frame,
                median_distance,
                other_person: median_distance.is_some_and(|d| d > OTHER_PERSON_DISTANCE),
            }
        })
        .collect();
    SamePersonReport { sensors }
}

/// What `mocap fuse run` fuses, and where to.
#[derive(Debug, Clone)]
pub struct FuseFilesOptions {
    /// Recordings (`.jsonl`, NTU `.skeleton`) of the sensors.
    pub recordings: Vec<PathBuf>,
    /// The calibration file (every sensor's pose).
    pub calibration: PathBuf,
    /// The person's body file; `None` measures the person from the
    /// recordings themselves.
    pub body: Option<PathBuf>,
    pub outputs: OutputFiles,
    pub fusion: FusionOptions,
    /// Fused frames per second.
    pub fps: f64,
}

/// What [`fuse_files`] did.
#[derive(Debug, Clone, Serialize)]
pub struct FuseFilesReport {
    pub fused_frames: usize,
    pub sensors: Vec<u16>,
    /// Joints farther than [`crate::MAX_JOINT_DISTANCE`] from their sensor,
    /// treated as NotTracked ([`SensorFrame::screen_implausible_joints`]).
    pub implausible_joints: usize,
    pub body_measured_from_recordings: bool,
    pub outputs: Vec<OutputReport>,
    /// How the recordings were read: bodies kept and dropped, gaps, sensor
    /// ids, time offsets ([`RecordingsReport::notes`]).
    pub recordings: RecordingsReport,
    /// Whether every sensor's body is the same person in the calibration's
    /// world ([`check_same_person`]).
    pub same_person: SamePersonReport,
}

/// `mocap fuse run`: fuses recordings with their calibration and the
/// person's body ([`fuse_recordings`]) into the output files; the
/// recordings are read with the default [`ReadOptions`]
/// ([`fuse_files_with`]).
pub fn fuse_files(options: &FuseFilesOptions) -> Result<FuseFilesReport> {
    fuse_files_with(options, &ReadOptions::default())
}

/// [`fuse_files`], the recordings read as `reading` says (the input frame
/// rate of NTU files, time offsets: [`read_recordings_with`]).
pub fn fuse_files_with(
    options: &FuseFilesOptions,
    reading: &ReadOptions,
) -> Result<FuseFilesReport> {
    let calibration = Calibration::read(&options.calibration)?;
    let Recordings {
        mut frames,
        report: recordings,
    } = read_recordings_with(&options.recordings, reading)?;
    // Screened here, as the fusion would, so that the person is measured
    // without the outliers too, and they are counted.
    let implausible_joints = frames
        .iter_mut()
        .map(SensorFrame::screen_implausible_joints)
        .sum();
    let mut sensors: Vec<u16> = frames.iter().map(|f| f.sensor).collect();
    sensors.sort();
    sensors.dedup();
    let body = match &options.body {
        Some(path) => BodyModel::read(path)?,
        None => BodyModel::measure(frames.iter().map(|f| &f.joints), MeasureOptions::default()),
    };
    let mut outputs = FusedOutputs::open(&options.outputs, body.clone(), options.fps)?;
    let mut fuser = Fuser::new(options.fusion, body);
    let streams = SensorStreams::new(frames);
    let count = fuse_stream_set(
        &streams,
        &calibration,
        &mut fuser,
        options.fps,
        &mut outputs,
    )?;
    let same_person = check_same_person(&streams, &calibration, 1.0 / options.fps);
    Ok(FuseFilesReport {
        fused_frames: count,
        sensors,
        implausible_joints,
        body_measured_from_recordings: options.body.is_none(),
        outputs: outputs.reports().to_vec(),
        recordings,
        same_person,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinect::TrackingState;
    use crate::recording::TimeOffsets;
    use mocap_core::rotation::Vec3;

    fn frame(seq: u64, t: f64, x: f32, state: TrackingState) -> SensorFrame {
        SensorFrame {
            sensor: 0,
            seq,
            timestamp: t,
            arrival: None,
            joints: [JointObservation {
                position: Vec3::new(x, 0.0, 2.0),
                state,
            }; JOINT_COUNT],
        }
    }

    #[test]
    fn streams_are_interpolated_and_gaps_respected() {
        let p = 1.0 / 30.0;
        let frames = vec![
            frame(0, 0.0, 0.0, TrackingState::Tracked),
            frame(1, p, 1.0, TrackingState::Inferred),
            frame(5, 5.0 * p, 5.0, TrackingState::Tracked),
        ];
        let s = sample_stream(&frames, 0.5 * p, p).unwrap();
        assert!((s[0].position.x - 0.5).abs() < 1e-5);
        assert_eq!(s[0].state, TrackingState::Inferred, "worse of the two");
        // In the 4-period gap: only near its ends.
        assert!(sample_stream(&frames, 3.0 * p, p).is_none());
        let near = sample_stream(&frames, 1.3 * p, p).unwrap();
        assert_eq!(near[0].position.x, 1.0);
        assert!(sample_stream(&frames, 7.0 * p, p).is_none());
    }

    #[test]
    fn duplicates_and_disorder_are_cleaned() {
        let p = 1.0 / 30.0;
        let s = SensorStreams::new(vec![
            frame(2, 2.0 * p, 2.0, TrackingState::Tracked),
            frame(0, 0.0, 0.0, TrackingState::Tracked),
            frame(2, 2.0 * p, 2.0, TrackingState::Tracked),
        ]);
        let v = &s.streams[&0];
        assert_eq!(v.iter().map(|f| f.seq).collect::<Vec<_>>(), vec![0, 2]);
    }

    #[test]
    fn outliers_are_screened_and_absurd_spans_refused() {
        let p = 1.0 / 30.0;
        let mut one_far = frame(1, p, 1.0, TrackingState::Tracked);
        one_far.joints[3].position = Vec3::new(0.0, 20.0, 0.0);
        let mut all_far = frame(2, 2.0 * p, 2.0, TrackingState::Tracked);
        for j in all_far.joints.iter_mut() {
            j.position = Vec3::splat(1e30);
        }
        let s = SensorStreams::new(vec![
            frame(0, 0.0, 0.0, TrackingState::Tracked),
            one_far,
            all_far,
        ]);
        let v = &s.streams[&0];
        assert_eq!(v.iter().map(|f| f.seq).collect::<Vec<_>>(), vec![0, 1]);
        assert_eq!(v[1].joints[3].state, TrackingState::NotTracked);
        assert_eq!(v[1].joints[3].position, Vec3::new(1.0, 0.0, 2.0));
        s.check_span(30.0).unwrap();
        let s = SensorStreams::new(vec![
            frame(0, 0.0, 0.0, TrackingState::Tracked),
            frame(7, 1e30, 0.0, TrackingState::Tracked),
        ]);
        let err = s.check_span(30.0).unwrap_err().to_string();
        assert!(
            err.contains("to 1000000000000000000000000000000 s (sensor 0 frame 7)"),
            "{err}"
        );
    }

    /// `mocap fuse run`'s fusion (method `best`) of `frames` at 30 fps.
    fn fused(frames: Vec<SensorFrame>, files: &crate::sim::SimulationFiles) -> Vec<FusedFrame> {
        let calibration = Calibration::read(&files.calibration).unwrap();
        let body = BodyModel::read(&files.body).unwrap();
        let mut fuser = Fuser::new(FusionOptions::best(), body);
        let mut sink = crate::output::MemorySink::default();
        fuse_recordings(frames, &calibration, &mut fuser, 30.0, &mut sink).unwrap();
        sink.frames
    }

    /// The largest distance (mm) between the joints of two fusions at the
    /// same instants; both must have the same instants.
    fn largest_difference_mm(a: &[FusedFrame], b: &[FusedFrame]) -> f64 {
        assert_eq!(a.len(), b.len(), "as many fused frames");
        a.iter()
            .zip(b)
            .flat_map(|(x, y)| {
                assert!((x.time - y.time).abs() < 1e-3, "{} vs {}", x.time, y.time);
                x.joints
                    .iter()
                    .zip(&y.joints)
                    .map(|(p, q)| p.distance(*q) as f64 * 1000.0)
            })
            .fold(0.0, f64::max)
    }

    fn ntu_frames(files: &crate::sim::SimulationFiles, time_offsets: TimeOffsets) -> Recordings {
        let options = ReadOptions {
            time_offsets,
            ..Default::default()
        };
        crate::recording::read_recordings_with(&files.ntu, &options).unwrap()
    }

    #[test]
    fn a_microsecond_on_every_time_moves_no_fused_joint() {
        let (_dir, files) = crate::sim::simulated_walk_files();
        // NTU frames sit exactly on the fused instants, the worst case.
        let frames = ntu_frames(&files, TimeOffsets::Off).frames;
        let mut late = frames.clone();
        for f in late.iter_mut() {
            f.timestamp += 1e-6;
        }
        let moved = largest_difference_mm(&fused(frames, &files), &fused(late, &files));
        eprintln!("a 1 us shift moves a fused joint by up to {moved:.4} mm");
        assert!(moved < 1.0, "{moved} mm");
    }

    #[test]
    fn skeleton_files_and_their_jsonl_fuse_alike() {
        let (dir, files) = crate::sim::simulated_walk_files();
        let ntu = ntu_frames(&files, TimeOffsets::Off).frames;
        // The same frames as .jsonl recordings (times i/30 s written as
        // text and read back, positions to 0.1 mm).
        let jsonl: Vec<PathBuf> = (0..3u16)
            .map(|k| {
                let path = dir.path().join(format!("C{k}.jsonl"));
                let mine: Vec<SensorFrame> =
                    ntu.iter().filter(|f| f.sensor == k).cloned().collect();
                crate::recording::write_recording(&path, &mine).unwrap();
                path
            })
            .collect();
        let read = |offsets: TimeOffsets| {
            let options = ReadOptions {
                time_offsets: offsets,
                ..Default::default()
            };
            crate::recording::read_recordings_with(&jsonl, &options).unwrap()
        };
        let from_jsonl = read(TimeOffsets::default()).frames;
        let apart = largest_difference_mm(&fused(ntu, &files), &fused(from_jsonl, &files));
        eprintln!(".skeleton and .jsonl fused up to {apart:.4} mm apart");
        assert!(apart < 1.0, "{apart} mm");
        // With the offsets estimated for the NTU files given to the .jsonl.
        let estimated = ntu_frames(&files, TimeOffsets::default());
        let given: Vec<f64> = (0..3u16)
            .map(|k| {
                estimated
                    .report
                    .time_offsets
                    .iter()
                    .find(|o| o.sensor == k && o.applied)
                    .and_then(|o| o.frames)
                    .unwrap_or(0.0)
            })
            .collect();
        assert!(given.iter().any(|x| *x != 0.0), "{given:?}");
        let from_jsonl = read(TimeOffsets::Frames(given)).frames;
        let apart =
            largest_difference_mm(&fused(estimated.frames, &files), &fused(from_jsonl, &files));
        assert!(apart < 1.0, "{apart} mm with the offsets");
    }

    #[test]
    fn a_sensor_following_another_person_is_flagged() {
        let (_dir, files) = crate::sim::simulated_walk_files();
        let calibration = Calibration::read(&files.calibration).unwrap();
        let frames = crate::recording::read_recordings(&files.recordings).unwrap();
        let period = 1.0 / 30.0;
        let report = check_same_person(&SensorStreams::new(frames.clone()), &calibration, period);
        assert_eq!(report.sensors.len(), 3);
        for s in &report.sensors {
            assert!(s.median_distance.unwrap() < 0.15, "{s:?}");
            assert!(s.per_frame.len() > 150);
        }
        assert!(report.other_people().is_empty() && report.notes().is_empty());
        // Sensor 2 follows someone 1.2 m to the side of the performer.
        let mut other = frames.clone();
        for f in other.iter_mut().filter(|f| f.sensor == 2) {
            for j in f.joints.iter_mut() {
                j.position += Vec3::new(1.2, 0.0, 0.0);
            }
        }
        let report = check_same_person(&SensorStreams::new(other.clone()), &calibration, period);
        assert_eq!(report.other_people(), vec![2]);
        let median = |s: u16| {
            report
                .sensors
                .iter()
                .find(|a| a.sensor == s)
                .unwrap()
                .median_distance
                .unwrap()
        };
        assert!(median(0) < 0.15 && median(1) < 0.15);
        assert!((median(2) - 1.2).abs() < 0.2, "{}", median(2));
        let notes = report.notes().join("\n");
        assert!(
            notes.contains("sensor 2's body is 1.") && notes.contains("follows another person"),
            "{notes}"
        );
        // Two sensors: which one is wrong cannot be told.
        other.retain(|f| f.sensor != 1);
        let report = check_same_person(&SensorStreams::new(other), &calibration, period);
        assert_eq!(report.other_people(), vec![0, 2]);
        let notes = report.notes().join("\n");
        assert!(notes.contains("cannot be told"), "{notes}");
    }
}
