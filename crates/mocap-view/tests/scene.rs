//! The viewer's data: positions from mocap_core's FK in metres, topology,
//! end sites, confidence, JSON; on the bundled sample and real takes.

use mocap_testdata::shared_data;
use std::path::{Path, PathBuf};

use mocap_core::io::asf_amc::read_asf_amc;
use mocap_core::io::bvh::read_bvh;
use mocap_core::kinematics::{end_site_positions, forward_kinematics};
use mocap_core::rotation::Vec3;
use mocap_view::{guess_metres_per_unit, read_capture, Scene, ViewMotion};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn sample() -> PathBuf {
    workspace().join("samples/dataset-1_walk_normal_001.bvh")
}

/// Height of the shown points of one frame.
fn figure_height(m: &ViewMotion, frame: usize) -> f32 {
    let ys: Vec<f32> = m
        .frame_positions(frame)
        .iter()
        .enumerate()
        .filter(|&(p, _)| m.point_shown(p))
        .map(|(_, p)| p.y)
        .collect();
    ys.iter().cloned().fold(f32::MIN, f32::max) - ys.iter().cloned().fold(f32::MAX, f32::min)
}

#[test]
fn sample_positions_are_core_fk_in_metres_with_end_sites() {
    let motion = read_bvh(&sample()).unwrap();
    let view = ViewMotion::from_motion("walk", &motion);
    let poses = forward_kinematics(&motion);
    let skeleton = motion.skeleton();
    let end_sites: usize = skeleton.joints().iter().map(|j| j.end_sites.len()).sum();

    assert_eq!(view.metres_per_unit, 0.01, "Bandai is in centimetres");
    assert_eq!(view.joint_count, skeleton.joint_count());
    assert_eq!(view.point_count(), skeleton.joint_count() + end_sites);
    assert_eq!(view.frame_count, motion.frame_count());
    assert_eq!(view.frame_time, motion.frame_time());
    for f in [0, 57, motion.frame_count() - 1] {
        for j in 0..skeleton.joint_count() {
            let expected = poses.position(f, j) * 0.01;
            assert!(
                (view.frame_positions(f)[j] - expected).length() < 1e-6,
                "frame {f} joint {j}"
            );
        }
        let ends = end_site_positions(&motion, &poses, f);
        for (k, (joint, p)) in ends.iter().enumerate() {
            let point = skeleton.joint_count() + k;
            assert_eq!(view.parents[point], Some(*joint));
            assert!(view.names[point].starts_with(&skeleton.joint(*joint).name));
            assert!((view.frame_positions(f)[point] - *p * 0.01).length() < 1e-6);
        }
    }
}

#[test]
fn bandai_root_translation_is_no_bone() {
    let motion = read_bvh(&sample()).unwrap();
    let view = ViewMotion::from_motion("walk", &motion);
    let hips = motion.skeleton().find("Hips").unwrap();
    let root = motion.skeleton().find("joint_Root").unwrap();
    // Hips walks several metres away from joint_Root, which stays put: the
    // line between them is a translation, not a bone.
    assert!(!view.bones[hips]);
    assert!(!view.point_shown(root));
    assert_eq!(view.body_root(), hips);
    // Every other joint hangs on a rigid bone.
    for j in 0..view.point_count() {
        if j != hips && j != root {
            assert!(view.bones[j], "{}", view.names[j]);
            assert!(view.point_shown(j), "{}", view.names[j]);
        }
    }
    let height = figure_height(&view, 0);
    // Floor to head joint: Bandai's head end site has no offset.
    assert!(
        (1.2..2.0).contains(&height),
        "standing figure {height} m tall"
    );
}

