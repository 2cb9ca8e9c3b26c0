//! Any datagrams given to the fusion server (decoded, their time judged
//! against the server's clock, their joints screened, put on the timeline
//! and fused, as `mocap fuse serve` does) leave it standing: no panic, every
//! datagram counted once, no more fused frames than the time allows, and
//! every fused joint within reach of the sensors.
//!
//! The input is a sequence of records: two bytes (little-endian) of
//! milliseconds since the previous datagram arrived, two bytes of length,
//! then the datagram (`MCF1` and a JSON sensor frame; the seeds are real
//! frames of a simulated capture, and hostile ones).
#![no_main]

use std::net::SocketAddr;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use mocap_fuse::{
    BodyModel, Calibration, FusionOptions, MeasureOptions, MemorySink, RigidTransform, SensorPose,
    ServeOptions, ServerCore, DEFAULT_MAX_SKEW, MAX_JOINT_DISTANCE,
};

/// Sensors 0 to 3 at the origin (so that every fused joint is within
/// MAX_JOINT_DISTANCE of it), 30 fps, the default fusion.
fn options() -> &'static ServeOptions {
    static OPTIONS: OnceLock<ServeOptions> = OnceLock::new();
    OPTIONS.get_or_init(|| {
        let mut calibration = Calibration::default();
        for id in 0..4 {
            calibration.set(SensorPose {
                id,
                transform: RigidTransform::IDENTITY,
                method: None,
                rms_residual: None,
                pairs: None,
            });
        }
        let nobody: [[mocap_fuse::JointObservation; mocap_fuse::JOINT_COUNT]; 0] = [];
        ServeOptions {
            listen: "127.0.0.1:0".parse().unwrap(),
            calibration,
            body: BodyModel::measure(&nobody, MeasureOptions::default()),
            fusion: FusionOptions::best(),
            fps: 30.0,
            wait: 0.1,
            sensor_timeout: 0.5,
            max_skew: DEFAULT_MAX_SKEW,
            duration: None,
            idle_exit: None,
        }
    })
}

fuzz_target!(|data: &[u8]| {
    let options = options();
    let mut core = ServerCore::new(options).unwrap().quiet();
    let mut sink = MemorySink::default();
    let from: SocketAddr = "127.0.0.1:9".parse().unwrap();
    let mut now = 0.0;
    let mut rest = data;
    while rest.len() >= 4 {
        let millis = u16::from_le_bytes([rest[0], rest[1]]);
        let len = u16::from_le_bytes([rest[2], rest[3]]) as usize;
        let end = (4 + len).min(rest.len());
        now += millis as f64 / 1000.0;
        core.receive(&rest[4..end], from, now);
        core.drain(now, false, &mut sink).unwrap();
        rest = &rest[end..];
    }
    now += 1.0;
    core.drain(now, true, &mut sink).unwrap();
    let report = core.finish();
    assert_eq!(report.datagrams_settled(), report.datagrams, "{report:?}");
    assert_eq!(sink.frames.len() as u64, report.fused_frames);
    let allowed = (now + 2.0 * options.max_skew + 1.0) * options.fps + 2.0;
    assert!(
        (sink.frames.len() as f64) <= allowed,
        "{} fused frames in {now} s",
        sink.frames.len()
    );
    for f in &sink.frames {
        for p in &f.joints {
            assert!(
                p.length() <= MAX_JOINT_DISTANCE * 1.001,
                "a fused joint at {p} at {}",
                f.time
            );
        }
    }
});
