//! Soak test of `mocap fuse serve` (not in CI; `bench/soak_fuse_serve.sh`
//! runs it): N senders at 30 Hz for S seconds on loopback, each replaying
//! one sensor of a simulated capture (looped, on a fresh clock), and 1% of
//! extra datagrams that are garbage or hostile. The server's resident
//! memory is read from /proc every few seconds; at the end its report is
//! checked against what was sent: every frame that arrived in time was
//! accepted, every bad datagram counted where it belongs. Prints a Markdown
//! summary; exits with 1 when a check fails.
//!
//! ```text
//! mocap fuse simulate take.bvh --sensors 8 -o sim/
//! cargo run --release -p mocap-fuse --example soak_serve -- MOCAP_BINARY sim/ [SENDERS=8] [SECONDS=600]
//! ```

use std::io::{BufRead, BufReader};
use std::net::UdpSocket;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use mocap_fuse::{encode_datagram, read_recording, SensorFrame};

/// What one sender sent.
#[derive(Default, Clone, Copy)]
struct Sent {
    frames: u64,
    malformed: u64,
    implausible_time: u64,
    implausible_frames: u64,
}

/// The bad datagram number `k`: four kinds of garbage (random bytes, a
/// wrong magic, cut JSON, a frame of 24 joints) and two of well-formed
/// nonsense (a time of 1e30 s, every joint at 1e30 m).
fn bad_datagram(k: u64, frame: &SensorFrame, sent: &mut Sent) -> Vec<u8> {
    let good = encode_datagram(frame);
    match k % 6 {
        0 => {
            sent.malformed += 1;
            (0..200u64)
                .map(|i| (i.wrapping_mul(2654435761).wrapping_add(k) >> 7) as u8)
                .collect()
        }
        1 => {
            sent.malformed += 1;
            let mut d = good;
            d[..4].copy_from_slice(b"MCF9");
            d
        }
        2 => {
            sent.malformed += 1;
            good[..good.len() / 2].to_vec()
        }
        3 => {
            sent.malformed += 1;
            let text = String::from_utf8(good).unwrap();
            let cut = text.rfind(",[").unwrap();
            format!("{}]}}", &text[..cut]).into_bytes()
        }
        4 => {
            sent.implausible_time += 1;
            let mut f = frame.clone();
            f.seq += 1 << 40;
            f.timestamp = 1e30;
            encode_datagram(&f)
        }
        _ => {
            sent.implausible_frames += 1;
            let mut f = frame.clone();
            f.seq += 1 << 41;
            for j in f.joints.iter_mut() {
                j.position = mocap_core::rotation::Vec3::splat(1e30);
            }
            encode_datagram(&f)
        }
    }
}

