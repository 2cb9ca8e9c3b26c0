//! Every BVH that `mocap` writes imports into Blender with its joints where
//! our forward kinematics puts them: runs `tests/blender/run.sh` (the
//! sample, an ASF/AMC conversion and the demo's fused, noisy, cleaned and
//! restyled takes) with this build's `mocap`. Skipped with a note when
//! Blender is not installed (Debian: `apt-get install blender`).

use std::process::Command;

fn blender_installed() -> bool {
    Command::new("blender")
        .arg("--version")
        .output()
        .is_ok_and(|out| out.status.success())
}

#[test]
fn mocap_outputs_import_into_blender() {
    if !blender_installed() {
        eprintln!("note: blender is not installed; Blender import check skipped");
        return;
    }
    let out_dir = tempfile::tempdir().unwrap();
    let script = mocap_testdata::repo_root().join("tests/blender/run.sh");
    let out = Command::new("bash")
        .arg(&script)
        .env("MOCAP", env!("CARGO_BIN_EXE_mocap"))
        .env("OUT", out_dir.path())
        .output()
        .expect("bash runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = std::fs::read_to_string(out_dir.path().join("blender-check.json"))
        .expect("the check writes its report");
    let report: serde_json::Value = serde_json::from_str(&report).unwrap();
    eprintln!("{report}");
    // At least the sample and the demo's outputs were compared.
    let results = report["results"].as_array().expect("a list of results");
    assert!(results.len() >= 2, "too few files checked: {report}");
    assert!(
        results.iter().all(|r| r["passed"] == true),
        "failed: {report}"
    );
}
