//! Streaming over UDP: sensors send their skeleton frames to a fusion server.
//!
//! # Datagram format, version 1
//!
//! One datagram per sensor frame: the 4 bytes `MCF1` (magic and format
//! version), then one sensor frame as UTF-8 JSON exactly as one line of a
//! recording (see [`crate::recording`]). A frame of 25 joints is about 1 KB,
//! under the 1472-byte payload of an Ethernet frame. Anything else (another
//! magic, bad UTF-8, bad JSON, wrong joint count, a tracking state other than
//! 0/1/2, non-finite numbers) is counted as malformed, logged (the first few)
//! and dropped; the server never stops for a datagram.
//!
//! # The server
//!
//! The server keeps each sensor's recent frames and fuses on a grid of
//! instants at the sensors' frame rate, on the sensors' shared clock, as the
//! offline fusion does ([`crate::offline`]). An instant is fused as soon as
//! every active sensor has sent a frame at or after it, or when some sensor is
//! already `wait` seconds past it (a sensor that lags or vanished does not
//! hold the output back). A sensor is active while its latest frame is within
//! `sensor_timeout` of the newest frame of any sensor; one that joins late
//! simply starts to contribute. Duplicates (same sensor and seq) are dropped;
//! reordered frames are put in order; a frame for an instant already fused
//! is counted as late.
//!
//! # Judging a datagram's time
//!
//! A datagram's time `t` is the sensor's word; one wrong time (`t` = 1e30,
//! or 1e4 in the middle of a take) must not make the server fuse millions
//! of instants or call the real frames late. So the server keeps its own
//! reckoning of the sensors' (shared) clock: the offset `t - s` between a
//! datagram's time and the server's clock `s` when it arrived (seconds
//! since the server started). A live sensor's offset is its clock's
//! difference to the server's minus its latency, nearly constant; the
//! server keeps the lowest offset of the frames it accepted (the one that
//! took longest to come), and the *lead* of a datagram is how much its own
//! offset exceeds that: how far its time is ahead of what the server's
//! elapsed time allows since the frames before it.
//!
//! - A time that is not finite, or beyond [`MAX_TIMESTAMP`] either way, is
//!   implausible.
//! - The clock is set by the first two datagrams (not one datagram sent
//!   twice) whose offsets agree within `max_skew`; until then up to eight
//!   wait. So a lone wrong first datagram sets nothing: it is dropped as
//!   implausible once two others agree without it.
//! - Then a datagram whose lead is more than `max_skew` (default
//!   [`DEFAULT_MAX_SKEW`]) ahead or behind is implausible. A live sensor
//!   leads by its latency jitter; a replay at `k` times real time by
//!   `1 - 1/k` of the time it has sent; a slower replay never leads (the
//!   lowest offset follows it down).
//!
//! Implausible datagrams are counted (`implausible_time`), the first few
//! printed on standard error like malformed ones, and dropped. Instants are
//! counted, not summed (`index * period`), and a drain never fuses an
//! instant later than the sensors' clock now plus `max_skew`, nor more
//! instants than the time since the previous drain allows plus a burst
//! worth `max_skew` and a second: whatever datagrams come, each one costs a
//! bounded amount of work and output, and the server answers Ctrl-C.
//!
//! # Implausible joints
//!
//! Every frame is screened as the offline fusion screens it
//! ([`SensorFrame::screen_implausible_joints`]): a joint farther than
//! [`crate::MAX_JOINT_DISTANCE`] from its sensor is fused as NotTracked
//! (`implausible_joints`), and a frame with no plausible joint is dropped
//! (`implausible_frames`).

use std::collections::{BTreeMap, BTreeSet, HashSet, VecDeque};
use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use mocap_core::error::printable;
use mocap_core::{Error, Result};
use serde::{Deserialize, Serialize};
use tokio::net::UdpSocket;

use crate::body::BodyModel;
use crate::calib::Calibration;
use crate::fusion::{Fuser, FusionOptions, SensorView};
use crate::kinect::JOINT_COUNT;
use crate::offline::sample_stream;
use crate::output::{FrameSink, FusedOutputs, OutputFiles, OutputReport};
use crate::recording::{read_recordings, JointObservation, SensorFrame};

/// The datagram magic and version.
pub const MAGIC: &[u8; 4] = b"MCF1";

/// Encodes a frame as a datagram.
pub fn encode_datagram(frame: &SensorFrame) -> Vec<u8> {
    let json = frame.to_json();
    let mut out = Vec::with_capacity(4 + json.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(json.as_bytes());
    out
}

/// Decodes a datagram, or says what is wrong with it.
pub fn decode_datagram(bytes: &[u8]) -> std::result::Result<SensorFrame, String> {
    let Some(body) = bytes.strip_prefix(MAGIC.as_slice()) else {
        return Err(format!(
            "bad magic {:?} (expected \"MCF1\")",
            String::from_utf8_lossy(&bytes[..bytes.len().min(4)])
        ));
    };
    let text = std::str::from_utf8(body).map_err(|e| format!("not UTF-8: {e}"))?;
    SensorFrame::from_json(text)
}

/// How far, by default, a datagram's time may be ahead of or behind the
/// sensors' clock as the server reckons it, in seconds (see the module
/// documentation). A live sensor is never more than its latency behind;
/// ten seconds leaves room for a replay at a few times real time.
pub const DEFAULT_MAX_SKEW: f64 = 10.0;

/// The largest time (seconds, either sign) a datagram may carry: 317 years,
/// enough for Unix time. Below it a period of a millisecond is still
/// thousands of times the resolution of an `f64`, so instants stay distinct.
pub const MAX_TIMESTAMP: f64 = 1e10;

/// The fastest frame rate the server fuses at (frames per second).
const MAX_FPS: f64 = 1000.0;

/// The longest `wait`, `sensor_timeout` or `max_skew` (seconds): an hour.
const MAX_SECONDS: f64 = 3600.0;

/// Datagrams kept while the clock is not set yet (see the module
/// documentation); older ones are dropped.
const HELD_BEFORE_CLOCK: usize = 8;

/// Problems of each kind printed on standard error; the rest are counted.
const LOGGED_PER_KIND: u64 = 5;

/// Options of the fusion server.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    pub listen: SocketAddr,
    pub calibration: Calibration,
    pub body: BodyModel,
    pub fusion: FusionOptions,
    /// Output instants per second (the sensors' frame rate), 0.1 to 1000.
    pub fps: f64,
    /// Seconds (sensor clock) past an instant after which it is fused
    /// without waiting for slower sensors.
    pub wait: f64,
    /// Seconds (sensor clock) behind the newest frame after which a sensor
    /// counts as gone.
    pub sensor_timeout: f64,
    /// Seconds a datagram's time may be ahead of or behind the sensors'
    /// clock as the server reckons it ([`DEFAULT_MAX_SKEW`]; see the module
    /// documentation). A replay faster than real time runs ahead by the
    /// take's length times `1 - 1/speed`.
    pub max_skew: f64,
    /// Stop after this long (wall clock); `None`: until the shutdown signal.
    pub duration: Option<Duration>,
    /// Stop when no datagram has come for this long after the first one
    /// (a replay has ended); `None`: keep listening.
    pub idle_exit: Option<Duration>,
}

