//! The capture stage on real camera data: the Pose2Sim demo's four cameras
//! (OpenPose BODY_25B), compared with Pose2Sim's own triangulation of the
//! same keypoints. Skipped with a note when ../shared/data is absent.

use std::path::{Path, PathBuf};

use mocap_cameras::{
    read_trc, read_trial, run_capture, trc_to_zup, triangulate_trial, AssociationOptions,
    CaptureOptions, Markers, Method, Person3d, TriangulationOptions,
};

fn demo(trial: &str) -> Option<PathBuf> {
    let p = mocap_testdata::shared("pose2sim-demo")?.join(trial);
    if p.is_dir() {
        Some(p)
    } else {
        eprintln!("note: {} absent, test skipped", p.display());
        None
    }
}

fn pose2sim(trial: &Path, person: &str) -> Markers {
    let file = std::fs::read_dir(trial.join("pose-3d"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .find(|p| {
            let name = p.file_name().unwrap().to_str().unwrap();
            name.ends_with("0-100.trc") && name.contains(person)
        })
        .expect("Pose2Sim's raw TRC");
    read_trc(&file).unwrap()
}

/// Mean distance (mm) between a person's keypoints and Pose2Sim's markers of
/// the same names, frame by frame.
fn distance_to(person: &Person3d, names: &[&str], markers: &Markers) -> f64 {
    let (mut sum, mut n) = (0.0, 0);
    for (f, frame) in person.frames.iter().enumerate() {
        for (k, name) in names.iter().enumerate() {
            let Some(i) = markers.names.iter().position(|m| m == name) else {
                continue;
            };
            let theirs = trc_to_zup(markers.positions[f][i]);
            if let (Some(ours), true) = (frame[k], theirs.is_finite()) {
                sum += ours.position.distance(theirs) * 1000.0;
                n += 1;
            }
        }
    }
    assert!(n > 1000, "{n} keypoints compared");
    sum / n as f64
}

#[test]
fn the_balancing_trial_lands_near_pose2sims_own_triangulation() {
    let Some(trial) = demo("S00_P00_SingleParticipant/S00_P00_T01_BalancingTrial") else {
        return;
    };
    let read = read_trial(&CaptureOptions::new(&trial)).unwrap();
    assert_eq!((read.cameras.len(), read.frames, read.fps), (4, 100, 60.0));
    let markers = pose2sim(&trial, "");
    let names = read.layout.names();
    for method in [Method::Plain, Method::Robust] {
        let options = TriangulationOptions {
            method,
            ..TriangulationOptions::default()
        };
        let people = triangulate_trial(&read, 1, &options, &AssociationOptions::default());
        let d = distance_to(&people[0], names, &markers);
        // Two triangulations of the same keypoints with the same cameras:
        // centimetres apart, not decimetres (a wrong axis or a wrong person
        // would be 0.5 m and more).
        assert!(d < 40.0, "{method:?}: {d:.1} mm from Pose2Sim's");
    }
}

#[test]
fn the_two_person_trial_gives_two_people_each_near_one_of_pose2sims() {
    let Some(trial) = demo("S00_P01_MultiParticipants/S00_P01_T02_Participants1-2") else {
        return;
    };
    // The raw OpenPose output: up to three detections a view, in any order.
    let read = read_trial(&CaptureOptions::new(trial.join("pose"))).unwrap();
    let people = triangulate_trial(
        &read,
        2,
        &TriangulationOptions::default(),
        &AssociationOptions::default(),
    );
    assert_eq!(people.len(), 2);
    let names = read.layout.names();
    let (p1, p2) = (pose2sim(&trial, "_P1_"), pose2sim(&trial, "_P2_"));
    let d = |i: usize, m: &Markers| distance_to(&people[i], names, m);
    let (straight, crossed) = (d(0, &p1) + d(1, &p2), d(0, &p2) + d(1, &p1));
    let (near, far) = (straight.min(crossed), straight.max(crossed));
    assert!(
        near < 80.0,
        "each person near one of Pose2Sim's: {near:.1} mm"
    );
    assert!(far > 500.0, "and far from the other: {far:.1} mm");
}

#[test]
fn run_writes_an_upright_bvh_that_stands_on_the_calibrations_floor() {
    let Some(trial) = demo("S00_P00_SingleParticipant/S00_P00_T01_BalancingTrial") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("balancing.bvh");
    let report = run_capture(&CaptureOptions::new(&trial), &out).unwrap();
    assert_eq!(report.people.len(), 1);
    assert!(report.notes.iter().any(|n| n.contains("+z axis is up")));
    let motion = mocap_core::io::bvh::read_bvh(&out).unwrap();
    assert_eq!(motion.frame_count(), 100);
    assert!((motion.fps() - 60.0).abs() < 1e-6);
    let poses = mocap_core::kinematics::forward_kinematics(&motion);
    let index = |name: &str| motion.skeleton().find(name).unwrap();
    let (head, foot) = (index("Head"), index("FootLeft"));
    for f in [0, 50, 99] {
        let p = |j: usize| poses.position(f, j).as_dvec3();
        // Y up, centimetres: the head 1.3-1.9 m above the feet, the feet
        // within 15 cm of the floor the calibration put at zero height.
        let height = p(head).y - p(foot).y;
        assert!((130.0..190.0).contains(&height), "frame {f}: {height}");
        assert!(p(foot).y.abs() < 15.0, "frame {f}: foot at {}", p(foot).y);
    }
}

#[test]
fn a_calibration_of_other_cameras_is_refused_naming_both() {
    let Some(trial) = demo("S00_P00_SingleParticipant/S00_P00_T01_BalancingTrial") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let calib = dir.path().join("three.toml");
    let text =
        std::fs::read_to_string(trial.join("../../S00_Calibration/Calib_qualisys.toml")).unwrap();
    // The first three cameras only.
    let three: String = text.split("[cam_04]").next().unwrap().to_string();
    std::fs::write(&calib, three).unwrap();
    let options = CaptureOptions {
        calibration: Some(calib.clone()),
        ..CaptureOptions::new(&trial)
    };
    let error = read_trial(&options).unwrap_err().to_string();
    assert!(error.contains("three.toml has 3 cameras"), "{error}");
    assert!(error.contains("4 camera keypoint folders"), "{error}");
}
