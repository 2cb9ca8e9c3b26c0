//! `mocap fuse` as a user runs it: simulate a capture from the bundled
//! sample take, calibrate, fuse to JSON lines and BVH, stream over loopback
//! UDP, evaluate. Every network test uses 127.0.0.1 and is bounded in time.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::{mocap, stderr};

fn sample() -> String {
    mocap_testdata::sample_walk().display().to_string()
}

fn json(out: &Output) -> serde_json::Value {
    assert!(out.status.success(), "{}", stderr(out));
    serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("not JSON ({e}): {}", String::from_utf8_lossy(&out.stdout)))
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

/// A simulated 3-sensor capture of the sample take in a temporary folder.
fn simulated(extra: &[&str]) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let sim = dir.path().join("sim");
    let mut args = vec![
        "fuse",
        "simulate",
        &sample(),
        "--sensors",
        "3",
        "--seed",
        "2",
        "--output",
    ]
    .into_iter()
    .map(String::from)
    .collect::<Vec<_>>();
    args.push(s(&sim));
    args.extend(extra.iter().map(|a| a.to_string()));
    args.push("--json".into());
    let out = mocap(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let report = json(&out);
    assert_eq!(report["sensors"].as_array().unwrap().len(), 3);
    (dir, sim)
}

fn recordings(sim: &Path) -> Vec<String> {
    (0..3)
        .map(|k| s(&sim.join(format!("sensor-{k}.jsonl"))))
        .collect()
}

/// Mean distance (m) between the joints of two fused-frame JSON lines files
/// at the same times (to 1 ms).
fn mean_distance(a: &Path, b: &Path) -> f64 {
    let read = |p: &Path| -> Vec<(f64, Vec<[f64; 3]>)> {
        std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .map(|l| {
                let v: serde_json::Value = serde_json::from_str(l).unwrap();
                let joints = v["joints"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|j| {
                        let c: Vec<f64> = j
                            .as_array()
                            .unwrap()
                            .iter()
                            .map(|x| x.as_f64().unwrap())
                            .collect();
                        [c[0], c[1], c[2]]
                    })
                    .collect();
                (v["t"].as_f64().unwrap(), joints)
            })
            .collect()
    };
    let (a, b) = (read(a), read(b));
    let mut sum = 0.0;
    let mut count = 0;
    for (t, ja) in &a {
        if let Some((_, jb)) = b.iter().find(|(u, _)| (u - t).abs() < 1e-3) {
            for (p, q) in ja.iter().zip(jb) {
                sum +=
                    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
                count += 1;
            }
        }
    }
    assert!(count > 1000, "too few common frames: {count}");
    sum / count as f64
}

