//! The viewer's data: positions from mocap_core's FK in metres, topology,
//! end sites, confidence, JSON; on the bundled sample and real takes.

use std::path::{Path, PathBuf};

use mocap_core::io::asf_amc::read_asf_amc;
use mocap_core::io::bvh::read_bvh;
use mocap_core::kinematics::{end_site_positions, forward_kinematics};
use mocap_core::rotation::Vec3;
use mocap_view::scene::guess_metres_per_unit;
use mocap_view::{Scene, ViewMotion};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn sample() -> PathBuf {
    workspace().join("samples/dataset-1_walk_normal_001.bvh")
}

/// `<workspace root>/../shared/data`, or `MOCAP_SHARED_DATA`.
fn shared_data() -> Option<PathBuf> {
    let dir = match std::env::var_os("MOCAP_SHARED_DATA") {
        Some(d) => PathBuf::from(d),
        None => workspace().join("../shared/data"),
    };
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!(
            "note: shared data not found at {}; set MOCAP_SHARED_DATA. Skipping.",
            dir.display()
        );
        None
    }
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
    assert!(err(ok(vec![Some(1), None], two_frames.clone(), 0.1)).contains("not an earlier joint"));
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
