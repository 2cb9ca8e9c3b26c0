//! Speed and peak memory of the BVH reader on a large file.
//!
//! ```text
//! cargo run --release -p mocap-core --example bvh_peak_memory -- [FILE.bvh | DIR] [--mb 300] [--runs 3]
//! ```
//!
//! With a file, parses it; with a folder, parses every `.bvh` file in it one
//! after the other (to compare with tools that are too slow or too hungry
//! for one large file, e.g. `bench/bvhio_parse.py` on the same folder).
//! Without either, writes a synthetic take of about
//! `--mb` megabytes (default 300) to a temporary file by repeating the frame
//! lines of the longest Bandai take in `bandai/dataset-1` of the shared data
//! (found as in the tests, by `mocap_testdata::shared`),
//! then parses that. Prints the file size, the parse time, the throughput and
//! the peak resident memory of the parse (`VmHWM` from `/proc/self/status`,
//! reset before the parse through `/proc/self/clear_refs` where the kernel
//! allows it).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use mocap_core::io::bvh::read_bvh;

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let mut file: Option<PathBuf> = None;
    let mut target_mb: u64 = 300;
    let mut runs: usize = 3;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--mb" => target_mb = args.next().ok_or("--mb needs a number")?.parse()?,
            "--runs" => runs = args.next().ok_or("--runs needs a number")?.parse()?,
            _ => file = Some(PathBuf::from(arg)),
        }
    }

    // Kept alive until the end so that the temporary file is not deleted.
    let _temporary;
    let path = match file {
        Some(p) => p,
        None => {
            let source = longest_bandai_take()?;
            let tmp = tempfile::Builder::new().suffix(".bvh").tempfile()?;
            let started = Instant::now();
            let frames = write_synthetic(&source, tmp.path(), target_mb * 1_000_000)?;
            println!(
                "synthetic file: {frames} frames from {} repeated, written in {:.1} s",
                source.display(),
                started.elapsed().as_secs_f64()
            );
            let path = tmp.path().to_path_buf();
            _temporary = tmp;
            path
        }
    };

    let files = if path.is_dir() {
        mocap_testdata::bvh_files(&path)
    } else {
        vec![path.clone()]
    };
    let mut size = 0;
    for file in &files {
        size += std::fs::metadata(file)?.len();
    }
    println!(
        "{}: {} file(s), {:.1} MB",
        path.display(),
        files.len(),
        size as f64 / 1e6
    );
    println!("peak RSS before parsing: {:.1} MB", peak_rss_mb()?);
    for run in 1..=runs {
        let reset = reset_peak_rss();
        let started = Instant::now();
        let (mut frames, mut values_bytes, mut channels) = (0, 0, 0);
        for file in &files {
            let motion = read_bvh(file)?;
            frames += motion.frame_count();
            values_bytes += std::mem::size_of_val(motion.values());
            channels = motion.skeleton().channel_count();
        }
        let seconds = started.elapsed().as_secs_f64();
        let peak = peak_rss_mb()?;
        println!(
            "run {run}: {frames} frames x {channels} channels in {seconds:.3} s = {:.0} MB/s; \
             values {:.1} MB; peak RSS {peak:.1} MB{} = {:.2} x file size",
            size as f64 / 1e6 / seconds,
            values_bytes as f64 / 1e6,
            if reset { "" } else { " (since start)" },
            peak / (size as f64 / 1e6),
        );
    }
    Ok(())
}

/// The dataset-1 take with the most bytes.
fn longest_bandai_take() -> Result<PathBuf, Box<dyn std::error::Error>> {
    let dir = mocap_testdata::shared("bandai/dataset-1").ok_or("no shared data")?;
    let mut best: Option<(u64, PathBuf)> = None;
    for path in mocap_testdata::bvh_files(&dir) {
        let len = std::fs::metadata(&path)?.len();
        if best.as_ref().is_none_or(|(l, _)| len > *l) {
            best = Some((len, path));
        }
    }
    Ok(best.ok_or("no BVH file in bandai/dataset-1")?.1)
}

/// Writes the source's hierarchy, then its frame lines over and over until
/// the file reaches `target_bytes`; returns the number of frames.
fn write_synthetic(
    source: &Path,
    out: &Path,
    target_bytes: u64,
) -> Result<usize, Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(source)?;
    let mut lines = text.lines();
    let mut header = Vec::new();
    for line in lines.by_ref() {
        let word = line.split_whitespace().next().unwrap_or("");
        if word.eq_ignore_ascii_case("Frames:") {
            continue; // rewritten below with the new count
        }
        header.push(line);
        if line.trim_start().starts_with("Frame Time") {
            break;
        }
    }
    let frames: Vec<&str> = lines.filter(|l| !l.trim().is_empty()).collect();
    let cycle_bytes: u64 = frames.iter().map(|l| l.len() as u64 + 1).sum();
    if cycle_bytes == 0 {
        return Err(format!("{}: no frame lines", source.display()).into());
    }
    let cycles = target_bytes.div_ceil(cycle_bytes) as usize;
    let total = cycles * frames.len();

    let mut w = BufWriter::with_capacity(1 << 20, File::create(out)?);
    for line in &header {
        if line.trim_start().starts_with("Frame Time") {
            writeln!(w, "Frames:\t{total}")?;
        }
        writeln!(w, "{line}")?;
    }
    for _ in 0..cycles {
        for line in &frames {
            writeln!(w, "{line}")?;
        }
    }
    w.flush()?;
    Ok(total)
}

/// Peak resident set size of this process in MB (`VmHWM`).
fn peak_rss_mb() -> Result<f64, Box<dyn std::error::Error>> {
    let status = std::fs::read_to_string("/proc/self/status")?;
    let line = status
        .lines()
        .find(|l| l.starts_with("VmHWM:"))
        .ok_or("no VmHWM in /proc/self/status")?;
    let kb: f64 = line
        .split_whitespace()
        .nth(1)
        .ok_or("VmHWM without a value")?
        .parse()?;
    Ok(kb * 1024.0 / 1e6)
}

/// Resets `VmHWM` to the current RSS (Linux 4.0+); `false` if not allowed.
fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}
