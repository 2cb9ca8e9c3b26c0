//! Every file that cannot be read, and every take that cannot be written,
//! is refused with an error naming the file and what is missing; a refused
//! write leaves nothing behind.

mod common;

use std::path::Path;

use common::{Foreign, NodeSpec, Quat};
use gltf_json::animation::{Interpolation, Property};
use mocap_core::io::bvh::read_bvh;
use mocap_core::{Joint, Motion, Skeleton};
use mocap_gltf::{read_gltf, write_gltf};

fn read_error(path: &Path) -> String {
    read_gltf(path, None).unwrap_err().to_string()
}

fn assert_names_file(err: &str, path: &Path, what: &str) {
    assert!(err.contains(&path.display().to_string()), "{err}");
    assert!(err.contains(what), "expected {what:?} in: {err}");
}

/// Two joints under a plain root node, skinned and animated as asked.
fn two_joints(skin: bool, animated_node: Option<u32>) -> Foreign {
    let mut file = Foreign::default();
    file.node(NodeSpec {
        name: "Hips",
        children: &[1],
        ..Default::default()
    });
    file.node(NodeSpec {
        name: "Knee",
        translation: [0.0, -0.4, 0.0],
        ..Default::default()
    });
    file.node(NodeSpec {
        name: "Lamp",
        ..Default::default()
    });
    if skin {
        file.skin(&[0, 1]);
    }
    if let Some(node) = animated_node {
        let values: Vec<f32> = [Quat::IDENTITY, Quat::from_rotation_x(1.0)]
            .iter()
            .flat_map(|q| q.to_array())
            .collect();
        file.animation(
            "Bend",
            &[(node, Property::Rotation, &[0.0, 1.0], &values)],
            Interpolation::Linear,
        );
    }
    file
}

#[test]
fn files_without_a_skin_an_animation_or_a_moving_joint_are_refused() {
    let dir = tempfile::tempdir().unwrap();

    let path = dir.path().join("no_skin.glb");
    two_joints(false, Some(1)).write_glb(&path);
    assert_names_file(&read_error(&path), &path, "has no skin");

    let path = dir.path().join("no_animation.glb");
    two_joints(true, None).write_glb(&path);
    assert_names_file(&read_error(&path), &path, "has no animation");

    let path = dir.path().join("lamp_only.glb");
    two_joints(true, Some(2)).write_glb(&path);
    assert_names_file(
        &read_error(&path),
        &path,
        "animation \"Bend\" moves none of the skin's joints",
    );

    let path = dir.path().join("bend.glb");
    two_joints(true, Some(1)).write_glb(&path);
    assert!(read_gltf(&path, None).is_ok());
    let err = read_gltf(&path, Some("Walk")).unwrap_err().to_string();
    assert_names_file(&err, &path, "no animation named \"Walk\" (it has \"Bend\")");
}

#[test]
fn truncated_and_garbled_files_are_refused_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let walk = read_bvh(&mocap_testdata::sample_walk()).unwrap();
    let good = dir.path().join("walk.glb");
    write_gltf(&good, &walk).unwrap();
    let bytes = std::fs::read(&good).unwrap();

    let truncated = dir.path().join("truncated.glb");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    assert_names_file(
        &read_error(&truncated),
        &truncated,
        "not a readable glTF 2.0 file",
    );

    let mut garbled_bytes = bytes.clone();
    garbled_bytes[20..60].fill(b'#');
    let garbled = dir.path().join("garbled.glb");
    std::fs::write(&garbled, &garbled_bytes).unwrap();
    assert_names_file(
        &read_error(&garbled),
        &garbled,
        "not a readable glTF 2.0 file",
    );

    let missing = dir.path().join("missing.glb");
    let err = read_error(&missing);
    assert!(err.contains("missing.glb"), "{err}");
}

#[test]
fn a_missing_buffer_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("take.gltf");
    two_joints(true, Some(1)).write_gltf_with_bin(&path, "take.bin", false);
    let err = read_error(&path);
    assert_names_file(&err, &path, "its buffer file");
    assert!(
        err.contains(&dir.path().join("take.bin").display().to_string()),
        "{err}"
    );
}