impl ServeOptions {
    /// Checks the numbers: a frame rate of 0.1 to 1000 per second, and
    /// `wait`, `sensor_timeout` and `max_skew` of at most an hour.
    pub fn check(&self) -> Result<()> {
        if !(self.fps.is_finite() && (0.1..=MAX_FPS).contains(&self.fps)) {
            return Err(Error::Invalid(format!(
                "the frame rate must be 0.1 to {MAX_FPS} frames per second, got {}",
                self.fps
            )));
        }
        for (name, value, least) in [
            ("wait", self.wait, 0.0),
            ("sensor timeout", self.sensor_timeout, 0.0),
            ("max skew", self.max_skew, 1.0 / self.fps),
        ] {
            if !(value.is_finite() && (least..=MAX_SECONDS).contains(&value)) {
                return Err(Error::Invalid(format!(
                    "the {name} must be {least} to {MAX_SECONDS} seconds, got {value}"
                )));
            }
        }
        Ok(())
    }
}

/// What the server saw and did. Every datagram is counted once: in
/// `malformed`, `uncalibrated`, `implausible_time`, `implausible_frames`,
/// `duplicates`, `late`, `overflow` or `frames_accepted`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct ServeReport {
    pub datagrams: u64,
    pub frames_accepted: u64,
    pub malformed: u64,
    pub duplicates: u64,
    pub uncalibrated: u64,
    /// Frames for instants already fused.
    pub late: u64,
    /// Datagrams whose time does not fit the sensors' clock (see the
    /// module documentation): dropped.
    #[serde(default)]
    pub implausible_time: u64,
    /// Frames none of whose joints was within [`crate::MAX_JOINT_DISTANCE`]
    /// of the sensor: dropped.
    #[serde(default)]
    pub implausible_frames: u64,
    /// Joints of accepted frames farther than [`crate::MAX_JOINT_DISTANCE`]
    /// from their sensor, fused as NotTracked
    /// ([`SensorFrame::screen_implausible_joints`]).
    #[serde(default)]
    pub implausible_joints: u64,
    /// Frames beyond what a sensor can have sent in the time the server
    /// keeps (a flood): dropped.
    #[serde(default)]
    pub overflow: u64,
    pub fused_frames: u64,
    pub sensors_seen: Vec<u16>,
    /// Joint observations that went into fused frames.
    pub observations: u64,
    /// Wall seconds spent fusing (for throughput).
    pub fusion_seconds: f64,
    /// Datagram arrival to fused frame written, milliseconds.
    pub latency_median_ms: f64,
    pub latency_p99_ms: f64,
    pub latency_max_ms: f64,
}

impl ServeReport {
    /// Datagrams with an outcome: accepted, or dropped for one of the
    /// counted reasons. Every datagram received has exactly one, so this
    /// equals `datagrams` (what the tests and the fuzz target check).
    pub fn datagrams_settled(&self) -> u64 {
        self.malformed
            + self.uncalibrated
            + self.implausible_time
            + self.implausible_frames
            + self.duplicates
            + self.late
            + self.overflow
            + self.frames_accepted
    }
}

/// Why the timeline did not take a frame.
enum Refusal {
    Duplicate,
    Late,
    Overflow,
}

/// Per-sensor state of the server.
#[derive(Default)]
struct SensorState {
    /// In time order.
    frames: Vec<SensorFrame>,
    seen: HashSet<u64>,
    latest: f64,
}

/// The timeline: sensor streams and the next instant to fuse. Instants are
/// counted (`index * period`), never summed, so that every step moves on.
struct Timeline {
    sensors: BTreeMap<u16, SensorState>,
    next_index: Option<i64>,
    period: f64,
    wait: f64,
    sensor_timeout: f64,
    /// The most frames a sensor may have waiting.
    capacity: usize,
    /// Accepted frames not yet covered by a fused instant: (timestamp,
    /// arrival in server seconds).
    pending: VecDeque<(f64, f64)>,
}

impl Timeline {
    fn new(options: &ServeOptions) -> Timeline {
        // Frames a sensor keeps: those of the last few periods, and those up
        // to `max_skew` ahead; four times that at its frame rate is more
        // than a live sensor (or a replay) can have sent.
        let span = 2.0 * options.max_skew + options.wait + options.sensor_timeout + 1.0;
        Timeline {
            sensors: BTreeMap::new(),
            next_index: None,
            period: 1.0 / options.fps,
            wait: options.wait,
            sensor_timeout: options.sensor_timeout,
            capacity: (4.0 * span * options.fps).ceil() as usize + 16,
            pending: VecDeque::new(),
        }
    }

