//! Stage 1: a multi-sensor capture of the sample, streamed over UDP on
//! loopback to the fusion server and fused.
//!
//! The sample's joints, mapped to the Kinect v2 layout, are the ground
//! truth. mocap-fuse's simulator turns them into the recordings of
//! `sensors` Kinect v2 sensors around the actor (occlusion, depth noise,
//! left/right swaps when seen from behind, latency, dropped frames). The
//! person's body (bone lengths, joint ranges) is measured from a second,
//! independent simulated capture, as a real capture measures it beforehand.
//! The sensor poses are the simulator's (the demo does not estimate the
//! calibration; `mocap fuse calibrate` does).
//!
//! The fusion server runs on its own runtime in a thread, listening on
//! 127.0.0.1 port 0; the sensors' frames are sent to it in order of arrival
//! at `send_speed` times real time. The server stops when no datagram has
//! come for half a second.

use std::net::SocketAddr;
use std::time::Duration;

use anyhow::{anyhow, Context};
use mocap_core::bodymap::BodyMap;
use mocap_core::io::bvh::{read_bvh, write_bvh};
use mocap_core::retarget::Retargeting;
use mocap_core::rotation::{Quat, Vec3};
use mocap_core::{forward_kinematics, Motion};
use mocap_fuse::{
    fit_error, fused_to_motion, poses_to_motion, regular_poses, simulate_capture, views_at,
    BvhOptions, FusedFrame, FusionOptions, MemorySink, SendOptions, SendReport, SensorFrame,
    SensorStreams, ServeOptions, ServeReport, SimulatedCapture, SimulationOptions, JOINT_COUNT,
};
use mocap_view::{plot_lines, render_files, LinePlot, RenderOptions, Series};

use crate::chain::{errors_against_truth, ChainTake};
use crate::{units_per_metre, viewer_command, StageContext, StageReport, StageResult};

/// Mean distance (metres) between two poses over the 25 joints.
fn pose_error(a: &[Vec3; JOINT_COUNT], b: &[Vec3; JOINT_COUNT]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| p.distance(*q) as f64)
        .sum::<f64>()
        / JOINT_COUNT as f64
}

/// Runs the fusion server in a thread and replays `frames` to it over UDP.
fn stream_over_udp(
    frames: &[SensorFrame],
    serve: ServeOptions,
    speed: f64,
) -> anyhow::Result<(ServeReport, Vec<FusedFrame>, SendReport)> {
    let (bound_tx, bound_rx) = tokio::sync::oneshot::channel::<SocketAddr>();
    let (stop_tx, stop_rx) = tokio::sync::oneshot::channel::<()>();
    let server = std::thread::Builder::new()
        .name("mocap-demo fusion server".into())
        .spawn(
            move || -> mocap_core::Result<(ServeReport, Vec<FusedFrame>)> {
                let mut sink = MemorySink::default();
                let report = mocap_fuse::runtime()?.block_on(mocap_fuse::serve(
                    serve,
                    &mut sink,
                    async {
                        let _ = stop_rx.await;
                    },
                    Some(bound_tx),
                ))?;
                Ok((report, sink.frames))
            },
        )
        .context("cannot start the fusion server thread")?;
    let sent = match bound_rx.blocking_recv() {
        Ok(addr) => mocap_fuse::send_blocking(
            frames,
            SendOptions {
                to: addr,
                realtime: true,
                speed,
            },
        )
        .map_err(anyhow::Error::from),
        // The server could not open its socket; its error is below.
        Err(_) => Err(anyhow!("the fusion server did not start")),
    };
    if sent.is_err() {
        // Nothing more is coming: stop the server rather than wait.
        let _ = stop_tx.send(());
    }
    let served = server
        .join()
        .map_err(|_| anyhow!("the fusion server thread panicked"))?;
    let (report, fused) = served.context("fusion server")?;
    Ok((report, fused, sent?))
}

/// The file the chain goes on with.
const ON_RIG_FILE: &str = "fused-on-sample-rig.bvh";