#[test]
fn scales_a_skeleton_cannot_hold_are_refused() {
    let dir = tempfile::tempdir().unwrap();

    // Stretched one way only, above the joints.
    let mut file = Foreign::default();
    file.node(NodeSpec {
        name: "Armature",
        scale: [1.0, 2.0, 1.0],
        children: &[1],
        ..Default::default()
    });
    file.node(NodeSpec {
        name: "Hips",
        ..Default::default()
    });
    file.skin(&[1]);
    let values: Vec<f32> = [Quat::IDENTITY, Quat::from_rotation_x(1.0)]
        .iter()
        .flat_map(|q| q.to_array())
        .collect();
    file.animation(
        "Turn",
        &[(1, Property::Rotation, &[0.0, 1.0], &values)],
        Interpolation::Linear,
    );
    let path = dir.path().join("stretched.glb");
    file.write_glb(&path);
    assert_names_file(
        &read_error(&path),
        &path,
        "node \"Armature\" has the scale [1.0, 2.0, 1.0], which is not uniform",
    );

    // Scaled by the animation.
    let mut file = two_joints(true, None);
    file.animation(
        "Grow",
        &[(
            1,
            Property::Scale,
            &[0.0, 1.0],
            &[1.0, 1.0, 1.0, 1.5, 1.5, 1.5],
        )],
        Interpolation::Linear,
    );
    let path = dir.path().join("growing.glb");
    file.write_glb(&path);
    assert_names_file(&read_error(&path), &path, "the animation scales it");

    // The armature above the joints moved by the animation.
    let mut file = Foreign::default();
    file.node(NodeSpec {
        name: "Armature",
        children: &[1],
        ..Default::default()
    });
    file.node(NodeSpec {
        name: "Hips",
        ..Default::default()
    });
    file.skin(&[1]);
    file.animation(
        "Slide",
        &[
            (
                0,
                Property::Translation,
                &[0.0, 1.0],
                &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            ),
            (1, Property::Rotation, &[0.0, 1.0], &values),
        ],
        Interpolation::Linear,
    );
    let path = dir.path().join("sliding_armature.glb");
    file.write_glb(&path);
    assert_names_file(
        &read_error(&path),
        &path,
        "moves this node above the skin's joints",
    );
}

/// The names in `dir`, sorted.
fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn takes_gltf_cannot_hold_are_refused_and_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let walk = read_bvh(&mocap_testdata::sample_walk()).unwrap();

    // No frames.
    let skeleton = walk.skeleton().clone();
    let empty = Motion::new(skeleton, walk.frame_time(), 0, Vec::new()).unwrap();
    let path = dir.path().join("empty.glb");
    let err = write_gltf(&path, &empty).unwrap_err().to_string();
    assert_names_file(&err, &path, "it has no frames");

    // A value that is not a number, over a file that was there: it stays.
    let mut broken = walk.clone();
    let column = broken.skeleton().channel_start(5) + 1;
    broken.frame_mut(17)[column] = f32::NAN;
    let path = dir.path().join("broken.gltf");
    std::fs::write(&path, "the old file").unwrap();
    let err = write_gltf(&path, &broken).unwrap_err().to_string();
    let joint = &walk.skeleton().joint(5);
    assert_names_file(
        &err,
        &path,
        &format!(
            "frame 17, joint {:?}, {} is NaN (not a finite number)",
            joint.name,
            joint.channels[1].name()
        ),
    );
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "the old file");

    // An offset that is not a number.
    let mut joints = walk.skeleton().joints().to_vec();
    joints[3].offset.y = f32::INFINITY;
    let skeleton = Skeleton::new(joints).unwrap();
    let far = Motion::new(
        skeleton,
        walk.frame_time(),
        walk.frame_count(),
        walk.values().to_vec(),
    )
    .unwrap();
    let path = dir.path().join("far.glb");
    let err = write_gltf(&path, &far).unwrap_err().to_string();
    assert_names_file(
        &err,
        &path,
        "has an offset or end site that is not a finite number",
    );

    // Not a glTF name.
    let path = dir.path().join("take.obj");
    let err = write_gltf(&path, &walk).unwrap_err().to_string();
    assert_names_file(&err, &path, "ends in .glb (binary) or .gltf (JSON)");

    // No joints: a skeleton of none.
    let nothing = Motion::new(
        Skeleton::new(Vec::<Joint>::new()).unwrap(),
        0.01,
        3,
        Vec::new(),
    )
    .unwrap();
    let path = dir.path().join("nothing.glb");
    let err = write_gltf(&path, &nothing).unwrap_err().to_string();
    assert_names_file(&err, &path, "it has no joints");

    // Nothing written, no temporary files left.
    assert_eq!(names_in(dir.path()), ["broken.gltf"]);

    // A write that cannot start (its folder is a file) leaves nothing.
    let blocked = dir.path().join("broken.gltf").join("take.glb");
    assert!(write_gltf(&blocked, &walk).is_err());
    assert_eq!(names_in(dir.path()), ["broken.gltf"]);
}
