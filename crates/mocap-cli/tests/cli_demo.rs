//! `mocap demo` end to end: the report folder, the numbers of the stages
//! that ran, and honest statuses for the stages that could not.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

fn workspace() -> PathBuf {
    mocap_testdata::repo_root()
}

/// Runs `mocap demo -o DIR --json ARGS...` and returns the parsed report.
fn demo(out: &Path, extra: &[&str]) -> Value {
    let output = Command::new(env!("CARGO_BIN_EXE_mocap"))
        .current_dir(workspace())
        .args(["demo", "--json", "--output"])
        .arg(out)
        .args(extra)
        .output()
        .expect("the mocap binary runs");
    assert!(
        output.status.success(),
        "mocap demo failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("--json prints the report as JSON")
}

fn stage<'a>(report: &'a Value, name: &str) -> &'a Value {
    report["stages"]
        .as_array()
        .expect("stages")
        .iter()
        .find(|s| s["name"] == name)
        .unwrap_or_else(|| panic!("no stage {name} in the report"))
}

fn number(stage: &Value, name: &str) -> f64 {
    stage["numbers"]
        .as_array()
        .unwrap()
        .iter()
        .find(|n| n["name"] == name)
        .unwrap_or_else(|| panic!("stage {} has no number {name}", stage["name"]))["value"]
        .as_f64()
        .expect("a number")
}

fn fact<'a>(stage: &'a Value, name: &str) -> &'a str {
    stage["facts"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f[0] == name)
        .unwrap_or_else(|| panic!("stage {} has no fact {name}", stage["name"]))[1]
        .as_str()
        .unwrap()
}

/// A stage that ran has finite numbers, its files exist; one that did not
/// has a message and no numbers.
fn check_consistent(out: &Path, stage: &Value) {
    let name = stage["name"].as_str().unwrap();
    let numbers = stage["numbers"].as_array().unwrap();
    if stage["status"] == "ran" {
        assert!(!numbers.is_empty(), "{name} ran but reports no number");
        for n in numbers {
            let v = n["value"].as_f64();
            assert!(v.is_some_and(f64::is_finite), "{name}: {n}");
        }
        for f in stage["outputs"]
            .as_array()
            .unwrap()
            .iter()
            .chain(stage["pictures"].as_array().unwrap())
        {
            let path = out.join(f["path"].as_str().unwrap());
            assert!(path.is_file(), "{name}: {} was not written", path.display());
        }
    } else {
        assert!(numbers.is_empty(), "{name} did not run but has numbers");
        assert!(
            stage["message"].as_str().is_some_and(|m| !m.is_empty()),
            "{name}: a stage that did not run must say why"
        );
    }
}

#[test]
fn demo_writes_a_report_with_honest_statuses() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let absent = dir.path().join("no-such-model.safetensors");
    let report = demo(&out, &["--clean-model", absent.to_str().unwrap()]);

    let html = std::fs::read_to_string(out.join("index.html")).expect("index.html");
    assert!(html.contains("<h1>mocap demo</h1>"));
    assert!(out.join("report.json").is_file());
    for s in report["stages"].as_array().unwrap() {
        check_consistent(&out, s);
    }

    // The denoiser file is absent: the stage says so, naming the file.
    let clean = stage(&report, "clean");
    assert_eq!(clean["status"], "model_missing", "{clean}");
    let message = clean["message"].as_str().unwrap();
    assert!(message.contains("no-such-model.safetensors"), "{message}");
    assert!(html.contains("no-such-model.safetensors"));
    // The chain goes on without it, with the fused take.
    let feet = stage(&report, "feet");
    assert_eq!(feet["status"], "ran", "{feet}");
    assert!(
        fact(feet, "input").ends_with("fused-on-sample-rig.bvh"),
        "{feet}"
    );

    // Fusion needs no model: it runs, on every frame of the take, and the
    // fused joints are closer to the truth than a Kinect's error scale
    // would allow by chance (a few centimetres, not metres).
    let fuse = stage(&report, "fuse");
    assert_eq!(fuse["status"], "ran", "{fuse}");
    assert!(number(fuse, "datagrams_received") > 0.0);
    let truth_frames = number(fuse, "truth_frames");
    assert!(number(fuse, "fused_frames") >= 0.9 * truth_frames, "{fuse}");
    let mpjpe = number(fuse, "mpjpe_mm");
    assert!(mpjpe > 0.0 && mpjpe < 200.0, "fused MPJPE {mpjpe} mm");
    assert!(fuse["viewer_command"]
        .as_str()
        .is_some_and(|c| c.starts_with("mocap view ") && c.contains("fused.bvh")));

    // Search and style: ran, or say which bundled file is missing.
    let bundled = |file: &str| {
        std::fs::metadata(workspace().join(file)).is_ok_and(|m| m.is_file() && m.len() > 0)
    };
    for (name, file) in [
        ("search", "models/search-bandai-content.idx"),
        ("style", "models/style-default.safetensors"),
    ] {
        let s = stage(&report, name);
        if bundled(file) {
            assert_ne!(s["status"], "model_missing", "{s}");
        } else {
            assert_eq!(s["status"], "model_missing", "{s}");
        }
    }
    let search = stage(&report, "search");
    if search["status"] == "ran" {
        // The bundled sample is a walk.
        assert_eq!(fact(search, "predicted"), "walk", "{search}");
    }
}

/// The demo runs one chain: fused take -> cleaned -> feet planted ->
/// searched and restyled, each stage reading what the one before wrote.
#[test]
fn demo_runs_the_fused_take_through_the_whole_chain() {
    if !workspace()
        .join("models/clean-default.safetensors")
        .is_file()
    {
        eprintln!("note: models/clean-default.safetensors is absent, skipping");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let report = demo(&out, &["--no-pictures"]);
    for s in report["stages"].as_array().unwrap() {
        check_consistent(&out, s);
    }
    let fuse = stage(&report, "fuse");
    assert_eq!(fuse["status"], "ran", "{fuse}");
    // The fused take on the sample's rig is within centimetres of the sample.
    let on_rig = number(fuse, "on_rig_position_error_mm");
    assert!(on_rig > 0.0 && on_rig < 200.0, "{on_rig} mm");

    // The page shows the chain's errors, the fused take's first.
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    let table = &html[html
        .find("The take through the chain")
        .expect("the chain table")..];
    assert!(table.contains(&format!("{on_rig:.2}")), "{on_rig}");

    let clean = stage(&report, "clean");
    assert_eq!(clean["status"], "ran", "{clean}");
    assert!(fact(clean, "input").ends_with("fused-on-sample-rig.bvh"));
    // The clean stage starts from the fuse stage's take: its "fused" error
    // is the one the fuse stage measured.
    assert!((number(clean, "position_error_fused_mm") - on_rig).abs() < 1e-6);
    assert!(number(clean, "jitter_fused") > 0.0);

    let feet = stage(&report, "feet");
    assert_eq!(feet["status"], "ran", "{feet}");
    assert!(fact(feet, "input").ends_with("cleaned.bvh"));
    assert!(number(feet, "contacts") > 0.0, "{feet}");
    let (before, after) = (
        number(feet, "sliding_before_cm_s"),
        number(feet, "sliding_after_cm_s"),
    );
    assert!(
        after < before,
        "feet did not slide less: {before} -> {after} cm/s"
    );

    let search = stage(&report, "search");
    if search["status"] == "ran" {
        assert!(fact(search, "query").ends_with("planted.bvh"), "{search}");
    }
    let style = stage(&report, "style");
    if style["status"] == "ran" {
        assert!(fact(style, "source").ends_with("planted.bvh"), "{style}");
    }
}
