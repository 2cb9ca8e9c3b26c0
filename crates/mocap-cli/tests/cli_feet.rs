//! `mocap feet IN -o OUT` end to end on the bundled Bandai walk.

use std::path::Path;
use std::process::Output;

use mocap_core::io::bvh::{read_bvh, write_bvh};
use mocap_core::rotation::Vec3;

mod common;
use common::mocap;

fn path(p: &Path) -> &str {
    p.to_str().expect("utf-8 temp path")
}

#[test]
fn feet_stops_a_dragged_walk_sliding_and_keeps_the_layout() {
    let dir = tempfile::tempdir().unwrap();
    let walk = read_bvh(&mocap_testdata::sample_walk()).unwrap();
    // The root dragged sideways at 40 cm/s: the planted feet slide.
    let mut dragged = walk.clone();
    for f in 0..dragged.frame_count() {
        let t = dragged.local_translation(f, 0);
        let drift = Vec3::new(40.0 * f as f32 / dragged.fps() as f32, 0.0, 0.0);
        dragged.set_local_translation(f, 0, t + drift);
    }
    let input = dir.path().join("dragged.bvh");
    write_bvh(&input, &dragged).unwrap();
    let output = dir.path().join("planted.bvh");
    let out = mocap(&["feet", path(&input), "-o", path(&output), "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let sliding = |when: &str| report[when]["sliding"].as_f64().unwrap();
    assert!(
        sliding("after") < sliding("before") / 3.0,
        "{} -> {}",
        sliding("before"),
        sliding("after")
    );
    assert_eq!(report["after"]["below_floor"]["frames_below"], 0);
    assert!(report["feet"][0]["contacts"].as_u64().unwrap() >= 4);
    assert_eq!(report["rig"], "Bandai Namco");
    let planted = read_bvh(&output).unwrap();
    assert_eq!(planted.skeleton(), dragged.skeleton());
    assert_eq!(planted.frame_count(), dragged.frame_count());
    assert_eq!(planted.frame_time(), dragged.frame_time());
    assert_ne!(planted.values(), dragged.values());

    // Without --json: what it did, in words, on standard error.
    let out = mocap(&["feet", path(&input), "-o", path(&output)]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stderr);
    for words in [
        "left foot:",
        "contacts",
        "planted-foot sliding",
        "below the floor",
        "jitter",
    ] {
        assert!(text.contains(words), "{text}");
    }
}

#[test]
fn feet_refuses_a_take_too_short_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let walk = read_bvh(&mocap_testdata::sample_walk()).unwrap();
    let short = mocap_core::ops::trim(&walk, 0..2).unwrap();
    let input = dir.path().join("short.bvh");
    write_bvh(&input, &short).unwrap();
    let output = dir.path().join("out.bvh");
    let out = mocap(&["feet", path(&input), "-o", path(&output)]);
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(
        text.contains("short.bvh") && text.contains("feet stage") && text.contains("has 2"),
        "{text}"
    );
    assert!(!output.exists());

    // The same through another command's --feet: which option, why, and
    // nothing written.
    let out = mocap(&[
        "clean",
        "apply",
        path(&input),
        "-o",
        path(&output),
        "--filter",
        "butterworth:2:3",
        "--feet",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(
        text.contains("short.bvh: --feet: ") && text.contains("has 2"),
        "{text}"
    );
    assert!(!output.exists());
}

#[test]
fn feet_takes_a_studio_rig_described_with_rig() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("renamed.bvh");
    std::fs::write(
        &input,
        mocap_testdata::renamed_bandai_bvh(&mocap_testdata::sample_walk()),
    )
    .unwrap();
    let rig = dir.path().join("rig.toml");
    std::fs::write(&rig, mocap_testdata::RENAMED_BANDAI_RIG).unwrap();
    let output = dir.path().join("out.bvh");
    let out = mocap(&[
        "--rig",
        path(&rig),
        "feet",
        path(&input),
        "-o",
        path(&output),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["rig"], "Studio (German names)");
    assert!(output.exists());
}

/// Runs mocap and fails with its standard error if it did not succeed.
fn mocap_ok(args: &[&str]) -> Output {
    let out = mocap(args);
    assert!(
        out.status.success(),
        "mocap {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// `--feet` on clean, style and fuse is the feet stage on their output:
/// the file is the one `mocap feet` writes from the output without it.
#[test]
fn the_feet_option_writes_what_the_feet_command_writes() {
    let dir = tempfile::tempdir().unwrap();
    let file = |name: &str| dir.path().join(name);
    let walk = mocap_testdata::sample_walk();
    let style = mocap_testdata::repo_root().join("samples/dataset-1_walk_proud_001.bvh");
    let same_as_feet_command = |with: &Path, without: &Path, name: &str| {
        let planted = file(&format!("{name}-planted.bvh"));
        mocap_ok(&["feet", path(without), "-o", path(&planted)]);
        assert!(
            std::fs::read(with).unwrap() == std::fs::read(&planted).unwrap(),
            "{name} --feet differs from mocap feet on its output"
        );
    };

    // clean, with the report of the feet stage in its JSON.
    let filter = ["--filter", "butterworth-gcv:2"];
    let (with, without) = (file("clean-feet.bvh"), file("clean.bvh"));
    let out = mocap_ok(
        &[
            &["clean", "apply", path(&walk), "-o", path(&with)][..],
            &filter,
            &["--feet", "--json"],
        ]
        .concat(),
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(
        report["feet"]["after"]["sliding"].as_f64().is_some(),
        "{report}"
    );
    mocap_ok(
        &[
            &["clean", "apply", path(&walk), "-o", path(&without)][..],
            &filter,
        ]
        .concat(),
    );
    same_as_feet_command(&with, &without, "clean");

    // style.
    let (with, without) = (file("style-feet.bvh"), file("style.bvh"));
    let style_args = ["style", "apply", path(&walk), "--style", path(&style), "-o"];
    mocap_ok(&[&style_args[..], &[path(&with), "--feet"]].concat());
    mocap_ok(&[&style_args[..], &[path(&without)]].concat());
    same_as_feet_command(&with, &without, "style");

    // fuse run, on a simulated capture of the walk.
    let sim = file("sim");
    mocap_ok(&["-q", "fuse", "simulate", path(&walk), "-o", path(&sim)]);
    let recordings: Vec<String> = (0..3)
        .map(|s| path(&sim.join(format!("sensor-{s}.jsonl"))).to_string())
        .collect();
    let calib = sim.join("truth.calib.toml");
    let body = sim.join("body.json");
    let (with, without) = (file("fused-feet.bvh"), file("fused.bvh"));
    let run = |output: &Path, extra: &[&str]| {
        let mut args = vec!["fuse", "run"];
        args.extend(recordings.iter().map(String::as_str));
        args.extend([
            "--calib",
            path(&calib),
            "--body",
            path(&body),
            "-o",
            path(output),
        ]);
        args.extend(extra);
        mocap_ok(&args)
    };
    let out = run(&with, &["--feet", "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let feet = &report["outputs"][0]["feet"];
    assert_eq!(feet["after"]["below_floor"]["frames_below"], 0, "{feet}");
    run(&without, &[]);
    same_as_feet_command(&with, &without, "fuse run");
}