#[test]
fn scene_json_has_what_the_page_reads() {
    let scene = Scene::from_files(&[sample(), sample()]).unwrap();
    let json: serde_json::Value = serde_json::from_str(&scene.to_json()).unwrap();
    assert_eq!(json["version"], 1);
    assert_eq!(json["unit"], "m");
    let motions = json["motions"].as_array().unwrap();
    assert_eq!(motions.len(), 2);
    // Distinct colours, label from the file name.
    assert_ne!(motions[0]["colour"], motions[1]["colour"]);
    assert_eq!(motions[0]["label"], "dataset-1_walk_normal_001");
    let view = &scene.motions[0];
    let m = &motions[0];
    assert_eq!(m["frame_count"], view.frame_count);
    assert_eq!(m["joint_count"], view.joint_count);
    assert_eq!(m["names"].as_array().unwrap().len(), view.point_count());
    assert_eq!(m["bones"].as_array().unwrap().len(), view.point_count());
    assert_eq!(m["shown"].as_array().unwrap().len(), view.point_count());
    assert!(m["confidence"].is_null());
    let positions = m["positions"].as_array().unwrap();
    assert_eq!(positions.len(), view.frame_count * view.point_count() * 3);
    // Rounded to 0.1 mm.
    for (i, v) in positions.iter().enumerate().step_by(97) {
        let p = view.positions[i / 3][i % 3];
        assert!(
            (v.as_f64().unwrap() as f32 - p).abs() <= 0.6e-4,
            "value {i}"
        );
    }
}

#[test]
fn positions_and_confidence_are_checked() {
    let names = vec!["a".to_string(), "b".to_string()];
    let ok = |parents: Vec<Option<usize>>, positions: Vec<Vec3>, ft: f64| {
        ViewMotion::from_positions("x", names.clone(), parents, ft, positions, None)
    };
    let two_frames = vec![Vec3::ZERO, Vec3::Y, Vec3::ZERO, Vec3::Y];
    let m = ok(vec![None, Some(0)], two_frames.clone(), 0.1).unwrap();
    assert_eq!(m.frame_count, 2);
    assert_eq!(m.metres_per_unit, 1.0, "a 1 unit tall figure is in metres");

    let err = |r: mocap_core::Result<ViewMotion>| r.unwrap_err().to_string();
    assert!(err(ok(vec![None], two_frames.clone(), 0.1)).contains("2 joint names but 1 parents"));
    assert!(err(ok(vec![Some(2), None], two_frames.clone(), 0.1)).contains("not another joint"));
    assert!(err(ok(vec![None, Some(1)], two_frames.clone(), 0.1)).contains("not another joint"));
    // Children may come first, as in Kinect's joint order.
    assert!(ok(vec![Some(1), None], two_frames.clone(), 0.1).is_ok());
    assert!(err(ok(vec![None, Some(0)], two_frames[..3].to_vec(), 0.1))
        .contains("whole number of frames"));
    assert!(err(ok(vec![None, Some(0)], two_frames.clone(), 0.0)).contains("frame time"));
    let mut nan = two_frames.clone();
    nan[3].x = f32::NAN;
    assert!(err(ok(vec![None, Some(0)], nan, 0.1)).contains("joint 1 (b) of frame 1"));

    let with = |c: Vec<f32>| m.clone().with_confidence(c);
    assert!(err(with(vec![1.0; 3])).contains("need 4 confidence values, got 3"));
    assert!(err(with(vec![1.0, f32::NAN, 1.0, 1.0])).contains("joint 1 in frame 0"));
    let clamped = with(vec![-1.0, 0.5, 2.0, 1.0]).unwrap();
    assert_eq!(
        clamped.confidence.as_deref(),
        Some(&[0.0, 0.5, 1.0, 1.0][..])
    );
    assert_eq!(clamped.joint_confidence(1, 1), Some(1.0));
}

#[test]
fn units_are_guessed_from_the_figure_size() {
    assert_eq!(guess_metres_per_unit(1.8), 1.0);
    assert_eq!(guess_metres_per_unit(175.0), 0.01);
    assert_eq!(guess_metres_per_unit(1750.0), 0.001);
    // CMU takes converted to BVH: 1/0.45 inch (the CMU-style parser case
    // spans 26 units in its first frame, a 1.4 m figure).
    assert!((guess_metres_per_unit(26.0) - 0.056444).abs() < 1e-5);
    // Nothing human-sized: keep the numbers as they are.
    assert_eq!(guess_metres_per_unit(0.01), 1.0);
    assert_eq!(guess_metres_per_unit(1.0e6), 1.0);
}

#[test]
fn bad_files_are_named_in_the_error() {
    let missing = workspace().join("samples/no-such-take.bvh");
    let e = Scene::from_files(std::slice::from_ref(&missing))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no-such-take.bvh"), "{e}");
    let e = Scene::from_files(&[PathBuf::from("take.fbx")])
        .unwrap_err()
        .to_string();
    assert!(e.contains("take.fbx"), "{e}");
    assert!(Scene::from_files(&[]).is_err());
}