fn rss_kib(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: soak_serve MOCAP_BINARY SIM_DIR [SENDERS=8] [SECONDS=600]";
    let mocap = PathBuf::from(args.first().ok_or(usage)?);
    let sim = PathBuf::from(args.get(1).ok_or(usage)?);
    let senders: usize = args.get(2).map_or(Ok(8), |s| s.parse())?;
    let seconds: f64 = args.get(3).map_or(Ok(600.0), |s| s.parse())?;
    let period = 1.0 / 30.0;

    // Each sensor's frames looped to cover the duration, on a fresh clock.
    let streams: Vec<Vec<SensorFrame>> = (0..senders)
        .map(
            |k| -> Result<Vec<SensorFrame>, Box<dyn std::error::Error>> {
                let frames = read_recording(&sim.join(format!("sensor-{k}.jsonl")))?;
                let phase = frames[0].timestamp.rem_euclid(period);
                let n = (seconds * 30.0) as usize;
                Ok((0..n)
                    .map(|i| {
                        let mut f = frames[i % frames.len()].clone();
                        f.seq = i as u64;
                        f.timestamp = phase + i as f64 * period;
                        f.arrival = Some(f.timestamp);
                        f
                    })
                    .collect())
            },
        )
        .collect::<Result<_, _>>()?;

    let out = std::env::temp_dir().join(format!("soak-{}.jsonl", std::process::id()));
    let mut server = Command::new(&mocap)
        .args(["fuse", "serve", "--calib"])
        .arg(sim.join("truth.calib.toml"))
        .arg("--body")
        .arg(sim.join("body.json"))
        .args([
            "--listen",
            "127.0.0.1:0",
            "--idle-exit",
            "2",
            "--json",
            "-o",
        ])
        .arg(&out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()?;
    let pid = server.id();
    let mut lines = BufReader::new(server.stderr.take().ok_or("no stderr")?).lines();
    let addr = loop {
        let line = lines
            .next()
            .ok_or("the server stopped before listening")??;
        if let Some(rest) = line.split("listening on ").nth(1) {
            break rest
                .split_whitespace()
                .next()
                .ok_or("no address")?
                .to_string();
        }
    };
    let log = std::thread::spawn(move || lines.map_while(Result::ok).collect::<Vec<_>>());

    // Memory, every five seconds while the senders run.
    let done = Arc::new(AtomicBool::new(false));
    let started = Instant::now();
    let sampler = {
        let done = done.clone();
        std::thread::spawn(move || {
            let mut samples = Vec::new();
            while !done.load(Ordering::Relaxed) {
                if let Some(kib) = rss_kib(pid) {
                    samples.push((started.elapsed().as_secs_f64(), kib));
                }
                for _ in 0..50 {
                    if done.load(Ordering::Relaxed) {
                        break;
                    }
                    std::thread::sleep(Duration::from_millis(100));
                }
            }
            samples
        })
    };

    // The senders: frame i of every stream at start + i periods, and after
    // every 100th frame one bad datagram.
    let handles: Vec<_> = streams
        .into_iter()
        .map(|stream| {
            let addr = addr.clone();
            std::thread::spawn(move || -> std::io::Result<Sent> {
                let socket = UdpSocket::bind("127.0.0.1:0")?;
                let mut sent = Sent::default();
                let t0 = stream[0].timestamp;
                for (i, f) in stream.iter().enumerate() {
                    let due = started + Duration::from_secs_f64(f.timestamp - t0);
                    std::thread::sleep(due.saturating_duration_since(Instant::now()));
                    socket.send_to(&encode_datagram(f), &addr)?;
                    sent.frames += 1;
                    if i % 100 == 99 {
                        let bad = bad_datagram(i as u64 / 100, f, &mut sent);
                        socket.send_to(&bad, &addr)?;
                    }
                }
                Ok(sent)
            })
        })
        .collect();
    let mut sent = Sent::default();
    for h in handles {
        let s = h.join().map_err(|_| "a sender panicked")??;
        sent.frames += s.frames;
        sent.malformed += s.malformed;
        sent.implausible_time += s.implausible_time;
        sent.implausible_frames += s.implausible_frames;
    }
    let sending = started.elapsed().as_secs_f64();
    done.store(true, Ordering::Relaxed);
    let samples = sampler.join().map_err(|_| "the sampler panicked")?;
    let output = server.wait_with_output()?;
    let log = log.join().map_err(|_| "the log reader panicked")?;
    let report: serde_json::Value = serde_json::from_slice(&output.stdout)
        .map_err(|e| format!("the server's report is not JSON ({e}): {log:?}"))?;
    let server_report = &report["server"];
    let count = |key: &str| server_report[key].as_u64().unwrap_or(u64::MAX);
    let written = std::fs::read_to_string(&out).map_or(0, |t| t.lines().count());
    let _ = std::fs::remove_file(&out);

    let bad = sent.malformed + sent.implausible_time + sent.implausible_frames;
    let mut failures = Vec::new();
    let mut check = |ok: bool, what: String| {
        if !ok {
            failures.push(what);
        }
    };
    check(
        count("datagrams") == sent.frames + bad,
        format!(
            "{} datagrams received of {} sent",
            count("datagrams"),
            sent.frames + bad
        ),
    );
    check(
        count("frames_accepted") + count("late") == sent.frames,
        format!(
            "{} frames accepted and {} late of {} sent: frames lost",
            count("frames_accepted"),
            count("late"),
            sent.frames
        ),
    );
    for (key, expected) in [
        ("malformed", sent.malformed),
        ("implausible_time", sent.implausible_time),
        ("implausible_frames", sent.implausible_frames),
        ("duplicates", 0),
        ("overflow", 0),
        ("uncalibrated", 0),
    ] {
        check(
            count(key) == expected,
            format!("{key}: {} (expected {expected})", count(key)),
        );
    }
    let expected_fused = (seconds * 30.0) as u64;
    check(
        count("fused_frames") + 2 >= expected_fused && count("fused_frames") <= expected_fused + 1,
        format!(
            "{} fused frames for {expected_fused} instants",
            count("fused_frames")
        ),
    );
    check(
        written as u64 == count("fused_frames"),
        format!(
            "{written} lines written for {} fused frames",
            count("fused_frames")
        ),
    );

    let at = |fraction: f64| -> (f64, u64) {
        let i = ((samples.len().saturating_sub(1)) as f64 * fraction).round() as usize;
        samples.get(i).copied().unwrap_or((0.0, 0))
    };
    let peak = samples.iter().map(|s| s.1).max().unwrap_or(0);
    println!("## Soak: `mocap fuse serve`, {senders} senders at 30 Hz for {seconds} s, 1% bad datagrams\n");
    println!("| | |\n| --- | --- |");
    for (name, fraction) in [("start", 0.0), ("middle", 0.5), ("end", 1.0)] {
        let (t, kib) = at(fraction);
        println!(
            "| RSS at {name} ({t:.0} s) | {:.1} MiB |",
            kib as f64 / 1024.0
        );
    }
    println!("| RSS peak | {:.1} MiB |", peak as f64 / 1024.0);
    println!("| RSS samples | {} (every 5 s) |", samples.len());
    println!("| sending took | {sending:.1} s |");
    println!(
        "| frames sent / accepted / late | {} / {} / {} |",
        sent.frames,
        count("frames_accepted"),
        count("late")
    );
    println!(
        "| bad datagrams sent: malformed / time 1e30 / joints at 1e30 | {} / {} / {} |",
        sent.malformed, sent.implausible_time, sent.implausible_frames
    );
    println!(
        "| server counted: malformed / implausible time / implausible frames | {} / {} / {} |",
        count("malformed"),
        count("implausible_time"),
        count("implausible_frames")
    );
    println!(
        "| fused frames (expected {expected_fused}) / lines written | {} / {written} |",
        count("fused_frames")
    );
    println!(
        "| latency median / p99 / max | {:.1} / {:.1} / {:.1} ms |",
        server_report["latency_median_ms"]
            .as_f64()
            .unwrap_or(f64::NAN),
        server_report["latency_p99_ms"].as_f64().unwrap_or(f64::NAN),
        server_report["latency_max_ms"].as_f64().unwrap_or(f64::NAN)
    );
    println!("| server stderr lines | {} |", log.len());
    println!(
        "\nRSS over time (s, MiB): {}",
        samples
            .iter()
            .step_by((samples.len() / 12).max(1))
            .map(|(t, kib)| format!("{t:.0}: {:.1}", *kib as f64 / 1024.0))
            .collect::<Vec<_>>()
            .join(", ")
    );
    println!(
        "\nThe server writes JSON lines only (a BVH output keeps the take in memory \
         to fit its skeleton at the end, by design). The largest latency is that of \
         the last instants, fused when the server stops after 2 s without a datagram."
    );
    if failures.is_empty() {
        println!("\nAll checks passed.");
        Ok(())
    } else {
        println!("\nFailed:\n- {}", failures.join("\n- "));
        std::process::exit(1);
    }
}