#[test]
fn simulate_calibrate_measure_and_run_to_jsonl_and_bvh() {
    let (dir, sim) = simulated(&[]);
    let d = dir.path();
    // Fused with the true calibration, compared with the ground truth.
    let fused = d.join("fused.jsonl");
    let bvh = d.join("fused.bvh");
    let mut args = vec!["fuse".to_string(), "run".into()];
    args.extend(recordings(&sim));
    args.extend(
        [
            "--calib",
            &s(&sim.join("truth.calib.toml")),
            "--body",
            &s(&sim.join("body.json")),
            "-o",
            &s(&fused),
            "-o",
            &s(&bvh),
            // In the truth's world, to compare with it (by default the BVH
            // stands on the floor found under the feet).
            "--calibration-world",
            "--json",
        ]
        .map(String::from),
    );
    let report = json(&mocap(&args.iter().map(String::as_str).collect::<Vec<_>>()));
    assert!(report["fused_frames"].as_u64().unwrap() > 180, "{report}");
    let error = mean_distance(&fused, &sim.join("truth.jsonl"));
    eprintln!("fused vs ground truth: {:.1} mm", error * 1000.0);
    assert!(error < 0.08, "{error} m");
    // The BVH: Kinect joints, readable, and its forward kinematics close to
    // the fused joints (what is left is the fused bones' stretch).
    let outputs = report["outputs"].as_array().unwrap();
    let bvh_report = outputs.iter().find(|o| o["format"] == "bvh").unwrap();
    let fit = &bvh_report["fit_error"];
    eprintln!("BVH vs fused joints: {fit}");
    assert!(fit["body_mean_mm"].as_f64().unwrap() < 35.0, "{fit}");
    let motion = mocap_core::io::bvh::read_bvh(&bvh).unwrap();
    assert_eq!(motion.skeleton().joint_count(), 25);
    assert_eq!(
        motion.frame_count() as u64,
        bvh_report["frames"].as_u64().unwrap()
    );
    // Its forward kinematics against the ground truth: as close as the fused
    // joints are (fixed bone lengths do not cost accuracy).
    let first_time = {
        let line = std::fs::read_to_string(&fused).unwrap();
        let v: serde_json::Value = serde_json::from_str(line.lines().next().unwrap()).unwrap();
        v["t"].as_f64().unwrap()
    };
    let bvh_as_jsonl = d.join("bvh.jsonl");
    let fk = mocap_core::forward_kinematics(&motion);
    let names = mocap_core::bodymap::KINECT_V2_JOINTS.map(|(name, _)| name);
    let index: Vec<usize> = names
        .iter()
        .map(|n| motion.skeleton().find(n).unwrap())
        .collect();
    let mut lines = String::new();
    for f in 0..motion.frame_count() {
        let joints: Vec<String> = index
            .iter()
            .map(|&j| {
                let p = fk.position(f, j) / 100.0;
                format!("[{},{},{}]", p.x, p.y, p.z)
            })
            .collect();
        lines += &format!(
            "{{\"t\":{},\"joints\":[{}]}}\n",
            first_time + f as f64 / 30.0,
            joints.join(",")
        );
    }
    std::fs::write(&bvh_as_jsonl, lines).unwrap();
    let bvh_error = mean_distance(&bvh_as_jsonl, &sim.join("truth.jsonl"));
    eprintln!("BVH vs ground truth: {:.1} mm", bvh_error * 1000.0);
    assert!(bvh_error < error + 0.01, "{bvh_error} vs {error}");

    // Calibration from the body, then a body file measured from the
    // recordings, then fusion with both: it must run and give as many frames.
    let rig = d.join("rig.toml");
    let mut args = vec!["fuse".to_string(), "calibrate".into()];
    args.extend(recordings(&sim));
    args.extend(["-o", &s(&rig), "--json"].map(String::from));
    let calibrated = json(&mocap(&args.iter().map(String::as_str).collect::<Vec<_>>()));
    assert_eq!(calibrated["sensors"].as_array().unwrap().len(), 2);
    let body = d.join("measured.json");
    let mut args = vec!["fuse".to_string(), "measure".into()];
    args.extend(recordings(&sim));
    args.extend(["-o", &s(&body)].map(String::from));
    let out = mocap(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
    let mut args = vec!["fuse".to_string(), "run".into()];
    args.extend(recordings(&sim));
    args.extend(
        [
            "--calib",
            &s(&rig),
            "--body",
            &s(&body),
            "--method",
            "report",
            "-o",
            &s(&d.join("body-calibrated.bvh")),
            "--json",
        ]
        .map(String::from),
    );
    let again = json(&mocap(&args.iter().map(String::as_str).collect::<Vec<_>>()));
    assert_eq!(again["fused_frames"], report["fused_frames"]);
}

/// Starts `mocap fuse serve` on 127.0.0.1 (a free port) with the simulated
/// take's calibration and body, writing `live` and `live_bvh`, stopping
/// after 1 s without datagrams or after `duration` seconds; returns the
/// process, the address it listens on and the rest of its standard error.
fn start_server(
    sim: &Path,
    live: &Path,
    live_bvh: &Path,
    duration: &str,
) -> (
    std::process::Child,
    String,
    std::io::Lines<BufReader<std::process::ChildStderr>>,
) {
    let mut server = Command::new(env!("CARGO_BIN_EXE_mocap"))
        .args([
            "fuse",
            "serve",
            "--calib",
            &s(&sim.join("truth.calib.toml")),
            "--body",
            &s(&sim.join("body.json")),
            "--listen",
            "127.0.0.1:0",
            "-o",
            &s(live),
            "-o",
            &s(live_bvh),
            "--idle-exit",
            "1",
            "--duration",
            duration,
            "--json",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The server says where it listens.
    let mut lines = BufReader::new(server.stderr.take().unwrap()).lines();
    let addr = loop {
        let line = lines
            .next()
            .expect("the server prints its address")
            .unwrap();
        if let Some(rest) = line.split("listening on ").nth(1) {
            break rest.split_whitespace().next().unwrap().to_string();
        }
    };
    (server, addr, lines)
}

#[test]
fn serve_and_send_over_loopback() {
    let (dir, sim) = simulated(&[]);
    let d = dir.path();
    let live = d.join("live.jsonl");
    let live_bvh = d.join("live.bvh");
    let (server, addr, _lines) = start_server(&sim, &live, &live_bvh, "30");
    let started = Instant::now();
    let mut args = vec!["fuse".to_string(), "send".into()];
    args.extend(recordings(&sim));
    args.extend(["--to", &addr, "--realtime", "--speed", "4", "--json"].map(String::from));
    let sent = json(&mocap(&args.iter().map(String::as_str).collect::<Vec<_>>()));
    let datagrams = sent["datagrams"].as_u64().unwrap();
    assert!(datagrams > 500, "{sent}");
    let out = server.wait_with_output().unwrap();
    assert!(
        started.elapsed() < Duration::from_secs(30),
        "the server stops when the sender is done"
    );
    let report = json(&out);
    let server_report = &report["server"];
    assert_eq!(server_report["datagrams"].as_u64().unwrap(), datagrams);
    assert_eq!(server_report["malformed"], 0);
    assert!(
        server_report["fused_frames"].as_u64().unwrap() > 180,
        "{report}"
    );
    let error = mean_distance(&live, &sim.join("truth.jsonl"));
    eprintln!("served fusion vs ground truth: {:.1} mm", error * 1000.0);
    assert!(error < 0.08, "{error} m");
    let motion = mocap_core::io::bvh::read_bvh(&live_bvh).unwrap();
    assert!(motion.frame_count() > 180);
}

/// A hostile datagram for [`serve_a_take_with`]: sent before the take's
/// first datagram (`at` 0.0) or after that fraction of its datagrams.
struct Hostile {
    at: f64,
    datagram: Vec<u8>,
}

/// A sensor frame of the take (sensor 0's first), with `seq` changed so
/// that it is no duplicate, then edited.
fn edited_frame(
    sim: &Path,
    seq: u64,
    edit: impl FnOnce(&mut mocap_fuse::SensorFrame),
) -> mocap_fuse::SensorFrame {
    let mut frame = mocap_fuse::read_recording(&sim.join("sensor-0.jsonl")).unwrap()[0].clone();
    frame.seq = seq;
    edit(&mut frame);
    frame
}

/// What [`serve_a_take_with`] saw.
struct Served {
    report: serde_json::Value,
    /// Fused frames in the BVH output.
    bvh_frames: usize,
    /// Fused frames the take spans at 30 fps.
    take_frames: usize,
    /// The largest coordinate of the fused joints (m).
    largest: f64,
    /// Mean distance of the fused joints to the truth (m).
    error: f64,
}

/// Runs `mocap fuse serve` on 127.0.0.1, replays the simulated take to it
/// at 4 times real time with the hostile datagrams among its own, and waits
/// for the server to stop by itself (`--idle-exit 1`) within 20 seconds of
/// the last datagram; kills it and fails otherwise.
fn serve_a_take_with(hostile: impl FnOnce(&Path) -> Vec<Hostile>) -> Served {
    use std::net::UdpSocket;
    let (dir, sim) = simulated(&[]);
    let hostile = hostile(&sim);
    let d = dir.path();
    let live = d.join("live.jsonl");
    let live_bvh = d.join("live.bvh");
    let (mut server, addr, lines) = start_server(&sim, &live, &live_bvh, "60");
    // The rest of standard error, read as it comes so that the server
    // never blocks on a full pipe.
    let log = std::thread::spawn(move || lines.map_while(Result::ok).collect::<Vec<_>>());
    let paths: Vec<PathBuf> = recordings(&sim).iter().map(PathBuf::from).collect();
    let mut frames = mocap_fuse::read_recordings(&paths).unwrap();
    let when = |f: &mocap_fuse::SensorFrame| f.arrival.unwrap_or(f.timestamp);
    frames.sort_by(|a, b| when(a).total_cmp(&when(b)));
    let (first, last) = frames.iter().fold((f64::MAX, f64::MIN), |(lo, hi), f| {
        (lo.min(f.timestamp), hi.max(f.timestamp))
    });
    let take_frames = ((last * 30.0).floor() - (first * 30.0).ceil()) as usize + 1;
    let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
    let started = Instant::now();
    let t0 = when(&frames[0]);
    let mut hostile = hostile;
    hostile.sort_by(|a, b| a.at.total_cmp(&b.at));
    let mut hostile = hostile.into_iter().peekable();
    for (i, f) in frames.iter().enumerate() {
        while let Some(h) = hostile.next_if(|h| h.at * frames.len() as f64 <= i as f64) {
            socket.send_to(&h.datagram, &addr).unwrap();
        }
        let due = started + Duration::from_secs_f64(((when(f) - t0) / 4.0).max(0.0));
        std::thread::sleep(due.saturating_duration_since(Instant::now()));
        socket
            .send_to(&mocap_fuse::encode_datagram(f), &addr)
            .unwrap();
    }
    let sent = Instant::now();
    let status = loop {
        if let Some(status) = server.try_wait().unwrap() {
            break status;
        }
        if sent.elapsed() > Duration::from_secs(20) {
            server.kill().unwrap();
            server.wait().unwrap();
            let size = |p: &Path| std::fs::metadata(p).map_or(0, |m| m.len());
            let temp: u64 = std::fs::read_dir(d)
                .unwrap()
                .map(|e| size(&e.unwrap().path()))
                .sum();
            panic!(
                "the server did not stop within 20 s of the take's end ({temp} bytes in its folder): {:?}",
                log.join().unwrap()
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let mut stdout = String::new();
    std::io::Read::read_to_string(&mut server.stdout.take().unwrap(), &mut stdout).unwrap();
    let log = log.join().unwrap();
    assert!(status.success(), "{log:?}");
    assert!(
        log.len() <= 20,
        "the server floods its standard error: {log:?}"
    );
    let report: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let bvh_frames = mocap_core::io::bvh::read_bvh(&live_bvh)
        .unwrap()
        .frame_count();
    let largest = std::fs::read_to_string(&live)
        .unwrap()
        .lines()
        .flat_map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            let joints: Vec<f64> = v["joints"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(|j| j.as_array().unwrap().iter().map(|c| c.as_f64().unwrap()))
                .collect();
            joints
        })
        .fold(0.0f64, |m, c| m.max(c.abs()));
    let error = mean_distance(&live, &sim.join("truth.jsonl"));
    Served {
        report,
        bvh_frames,
        take_frames,
        largest,
        error,
    }
}

/// The take's frames, no more: a few at either end may be lost to the
/// timing of a replay.
fn assert_the_take_alone(served: &Served) {
    let Served {
        bvh_frames,
        take_frames,
        ..
    } = *served;
    eprintln!(
        "{bvh_frames} frames in the BVH for a take of {take_frames}; largest coordinate {:.2} m; {:.1} mm from the truth",
        served.largest,
        served.error * 1000.0
    );
    assert!(
        bvh_frames <= take_frames + 1 && bvh_frames + 5 >= take_frames,
        "{bvh_frames} frames in the BVH for a take of {take_frames}: {}",
        served.report
    );
    assert!(
        served.largest < 10.0,
        "a fused joint at {} m",
        served.largest
    );
    assert!(served.error < 0.08, "{} m from the truth", served.error);
}

/// The sensor frame at `at` (fraction of the take's datagrams) as a
/// hostile datagram, edited.
fn hostile_frame(
    at: f64,
    edit: impl FnOnce(&mut mocap_fuse::SensorFrame),
) -> impl FnOnce(&Path) -> Vec<Hostile> {
    move |sim| {
        let datagram = mocap_fuse::encode_datagram(&edited_frame(sim, 1_000_000, edit));
        vec![Hostile { at, datagram }]
    }
}

#[test]
fn serve_drops_a_first_datagram_from_the_far_future() {
    let served = serve_a_take_with(hostile_frame(0.0, |f| f.timestamp = 1e30));
    assert_the_take_alone(&served);
    assert_eq!(served.report["server"]["implausible_time"], 1);
}

#[test]
fn serve_drops_a_first_datagram_from_the_far_past() {
    let served = serve_a_take_with(hostile_frame(0.0, |f| f.timestamp = -1e30));
    assert_the_take_alone(&served);
    assert_eq!(served.report["server"]["implausible_time"], 1);
}

#[test]
fn serve_drops_a_datagram_hours_ahead_mid_stream() {
    let served = serve_a_take_with(hostile_frame(0.5, |f| f.timestamp = 1e4));
    assert_the_take_alone(&served);
    assert_eq!(served.report["server"]["implausible_time"], 1);
}

#[test]
fn serve_never_fuses_joints_at_absurd_distances() {
    // Sensor 0 in the middle of the take, every joint Tracked at 1e30 m.
    let served = serve_a_take_with(|sim| {
        let frames = mocap_fuse::read_recording(&sim.join("sensor-0.jsonl")).unwrap();
        let middle = frames[frames.len() / 2].timestamp;
        hostile_frame(0.5, |f| {
            f.timestamp = middle;
            for j in f.joints.iter_mut() {
                j.position = mocap_core::rotation::Vec3::splat(1e30);
                j.state = mocap_fuse::TrackingState::Tracked;
            }
        })(sim)
    });
    assert_the_take_alone(&served);
    assert_eq!(served.report["server"]["implausible_frames"], 1);
}

#[test]
fn calibrate_one_room_scan_against_another() {
    let (dir, sim) = simulated(&[]);
    let rig = dir.path().join("scans.toml");
    let out = mocap(&[
        "fuse",
        "calibrate",
        "--points",
        &s(&sim.join("sensor-0.ply")),
        &s(&sim.join("sensor-1.ply")),
        "--pairs",
        &s(&sim.join("pairs-0-1.txt")),
        "-o",
        &s(&rig),
        "--json",
    ]);
    let result = json(&out);
    // Sensors around the person share little but the floor: ICP must say so.
    assert!(!result["icp"]["unconstrained"]
        .as_array()
        .unwrap()
        .is_empty());
    // Sensor 1's pose relative to sensor 0, against the truth.
    use mocap_fuse::Calibration;
    let truth = Calibration::read(&sim.join("truth.calib.toml")).unwrap();
    let relative = |c: &Calibration| c.get(0).unwrap().inverse().then_after(c.get(1).unwrap());
    let expected = relative(&truth);
    let found = relative(&Calibration::read(&rig).unwrap());
    let (r, t) = (found.rotation, found.translation);
    let (true_rotation, true_translation) = (expected.rotation, expected.translation);
    let angle = r.angle_between(true_rotation).to_degrees();
    let shift = (t - true_translation).length();
    eprintln!("scan calibration off by {angle:.2} degrees, {shift:.3} m");
    assert!(angle < 1.5, "{angle} degrees");
    assert!(shift < 0.05, "{shift} m");
}

#[test]
fn eval_on_ntu_files_without_ground_truth() {
    let (_dir, sim) = simulated(&["--ntu"]);
    let files: Vec<String> = (0..3)
        .map(|k| s(&sim.join(format!("S001C{k:03}P001R001A001.skeleton"))))
        .collect();
    let mut args = vec!["fuse", "eval"];
    args.extend(files.iter().map(String::as_str));
    args.push("--json");
    let reports = json(&mocap(&args));
    let report = &reports[0];
    assert_eq!(report["sensors"].as_array().unwrap().len(), 3);
    let rows = report["rows"].as_array().unwrap();
    let std_of = |name: &str| {
        rows.iter()
            .find(|r| r["source"] == name)
            .unwrap_or_else(|| panic!("no row {name}: {rows:?}"))["bone_std_mm"]
            .as_f64()
            .unwrap()
    };
    let best_single = (0..3)
        .map(|k| std_of(&format!("sensor {k}")))
        .fold(f64::MAX, f64::min);
    let fused = std_of("fused (best)");
    eprintln!("bone length std: best single sensor {best_single:.1} mm, fused {fused:.1} mm");
    assert!(fused < best_single, "{fused} vs {best_single}");
}

#[test]
fn eval_on_a_bvh_take_compares_methods_with_the_truth() {
    let plots = tempfile::tempdir().unwrap();
    let markdown = plots.path().join("eval.md");
    let out = mocap(&[
        "fuse",
        "eval",
        &sample(),
        "--sensors",
        "3",
        "--seeds",
        "1",
        "--json",
        "--markdown",
        &s(&markdown),
        "--plots",
        plots.path().to_str().unwrap(),
    ]);
    let report = json(&out);
    // The Markdown tables go to their file, the JSON to standard output.
    let tables = std::fs::read_to_string(&markdown).unwrap();
    assert!(tables.starts_with("Command: `mocap fuse eval "), "{tables}");
    assert!(tables.contains("| sensors | method |"), "{tables}");
    let results = report["results"].as_array().unwrap();
    // Per-joint errors average to the method's MPJPE, and are drawn.
    for r in results {
        let per_joint: Vec<f64> = r["per_joint_mm"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(per_joint.len(), 25);
        let mean = per_joint.iter().sum::<f64>() / 25.0;
        assert!((mean - r["mpjpe_mm"].as_f64().unwrap()).abs() < 1e-6);
    }
    for extension in ["png", "svg"] {
        let plot = plots
            .path()
            .join(format!("per-joint-3-sensors.{extension}"));
        assert!(
            std::fs::metadata(&plot).unwrap().len() > 1000,
            "{}",
            plot.display()
        );
    }
    let mpjpe = |prefix: &str| {
        results
            .iter()
            .find(|r| r["method"].as_str().unwrap().starts_with(prefix))
            .unwrap()["mpjpe_mm"]
            .as_f64()
            .unwrap()
    };
    assert!(mpjpe("best:") < mpjpe("state only (report baseline)"));
}

#[test]
fn errors_name_the_problem() {
    let (dir, sim) = simulated(&[]);
    // A calibration without sensor 2.
    let partial = dir.path().join("partial.toml");
    let text = std::fs::read_to_string(sim.join("truth.calib.toml")).unwrap();
    let cut = text.find("[[sensor]]\nid = 2").unwrap();
    std::fs::write(&partial, &text[..cut]).unwrap();
    let mut args = vec!["fuse".to_string(), "run".into()];
    args.extend(recordings(&sim));
    args.extend(
        [
            "--calib",
            &s(&partial),
            "-o",
            &s(&dir.path().join("x.jsonl")),
        ]
        .map(String::from),
    );
    let out = mocap(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("no pose for sensor(s) 2"),
        "{}",
        stderr(&out)
    );
    // An output of unknown type.
    let out = mocap(&[
        "fuse",
        "run",
        &recordings(&sim)[0],
        "--calib",
        &s(&sim.join("truth.calib.toml")),
        "-o",
        &s(&dir.path().join("x.csv")),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains(".jsonl"), "{}", stderr(&out));
    // A bad recording line.
    let bad = dir.path().join("bad.jsonl");
    std::fs::write(&bad, "{\"sensor\":0}\n").unwrap();
    let out = mocap(&[
        "fuse",
        "measure",
        &s(&bad),
        "-o",
        &s(&dir.path().join("b.json")),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("bad.jsonl:1:"), "{}", stderr(&out));
    // An unknown method is a usage error.
    let out = mocap(&[
        "fuse",
        "run",
        &recordings(&sim)[0],
        "--calib",
        "c.toml",
        "-o",
        "x.jsonl",
        "--method",
        "magic",
    ]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn one_sensors_recording_is_a_motion_for_info_render_and_convert() {
    let dir = tempfile::tempdir().unwrap();
    let sim = dir.path().join("sim");
    let out = mocap(&[
        "fuse",
        "simulate",
        &sample(),
        "--sensors",
        "2",
        "--ntu",
        "-o",
        &s(&sim),
        "--json",
    ]);
    let report = json(&out);
    let ntu: Vec<String> = report["files"]["ntu"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_str().unwrap().to_string())
        .collect();
    assert_eq!(ntu.len(), 2);
    assert!(ntu[0].ends_with(".skeleton"), "{ntu:?}");
    let frames = report["sensors"][0]["frames"].as_u64().unwrap();

    // `mocap info` of one NTU file: the Kinect v2 skeleton at 30 fps.
    let out = mocap(&["info", &ntu[0]]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Kinect"), "{text}");
    assert!(text.contains("30.000 fps"), "{text}");
    let info = json(&mocap(&["info", &ntu[0], "--json"]));
    assert_eq!(info[0]["rig"], "Kinect v2");
    // At least every frame the sensor kept (dropped ones are held).
    assert!(info[0]["frames"].as_u64().unwrap() >= frames, "{info}");

    // ... drawn as a filmstrip.
    let png = dir.path().join("x.png");
    let out = mocap(&["render", &ntu[0], "-o", &s(&png)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG"), "not a PNG");

    // One sensor's JSON lines recording, as `fuse simulate` writes it, and
    // the same sensor's NTU file, on the same grid.
    let jsonl = s(&sim.join("sensor-0.jsonl"));
    let out = mocap(&["info", &jsonl]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("Kinect"));
    let from_jsonl = json(&mocap(&["info", &jsonl, "--json"]));
    assert_eq!(from_jsonl[0]["frames"], info[0]["frames"]);

    // Written as BVH by `mocap convert`.
    let bvh = dir.path().join("sensor-0.bvh");
    let out = mocap(&["convert", &jsonl, &s(&bvh)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let back = json(&mocap(&["info", &s(&bvh), "--json"]));
    assert_eq!(back[0]["frames"], info[0]["frames"]);

    // Several sensors in one file: refused, naming them and `fuse run`.
    let both = dir.path().join("both.jsonl");
    let text = [0, 1]
        .map(|k| std::fs::read_to_string(sim.join(format!("sensor-{k}.jsonl"))).unwrap())
        .concat();
    std::fs::write(&both, text).unwrap();
    let out = mocap(&["info", &s(&both)]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("both.jsonl") && err.contains("ids 0, 1"),
        "{err}"
    );
    assert!(err.contains("mocap fuse run"), "{err}");

    // A file of no known type names the recordings among what is expected.
    let out = mocap(&["info", &s(&sim.join("sensor-0.ply"))]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("unknown motion file type"), "{err}");
    assert!(err.contains(".skeleton or .jsonl"), "{err}");
}

/// The simulator's NTU files, edited as a real NTU triple goes wrong.
fn ntu_files(sim: &Path) -> Vec<PathBuf> {
    (0..3)
        .map(|k| sim.join(format!("S001C{k:03}P001R001A001.skeleton")))
        .collect()
}

#[test]
fn run_says_what_it_made_of_ntu_files() {
    let (dir, sim) = simulated(&["--ntu"]);
    let files = ntu_files(&sim);
    // C000: a bystander, standing still, listed first in every frame.
    let mut zero = mocap_fuse::read_ntu_skeleton(&files[0]).unwrap();
    let first = zero.iter().flatten().next().unwrap().clone();
    let bystander = mocap_fuse::NtuBody {
        body_id: 7,
        joints: first.joints.map(|j| mocap_fuse::JointObservation {
            position: j.position + mocap_core::rotation::Vec3::new(1.5, 0.0, 0.3),
            ..j
        }),
    };
    for bodies in zero.iter_mut() {
        bodies.insert(0, bystander.clone());
    }
    mocap_fuse::write_ntu_bodies(&files[0], &zero).unwrap();
    // C001 started 2 frames late; C002 misses frames 30-39 and ends a
    // frame early.
    let mut one = mocap_fuse::read_ntu_skeleton(&files[1]).unwrap();
    one.drain(..2);
    mocap_fuse::write_ntu_bodies(&files[1], &one).unwrap();
    let mut two = mocap_fuse::read_ntu_skeleton(&files[2]).unwrap();
    for bodies in two[30..40].iter_mut() {
        bodies.clear();
    }
    two.pop();
    mocap_fuse::write_ntu_bodies(&files[2], &two).unwrap();

    let fused = dir.path().join("fused.jsonl");
    let run = |extra: &[&str]| {
        let mut args = vec!["fuse".to_string(), "run".into()];
        args.extend(files.iter().map(|f| s(f)));
        args.extend(
            [
                "--calib",
                &s(&sim.join("truth.calib.toml")),
                "--body",
                &s(&sim.join("body.json")),
                "-o",
                &s(&fused),
            ]
            .map(String::from),
        );
        args.extend(extra.iter().map(|a| a.to_string()));
        mocap(&args.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let out = run(&[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let notes = stderr(&out);
    assert!(
        notes
            .contains("note: C000: 2 people in view; kept body 72057594037927936 as the performer"),
        "{notes}"
    );
    assert!(notes.contains(", dropped 7 ("), "{notes}");
    assert!(notes.contains("note: C001 shifted +"), "{notes}");
    assert!(notes.contains("to match C000, correlation"), "{notes}");
    let gaps = notes
        .lines()
        .find(|l| l.starts_with("note: C002: no performer in"))
        .unwrap_or_else(|| panic!("{notes}"));
    // Frames 30-39 are a run (from 29 when the sensor dropped that one).
    assert!(gaps.contains("30-39") || gaps.contains("29-39"), "{gaps}");
    assert!(
        notes.contains(&format!(
            "note: the NTU files have different frame counts: C000 {}, C001 {}, C002 {}",
            zero.len(),
            one.len(),
            two.len()
        )),
        "{notes}"
    );
    assert!(
        !notes.contains("warning:"),
        "the same person everywhere: {notes}"
    );
    // The same in the JSON report.
    let report = json(&run(&["--json"]));
    let offset = &report["recordings"]["time_offsets"][0];
    assert_eq!(offset["sensor"], 1);
    let frames = offset["frames"].as_f64().unwrap();
    assert!((1.0..3.0).contains(&frames), "{offset}");
    assert_eq!(
        report["same_person"]["sensors"].as_array().unwrap().len(),
        3
    );
    // Offsets switched off, or given; the input frame rate.
    let out = run(&["--time-offsets", "off"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("shifted"), "{}", stderr(&out));
    let out = run(&["--time-offsets", "0,2,0", "--input-fps", "30"]);
    assert!(
        stderr(&out).contains("note: C001 shifted +2.0 frames (66.7 ms) as given"),
        "{}",
        stderr(&out)
    );
    let out = run(&["--time-offsets", "0,2"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("2 time offsets given for 3 recordings"),
        "{}",
        stderr(&out)
    );
    let out = run(&["--time-offsets", "0,two"]);
    assert_eq!(out.status.code(), Some(2), "a wrong command line");
    let out = run(&["--input-fps", "0"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("input frame rate must be positive"));
}

#[test]
fn the_same_camera_or_file_twice_is_refused() {
    let (dir, sim) = simulated(&["--ntu"]);
    let files = ntu_files(&sim);
    let other_take = dir.path().join("S001C001P001R002A001.skeleton");
    std::fs::copy(&files[1], &other_take).unwrap();
    let rig = s(&dir.path().join("rig.toml"));
    let out = mocap(&[
        "fuse",
        "calibrate",
        &s(&files[0]),
        &s(&files[1]),
        &s(&other_take),
        "-o",
        &rig,
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("S001C001P001R001A001.skeleton and")
            && err.contains("S001C001P001R002A001.skeleton are both sensor 1"),
        "{err}"
    );
    let out = mocap(&[
        "fuse",
        "measure",
        &s(&files[0]),
        &s(&files[0]),
        "-o",
        &s(&dir.path().join("body.json")),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("S001C000P001R001A001.skeleton is given twice"));
    // One take's cameras calibrate, with what reading them did on stderr.
    let out = mocap(&[
        "fuse",
        "calibrate",
        &s(&files[0]),
        &s(&files[1]),
        &s(&files[2]),
        "-o",
        &rig,
        "--input-fps",
        "30",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("to match C000"), "{}", stderr(&out));
}