/// Every 15th Bandai take of both datasets: centimetres, a person-sized
/// figure, followed at the hips.
#[test]
fn bandai_takes_look_like_people() {
    let Some(data) = shared_data() else { return };
    let mut checked = 0;
    for set in ["dataset-1", "dataset-2"] {
        let mut files: Vec<PathBuf> = std::fs::read_dir(data.join("bandai").join(set))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
            .collect();
        files.sort();
        for path in files.iter().step_by(15) {
            let motion = read_bvh(path).unwrap();
            let view = ViewMotion::from_motion("take", &motion);
            let name = path.display();
            assert_eq!(view.metres_per_unit, 0.01, "{name}");
            assert_eq!(view.names[view.body_root()], "Hips", "{name}");
            // The tallest pose of the take: a standing adult (the take may
            // start crouched or lying).
            let tallest = (0..view.frame_count)
                .step_by(10)
                .map(|f| figure_height(&view, f))
                .fold(0.0, f32::max);
            assert!((1.2..2.1).contains(&tallest), "{name}: {tallest} m");
            checked += 1;
        }
    }
    assert!(checked > 50, "{checked} takes");
}

#[test]
fn hdm05_asf_amc_is_read_in_centimetres() {
    let Some(data) = shared_data() else { return };
    let dir = data.join("hdm05-sample");
    let motion = read_asf_amc(
        dir.join("HDM_bd.asf"),
        dir.join("HDM_bd_depositFloorR_001_120.amc"),
    )
    .unwrap();
    let view = ViewMotion::from_motion("hdm05", &motion);
    assert_eq!(view.metres_per_unit, 0.01);
    assert!(view.bones.iter().skip(1).all(|&b| b), "ASF bones are rigid");
    let height = figure_height(&view, 0);
    assert!((1.3..2.1).contains(&height), "{height} m");
    // Through Scene::from_files, as `mocap view X.asf Y.amc` does.
    let scene = Scene::from_files(&[
        dir.join("HDM_bd.asf"),
        dir.join("HDM_bd_depositFloorR_001_120.amc"),
    ])
    .unwrap();
    assert_eq!(scene.motions.len(), 1);
    assert_eq!(scene.motions[0].frame_count, motion.frame_count());
}

/// A Kinect v2 pose (25 joints, metres): a person 1.7 m tall standing 2 m
/// in front of the sensor, moved `dx` to the side.
fn kinect_pose(dx: f32) -> Vec<[f32; 3]> {
    use mocap_core::bodymap::KINECT_V2_JOINTS;
    // Heights of the joints above the floor (y = -1 m: the sensor is 1 m up).
    let height = |name: &str| match name {
        "Head" => 1.6,
        "Neck" | "SpineShoulder" => 1.45,
        n if n.starts_with("Shoulder") => 1.4,
        n if n.starts_with("Elbow") => 1.1,
        n if n.starts_with("Wrist") || n.starts_with("Hand") || n.starts_with("Thumb") => 0.85,
        "SpineMid" => 1.2,
        "SpineBase" => 0.95,
        n if n.starts_with("Hip") => 0.92,
        n if n.starts_with("Knee") => 0.5,
        n if n.starts_with("Ankle") => 0.08,
        _ => 0.02,
    };
    KINECT_V2_JOINTS
        .iter()
        .map(|(name, _)| {
            let side = if name.ends_with("Left") {
                -0.2
            } else if name.ends_with("Right") {
                0.2
            } else {
                0.0
            };
            [dx + side, height(name) - 1.0, 2.0]
        })
        .collect()
}

fn joints_json(pose: &[[f32; 3]], state: Option<u8>) -> String {
    let items: Vec<String> = pose
        .iter()
        .map(|p| match state {
            Some(s) => format!("[{},{},{},{s}]", p[0], p[1], p[2]),
            None => format!("[{},{},{}]", p[0], p[1], p[2]),
        })
        .collect();
    format!("[{}]", items.join(","))
}

