//! glTF through the `mocap` command: `convert` writes it and says what it
//! scaled, and every command reads it.

use std::path::Path;

use mocap_core::forward_kinematics;
use mocap_core::io::bvh::read_bvh;

mod common;
use common::{mocap, stderr};

fn text(path: &Path) -> &str {
    path.to_str().unwrap()
}

#[test]
fn convert_writes_glb_with_a_note_on_units_and_every_command_reads_it() {
    let dir = tempfile::tempdir().unwrap();
    let sample = mocap_testdata::sample_walk();
    let glb = dir.path().join("walk.glb");

    let out = mocap(&["convert", text(&sample), text(&glb)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains(
            "note: lengths scaled by 0.01: the take's units read as centimetres (rest height 134.5 cm)"
        ),
        "{err}"
    );
    assert!(err.contains("wrote"), "{err}");
    assert_eq!(&std::fs::read(&glb).unwrap()[..4], b"glTF");

    // --quiet: no notes.
    let quiet = dir.path().join("quiet.gltf");
    let out = mocap(&["convert", "--quiet", text(&sample), text(&quiet)]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stderr(&out), "");

    // info reads it back in the take's own units (centimetres).
    let out = mocap(&["info", "--json", text(&glb)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(info[0]["frames"], 195);
    assert_eq!(info[0]["joints"], 22);
    assert_eq!(info[0]["channels"], 132);
    assert_eq!(info[0]["frame_time"], 0.0333333);
    assert_eq!(info[0]["rig"], "Bandai Namco");
    let hi_y = info[0]["bounding_box"][1][1].as_f64().unwrap();
    assert!((100.0..250.0).contains(&hi_y), "head height {hi_y} cm");

    // Back to BVH: the same poses within 0.1 mm.
    let bvh = dir.path().join("back.bvh");
    let out = mocap(&["convert", text(&quiet), text(&bvh)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (a, b) = (
        forward_kinematics(&read_bvh(&sample).unwrap()),
        forward_kinematics(&read_bvh(&bvh).unwrap()),
    );
    let worst = a
        .positions
        .iter()
        .zip(&b.positions)
        .map(|(p, q)| (*p - *q).length())
        .fold(0.0f32, f32::max);
    assert!(worst < 0.01, "joints up to {worst} cm apart");

    // positions reads it too: a header and a row per frame.
    let out = mocap(&["positions", text(&glb)]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 196);
}

#[test]
fn an_unknown_output_type_names_what_can_be_written() {
    let dir = tempfile::tempdir().unwrap();
    let sample = mocap_testdata::sample_walk();
    let out = mocap(&["convert", text(&sample), text(&dir.path().join("walk.fbx"))]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("walk.fbx: cannot write this type of motion file (can write .bvh, or .glb or .gltf (glTF 2.0))"),
        "{err}"
    );
}
