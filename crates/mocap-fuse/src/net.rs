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

use std::collections::{BTreeMap, HashSet, VecDeque};
use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use mocap_core::{Error, Result};
use serde::{Deserialize, Serialize};
use tokio::net::UdpSocket;

use crate::body::BodyModel;
use crate::calib::Calibration;
use crate::fusion::{Fuser, FusionOptions, SensorView};
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

/// Options of the fusion server.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    pub listen: SocketAddr,
    pub calibration: Calibration,
    pub body: BodyModel,
    pub fusion: FusionOptions,
    /// Output instants per second (the sensors' frame rate).
    pub fps: f64,
    /// Seconds (sensor clock) past an instant after which it is fused
    /// without waiting for slower sensors.
    pub wait: f64,
    /// Seconds (sensor clock) behind the newest frame after which a sensor
    /// counts as gone.
    pub sensor_timeout: f64,
    /// Stop after this long (wall clock); `None`: until the shutdown signal.
    pub duration: Option<Duration>,
    /// Stop when no datagram has come for this long after the first one
    /// (a replay has ended); `None`: keep listening.
    pub idle_exit: Option<Duration>,
}

/// What the server saw and did.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct ServeReport {
    pub datagrams: u64,
    pub frames_accepted: u64,
    pub malformed: u64,
    pub duplicates: u64,
    pub uncalibrated: u64,
    /// Frames for instants already fused.
    pub late: u64,
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

/// Per-sensor state of the server.
#[derive(Default)]
struct SensorState {
    frames: VecDeque<SensorFrame>,
    seen: HashSet<u64>,
    latest: f64,
}

/// The timeline: sensor streams and the next instant to fuse.
pub struct Timeline {
    sensors: BTreeMap<u16, SensorState>,
    next_instant: Option<f64>,
    period: f64,
    wait: f64,
    sensor_timeout: f64,
    /// Accepted frames not yet covered by a fused instant: (timestamp, arrival).
    pending: VecDeque<(f64, Instant)>,
}

impl Timeline {
    pub fn new(fps: f64, wait: f64, sensor_timeout: f64) -> Timeline {
        Timeline {
            sensors: BTreeMap::new(),
            next_instant: None,
            period: 1.0 / fps,
            wait,
            sensor_timeout,
            pending: VecDeque::new(),
        }
    }

    /// Adds a frame; says why it was not taken.
    pub fn push(
        &mut self,
        frame: SensorFrame,
        arrival: Instant,
    ) -> std::result::Result<(), &'static str> {
        let period = self.period;
        if let Some(next) = self.next_instant {
            if frame.timestamp < next - 2.0 * period {
                return Err("late");
            }
        }
        let s = self.sensors.entry(frame.sensor).or_default();
        if !s.seen.insert(frame.seq) {
            return Err("duplicate");
        }
        s.latest = s.latest.max(frame.timestamp);
        let at = s.frames.partition_point(|f| f.timestamp <= frame.timestamp);
        s.frames.insert(at, frame.clone());
        if self.next_instant.is_none() {
            self.next_instant = Some((frame.timestamp / period).ceil() * period);
        }
        self.pending.push_back((frame.timestamp, arrival));
        Ok(())
    }

    /// The next instant if it is ready to fuse.
    fn ready(&self, flush: bool) -> Option<f64> {
        let t = self.next_instant?;
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
                let frames: &[SensorFrame] = &s.frames.iter().cloned().collect::<Vec<_>>();
                let joints = sample_stream(frames, t, self.period)?;
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

    /// Drops frames too old to matter for instants from `t` on.
    fn forget_before(&mut self, t: f64) {
        let keep_from = t - 3.0 * self.period;
        for s in self.sensors.values_mut() {
            while s.frames.len() > 1 && s.frames[1].timestamp < keep_from {
                if let Some(f) = s.frames.pop_front() {
                    s.seen.remove(&f.seq);
                }
            }
        }
    }
}

fn percentile_ms(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    sorted[((sorted.len() - 1) as f64 * q).round() as usize] * 1000.0
}