    fn instant(&self, index: i64) -> f64 {
        index as f64 * self.period
    }

    /// Adds a frame (arrived at `arrival`, server seconds).
    fn push(&mut self, frame: SensorFrame, arrival: f64) -> std::result::Result<(), Refusal> {
        let period = self.period;
        if let Some(next) = self.next_index {
            if frame.timestamp < self.instant(next) - 2.0 * period {
                return Err(Refusal::Late);
            }
        }
        let capacity = self.capacity;
        let s = self.sensors.entry(frame.sensor).or_default();
        if s.seen.contains(&frame.seq) {
            return Err(Refusal::Duplicate);
        }
        if s.frames.len() >= capacity {
            return Err(Refusal::Overflow);
        }
        s.seen.insert(frame.seq);
        let timestamp = frame.timestamp;
        s.latest = if s.frames.is_empty() {
            timestamp
        } else {
            s.latest.max(timestamp)
        };
        let at = s.frames.partition_point(|f| f.timestamp <= timestamp);
        s.frames.insert(at, frame);
        if self.next_index.is_none() {
            self.next_index = Some((timestamp / period).ceil() as i64);
        }
        self.pending.push_back((timestamp, arrival));
        Ok(())
    }

    /// The next instant if it is ready to fuse.
    fn ready(&self, flush: bool) -> Option<f64> {
        let t = self.instant(self.next_index?);
        let newest = self
            .sensors
            .values()
            .map(|s| s.latest)
            .fold(f64::MIN, f64::max);
        if newest < t && !flush {
            return None;
        }
        if flush {
            return (newest >= t - self.period).then_some(t);
        }
        let all_there = self
            .sensors
            .values()
            .filter(|s| newest - s.latest <= self.sensor_timeout)
            .all(|s| s.latest >= t);
        (all_there || newest >= t + self.wait).then_some(t)
    }