/// `fused` (on the skeleton fitted to the Kinect joints, in the simulator's
/// world) on the sample's rig and in the sample's world: retargeted by the
/// two rigs' rest poses, then with `truth_shift`, what the simulator took
/// off the truth (centring, and the treadmill that keeps a long walk in the
/// sensors' view; metres, one per truth frame at `fps`), added back through
/// the joint that carries the body, so that planted feet stand still
/// again. The fused frame `i` is the sample's instant `first_time + i / fps`.
fn on_sample_rig(
    fused: &Motion,
    sample: &Motion,
    truth_shift: &[Vec3],
    fps: f64,
    first_time: f64,
) -> anyhow::Result<Motion> {
    let retargeting = Retargeting::detect(fused.skeleton(), sample.skeleton())
        .context("cannot relate the fused skeleton to the sample's rig")?;
    let mut out = retargeting.apply(fused)?;
    let carrier = BodyMap::detect(out.skeleton())?
        .position_carrier(out.skeleton())
        .ok_or_else(|| {
            anyhow!(
                "no joint at or above the sample's pelvis has position channels to carry the walk"
            )
        })?;
    let parent = out.skeleton().joint(carrier).parent;
    let last = truth_shift
        .len()
        .checked_sub(1)
        .ok_or_else(|| anyhow!("the simulation kept no shift of the truth"))?;
    // Moving the carrier turns no joint: its parent's rotations are those
    // of the retargeted take.
    let poses = forward_kinematics(&out);
    let units = units_per_metre(sample);
    for f in 0..out.frame_count() {
        let t = first_time + f as f64 * out.frame_time();
        let k = ((t * fps).round().max(0.0) as usize).min(last);
        // Into the axes of the carrier's parent.
        let to_local = parent.map_or(Quat::IDENTITY, |p| poses.rotation(f, p).inverse());
        let translation = out.local_translation(f, carrier);
        out.set_local_translation(
            f,
            carrier,
            translation + to_local * (truth_shift[k] * units),
        );
    }
    Ok(out)
}

