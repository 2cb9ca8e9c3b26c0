//! `mocap fuse eval` of real-style recordings: a folder of NTU `.skeleton`
//! files, calibrated from the body or by a given calibration file.

use std::path::Path;
use std::process::Output;

mod common;
use common::mocap;

fn path(p: &Path) -> &str {
    p.to_str().expect("utf-8 temp path")
}

fn ok(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap_or(serde_json::Value::Null)
}

#[test]
fn a_folder_of_ntu_files_is_evaluated_with_the_body_or_a_given_calibration() {
    let dir = tempfile::tempdir().unwrap();
    let sim = dir.path().join("sim");
    let walk = mocap_testdata::sample_walk();
    ok(&mocap(&[
        "fuse",
        "simulate",
        path(&walk),
        "--sensors",
        "3",
        "--ntu",
        "-o",
        path(&sim),
    ]));
    // The NTU files alone, as a user has them.
    let ntu = dir.path().join("ntu");
    std::fs::create_dir(&ntu).unwrap();
    for entry in std::fs::read_dir(&sim).unwrap().flatten() {
        if entry.path().extension().is_some_and(|e| e == "skeleton") {
            std::fs::copy(entry.path(), ntu.join(entry.file_name())).unwrap();
        }
    }
    let plots = dir.path().join("plots");
    let body = ok(&mocap(&[
        "fuse",
        "eval",
        path(&ntu),
        "--json",
        "--plots",
        path(&plots),
    ]));
    let take = &body[0];
    assert_eq!(take["sensors"].as_array().unwrap().len(), 3, "{body}");
    assert_eq!(take["calibration"].as_array().unwrap().len(), 2, "{body}");
    // A filmstrip a person can judge: a row per sensor and the fused one
    // (panels are 320 pixels high).
    let strips: Vec<_> = std::fs::read_dir(&plots).unwrap().flatten().collect();
    assert_eq!(strips.len(), 1, "{strips:?}");
    let name = strips[0].file_name().to_string_lossy().into_owned();
    assert!(
        name.starts_with("filmstrip-S") && name.ends_with(".png"),
        "{name}"
    );
    let png = std::fs::read(strips[0].path()).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    let height = u32::from_be_bytes(png[20..24].try_into().unwrap());
    assert!((4 * 320..5 * 320).contains(&height), "{height} pixels high");

    // Calibrated once, then evaluated with that file.
    let files: Vec<String> = std::fs::read_dir(&ntu)
        .unwrap()
        .flatten()
        .map(|e| e.path().display().to_string())
        .collect();
    let rig = dir.path().join("rig.toml");
    let mut args = vec!["fuse", "calibrate"];
    args.extend(files.iter().map(String::as_str));
    args.extend(["-o", path(&rig)]);
    ok(&mocap(&args));
    let given = ok(&mocap(&[
        "fuse",
        "eval",
        path(&ntu),
        "--calib",
        path(&rig),
        "--json",
    ]));
    let take = &given[0];
    assert_eq!(take["calibration"].as_array().unwrap().len(), 0, "{given}");
    assert!(!take["rows"].as_array().unwrap().is_empty());

    // A calibration file does not place simulated sensors.
    let out = mocap(&["fuse", "eval", path(&walk), "--calib", path(&rig)]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("applies to recordings"));
    // A folder with neither takes nor recordings.
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let out = mocap(&["fuse", "eval", path(&empty)]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no BVH takes and no recordings"));
}