    /// The views of instant `t` (world space).
    fn views(&self, t: f64, calibration: &Calibration) -> Vec<SensorView> {
        self.sensors
            .iter()
            .filter_map(|(&sensor, s)| {
                let pose = calibration.get(sensor)?;
                let joints = sample_stream(&s.frames, t, self.period)?;
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

    /// Moves on to the next instant and drops the frames too old to matter
    /// for it.
    fn advance(&mut self) {
        let Some(index) = self.next_index.map(|i| i + 1) else {
            return;
        };
        self.next_index = Some(index);
        let keep_from = self.instant(index) - 3.0 * self.period;
        for s in self.sensors.values_mut() {
            let old = s
                .frames
                .iter()
                .skip(1)
                .take_while(|f| f.timestamp < keep_from)
                .count();
            for f in s.frames.drain(..old) {
                s.seen.remove(&f.seq);
            }
        }
    }
}

/// The sensors' clock as the server reckons it: `offset` is the lowest
/// `t - s` (sensor time minus server seconds at arrival) of the accepted
/// datagrams, that of the one that took longest to come; `None` until two
/// datagrams agree on it.
#[derive(Default)]
struct Clock {
    offset: Option<f64>,
    /// Datagrams waiting for the clock to be set.
    held: VecDeque<Held>,
}

/// A decoded, calibrated, screened datagram.
struct Held {
    frame: SensorFrame,
    arrival: f64,
    from: SocketAddr,
    outliers: usize,
}

impl Held {
    fn offset(&self) -> f64 {
        self.frame.timestamp - self.arrival
    }
}

/// Latencies in bins 1% wide on a log scale, from a microsecond to about
/// twenty minutes: the median and the 99th percentile to within 1%, in the
/// same memory however long the server runs.
#[derive(Default)]
struct Latencies {
    counts: Vec<u64>,
    total: u64,
    max: f64,
}

impl Latencies {
    const LEAST: f64 = 1e-6;
    const RATIO: f64 = 1.01;
    const BINS: usize = 2100;

    fn add(&mut self, seconds: f64) {
        if self.counts.is_empty() {
            self.counts = vec![0; Self::BINS];
        }
        let bin = if seconds > Self::LEAST {
            ((seconds / Self::LEAST).ln() / Self::RATIO.ln()) as usize
        } else {
            0
        };
        self.counts[bin.min(Self::BINS - 1)] += 1;
        self.total += 1;
        self.max = self.max.max(seconds);
    }

    /// The `q` quantile in milliseconds (the middle of its bin).
    fn quantile_ms(&self, q: f64) -> f64 {
        if self.total == 0 {
            return 0.0;
        }
        let rank = ((self.total - 1) as f64 * q).round() as u64;
        let mut below = 0;
        for (bin, &count) in self.counts.iter().enumerate() {
            below += count;
            if below > rank {
                let middle = Self::LEAST * Self::RATIO.powf(bin as f64 + 0.5);
                return middle.min(self.max) * 1000.0;
            }
        }
        self.max * 1000.0
    }
}

/// The server without its socket: judges each datagram, keeps the
/// timeline, fuses and writes. [`serve`] drives it from its socket and the
/// wall clock (`now`: seconds since the server started); tests and the fuzz
/// target drive it directly.
#[doc(hidden)]
pub struct ServerCore {
    calibration: Calibration,
    fps: f64,
    max_skew: f64,
    timeline: Timeline,
    clock: Clock,
    fuser: Fuser,
    report: ServeReport,
    latencies: Latencies,
    sensors_seen: BTreeSet<u16>,
    last_drain: Option<f64>,
    /// Instants a drain may fuse beyond what the time since the last one
    /// allows.
    burst: u64,
    log: bool,
}

impl ServerCore {
    /// A server with the options' calibration, body and fusion, which
    /// prints the first few problems of each kind on standard error.
    pub fn new(options: &ServeOptions) -> Result<ServerCore> {
        options.check()?;
        Ok(ServerCore {
            calibration: options.calibration.clone(),
            fps: options.fps,
            max_skew: options.max_skew,
            timeline: Timeline::new(options),
            clock: Clock::default(),
            fuser: Fuser::new(options.fusion.online(), options.body.clone()),
            report: ServeReport::default(),
            latencies: Latencies::default(),
            sensors_seen: BTreeSet::new(),
            last_drain: None,
            burst: (options.fps * (options.max_skew + 1.0)).ceil() as u64 + 2,
            log: true,
        })
    }

    /// Prints nothing.
    pub fn quiet(mut self) -> ServerCore {
        self.log = false;
        self
    }

    fn log(&self, count: u64, message: std::fmt::Arguments) {
        if self.log && count <= LOGGED_PER_KIND {
            eprintln!("fuse serve: {message}");
        }
    }

    /// One datagram from `from`, arrived at `now` (server seconds).
    pub fn receive(&mut self, bytes: &[u8], from: SocketAddr, now: f64) {
        self.report.datagrams += 1;
        let mut frame = match decode_datagram(bytes) {
            Ok(frame) => frame,
            Err(why) => {
                self.report.malformed += 1;
                self.log(
                    self.report.malformed,
                    format_args!(
                        "malformed datagram from {from} ({} bytes): {}; dropped",
                        bytes.len(),
                        printable(&why)
                    ),
                );
                return;
            }
        };
        if self.calibration.get(frame.sensor).is_none() {
            self.report.uncalibrated += 1;
            self.log(
                self.report.uncalibrated,
                format_args!(
                    "datagram from {from}: sensor {} is not in the calibration; ignored",
                    frame.sensor
                ),
            );
            return;
        }
        self.sensors_seen.insert(frame.sensor);
        if !(frame.timestamp.is_finite() && frame.timestamp.abs() <= MAX_TIMESTAMP) {
            let t = frame.timestamp;
            self.implausible_time(
                from,
                format_args!("time {t} s is beyond the {MAX_TIMESTAMP:e} s a clock may read"),
            );
            return;
        }
        let outliers = frame.screen_implausible_joints();
        if outliers == JOINT_COUNT {
            self.report.implausible_frames += 1;
            self.log(
                self.report.implausible_frames,
                format_args!(
                    "datagram from {from}: sensor {} frame {}: every joint is more than {} m from the sensor; dropped",
                    frame.sensor,
                    frame.seq,
                    crate::recording::MAX_JOINT_DISTANCE
                ),
            );
            return;
        }
        let held = Held {
            frame,
            arrival: now,
            from,
            outliers,
        };
        if self.clock.offset.is_some() {
            self.judge(held);
        } else {
            self.hold(held);
        }
    }

    fn implausible_time(&mut self, from: SocketAddr, why: std::fmt::Arguments) {
        self.report.implausible_time += 1;
        self.log(
            self.report.implausible_time,
            format_args!("datagram from {from}: implausible time: {why}; dropped"),
        );
    }

    /// Before the clock is set: keeps the datagram until another one
    /// agrees with it, then sets the clock and judges those held.
    fn hold(&mut self, held: Held) {
        let agrees = |h: &Held| {
            (h.offset() - held.offset()).abs() <= self.max_skew
                && (h.frame.sensor, h.frame.seq) != (held.frame.sensor, held.frame.seq)
        };
        if let Some(other) = self.clock.held.iter().find(|h| agrees(h)) {
            self.clock.offset = Some(other.offset().min(held.offset()));
            let mut waiting = std::mem::take(&mut self.clock.held);
            waiting.push_back(held);
            for h in waiting {
                self.judge(h);
            }
            return;
        }
        if self.clock.held.len() >= HELD_BEFORE_CLOCK {
            if let Some(old) = self.clock.held.pop_front() {
                self.implausible_time(
                    old.from,
                    format_args!(
                        "time {} s of sensor {} frame {}: no other datagram agreed with it",
                        old.frame.timestamp, old.frame.sensor, old.frame.seq
                    ),
                );
            }
        }
        self.clock.held.push_back(held);
    }

    /// Once the clock is set: drops a datagram whose time is more than
    /// `max_skew` ahead of or behind the clock, gives the others to the
    /// timeline.
    fn judge(&mut self, held: Held) {
        let Some(offset) = self.clock.offset else {
            return;
        };
        let lead = held.offset() - offset;
        let max_skew = self.max_skew;
        if lead.abs() > max_skew {
            let t = held.frame.timestamp;
            let (sensor, seq) = (held.frame.sensor, held.frame.seq);
            self.implausible_time(
                held.from,
                format_args!(
                    "sensor {sensor} frame {seq} at {t} s is {:.3} s {} the sensors' clock as the server reckons it (more than the {} s allowed)",
                    lead.abs(),
                    if lead > 0.0 { "ahead of" } else { "behind" },
                    max_skew
                ),
            );
            return;
        }
        let offset_here = held.offset();
        match self.timeline.push(held.frame, held.arrival) {
            Ok(()) => {
                self.report.frames_accepted += 1;
                self.report.implausible_joints += held.outliers as u64;
                self.clock.offset = Some(offset.min(offset_here));
            }
            Err(Refusal::Duplicate) => self.report.duplicates += 1,
            Err(Refusal::Late) => self.report.late += 1,
            Err(Refusal::Overflow) => {
                self.report.overflow += 1;
                self.log(
                    self.report.overflow,
                    format_args!(
                        "datagram from {}: more frames than a sensor can send; dropped",
                        held.from
                    ),
                );
            }
        }
    }

    /// Fuses the instants that are ready at `now` (server seconds), all of
    /// them when `flush` (the server stops), into `sink`. Never fuses an
    /// instant later than the sensors' clock now plus `max_skew`, nor more
    /// instants than the time since the last drain allows plus a burst of
    /// `max_skew` (and a second) worth.
    pub fn drain(&mut self, now: f64, flush: bool, sink: &mut dyn FrameSink) -> Result<()> {
        let Some(offset) = self.clock.offset else {
            return Ok(());
        };
        let period = 1.0 / self.fps;
        let fence = now + offset + self.max_skew + period;
        let since = self.last_drain.map_or(0.0, |last| (now - last).max(0.0));
        self.last_drain = Some(now);
        let mut budget = ((since * self.fps).ceil() as u64).saturating_add(self.burst);
        let started = Instant::now();
        while budget > 0 {
            let Some(t) = self.timeline.ready(flush) else {
                break;
            };
            if t > fence {
                break;
            }
            budget -= 1;
            let fusing = Instant::now();
            let views = self.timeline.views(t, &self.calibration);
            let fused = self.fuser.fuse(t, &views);
            self.report.fusion_seconds += fusing.elapsed().as_secs_f64();
            if let Some(f) = fused {
                sink.write(&f)?;
                self.report.fused_frames += 1;
                self.report.observations += (views.len() * JOINT_COUNT) as u64;
            }
            let written = now + started.elapsed().as_secs_f64();
            while let Some(&(timestamp, arrival)) = self.timeline.pending.front() {
                if timestamp > t + 1e-9 {
                    break;
                }
                self.timeline.pending.pop_front();
                self.latencies.add((written - arrival).max(0.0));
            }
            self.timeline.advance();
        }
        Ok(())
    }

    /// What the server saw and did; datagrams still waiting for the clock
    /// count as implausible.
    pub fn finish(mut self) -> ServeReport {
        self.report.implausible_time += self.clock.held.len() as u64;
        let mut report = self.report;
        report.latency_median_ms = self.latencies.quantile_ms(0.5);
        report.latency_p99_ms = self.latencies.quantile_ms(0.99);
        report.latency_max_ms = self.latencies.max * 1000.0;
        report.sensors_seen = self.sensors_seen.into_iter().collect();
        report
    }
}

/// Runs the fusion server until `shutdown` completes or `options.duration`
/// passes, then fuses what is left, finishes the sink and reports.
pub async fn serve(
    options: ServeOptions,
    sink: &mut dyn FrameSink,
    shutdown: impl std::future::Future<Output = ()>,
    bound: Option<tokio::sync::oneshot::Sender<SocketAddr>>,
) -> Result<ServeReport> {
    let mut core = ServerCore::new(&options)?;
    let socket = UdpSocket::bind(options.listen)
        .await
        .map_err(|e| Error::Invalid(format!("cannot listen on {}: {e}", options.listen)))?;
    if let Some(tx) = bound {
        let _ = tx.send(
            socket
                .local_addr()
                .map_err(|e| Error::Invalid(e.to_string()))?,
        );
    }
    let started = Instant::now();
    let now = || started.elapsed().as_secs_f64();
    let mut buf = vec![0u8; 65536];
    let deadline = options.duration.map(|d| tokio::time::Instant::now() + d);
    tokio::pin!(shutdown);
    let mut tick = tokio::time::interval(Duration::from_millis(20));
    let mut last_datagram: Option<Instant> = None;
    let mut receive_errors = 0u64;
    loop {
        let idle = match (options.idle_exit, last_datagram) {
            (Some(limit), Some(last)) => last.elapsed() >= limit,
            _ => false,
        };
        let stop = idle
            || tokio::select! {
                _ = &mut shutdown => true,
                _ = async {
                    match deadline {
                        Some(d) => tokio::time::sleep_until(d).await,
                        None => std::future::pending().await,
                    }
                } => true,
                _ = tick.tick() => false,
                received = socket.recv_from(&mut buf) => {
                    last_datagram = Some(Instant::now());
                    match received {
                        Ok((len, from)) => core.receive(&buf[..len], from, now()),
                        Err(e) => {
                            receive_errors += 1;
                            if receive_errors <= LOGGED_PER_KIND {
                                eprintln!("fuse serve: receive error: {e}");
                            }
                        }
                    }
                    false
                }
            };
        core.drain(now(), stop, sink)?;
        if stop {
            break;
        }
    }
    sink.finish()?;
    Ok(core.finish())
}

/// Options of the sender.
#[derive(Debug, Clone, Copy)]
pub struct SendOptions {
    pub to: SocketAddr,
    /// Send each frame at its `arrival` (or timestamp) time, relative to the
    /// first; otherwise as fast as possible.
    pub realtime: bool,
    /// Playback speed factor in real time mode.
    pub speed: f64,
}

/// What the sender did.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct SendReport {
    pub datagrams: u64,
    pub bytes: u64,
    pub seconds: f64,
}

/// Replays frames as a live sensor (or several, if the frames are of several).
pub async fn send(frames: &[SensorFrame], options: SendOptions) -> Result<SendReport> {
    let socket = UdpSocket::bind(if options.to.is_ipv4() {
        "0.0.0.0:0"
    } else {
        "[::]:0"
    })
    .await
    .map_err(|e| Error::Invalid(format!("cannot open a UDP socket: {e}")))?;
    let mut order: Vec<&SensorFrame> = frames.iter().collect();
    let when = |f: &SensorFrame| f.arrival.unwrap_or(f.timestamp);
    order.sort_by(|a, b| when(a).total_cmp(&when(b)));
    let start = tokio::time::Instant::now();
    let t0 = order.first().map(|f| when(f)).unwrap_or(0.0);
    let mut report = SendReport::default();
    for f in order {
        if options.realtime {
            let offset = ((when(f) - t0) / options.speed.max(1e-6)).max(0.0);
            tokio::time::sleep_until(start + Duration::from_secs_f64(offset)).await;
        }
        let bytes = encode_datagram(f);
        socket
            .send_to(&bytes, options.to)
            .await
            .map_err(|e| Error::Invalid(format!("cannot send to {}: {e}", options.to)))?;
        report.datagrams += 1;
        report.bytes += bytes.len() as u64;
    }
    report.seconds = start.elapsed().as_secs_f64();
    Ok(report)
}

/// A single-threaded tokio runtime for the blocking entry points.
pub fn runtime() -> Result<tokio::runtime::Runtime> {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| Error::Invalid(format!("cannot start the async runtime: {e}")))
}

/// `mocap fuse serve`: runs until Ctrl-C (or `duration`), flushing the output.
pub fn serve_blocking(options: ServeOptions, sink: &mut dyn FrameSink) -> Result<ServeReport> {
    runtime()?.block_on(serve(
        options,
        sink,
        async {
            let _ = tokio::signal::ctrl_c().await;
        },
        None,
    ))
}

/// Like [`serve_blocking`], calling `on_listening` with the bound address
/// once the socket is open (to print it when the port was 0).
pub fn serve_blocking_with(
    options: ServeOptions,
    sink: &mut dyn FrameSink,
    on_listening: impl FnOnce(SocketAddr),
) -> Result<ServeReport> {
    runtime()?.block_on(async {
        let (tx, rx) = tokio::sync::oneshot::channel();
        let server = serve(
            options,
            sink,
            async {
                let _ = tokio::signal::ctrl_c().await;
            },
            Some(tx),
        );
        let announce = async {
            if let Ok(addr) = rx.await {
                on_listening(addr);
            }
        };
        let (report, ()) = tokio::join!(server, announce);
        report
    })
}

/// `mocap fuse send`.
pub fn send_blocking(frames: &[SensorFrame], options: SendOptions) -> Result<SendReport> {
    runtime()?.block_on(send(frames, options))
}

/// What `mocap fuse serve` serves: the server's settings
/// ([`ServeOptions`]) with its calibration and body read from files, and the
/// files fused frames go to.
#[derive(Debug, Clone)]
pub struct ServeFilesOptions {
    /// The calibration file (every sensor's pose).
    pub calibration: PathBuf,
    /// The person's body file.
    pub body: PathBuf,
    pub outputs: OutputFiles,
    pub listen: SocketAddr,
    pub fusion: FusionOptions,
    pub fps: f64,
    pub wait: f64,
    pub sensor_timeout: f64,
    /// [`ServeOptions::max_skew`].
    pub max_skew: f64,
    pub duration: Option<Duration>,
    pub idle_exit: Option<Duration>,
}

/// What [`serve_files`] did.
#[derive(Debug, Clone, Serialize)]
pub struct ServeFilesReport {
    pub server: ServeReport,
    pub outputs: Vec<OutputReport>,
}

/// `mocap fuse serve`: the fusion server ([`serve_blocking_with`]) until
/// Ctrl-C, `duration` or `idle_exit`, writing the output files.
pub fn serve_files(
    options: ServeFilesOptions,
    on_listening: impl FnOnce(SocketAddr),
) -> Result<ServeFilesReport> {
    let calibration = Calibration::read(&options.calibration)?;
    let body = BodyModel::read(&options.body)?;
    let server_options = ServeOptions {
        listen: options.listen,
        calibration,
        body: body.clone(),
        fusion: options.fusion,
        fps: options.fps,
        wait: options.wait,
        sensor_timeout: options.sensor_timeout,
        max_skew: options.max_skew,
        duration: options.duration,
        idle_exit: options.idle_exit,
    };
    server_options.check()?;
    let mut outputs = FusedOutputs::open(&options.outputs, body, options.fps)?;
    let server = serve_blocking_with(server_options, &mut outputs, on_listening)?;
    Ok(ServeFilesReport {
        server,
        outputs: outputs.reports().to_vec(),
    })
}

/// `mocap fuse send`: sends the recordings' frames to a fusion server
/// ([`send_blocking`]).
pub fn send_files(recordings: &[PathBuf], options: SendOptions) -> Result<SendReport> {
    let frames = read_recordings(recordings)?;
    send_blocking(&frames, options)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::MeasureOptions;
    use crate::calib::{RigidTransform, SensorPose};
    use crate::kinect::{TrackingState, JOINT_COUNT};
    use crate::output::MemorySink;
    use mocap_core::rotation::Vec3;

    fn frame(sensor: u16, seq: u64) -> SensorFrame {
        let pose = crate::body::tests::standing_pose();
        SensorFrame {
            sensor,
            seq,
            timestamp: seq as f64 / 30.0,
            arrival: None,
            joints: pose.map(|position| JointObservation {
                position: position + Vec3::new(0.0, 0.0, sensor as f32 * 0.01),
                state: TrackingState::Tracked,
            }),
        }
    }

    #[test]
    fn datagrams_round_trip_and_garbage_is_refused() {
        let f = frame(2, 7);
        let back = decode_datagram(&encode_datagram(&f)).unwrap();
        assert_eq!(back.seq, 7);
        for bad in [
            &b""[..],
            b"MCF",
            b"XXXX{}",
            b"MCF1\xff\xfe",
            b"MCF1{\"sensor\":1}",
        ] {
            assert!(decode_datagram(bad).is_err());
        }
    }

    #[test]
    fn server_survives_garbage_loss_reordering_duplicates_and_a_vanishing_sensor() {
        let rt = runtime().unwrap();
        rt.block_on(async {
            let mut calibration = Calibration::default();
            for id in 0..3 {
                calibration.set(SensorPose {
                    id,
                    transform: RigidTransform::IDENTITY,
                    method: None,
                    rms_residual: None,
                    pairs: None,
                });
            }
            let pose = crate::body::tests::standing_pose();
            let options = ServeOptions {
                listen: "127.0.0.1:0".parse().unwrap(),
                calibration,
                body: BodyModel::from_positions([&pose; 20], MeasureOptions::default()),
                fusion: FusionOptions::best(),
                fps: 30.0,
                wait: 0.1,
                sensor_timeout: 0.5,
                max_skew: DEFAULT_MAX_SKEW,
                duration: Some(Duration::from_millis(3000)),
                idle_exit: Some(Duration::from_millis(400)),
            };
            let (tx, rx) = tokio::sync::oneshot::channel();
            let mut sink = MemorySink::default();
            let server = serve(options, &mut sink, std::future::pending(), Some(tx));
            let client = async {
                let addr = rx.await.unwrap();
                let sock = UdpSocket::bind("127.0.0.1:0").await.unwrap();
                let mut datagrams: Vec<Vec<u8>> = Vec::new();
                for seq in 0..30u64 {
                    for sensor in 0..3u16 {
                        // Sensor 2 vanishes after frame 10; sensor 1 loses
                        // every 7th frame; sensor 3 is not calibrated.
                        if (sensor == 2 && seq > 10) || (sensor == 1 && seq % 7 == 3) {
                            continue;
                        }
                        datagrams.push(encode_datagram(&frame(sensor, seq)));
                    }
                    datagrams.push(encode_datagram(&frame(3, seq)));
                    if seq % 5 == 0 {
                        datagrams.push(b"garbage".to_vec());
                        datagrams.push(encode_datagram(&frame(0, seq))); // duplicate
                        datagrams.push(
                            b"MCF1{\"v\":1,\"sensor\":0,\"seq\":1,\"t\":1e999,\"joints\":[]}"
                                .to_vec(),
                        );
                    }
                }
                // Reorder: swap neighbours.
                for i in (0..datagrams.len() - 1).step_by(4) {
                    datagrams.swap(i, i + 1);
                }
                for d in &datagrams {
                    sock.send_to(d, addr).await.unwrap();
                    tokio::time::sleep(Duration::from_micros(300)).await;
                }
            };
            let (report, ()) = tokio::join!(server, client);
            let report = report.unwrap();
            assert_eq!(report.malformed, 12, "{report:?}");
            assert_eq!(report.duplicates, 6, "{report:?}");
            assert_eq!(report.uncalibrated, 30);
            assert!(report.fused_frames >= 29, "{report:?}");
            assert_eq!(sink.frames.len() as u64, report.fused_frames);
            let f = &sink.frames[20];
            assert!(!f.sensors.is_empty() && !f.sensors.contains(&2));
            assert!(
                (f.joints[crate::kinect::joint::HEAD] - pose[crate::kinect::joint::HEAD]).length()
                    < 0.02
            );
            assert_eq!(f.joints.len(), JOINT_COUNT);
        });
    }

    /// Three calibrated sensors (0, 1, 2) at the origin, 30 fps.
    fn core_options() -> ServeOptions {
        let mut calibration = Calibration::default();
        for id in 0..3 {
            calibration.set(SensorPose {
                id,
                transform: RigidTransform::IDENTITY,
                method: None,
                rms_residual: None,
                pairs: None,
            });
        }
        let pose = crate::body::tests::standing_pose();
        ServeOptions {
            listen: "127.0.0.1:0".parse().unwrap(),
            calibration,
            body: BodyModel::from_positions([&pose; 20], MeasureOptions::default()),
            fusion: FusionOptions::best(),
            fps: 30.0,
            wait: 0.1,
            sensor_timeout: 0.5,
            max_skew: DEFAULT_MAX_SKEW,
            duration: None,
            idle_exit: None,
        }
    }

    /// A take of `frames` frames of sensors 0 and 1, each arriving 10 ms
    /// after its time (server seconds = sensor seconds), in arrival order.
    fn take(frames: u64) -> Vec<(f64, Vec<u8>)> {
        let mut out = Vec::new();
        for seq in 0..frames {
            for sensor in 0..2 {
                let f = frame(sensor, seq);
                out.push((
                    f.timestamp + 0.01 + sensor as f64 * 1e-4,
                    encode_datagram(&f),
                ));
            }
        }
        out
    }

    /// Feeds datagrams to a server core as the socket loop does (a drain
    /// after each), then stops it. Returns the report, the fused frames and
    /// the most frames one drain wrote.
    fn run_core(
        options: &ServeOptions,
        datagrams: &[(f64, Vec<u8>)],
    ) -> (ServeReport, Vec<crate::fusion::FusedFrame>, usize) {
        let mut core = ServerCore::new(options).unwrap().quiet();
        let mut sink = MemorySink::default();
        let from: SocketAddr = "127.0.0.1:9".parse().unwrap();
        let mut most = 0;
        let mut now = 0.0;
        for (arrival, bytes) in datagrams {
            now = *arrival;
            core.receive(bytes, from, now);
            let before = sink.frames.len();
            core.drain(now, false, &mut sink).unwrap();
            most = most.max(sink.frames.len() - before);
        }
        core.drain(now + 1.0, true, &mut sink).unwrap();
        let report = core.finish();
        (report, sink.frames, most)
    }

    fn same_frames(a: &[crate::fusion::FusedFrame], b: &[crate::fusion::FusedFrame]) {
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            assert_eq!(x.time, y.time);
            for (p, q) in x.joints.iter().zip(&y.joints) {
                assert!((*p - *q).length() < 1e-6, "{p} vs {q} at {}", x.time);
            }
        }
    }

