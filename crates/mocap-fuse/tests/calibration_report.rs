//! What `mocap fuse calibrate` reports of a calibration from the body: the
//! figures of the file it writes, and how sure the fit is.

use mocap_fuse::{
    calibrate_recordings, simulate_to_folder, BodyCalibrationOptions, Calibration,
    SimulationOptions,
};

#[test]
fn the_report_holds_the_files_figures_and_an_uncertainty_the_truth_respects() {
    // Over four simulated captures of the walk, the true error of each
    // calibrated sensor, in units of its reported uncertainty.
    let mut ratios = Vec::new();
    for seed in 5..=8u64 {
        let dir = tempfile::tempdir().unwrap();
        let options = SimulationOptions {
            sensors: 3,
            seed,
            ..Default::default()
        };
        let sim = simulate_to_folder(
            &mocap_testdata::sample_walk(),
            dir.path(),
            &options,
            None,
            false,
        )
        .unwrap();
        let output = dir.path().join("body.calib.toml");
        let report = calibrate_recordings(
            &sim.files.recordings,
            &BodyCalibrationOptions::default(),
            &output,
        )
        .unwrap();
        let written = Calibration::read(&output).unwrap();
        let truth = Calibration::read(&sim.files.calibration).unwrap();
        let world = *truth.get(report.reference).unwrap();
        assert_eq!(report.sensors.len(), 2);
        for s in &report.sensors {
            let pose = written.sensors.iter().find(|p| p.id == s.sensor).unwrap();
            // The printed figures are the file's, refined or not.
            assert_eq!(pose.pairs, Some(s.inliers), "sensor {}", s.sensor);
            assert_eq!(pose.rms_residual, Some(s.rms), "sensor {}", s.sensor);
            assert!(s.inliers <= s.pairs);
            let true_pose = world.inverse().then_after(truth.get(s.sensor).unwrap());
            let angle = pose
                .transform
                .rotation
                .angle_between(true_pose.rotation)
                .to_degrees() as f64;
            let shift = (pose.transform.translation - true_pose.translation).length() as f64;
            eprintln!(
                "seed {seed} sensor {}: off by {angle:.2} deg, {:.1} cm; reported +-{:.2} deg, +-{:.1} cm",
                s.sensor,
                shift * 100.0,
                s.rotation_uncertainty_degrees,
                s.translation_uncertainty * 100.0
            );
            ratios.push(angle / s.rotation_uncertainty_degrees);
            ratios.push(shift / s.translation_uncertainty);
        }
    }
    // An honest standard deviation: the truth within a few of them, and
    // not always far inside one (an uncertainty ten times too large, or
    // ten times too small, fails).
    let worst = ratios.iter().copied().fold(0.0, f64::max);
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    eprintln!("true error / reported uncertainty: mean {mean:.2}, worst {worst:.2}");
    assert!(worst < 5.0, "{ratios:?}");
    assert!(mean > 0.3, "{ratios:?}");
}

#[test]
fn a_sensor_few_of_whose_pairs_fit_is_warned_about() {
    use mocap_fuse::{BodyCalibrationReport, BodySensorReport, SamePersonReport};
    let sensor = |id: u16, pairs: usize, inliers: usize| BodySensorReport {
        sensor: id,
        pairs,
        inliers,
        rms: 0.02,
        settled_frames: 70,
        paired_frames: 79,
        mirrored_inliers: 10,
        yaw_uncertainty_degrees: 1.0,
        rotation_uncertainty_degrees: 1.0,
        translation_uncertainty: 0.03,
        refined: false,
    };
    let report = BodyCalibrationReport {
        calibration: "rig.toml".into(),
        reference: 1,
        // The real NTU case: a second person listed first, 18% of pairs fit.
        sensors: vec![sensor(2, 1400, 1300), sensor(3, 1407, 253)],
        same_person: SamePersonReport { sensors: vec![] },
    };
    let warnings = report.warnings();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].starts_with("sensor 3: only 18%"),
        "{}",
        warnings[0]
    );
}