pub(crate) fn run(context: &StageContext, report: &mut StageReport) -> StageResult {
    let options = context.options;
    let motion = read_bvh(&options.sample)?;
    let simulation = SimulationOptions {
        sensors: options.sensors,
        seed: options.seed,
        ..SimulationOptions::default()
    };
    // The person is measured from another capture (other seed) of the take.
    let SimulatedCapture {
        simulation: sim,
        body,
        truth_shift,
    } = simulate_capture(&motion, None, &simulation)?;
    let truth = &sim.truth;
    let calibration = sim.calibration();
    let frames: Vec<_> = sim
        .sensors
        .iter()
        .flat_map(|s| s.frames.iter().cloned())
        .collect();

    let serve = ServeOptions {
        listen: "127.0.0.1:0".parse().expect("a valid address"),
        calibration: calibration.clone(),
        body: body.clone(),
        fusion: FusionOptions::best(),
        fps: simulation.fps,
        wait: 0.1,
        sensor_timeout: 0.5,
        // A replay faster than real time runs ahead of the server's clock
        // by up to the take's length.
        max_skew: mocap_fuse::DEFAULT_MAX_SKEW + truth.duration(),
        // A safety net: the replay takes well under this.
        duration: Some(Duration::from_secs_f64(
            truth.duration() / options.send_speed.max(0.1) + 20.0,
        )),
        idle_exit: Some(Duration::from_millis(500)),
    };
    let (served, mut fused, sent) = stream_over_udp(&frames, serve, options.send_speed)?;
    fused.sort_by(|a, b| a.time.total_cmp(&b.time));
    if fused.is_empty() {
        return Err(anyhow!("the fusion server fused no frame").into());
    }

    // Fused joints against the truth at the same instants.
    let duration = truth.duration();
    let scored: Vec<&FusedFrame> = fused.iter().filter(|f| f.time <= duration).collect();
    let errors: Vec<f64> = scored
        .iter()
        .map(|f| pose_error(&f.joints, &truth.at(f.time)))
        .collect();
    let mpjpe = 1000.0 * errors.iter().sum::<f64>() / errors.len().max(1) as f64;

    // Each sensor alone (its joints in the world frame, no fusion), on the
    // same grid, for comparison.
    let streams = SensorStreams::new(frames.iter().cloned());
    let period = 1.0 / simulation.fps;
    let mut single: Vec<(u16, f64, usize)> = Vec::new();
    for &sensor in streams.streams.keys() {
        let (mut sum, mut count) = (0.0, 0usize);
        let mut i = 0;
        while i as f64 * period <= duration {
            let t = i as f64 * period;
            if let Some(v) = views_at(&streams, &calibration, t, period)
                .into_iter()
                .find(|v| v.sensor == sensor)
            {
                sum += pose_error(&v.joints.map(|j| j.position), &truth.at(t));
                count += 1;
            }
            i += 1;
        }
        if count > 0 {
            single.push((sensor, 1000.0 * sum / count as f64, count));
        }
    }
    // A sensor that saw less than half the take is no fair comparison.
    let best_single = single
        .iter()
        .filter(|s| s.2 * 2 >= truth.frames.len())
        .map(|s| s.1)
        .fold(f64::NAN, f64::min);

    // The fused capture and the truth on fitted skeletons (same layout, same
    // world frame), so that the viewer can overlay them.
    let units = 100.0;
    let bvh_options = BvhOptions {
        units_per_metre: units,
        fps: simulation.fps,
    };
    let fused_motion = fused_to_motion(&fused, &body, &bvh_options)?;
    let fit = fit_error(&fused_motion, &regular_poses(&fused, simulation.fps), units)?;
    let truth_motion = poses_to_motion(&truth.frames, &body, &bvh_options)?;
    let fused_path = context.path("fuse", "fused.bvh")?;
    let truth_path = context.path("fuse", "truth.bvh")?;
    write_bvh(&fused_path, &fused_motion)?;
    write_bvh(&truth_path, &truth_motion)?;
    report.output(
        StageContext::relative("fuse", "fused.bvh"),
        "fused joints as a BVH on a skeleton fitted to the measured bone lengths (cm)",
    );
    report.output(
        StageContext::relative("fuse", "truth.bvh"),
        "the ground truth (the sample's joints in the Kinect v2 layout) on a fitted skeleton, same frame as fused.bvh",
    );
    report.viewer_command = Some(viewer_command(&[&truth_path, &fused_path]));

    // The chain goes on with the fused take on the sample's rig, in the
    // sample's world (see `chain`).
    let first_time = fused[0].time;
    let on_rig = on_sample_rig(&fused_motion, &motion, &truth_shift, truth.fps, first_time)?;
    let on_rig_path = context.path("fuse", ON_RIG_FILE)?;
    write_bvh(&on_rig_path, &on_rig)?;
    report.output(
        StageContext::relative("fuse", ON_RIG_FILE),
        "fused.bvh retargeted onto the sample's rig and taken off the simulator's treadmill: what the next stages get",
    );
    let on_rig_errors = errors_against_truth(&on_rig, &motion, first_time)?;
    context.pass_on(ChainTake {
        path: on_rig_path,
        stage: "fuse",
        first_time,
    });

    report.number(
        "sensors",
        "simulated Kinect v2 sensors",
        options.sensors as f64,
        "",
    );
    report.number(
        "datagrams_sent",
        "sensor frames sent over UDP",
        sent.datagrams as f64,
        "",
    );
    report.number(
        "datagrams_received",
        "datagrams the server received",
        served.datagrams as f64,
        "",
    );
    report.number(
        "late_frames",
        "frames that came after their instant was fused",
        served.late as f64,
        "",
    );
    report.number("send_seconds", "wall time of the replay", sent.seconds, "s");
    report.number(
        "fused_frames",
        "frames fused by the server",
        served.fused_frames as f64,
        "",
    );
    report.number(
        "truth_frames",
        "frames of the ground truth",
        truth.frames.len() as f64,
        "",
    );
    report.number(
        "latency_median_ms",
        "datagram arrival to fused frame, median",
        served.latency_median_ms,
        "ms",
    );
    report.number(
        "mpjpe_mm",
        "fused joints vs ground truth, mean per-joint position error (25 Kinect joints)",
        mpjpe,
        "mm",
    );
    report.number(
        "best_single_sensor_mpjpe_mm",
        "the best sensor alone vs ground truth (sensors that saw at least half the take)",
        best_single,
        "mm",
    );
    report.number(
        "bvh_fit_error_mm",
        "fused.bvh's forward kinematics vs the fused joints (fixed bone lengths)",
        fit.mean_mm,
        "mm",
    );
    report.number(
        "on_rig_position_error_mm",
        "fused take on the sample's rig vs the sample, mean per-joint position error (all joints of the rig)",
        on_rig_errors.position_mm,
        "mm",
    );
    report.number(
        "on_rig_rotation_error_deg",
        "fused take on the sample's rig vs the sample, mean angle of the local joint rotations",
        on_rig_errors.rotation_deg,
        "deg",
    );
    report.number(
        "on_rig_jitter",
        "fused take on the sample's rig, mean jerk of its joints (mm/frame³)",
        on_rig_errors.jitter,
        "mm/frame³",
    );
    report.number(
        "sample_jitter",
        "the sample's own mean jerk over the same frames (mm/frame³)",
        on_rig_errors.truth_jitter,
        "mm/frame³",
    );
    report.fact(
        "fusion",
        "confidence-weighted mean, FusionOptions::best() (state x bone length x range of motion, swap repair, robust reweighting)",
    );
    report.note(
        "Sensor poses are the simulator's (known calibration); the person's bone lengths and joint ranges are measured from a second simulated capture.",
    );
    report.note(
        "Takes that travel more than 2 m are put on a treadmill (straight-line drift removed) so the actor stays in the sensors' view; truth.bvh has the same treatment.",
    );

    if options.pictures {
        let strip = context.path("fuse", "truth_vs_fused.png")?;
        render_files(
            &[truth_path.clone(), fused_path.clone()],
            &strip,
            &RenderOptions::default(),
        )?;
        report.picture(
            StageContext::relative("fuse", "truth_vs_fused.png"),
            "ground truth and fused skeleton, overlaid",
        );
        let plot_path = context.path("fuse", "error_per_frame.png")?;
        let points: Vec<(f32, f32)> = scored
            .iter()
            .zip(&errors)
            .map(|(f, e)| (f.time as f32, (*e * 1000.0) as f32))
            .collect();
        let plot = LinePlot::new(
            "Fused joints vs ground truth",
            "time (s)",
            "mean joint position error (mm)",
        )
        .with_series(Series::new("fused", points));
        plot_lines(&plot_path, &plot)?;
        report.picture(
            StageContext::relative("fuse", "error_per_frame.png"),
            "position error of the fused joints, per frame",
        );
    }
    Ok(())
}