    #[test]
    fn a_wrong_first_time_sets_no_clock() {
        let options = core_options();
        let clean = take(90);
        let (report, expected, _) = run_core(&options, &clean);
        assert_eq!(report.implausible_time, 0, "{report:?}");
        assert!(expected.len() >= 89, "{}", expected.len());
        for t in [1e30, -1e30, 1e4, -5e3, 60.0] {
            let mut bogus = frame(0, 999);
            bogus.timestamp = t;
            let mut datagrams = vec![(0.0, encode_datagram(&bogus))];
            datagrams.extend(clean.iter().cloned());
            let (report, fused, most) = run_core(&options, &datagrams);
            assert_eq!(report.implausible_time, 1, "t = {t}: {report:?}");
            assert_eq!(report.datagrams_settled(), report.datagrams, "{report:?}");
            same_frames(&fused, &expected);
            assert!(most <= 3, "t = {t}: {most} frames from one datagram");
        }
    }

    #[test]
    fn a_wrong_time_mid_stream_is_dropped() {
        let options = core_options();
        let clean = take(90);
        let (_, expected, _) = run_core(&options, &clean);
        for t in [1e30, 1e4, -1e4, 1.5 + 2.0 * DEFAULT_MAX_SKEW, -1e30] {
            let mut bogus = frame(1, 5000);
            bogus.timestamp = t;
            let mut datagrams = clean.clone();
            datagrams.insert(90, (1.5, encode_datagram(&bogus)));
            let (report, fused, most) = run_core(&options, &datagrams);
            assert_eq!(report.implausible_time, 1, "t = {t}: {report:?}");
            assert_eq!(report.datagrams_settled(), report.datagrams, "{report:?}");
            same_frames(&fused, &expected);
            assert!(most <= 3, "t = {t}: {most} frames from one datagram");
        }
    }

