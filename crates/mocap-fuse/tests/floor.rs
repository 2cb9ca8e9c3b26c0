//! `mocap fuse run` ([`fuse_files`]) on a capture whose calibration puts the
//! world 3.6 m away and tilted by 34 degrees (as a calibration from the
//! body does: the world is one sensor's camera frame): the BVH stands
//! upright on the floor at the origin, the JSON lines keep the calibration's
//! world, and `BvhWorld::Calibration` keeps it in the BVH too.

use mocap_core::rotation::{Quat, Vec3};
use mocap_fuse::{
    fuse_files, simulate_capture, write_simulation, BoneLengthSource, BvhWorld, Calibration,
    FloorMethod, FuseFilesOptions, FusionOptions, OutputFiles, OutputFormat, RigidTransform,
    SimulationOptions,
};

fn tilt() -> RigidTransform {
    RigidTransform {
        rotation: Quat::from_rotation_z(30f32.to_radians())
            * Quat::from_rotation_x(17f32.to_radians()),
        translation: Vec3::new(0.5, 1.2, 3.36),
    }
}

/// Positions (BVH units) of `names` in every frame of `motion`.
fn tracks(motion: &mocap_core::Motion, names: &[&str]) -> Vec<Vec<Vec3>> {
    let fk = mocap_core::forward_kinematics(motion);
    names
        .iter()
        .map(|name| {
            let j = motion.skeleton().find(name).unwrap();
            (0..motion.frame_count())
                .map(|f| fk.position(f, j))
                .collect()
        })
        .collect()
}

#[test]
fn the_fused_bvh_of_a_tilted_capture_stands_upright_on_the_floor() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let motion = mocap_core::io::bvh::read_bvh(&mocap_testdata::sample_walk()).unwrap();
    let options = SimulationOptions {
        sensors: 3,
        seed: 1,
        ..Default::default()
    };
    let capture = simulate_capture(&motion, None, &options).unwrap();
    let files = write_simulation(d, &capture.simulation, &capture.body, 1, false).unwrap();
    // The world of the calibration, tilted and moved away.
    let mut calibration = Calibration::read(&files.calibration).unwrap();
    for s in &mut calibration.sensors {
        s.transform = tilt().then_after(&s.transform);
    }
    let tilted = d.join("tilted.calib.toml");
    calibration.write(&tilted).unwrap();

    let run = |world: BvhWorld, name: &str| {
        fuse_files(&FuseFilesOptions {
            recordings: files.recordings.clone(),
            calibration: tilted.clone(),
            body: Some(files.body.clone()),
            outputs: OutputFiles {
                paths: vec![
                    d.join(format!("{name}.jsonl")),
                    d.join(format!("{name}.bvh")),
                ],
                bvh_units_per_metre: 100.0,
                bvh_lengths: BoneLengthSource::Fused,
                feet: None,
                bvh_world: world,
            },
            fusion: FusionOptions::best(),
            fps: 30.0,
        })
        .unwrap()
    };
    let report = run(BvhWorld::Floor, "upright");
    let bvh = report
        .outputs
        .iter()
        .find(|o| o.format == OutputFormat::Bvh)
        .unwrap();
    let jsonl = report
        .outputs
        .iter()
        .find(|o| o.format == OutputFormat::Jsonl)
        .unwrap();
    assert!(jsonl.floor.is_none());
    let floor = bvh.floor.expect("a floor under the walk");
    let true_tilt = (tilt().rotation * Vec3::Y)
        .angle_between(Vec3::Y)
        .to_degrees();
    eprintln!(
        "floor: {:?}, tilt removed {:.2} degrees (true {true_tilt:.2}), floor at {:.3} m, moved {:.2} m along it; BVH fit {:.1} mm",
        floor.floor.method,
        floor.floor.tilt_degrees,
        floor.floor.height,
        floor.moved_along_floor,
        bvh.fit_error.unwrap().mean_mm
    );
    assert_eq!(floor.floor.method, FloorMethod::Line);
    assert!((floor.floor.tilt_degrees - true_tilt).abs() < 2.0);
    assert!(floor.moved_along_floor > 2.5, "{floor:?}");
    // The BVH matches the fused joints it was made from, stood on the floor.
    assert!(bvh.fit_error.unwrap().body_mean_mm < 35.0);

    let upright = mocap_core::io::bvh::read_bvh(&d.join("upright.bvh")).unwrap();
    let [head, left, right, pelvis] =
        &tracks(&upright, &["Head", "FootLeft", "FootRight", "SpineBase"])[..]
    else {
        unreachable!()
    };
    // Upright: the head 1.2 m (120 cm) or more above the higher foot along +y
    // in every frame; the lower foot's height, frame by frame, near 0.
    let mut lowest: Vec<f32> = Vec::new();
    for f in 0..upright.frame_count() {
        let clearance = head[f].y - left[f].y.max(right[f].y);
        assert!(clearance > 100.0, "frame {f}: {clearance} cm");
        let up = (head[f] - (left[f] + right[f]) * 0.5).normalize();
        assert!(up.y > 0.97, "frame {f}: {up}");
        lowest.push(left[f].y.min(right[f].y));
    }
    lowest.sort_by(f32::total_cmp);
    let median = lowest[lowest.len() / 2];
    let low = lowest[lowest.len() / 20];
    eprintln!(
        "lower foot: median {median:.1} cm, 5th percentile {low:.1} cm, first pelvis {}",
        pelvis[0]
    );
    assert!(median.abs() < 3.0 && low > -4.0, "{median} {low}");
    assert!(pelvis[0].x.abs() < 0.01 && pelvis[0].z.abs() < 0.01);

    // The JSON lines are in the calibration's world: 3.6 m away.
    let line = std::fs::read_to_string(d.join("upright.jsonl")).unwrap();
    let first: serde_json::Value = serde_json::from_str(line.lines().next().unwrap()).unwrap();
    let p = &first["joints"][0];
    let at = Vec3::new(
        p[0].as_f64().unwrap() as f32,
        p[1].as_f64().unwrap() as f32,
        p[2].as_f64().unwrap() as f32,
    );
    assert!(at.distance(tilt().translation) < 1.5, "{at}");

    // Kept in the calibration's world on request: the BVH's pelvis is where
    // the JSON lines' is, and no floor is reported.
    let kept = run(BvhWorld::Calibration, "kept");
    assert!(kept.outputs.iter().all(|o| o.floor.is_none()));
    let kept = mocap_core::io::bvh::read_bvh(&d.join("kept.bvh")).unwrap();
    let pelvis = &tracks(&kept, &["SpineBase"])[0];
    assert!(
        (pelvis[0] / 100.0).distance(at) < 0.01,
        "{} vs {at}",
        pelvis[0]
    );
}