/// Runs the fusion server until `shutdown` completes or `options.duration`
/// passes, then fuses what is left, finishes the sink and reports.
pub async fn serve(
    options: ServeOptions,
    sink: &mut dyn FrameSink,
    shutdown: impl std::future::Future<Output = ()>,
    bound: Option<tokio::sync::oneshot::Sender<SocketAddr>>,
) -> Result<ServeReport> {
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
    let mut fuser = Fuser::new(options.fusion.online(), options.body.clone());
    let mut timeline = Timeline::new(options.fps, options.wait, options.sensor_timeout);
    let mut report = ServeReport::default();
    let mut latencies: Vec<f64> = Vec::new();
    let mut sensors_seen = HashSet::new();
    let mut buf = vec![0u8; 65536];
    let deadline = options.duration.map(|d| tokio::time::Instant::now() + d);
    tokio::pin!(shutdown);
    let mut tick = tokio::time::interval(Duration::from_millis(20));
    let mut last_datagram: Option<Instant> = None;
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
                    let arrival = Instant::now();
                    last_datagram = Some(arrival);
                    match received {
                        Ok((len, from)) => {
                            report.datagrams += 1;
                            match decode_datagram(&buf[..len]) {
                                Ok(frame) => {
                                    if options.calibration.get(frame.sensor).is_none() {
                                        report.uncalibrated += 1;
                                        if report.uncalibrated <= 5 {
                                            eprintln!("fuse serve: datagram from {from}: sensor {} is not in the calibration; ignored", frame.sensor);
                                        }
                                    } else {
                                        sensors_seen.insert(frame.sensor);
                                        match timeline.push(frame, arrival) {
                                            Ok(()) => report.frames_accepted += 1,
                                            Err("duplicate") => report.duplicates += 1,
                                            Err(_) => report.late += 1,
                                        }
                                    }
                                }
                                Err(why) => {
                                    report.malformed += 1;
                                    if report.malformed <= 5 {
                                        eprintln!("fuse serve: malformed datagram from {from} ({len} bytes): {why}");
                                    }
                                }
                            }
                        }
                        Err(e) => eprintln!("fuse serve: receive error: {e}"),
                    }
                    false
                }
            };
        drain(
            &mut timeline,
            &mut fuser,
            &options,
            sink,
            &mut report,
            &mut latencies,
            stop,
        )?;
        if stop {
            break;
        }
    }
    sink.finish()?;
    latencies.sort_by(f64::total_cmp);
    report.latency_median_ms = percentile_ms(&latencies, 0.5);
    report.latency_p99_ms = percentile_ms(&latencies, 0.99);
    report.latency_max_ms = latencies.last().copied().unwrap_or(0.0) * 1000.0;
    let mut seen: Vec<u16> = sensors_seen.into_iter().collect();
    seen.sort();
    report.sensors_seen = seen;
    Ok(report)
}

fn drain(
    timeline: &mut Timeline,
    fuser: &mut Fuser,
    options: &ServeOptions,
    sink: &mut dyn FrameSink,
    report: &mut ServeReport,
    latencies: &mut Vec<f64>,
    flush: bool,
) -> Result<()> {
    while let Some(t) = timeline.ready(flush) {
        let started = Instant::now();
        let views = timeline.views(t, &options.calibration);
        let fused = fuser.fuse(t, &views);
        report.fusion_seconds += started.elapsed().as_secs_f64();
        if let Some(f) = fused {
            sink.write(&f)?;
            report.fused_frames += 1;
            report.observations += (views.len() * crate::kinect::JOINT_COUNT) as u64;
        }
        let written = Instant::now();
        while timeline
            .pending
            .front()
            .is_some_and(|(ts, _)| *ts <= t + 1e-9)
        {
            let (_, arrival) = timeline.pending.pop_front().unwrap();
            latencies.push((written - arrival).as_secs_f64());
        }
        timeline.next_instant = Some(t + timeline.period);
        timeline.forget_before(t + timeline.period);
    }
    Ok(())
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
    let mut outputs = FusedOutputs::open(&options.outputs, body.clone(), options.fps)?;
    let server_options = ServeOptions {
        listen: options.listen,
        calibration,
        body,
        fusion: options.fusion,
        fps: options.fps,
        wait: options.wait,
        sensor_timeout: options.sensor_timeout,
        duration: options.duration,
        idle_exit: options.idle_exit,
    };
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
}