    #[test]
    fn absurd_joints_never_move_the_fused_skeleton() {
        let options = core_options();
        let clean = take(90);
        let (_, expected, _) = run_core(&options, &clean);
        // A frame of sensor 0 at a real instant with every joint at 1e30 m,
        // Tracked; then one with only its head there.
        let mut far = frame(0, 6000);
        far.timestamp = 45.0 / 30.0;
        for j in far.joints.iter_mut() {
            j.position = Vec3::splat(1e30);
        }
        let mut head = frame(0, 6001);
        head.timestamp = 60.0 / 30.0;
        head.joints[crate::kinect::joint::HEAD].position = Vec3::new(0.0, 1e30, 0.0);
        let mut datagrams = clean.clone();
        datagrams.insert(91, (45.0 / 30.0 + 0.01, encode_datagram(&far)));
        datagrams.insert(121, (2.0 + 0.01, encode_datagram(&head)));
        let (report, fused, _) = run_core(&options, &datagrams);
        assert_eq!(report.implausible_frames, 1, "{report:?}");
        assert_eq!(report.implausible_joints, 1, "{report:?}");
        assert_eq!(report.datagrams_settled(), report.datagrams, "{report:?}");
        assert_eq!(fused.len(), expected.len());
        for (f, e) in fused.iter().zip(&expected) {
            for (p, q) in f.joints.iter().zip(&e.joints) {
                // The head frame is a third observation of sensor 0 at its
                // instant: its other joints count, the head does not.
                assert!((*p - *q).length() < 0.05, "{p} vs {q} at {}", f.time);
            }
        }
    }