#[test]
fn fused_capture_plays_with_its_confidence() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fused.jsonl");
    let mut text = String::new();
    for f in 0..10 {
        let mut confidence = [1.6f32; 25];
        confidence[7] = 0.0; // HandLeft unseen
        confidence[3] = 0.4;
        let c: Vec<String> = confidence.iter().map(|c| c.to_string()).collect();
        text += &format!(
            "{{\"t\":{},\"joints\":{},\"confidence\":[{}]}}\n",
            1.0 + f as f64 / 30.0,
            joints_json(&kinect_pose(0.01 * f as f32), None),
            c.join(",")
        );
    }
    std::fs::write(&path, text).unwrap();
    let scene = Scene::from_files(std::slice::from_ref(&path)).unwrap();
    assert_eq!(scene.motions.len(), 1);
    let m = &scene.motions[0];
    assert_eq!((m.frame_count, m.joint_count), (10, 25));
    assert!((m.frame_time - 1.0 / 30.0).abs() < 1e-9);
    assert_eq!(m.metres_per_unit, 1.0);
    assert_eq!(m.names[m.body_root()], "SpineBase");
    assert_eq!(m.joint_confidence(4, 7), Some(0.0));
    assert_eq!(m.joint_confidence(4, 3), Some(0.4));
    assert_eq!(
        m.joint_confidence(4, 0),
        Some(1.0),
        "a sum over sensors is shown as at most 1"
    );
    assert!((m.frame_positions(9)[0].x - 0.09).abs() < 1e-6);
    assert!((figure_height(m, 0) - 1.58).abs() < 1e-3);
}

#[test]
fn sensor_recording_gives_one_motion_per_sensor() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sensors.jsonl");
    let mut lines = Vec::new();
    // Two sensors, lines out of time order.
    for f in (0..6).rev() {
        for sensor in [1, 0] {
            let state = if sensor == 1 { 1 } else { 2 };
            lines.push(format!(
                "{{\"v\":1,\"sensor\":{sensor},\"seq\":{f},\"t\":{},\"joints\":{}}}",
                f as f64 * 0.04,
                joints_json(&kinect_pose(f as f32 * 0.1), Some(state))
            ));
        }
    }
    std::fs::write(&path, lines.join("\n")).unwrap();
    let motions = read_capture(&path).unwrap();
    assert_eq!(motions.len(), 2);
    assert_eq!(motions[0].label, "sensors sensor 0");
    assert_eq!(motions[1].label, "sensors sensor 1");
    for m in &motions {
        assert_eq!(m.frame_count, 6);
        assert!((m.frame_time - 0.04).abs() < 1e-9);
        // Sorted by time: the figure moves +x.
        assert!(m.frame_positions(5)[0].x > m.frame_positions(0)[0].x);
    }
    assert_eq!(motions[0].joint_confidence(0, 0), Some(1.0), "tracked");
    assert_eq!(motions[1].joint_confidence(0, 0), Some(0.5), "inferred");
}

#[test]
fn broken_captures_name_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.jsonl");
    let good = format!(
        "{{\"t\":0,\"joints\":{}}}",
        joints_json(&kinect_pose(0.0), None)
    );
    for (bad, expected) in [
        ("{\"t\":0,\"joints\":[[0,0,0]]}", "25 Kinect v2 joints"),
        ("not json", "not a JSON object"),
        ("{\"joints\":[]}", "time `t`"),
    ] {
        std::fs::write(&path, format!("{good}\n{bad}\n")).unwrap();
        let e = read_capture(&path).unwrap_err().to_string();
        assert!(e.contains("bad.jsonl:2:1") && e.contains(expected), "{e}");
    }
    let mut pose = kinect_pose(0.0);
    pose[5][1] = f32::NAN;
    std::fs::write(&path, joints_json(&pose, None).replace("NaN", "null")).unwrap();
    let line = format!(
        "{{\"t\":0,\"joints\":{}}}",
        joints_json(&pose, None).replace("NaN", "null")
    );
    std::fs::write(&path, line).unwrap();
    let e = read_capture(&path).unwrap_err().to_string();
    assert!(e.contains("joint 5 (ElbowLeft)"), "{e}");
    std::fs::write(&path, "\n").unwrap();
    assert!(read_capture(&path)
        .unwrap_err()
        .to_string()
        .contains("no frame"));
}
