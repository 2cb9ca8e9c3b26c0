//! The Rust side of `bench/python/run.sh`: forward kinematics of a whole take
//! with the core's front door (`mocap_core::forward_kinematics`: global
//! positions and rotations of every frame), best of `RUNS` runs, after the
//! file is read (reading is not timed). Prints one JSON line.
//!
//! `cargo run --release -p mocap-py --example fk_timing -- TAKE.bvh [RUNS]`

use std::path::PathBuf;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = PathBuf::from(args.next().ok_or("usage: fk_timing TAKE.bvh [RUNS]")?);
    let runs: usize = args.next().map_or(Ok(5), |r| r.parse())?;
    let motion = mocap_core::io::read_motion(&path)?;
    let mut best = f64::INFINITY;
    let mut checksum = 0.0f64;
    for _ in 0..runs.max(1) {
        let start = Instant::now();
        let poses = mocap_core::forward_kinematics(&motion);
        best = best.min(start.elapsed().as_secs_f64());
        checksum = poses.positions.iter().map(|p| p.x as f64).sum();
    }
    println!(
        "{{\"frames\": {}, \"joints\": {}, \"seconds\": {best}, \"checksum\": {checksum}}}",
        motion.frame_count(),
        motion.skeleton().joint_count()
    );
    Ok(())
}
