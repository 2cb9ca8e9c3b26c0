//! The feet stage measured on real clips (`bench/feet.sh`, figures in
//! `bench/results/feet.md`): planted-foot sliding, feet below the floor and
//! jitter before and after `plant_feet`, one Markdown row per clip.
//!
//! ```text
//! cargo run --release -p mocap-feet --example feet_bench -- [--drag V] [--wobble A] FILE_OR_FOLDER...
//! ```
//!
//! `--drag V` first drags the root sideways at V leg lengths per second
//! (0.5 is 40 cm/s on the Bandai rig): the planted feet slide, as a
//! restyled output's do. `--wobble A` moves it sideways by A leg lengths at
//! 2 Hz instead. A clip whose body parts are not found is listed with the
//! reason.

use std::path::PathBuf;

use mocap_core::bodymap::BodyMap;
use mocap_core::io::{find_files, read_motion};
use mocap_core::metrics::up_axis;
use mocap_core::rotation::Vec3;
use mocap_core::{forward_kinematics, Motion};
use mocap_feet::{plant_feet, FeetOptions, FeetReport};

enum Perturb {
    None,
    Drag(f32),
    Wobble(f32),
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut perturb = Perturb::None;
    let mut inputs = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--drag" => perturb = Perturb::Drag(args.next().ok_or("--drag V")?.parse()?),
            "--wobble" => perturb = Perturb::Wobble(args.next().ok_or("--wobble A")?.parse()?),
            _ => inputs.push(PathBuf::from(a)),
        }
    }
    let files = find_files(&inputs, &["bvh", "amc"])?;
    println!(
        "| clip | frames | contacts L/R | sliding before → after (% leg/s) | below floor: frames, deepest (% leg) before → after | jitter before → after | largest move (% leg) | root lowered: frames, most (% leg) |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    let mut sums = [0.0f64; 4];
    let mut count = 0;
    for path in files {
        let name = path
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let row = (|| -> Result<FeetReport, Box<dyn std::error::Error>> {
            let mut motion = read_motion(&path)?;
            let map = BodyMap::detect(motion.skeleton())?;
            perturbed(&mut motion, &map, &perturb)?;
            Ok(plant_feet(&motion, &map, &FeetOptions::default())?.1)
        })();
        match row {
            Ok(r) => {
                let leg = r.before.leg_length as f64;
                let pct = |v: f64| 100.0 * v / leg;
                println!(
                    "| {name} | {} | {}/{} | {:.1} → {:.1} | {}, {:.1} → {}, {:.1} | {:.4} → {:.4} ({:+.1}%) | {:.1} | {}, {:.1} |",
                    r.frames,
                    r.feet[0].contacts,
                    r.feet[1].contacts,
                    pct(r.before.sliding),
                    pct(r.after.sliding),
                    r.before.below_floor.frames_below,
                    pct(r.before.below_floor.max_depth as f64),
                    r.after.below_floor.frames_below,
                    pct(r.after.below_floor.max_depth as f64),
                    r.before.jitter,
                    r.after.jitter,
                    100.0 * (r.after.jitter / r.before.jitter - 1.0),
                    pct(r.largest_joint_move as f64),
                    r.root_lowered_frames,
                    pct(r.max_root_drop as f64),
                );
                sums[0] += pct(r.before.sliding);
                sums[1] += pct(r.after.sliding);
                sums[2] += r.before.jitter as f64 / leg;
                sums[3] += r.after.jitter as f64 / leg;
                count += 1;
            }
            Err(e) => {
                // The first clause says why (the body parts are not found...).
                let e = e.to_string();
                let why = e.split(": the closest").next().unwrap_or(&e);
                println!("| {name} | – | not measured: {why} | | | | | |")
            }
        }
    }
    if count > 0 {
        let c = count as f64;
        println!(
            "\nMean over {count} clips: sliding {:.2} → {:.2} % leg/s; jitter {:+.1}%",
            sums[0] / c,
            sums[1] / c,
            100.0 * (sums[3] / sums[2] - 1.0)
        );
    }
    Ok(())
}

/// The root moved sideways (perpendicular to up and to the take's travel).
fn perturbed(
    motion: &mut Motion,
    map: &BodyMap,
    perturb: &Perturb,
) -> Result<(), Box<dyn std::error::Error>> {
    if matches!(perturb, Perturb::None) {
        return Ok(());
    }
    let pelvis = map.require(mocap_core::bodymap::BodyPart::Pelvis)?;
    let head = map.require(mocap_core::bodymap::BodyPart::Head)?;
    let poses = forward_kinematics(motion);
    let up = up_axis(&poses, pelvis, head);
    let leg = map.leg_length(motion.skeleton())?;
    let side = if up.x.abs() > 0.5 { Vec3::Z } else { Vec3::X };
    let root = 0;
    if !motion.skeleton().joint(root).has_position_channels() {
        return Err("the root has no position channels".into());
    }
    let fps = motion.fps() as f32;
    for f in 0..motion.frame_count() {
        let t = f as f32 / fps;
        let amount = match perturb {
            Perturb::Drag(v) => v * leg * t,
            Perturb::Wobble(a) => a * leg * (std::f32::consts::TAU * 2.0 * t).sin(),
            Perturb::None => 0.0,
        };
        let p = motion.local_translation(f, root);
        motion.set_local_translation(f, root, p + side * amount);
    }
    Ok(())
}
