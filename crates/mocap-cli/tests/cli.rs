//! The `mocap` command as a user runs it: outputs, exit codes and messages.

use mocap_testdata::shared_data;
use std::path::Path;
use std::process::Command;

use mocap_core::io::asf_amc::read_asf_amc;
use mocap_core::io::bvh::read_bvh;
use mocap_core::{forward_kinematics, metrics};

mod common;
use common::{mocap, stderr};

fn sample() -> String {
    mocap_testdata::sample_walk().display().to_string()
}

#[test]
fn info_json_reports_the_sample() {
    let out = mocap(&["info", "--json", &sample()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let first = &info[0];
    assert_eq!(first["frames"], 195);
    assert_eq!(first["lead_in_frames"], 0);
    assert_eq!(first["joints"], 22);
    assert_eq!(first["channels"], 132);
    assert_eq!(first["frame_time"], 0.0333333);
    let hi_y = first["bounding_box"][1][1].as_f64().unwrap();
    assert!((100.0..250.0).contains(&hi_y), "head height {hi_y} cm");
    // Bandai's rig: every part but the hands beyond the wrists.
    assert_eq!(first["rig"], "Bandai Namco");
    let parts = first["body_parts"].as_array().unwrap();
    assert_eq!(parts.len(), 21, "{parts:?}");
    assert!(parts.contains(&serde_json::json!("left_clavicle")));
    assert!(!parts.contains(&serde_json::json!("left_hand")));
    assert_eq!(first["found_by"], "names");
    assert_eq!(first["body_part_joints"]["left_shoulder"], "UpperArm_L");
    assert!(first["body_parts_error"].is_null());
}

/// A BVH file's text with every joint renamed `j<k>` in file order.
fn with_meaningless_names(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let mut k = 0;
    text.lines()
        .map(|line| {
            let trimmed = line.trim_start();
            for keyword in ["ROOT ", "JOINT "] {
                if trimmed.starts_with(keyword) {
                    k += 1;
                    let indent = &line[..line.len() - trimmed.len()];
                    return format!("{indent}{keyword}j{k}");
                }
            }
            line.to_string()
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn info_says_how_the_body_parts_were_found() {
    let Some(data) = shared_data() else { return };
    let daz = data.join("other-rigs/cmu-daz/02/02_01.bvh");
    let xia = data.join("other-rigs/xia/neutral_01_000.bvh");
    let dir = tempfile::tempdir().unwrap();
    let renamed = dir.path().join("renamed.bvh");
    std::fs::write(&renamed, with_meaningless_names(&xia)).unwrap();
    let two_joints = data.join("parser-cases/bvhanim_test_simple.bvh");
    let files = [&daz, &renamed, &two_joints].map(|p| p.display().to_string());
    let files: Vec<&str> = files.iter().map(String::as_str).collect();

    let out = mocap(&[&["info", "--json"], &files[..]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // Daz/Poser names.
    assert_eq!(info[0]["rig"], "Daz/Poser");
    assert_eq!(info[0]["found_by"], "names");
    assert_eq!(info[0]["body_part_joints"]["right_hip"], "rThigh");
    // The CMU conversions start at the rest pose and blend out of it.
    assert_eq!(info[0]["lead_in_frames"], 5);
    assert_eq!(info[1]["lead_in_frames"], 0);
    // No name means anything: the shape. In the file, the CMU rig's
    // `LeftUpLeg` is the third joint and `RightArm` the 26th.
    assert_eq!(info[1]["rig"], "unnamed");
    assert_eq!(info[1]["found_by"], "shape");
    assert_eq!(info[1]["body_part_joints"]["left_hip"], "j3");
    assert_eq!(info[1]["body_part_joints"]["right_shoulder"], "j26");
    assert_eq!(info[1]["body_parts"].as_array().unwrap().len(), 23);
    // No body: refused, with a rig file to start from.
    assert!(info[2]["rig"].is_null() && info[2]["found_by"].is_null());
    let error = info[2]["body_parts_error"].as_str().unwrap();
    assert!(
        error.contains("--rig FILE") && error.contains("# pelvis = \"\""),
        "{error}"
    );

    let out = mocap(&[&["info"], &files[..]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    for expected in [
        "rig        Daz/Poser (21 of 23 body parts, found by joint name)",
        "rig        unnamed (23 of 23 body parts, found by the skeleton's shape)",
        "parts      pelvis j1, spine j13,",
        "body parts not found",
        "--rig FILE",
        "# left_hip = \"\"",
        "lead-in    frames 0..5 are the rest pose",
        "mocap convert --frames 5..",
    ] {
        assert!(text.contains(expected), "{expected}: {text}");
    }
}

#[test]
fn convert_trims_resamples_and_mirrors() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("clip.bvh");
    let out = mocap(&[
        "convert",
        &sample(),
        "--frames",
        "10..70",
        "--fps",
        "60",
        "--mirror",
        out_path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let clip = read_bvh(&out_path).unwrap();
    let source = read_bvh(Path::new(&sample())).unwrap();
    assert_eq!(
        clip.skeleton().joint_count(),
        source.skeleton().joint_count()
    );
    assert!((clip.fps() - 60.0).abs() < 1e-9);
    // 60 frames at 30 fps span 59 intervals: 118 intervals at 60 fps.
    assert_eq!(clip.frame_count(), 119);
}

#[test]
fn positions_csv_has_a_row_per_frame() {
    let out = mocap(&["positions", "--csv", &sample()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 1 + 195);
    assert!(lines[0].starts_with("frame,time,joint_Root.x,joint_Root.y,joint_Root.z,Hips.x"));
    assert_eq!(lines[1].split(',').count(), 2 + 22 * 3);
}

#[test]
fn bad_input_exits_1_with_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.bvh");
    std::fs::write(
        &bad,
        "HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition Wrotation\n}\n",
    )
    .unwrap();
    let out = mocap(&["info", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let message = stderr(&out);
    assert!(
        message.contains("bad.bvh:5:") && message.contains("Wrotation"),
        "{message}"
    );
    let missing = mocap(&["info", "no-such-file.bvh"]);
    assert_eq!(missing.status.code(), Some(1));
    assert!(stderr(&missing).contains("no-such-file.bvh"));
}

#[test]
fn usage_errors_exit_2() {
    assert_eq!(mocap(&["convert", &sample()]).status.code(), Some(1));
    assert_eq!(mocap(&["info"]).status.code(), Some(2));
    assert_eq!(mocap(&["no-such-command"]).status.code(), Some(2));
    for sub in ["info", "convert", "positions"] {
        let help = mocap(&[sub, "--help"]);
        assert!(help.status.success());
        assert!(!help.stdout.is_empty());
    }
}

#[test]
fn a_failed_convert_leaves_no_output_file() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("out.bvh");
    let out = mocap(&[
        "convert",
        &sample(),
        "--frames",
        "10..5000",
        out_path.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("outside the take"),
        "{}",
        stderr(&out)
    );
    assert!(!out_path.exists());
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "temp files left"
    );
}

/// Options whose values would write a file no reader takes (`--scale NaN`),
/// or allocate without bound (`--fps 1e9`: a billion frames a second), are
/// refused before any output, with exit code 1 and no file left.
#[test]
fn convert_refuses_options_that_would_write_an_absurd_or_unreadable_take() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("out.bvh");
    for (option, value, phrase) in [
        ("--fps", "1e9", "the rate must be 0.1 to 1000000"),
        (
            "--fps",
            "999999",
            "more than the 268435456 values a motion may hold",
        ),
        ("--scale", "NaN", "the factor must be a positive number"),
        ("--scale", "0", "the factor must be a positive number"),
        ("--scale", "1e37", "is not a finite number"),
    ] {
        let out = mocap(&[
            "convert",
            &sample(),
            option,
            value,
            out_path.to_str().unwrap(),
        ]);
        assert_eq!(
            out.status.code(),
            Some(1),
            "{option} {value}: {}",
            stderr(&out)
        );
        assert!(
            stderr(&out).contains(phrase),
            "{option} {value}: {}",
            stderr(&out)
        );
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "{option} {value}: a file was left"
        );
    }
}

/// Writing over an input is allowed (a take edited in place) but said, since
/// a mistyped path loses a take; a new output gets no such note.
#[test]
fn convert_says_when_the_output_replaces_an_input() {
    let dir = tempfile::tempdir().unwrap();
    let take = dir.path().join("take.bvh");
    std::fs::copy(sample(), &take).unwrap();
    let take = take.to_str().unwrap();
    let out = mocap(&["convert", take, "--frames", "0..10", take]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("is also an input: the input is replaced"),
        "{}",
        stderr(&out)
    );
    let other = dir.path().join("other.bvh");
    let out = mocap(&["convert", take, other.to_str().unwrap()]);
    assert!(out.status.success());
    assert!(!stderr(&out).contains("also an input"), "{}", stderr(&out));
}

#[test]
fn asf_amc_converts_to_a_bvh_with_the_same_poses() {
    let Some(data) = shared_data() else { return };
    let asf = data.join("hdm05-sample/HDM_bd.asf");
    let amc = data.join("hdm05-sample/HDM_bd_depositFloorR_001_120.amc");
    let dir = tempfile::tempdir().unwrap();
    let bvh = dir.path().join("deposit.bvh");
    let out = mocap(&[
        "convert",
        asf.to_str().unwrap(),
        amc.to_str().unwrap(),
        bvh.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let original = forward_kinematics(&read_asf_amc(&asf, &amc).unwrap());
    let converted = forward_kinematics(&read_bvh(&bvh).unwrap());
    let error = metrics::mean_joint_position_error(&original, &converted, None).unwrap();
    assert!(error < 1e-3, "mean joint position error {error} cm");
}

/// `mocap info ... | head`: the reader goes away; mocap ends quietly (on
/// Unix, by SIGPIPE as `yes | head` does), never with a panic.
#[cfg(unix)]
#[test]
fn output_to_a_closed_pipe_ends_quietly() {
    let dir = tempfile::tempdir().unwrap();
    let tiny = dir.path().join("tiny.bvh");
    std::fs::write(
        &tiny,
        "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xposition Yposition Zposition\n  \
         End Site\n  {\n    OFFSET 0 1 0\n  }\n}\nMOTION\nFrames: 1\nFrame Time: 0.0333333\n0 0 0\n",
    )
    .unwrap();
    // Far more output than a pipe holds, so writing must meet the closed end.
    let files: Vec<&Path> = std::iter::repeat_n(tiny.as_path(), 3000).collect();
    let mut child = Command::new(env!("CARGO_BIN_EXE_mocap"))
        .arg("info")
        .args(&files)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = stderr(&out);
    assert!(!err.contains("panicked"), "{err}");
}

/// The sample with its frames repeated `times` times (about 1 MB per
/// repetition): a take whose writing lasts long enough to be interrupted.
#[cfg(unix)]
fn long_take(dir: &Path, times: usize) -> std::path::PathBuf {
    let text = std::fs::read_to_string(sample()).unwrap();
    let (header, motion) = text.split_once("MOTION").unwrap();
    let frames: Vec<&str> = motion
        .lines()
        .skip_while(|l| !l.starts_with("Frame Time"))
        .collect();
    let (frame_time, rows) = frames.split_first().unwrap();
    let rows: Vec<&str> = rows
        .iter()
        .copied()
        .filter(|l| !l.trim().is_empty())
        .collect();
    let mut out = format!(
        "{header}MOTION\nFrames: {}\n{frame_time}\n",
        rows.len() * times
    );
    for _ in 0..times {
        for row in &rows {
            out.push_str(row);
            out.push('\n');
        }
    }
    let path = dir.join("long.bvh");
    std::fs::write(&path, out).unwrap();
    path
}

/// Names of the hidden temporary files of `out.bvh` in `dir`.
#[cfg(unix)]
fn temp_files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".out.bvh.") && n.ends_with(".tmp"))
        .collect()
}

/// Ctrl-C or `kill` in the middle of a write removes the temporary file;
/// after `kill -9`, which nothing can catch, the next write to the same path
/// removes it.
#[cfg(unix)]
#[test]
fn an_interrupted_write_leaves_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let input = long_take(dir.path(), 60);
    let output = dir.path().join("out.bvh");
    // Starts `convert`, waits for its temporary file, sends the signal;
    // `None` when the write finished before the signal came.
    let interrupt = |signal: &str| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_mocap"))
            .args(["convert", input.to_str().unwrap(), output.to_str().unwrap()])
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let started = std::time::Instant::now();
        while temp_files(dir.path()).is_empty() {
            assert!(started.elapsed().as_secs() < 60, "convert never wrote");
            std::thread::sleep(std::time::Duration::from_micros(200));
        }
        let kill = Command::new("kill")
            .args([format!("-{signal}"), child.id().to_string()])
            .status()
            .unwrap();
        assert!(kill.success());
        let status = child.wait().unwrap();
        if status.success() {
            std::fs::remove_file(&output).unwrap();
            return None;
        }
        Some(status)
    };
    for (signal, code) in [("TERM", Some(143)), ("INT", Some(130)), ("KILL", None)] {
        let status = (0..5)
            .find_map(|_| interrupt(signal))
            .unwrap_or_else(|| panic!("five writes ended before SIG{signal} came"));
        assert_eq!(status.code(), code, "after SIG{signal}");
        let left = temp_files(dir.path());
        if signal == "KILL" {
            assert_eq!(left.len(), 1, "{left:?}");
            let out = mocap(&["convert", &sample(), output.to_str().unwrap()]);
            assert!(out.status.success(), "{}", stderr(&out));
            assert!(temp_files(dir.path()).is_empty());
        } else {
            assert!(left.is_empty(), "after SIG{signal}: {left:?}");
            assert!(!output.exists(), "after SIG{signal}");
        }
    }
}
