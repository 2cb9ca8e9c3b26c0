//! Core throughput benchmark (run by `bench/core.sh`, which also runs bvhio).
//!
//! Usage: `cargo run --release -p mocap-core --example bench_core -- FILE...`
//!
//! Prints one JSON line: BVH parse and write throughput (MB/s of BVH text,
//! single thread, files read from the page cache after a warm-up pass) and
//! forward-kinematics throughput (joint transforms per second, single thread).
//!
//! Times are CPU time of this thread (`CLOCK_THREAD_CPUTIME_ID`), so that a
//! busy machine does not distort them; bvhio is timed the same way
//! (`time.thread_time()`).

use std::path::PathBuf;

use mocap_core::io::bvh::{read_bvh, write_bvh_to};
use mocap_core::{forward_kinematics, Motion};

fn main() {
    let paths: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    if paths.is_empty() {
        eprintln!("usage: bench_core FILE...");
        std::process::exit(2);
    }
    let bytes: u64 = paths
        .iter()
        .map(|p| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0))
        .sum();

    // Warm-up pass: loads the files into the page cache and keeps the motions.
    let motions: Vec<Motion> = paths
        .iter()
        .map(|p| read_bvh(p).unwrap_or_else(|e| panic!("{e}")))
        .collect();

    let parse_seconds = best_of(3, || {
        for p in &paths {
            std::hint::black_box(read_bvh(p).expect("file parsed before"));
        }
    });

    let mut written = 0usize;
    let write_seconds = best_of(3, || {
        written = 0;
        for m in &motions {
            let mut buffer = Vec::with_capacity(1 << 20);
            write_bvh_to(&mut buffer, m).expect("writing to memory");
            written += buffer.len();
            std::hint::black_box(&buffer);
        }
    });

    let joint_transforms: usize = motions
        .iter()
        .map(|m| m.frame_count() * m.skeleton().joint_count())
        .sum();
    let fk_seconds = best_of(5, || {
        for m in &motions {
            std::hint::black_box(forward_kinematics(m));
        }
    });

    println!(
        "{{\"files\":{},\"bytes\":{},\"frames\":{},\"parse_mb_per_s\":{:.1},\"write_mb_per_s\":{:.1},\"written_bytes\":{},\"fk_joint_transforms\":{},\"fk_transforms_per_s\":{:.0}}}",
        paths.len(),
        bytes,
        motions.iter().map(|m| m.frame_count()).sum::<usize>(),
        bytes as f64 / 1e6 / parse_seconds,
        written as f64 / 1e6 / write_seconds,
        written,
        joint_transforms,
        joint_transforms as f64 / fk_seconds,
    );
}

/// Shortest CPU time of `runs` runs of `work` on this thread, in seconds.
fn best_of(runs: usize, mut work: impl FnMut()) -> f64 {
    (0..runs)
        .map(|_| {
            let start = thread_cpu_seconds();
            work();
            thread_cpu_seconds() - start
        })
        .fold(f64::INFINITY, f64::min)
}

/// CPU time used by the calling thread.
fn thread_cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec for clock_gettime to fill.
    let status = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    assert_eq!(status, 0, "clock_gettime(CLOCK_THREAD_CPUTIME_ID) failed");
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}
