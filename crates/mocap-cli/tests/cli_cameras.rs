//! `mocap cameras simulate|run|eval` end to end on the bundled Bandai walk.

use std::path::Path;
use std::process::Output;

mod common;
use common::mocap;

fn path(p: &Path) -> &str {
    p.to_str().expect("utf-8 temp path")
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_simulated_trial_is_triangulated_written_as_bvh_and_evaluated() {
    let dir = tempfile::tempdir().unwrap();
    let trial = dir.path().join("trial");
    let walk = mocap_testdata::sample_walk();
    ok(&mocap(&[
        "cameras",
        "simulate",
        path(&walk),
        "-o",
        path(&trial),
        "--seed",
        "3",
    ]));
    // Simulating into a folder that holds something is refused.
    let again = mocap(&["cameras", "simulate", path(&walk), "-o", path(&trial)]);
    assert_eq!(again.status.code(), Some(1));

    let bvh = dir.path().join("walk.bvh");
    let out = mocap(&["cameras", "run", path(&trial), "-o", path(&bvh), "--json"]);
    ok(&out);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["layout"], "BODY_25");
    assert_eq!(report["method"], "robust");
    let person = &report["people"][0];
    assert!(
        person["reprojection_px"].as_f64().unwrap() < 8.0,
        "{person}"
    );
    let motion = mocap_core::io::bvh::read_bvh(&bvh).unwrap();
    let source = mocap_core::io::bvh::read_bvh(&walk).unwrap();
    assert_eq!(motion.frame_count(), source.frame_count());
    assert!((motion.fps() - source.fps()).abs() < 1e-3);
    // With the feet stage: the report says what it did.
    let planted = dir.path().join("walk-feet.bvh");
    let out = mocap(&[
        "cameras",
        "run",
        path(&trial),
        "-o",
        path(&planted),
        "--feet",
        "--json",
    ]);
    ok(&out);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let feet = &report["people"][0]["feet"];
    assert!(feet["feet"][0]["contacts"].as_u64().unwrap() >= 2, "{feet}");
    assert!(report["people"][0]["feet"].is_object() && person["feet"].is_null());
    // The BVH is a rig the rest of the pipeline knows.
    let info = mocap(&["info", path(&bvh)]);
    ok(&info);
    assert!(String::from_utf8_lossy(&info.stdout).contains("Kinect"));

    let md = dir.path().join("eval.md");
    let truth = trial.join("truth.trc");
    let out = mocap(&[
        "cameras",
        "eval",
        path(&trial),
        "--truth",
        path(&truth),
        "--markdown",
        path(&md),
    ]);
    ok(&out);
    let table = std::fs::read_to_string(&md).unwrap();
    for method in [
        "plain",
        "scores",
        "bone-length",
        "range-of-motion",
        "robust",
    ] {
        assert!(table.contains(&format!("| {method} |")), "{table}");
    }
    assert!(table.contains("Best MPJPE over plain DLT's"), "{table}");
}

#[test]
fn bad_command_lines_and_inputs_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let out = mocap(&[
        "cameras",
        "run",
        path(dir.path()),
        "-o",
        "x.bvh",
        "--layout",
        "BODY_99",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--layout \"BODY_99\""));
    let out = mocap(&[
        "cameras",
        "run",
        path(dir.path()),
        "-o",
        "x.bvh",
        "--method",
        "best",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--method \"best\": expected plain"));
    // An empty folder: no calibration to be found.
    let out = mocap(&["cameras", "run", path(dir.path()), "-o", "x.bvh"]);
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(
        text.contains("no calibration found") && text.contains("--calib"),
        "{text}"
    );
    assert!(!Path::new("x.bvh").exists());
}