    #[test]
    fn a_flood_ahead_of_the_clock_is_bounded() {
        // A minute of frames sent within a tenth of a second: the server
        // takes what is within max_skew of its clock and never fuses more
        // than the time allows.
        let options = core_options();
        let datagrams: Vec<(f64, Vec<u8>)> = take(1800)
            .into_iter()
            .enumerate()
            .map(|(i, (_, bytes))| (i as f64 * 0.1 / 3600.0, bytes))
            .collect();
        let (report, fused, most) = run_core(&options, &datagrams);
        assert_eq!(report.datagrams_settled(), report.datagrams, "{report:?}");
        let allowed = ((0.1 + 1.0 + DEFAULT_MAX_SKEW + 1.0) * 30.0) as usize;
        assert!(fused.len() <= allowed, "{} > {allowed}", fused.len());
        assert!(fused.len() >= 280, "{}", fused.len());
        assert!(report.implausible_time > 2900, "{report:?}");
        assert!(most as u64 <= (30.0 * (DEFAULT_MAX_SKEW + 1.0)) as u64 + 3);
    }

    #[test]
    fn options_out_of_range_are_refused() {
        let changes: [fn(&mut ServeOptions); 7] = [
            |o: &mut ServeOptions| o.fps = 0.0,
            |o: &mut ServeOptions| o.fps = 1e9,
            |o: &mut ServeOptions| o.fps = f64::NAN,
            |o: &mut ServeOptions| o.wait = -1.0,
            |o: &mut ServeOptions| o.sensor_timeout = f64::INFINITY,
            |o: &mut ServeOptions| o.max_skew = 1e30,
            |o: &mut ServeOptions| o.max_skew = 0.0,
        ];
        for change in changes {
            let mut options = core_options();
            change(&mut options);
            assert!(ServerCore::new(&options).is_err(), "{options:?}");
        }
    }

    #[test]
    fn latency_quantiles_are_within_a_percent() {
        let mut l = Latencies::default();
        let values: Vec<f64> = (1..=1000).map(|i| i as f64 * 1e-4).collect();
        for v in &values {
            l.add(*v);
        }
        let exact = |q: f64| values[((values.len() - 1) as f64 * q).round() as usize] * 1000.0;
        for q in [0.5, 0.99] {
            let (a, b) = (l.quantile_ms(q), exact(q));
            assert!((a - b).abs() <= 0.011 * b, "{a} vs {b}");
        }
        assert_eq!(l.max, 0.1);
    }
}
