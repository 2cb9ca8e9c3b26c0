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
use serde::Serialize;

use crate::body::{BodyModel, MeasureOptions};
use crate::calib::Calibration;
use crate::fusion::{FusedFrame, Fuser, FusionOptions, SensorView};
use crate::kinect::JOINT_COUNT;
use crate::output::{FrameSink, FusedOutputs, OutputFiles, OutputReport};
use crate::recording::{read_recordings, JointObservation, SensorFrame};

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

/// A sensor's skeleton at instant `t` (camera space), interpolated between
/// its frames; `None` when it has no frame close enough.
pub fn sample_stream(
    frames: &[SensorFrame],
    t: f64,
    period: f64,
) -> Option<[JointObservation; JOINT_COUNT]> {
    let max_gap = 2.5 * period;
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
            Some(std::array::from_fn(|n| JointObservation {
                position: a.joints[n].position.lerp(b.joints[n].position, w),
                state: a.joints[n].state.min(b.joints[n].state),
            }))
        }
        (a, b) => [a, b]
            .into_iter()
            .flatten()
            .filter(|f| (f.timestamp - t).abs() <= 0.5 * period + 1e-9)
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
    let count = (((last - t0) * fps).floor().max(-1.0) as i64 + 1).min(MAX_FUSED_FRAMES as i64);
    let mut out = Vec::with_capacity(count.max(0) as usize);
    for i in 0..count {
        let t = t0 + i as f64 * period;
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
    if !(fps.is_finite() && fps > 0.0) {
        return Err(Error::Invalid(format!(
            "the fused frame rate must be positive, got {fps}"
        )));
    }
    let streams = SensorStreams::new(frames);
    if streams.streams.is_empty() {
        return Err(Error::Invalid(
            "the recordings hold no sensor frames".into(),
        ));
    }
    check_calibrated(&streams, calibration)?;
    streams.check_span(fps)?;
    // Instants on multiples of the period, as the server fuses them, so that
    // offline and live outputs (and ground truth) share their times.
    let start = streams.span().map(|(first, _)| (first * fps).ceil() / fps);
    let fused = fuse_streams(&streams, calibration, fuser, fps, start);
    for f in &fused {
        sink.write(f)?;
    }
    sink.finish()?;
    Ok(fused.len())
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
}

/// `mocap fuse run`: fuses recordings with their calibration and the
/// person's body ([`fuse_recordings`]) into the output files.
pub fn fuse_files(options: &FuseFilesOptions) -> Result<FuseFilesReport> {
    let calibration = Calibration::read(&options.calibration)?;
    let mut frames = read_recordings(&options.recordings)?;
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
    let count = fuse_recordings(frames, &calibration, &mut fuser, options.fps, &mut outputs)?;
    Ok(FuseFilesReport {
        fused_frames: count,
        sensors,
        implausible_joints,
        body_measured_from_recordings: options.body.is_none(),
        outputs: outputs.reports().to_vec(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinect::TrackingState;
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
}
