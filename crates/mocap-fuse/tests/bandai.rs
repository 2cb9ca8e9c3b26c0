//! End-to-end checks on a real Bandai take: simulate sensors, calibrate from
//! the body, fuse, compare with the truth.

use mocap_fuse::{
    calibrate_from_body, center_truth, facing_of, fuse_streams, simulate, truth_from_motion,
    BodyModel, Calibration, Fuser, FusionOptions, GroundTruth, MeasureOptions, SensorPose,
    SensorStreams, SimulatedSensor, Simulation, SimulationOptions,
};

/// The take's Kinect joints, centred (on a treadmill beyond 2 m), and three
/// simulated sensors watching them.
fn three_sensors_watching(motion: &mocap_core::Motion) -> (GroundTruth, Simulation) {
    let mut truth = truth_from_motion(motion, None).unwrap();
    center_truth(&mut truth, Some(2.0));
    let sim = simulate(
        &truth,
        &SimulationOptions {
            sensors: 3,
            seed: 4,
            ..Default::default()
        },
    );
    (truth, sim)
}

/// How far a sensor's pose found from the body (relative to the reference
/// sensor) is from the simulation's truth: degrees and metres.
fn calibration_error(sim: &Simulation, reference: u16, found: &SensorPose) -> (f32, f32) {
    let truth = sim.sensors[reference as usize]
        .pose
        .inverse()
        .then_after(&sim.sensors[found.id as usize].pose);
    let angle = found
        .transform
        .rotation
        .angle_between(truth.rotation)
        .to_degrees();
    (
        angle,
        (found.transform.translation - truth.translation).length(),
    )
}

#[test]
fn fusion_and_body_calibration_on_a_real_take() {
    let Some(path) = mocap_testdata::shared("bandai/dataset-1/dataset-1_walk_normal_001.bvh")
    else {
        return;
    };
    let motion = mocap_core::io::bvh::read_bvh(&path).unwrap();
    let (truth, sim) = three_sensors_watching(&motion);
    let streams = SensorStreams::new(sim.sensors.iter().flat_map(|s| s.frames.iter().cloned()));
    let body = BodyModel::measure(
        sim.sensors
            .iter()
            .flat_map(|s| s.frames.iter().map(|f| &f.joints)),
        MeasureOptions::default(),
    );
    // The measured thigh is near the true one (Bandai: about 41 cm).
    let thigh = truth.frames[0][13].distance(truth.frames[0][12]);
    assert!((body.bone_lengths[13].unwrap() - thigh).abs() < 0.05);

    let error = |options: FusionOptions, calibration: &Calibration| {
        let mut fuser = Fuser::new(options, body.clone());
        let fused = fuse_streams(&streams, calibration, &mut fuser, 30.0, Some(0.0));
        let mut sum = 0.0;
        for f in &fused {
            let g = truth.at(f.time);
            sum += (0..25).map(|n| f.joints[n].distance(g[n])).sum::<f32>() / 25.0;
        }
        sum / fused.len() as f32
    };
    let calibration = sim.calibration();
    let plain = error(FusionOptions::state_only(), &calibration);
    let best = error(FusionOptions::best(), &calibration);
    assert!(best < plain, "best {best} vs state only {plain}");
    assert!(best < 0.12, "{best}");

    // Calibration from the body: one of these sensors sees the person's
    // back (left and right swapped), which turns a fit of the labelled
    // joints by about 180 degrees. Every sensor must come out within a few
    // degrees (the bound is what the simulated per-joint biases allow: a body is a
    // thin vertical shape, and a few centimetres of bias turn the fit by
    // degrees about it), and fusion with it must stay close to fusion with
    // the true poses.
    let behind = |s: &SimulatedSensor| {
        let cos = SimulationOptions::default()
            .model
            .behind_angle_degrees
            .to_radians()
            .cos();
        s.frames
            .iter()
            .filter(|f| {
                let pose = truth.at(f.timestamp);
                let to_sensor = (s.pose.translation - pose[0]).with_y(0.0).normalize();
                facing_of(&pose).dot(to_sensor) < cos
            })
            .count() as f32
            / s.frames.len() as f32
    };
    let most_behind = sim.sensors.iter().map(behind).fold(0.0, f32::max);
    assert!(
        most_behind > 0.5,
        "a sensor must see the back here: {most_behind}"
    );
    let found = calibrate_from_body(&streams, &Default::default()).unwrap();
    let world_from_reference = sim.sensors[found.reference as usize].pose;
    let mut body_calibration = found.calibration.clone();
    for s in &mut body_calibration.sensors {
        let (angle, shift) = calibration_error(&sim, found.reference, s);
        eprintln!(
            "sensor {}: body calibration off by {angle:.2} degrees, {shift:.3} m",
            s.id
        );
        assert!(angle < 8.0, "sensor {}: {angle} degrees", s.id);
        assert!(shift < 0.4, "sensor {}: {shift} m", s.id);
        s.transform = world_from_reference.then_after(&s.transform);
    }
    let with_body = error(FusionOptions::best(), &body_calibration);
    eprintln!("fused MPJPE: true calibration {best:.4} m, body calibration {with_body:.4} m");
    assert!(with_body < best + 0.03, "{with_body} vs {best}");
}

#[test]
fn a_take_as_the_capture_stage_makes_it_pairs_with_its_truth_frame_for_frame() {
    // The bundled walk: the fused take and its truth share one fitted
    // skeleton and their frames, and lie a few centimetres apart.
    let motion = mocap_core::io::bvh::read_bvh(&mocap_testdata::sample_walk()).unwrap();
    let options = SimulationOptions {
        sensors: 3,
        seed: 2,
        ..Default::default()
    };
    let (fused, truth) = mocap_fuse::simulated_fused_take(&motion, &options).unwrap();
    assert_eq!(fused.skeleton(), truth.skeleton());
    assert_eq!(fused.frame_count(), truth.frame_count());
    assert!(fused.frame_count() + 2 >= motion.frame_count());
    let (a, b) = (
        mocap_core::forward_kinematics(&fused),
        mocap_core::forward_kinematics(&truth),
    );
    let cm = mocap_core::metrics::mean_joint_position_error(&a, &b, None).unwrap();
    assert!(cm > 0.5 && cm < 10.0, "{cm} cm");
    // Shifted by one frame, the pair is further apart: the frames match.
    let shifted = mocap_core::ops::trim(&truth, 1..truth.frame_count()).unwrap();
    let ahead = mocap_core::ops::trim(&fused, 0..fused.frame_count() - 1).unwrap();
    let off = mocap_core::metrics::mean_joint_position_error(
        &mocap_core::forward_kinematics(&ahead),
        &mocap_core::forward_kinematics(&shifted),
        None,
    )
    .unwrap();
    assert!(off > cm, "{off} against {cm}");
}

#[test]
fn sensors_at_ten_frames_a_second_calibrate_from_the_body_at_their_own_rate() {
    // Every third frame of a 30 fps simulation: frames 100 ms apart. Paired
    // at a fixed 1/30 s, frames between two of the reference's were too far
    // from both (gaps over 2.5 periods); at the recording's own period every
    // frame pairs, and the calibration comes out.
    let motion = mocap_core::io::bvh::read_bvh(&mocap_testdata::sample_walk()).unwrap();
    let (_, sim) = three_sensors_watching(&motion);
    // The sensors' clocks are half a frame apart, so that pairs are made
    // between frames, not at shared instants.
    let streams = SensorStreams::new(sim.sensors.iter().enumerate().flat_map(|(k, s)| {
        s.frames.iter().step_by(3).map(move |f| {
            let mut f = f.clone();
            f.timestamp += 0.05 * k as f64;
            f
        })
    }));
    let found = calibrate_from_body(&streams, &Default::default()).unwrap();
    // Every frame pairs with the reference (at 1/30 s, only half did).
    let frames = sim.sensors[0].frames.len().div_ceil(3);
    for report in &found.sensors {
        assert!(
            report.paired_frames + 2 >= frames,
            "sensor {}: {} of {frames} frames paired",
            report.sensor,
            report.paired_frames
        );
    }
    for s in &found.calibration.sensors {
        let (angle, _) = calibration_error(&sim, found.reference, s);
        assert!(angle < 10.0, "sensor {}: {angle} degrees", s.id);
    }
}
