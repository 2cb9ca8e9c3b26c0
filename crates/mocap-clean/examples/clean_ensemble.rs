//! Study: does averaging the shipped model's output over symmetric copies of
//! the take (played backwards, mirrored left to right) lower its error?
//!
//! The noise is symmetric in time and across the body, the model is not
//! quite, so its mistakes on the copies are partly independent and an
//! average of the copies' outputs (mapped back) may be closer to the truth.
//! Validation takes with the spike studies' noise (level drawn in 0-10
//! degrees, 1-3 spikes), spikes found and bridged first as `mocap clean
//! --despike` does; and the same takes with the random noise only. Mean
//! rotation error (degrees).
//!
//! cargo run --profile test -p mocap-clean --example clean_ensemble -- DATA [TAKES]
//!
//! Result (session 13): every average is worse than the model alone
//! (bench/results/clean.md, "Averaging over symmetric copies of the take").

mod support;

use mocap_clean::despike::{remove_spikes, DespikeOptions};
use mocap_clean::eval::rotation_error_deg;
use mocap_clean::infer::CleanModel;
use mocap_core::ops::mirror_auto;
use mocap_core::rotation::mean_of_close;
use mocap_core::Motion;
use mocap_nn::device::DeviceChoice;

/// The take played backwards.
fn reversed(motion: &Motion) -> Motion {
    let mut out = motion.clone();
    let n = motion.frame_count();
    for f in 0..n {
        out.frame_mut(f).copy_from_slice(motion.frame(n - 1 - f));
    }
    out
}

/// The frame-by-frame mean of motions on one skeleton: rotations by
/// [`mean_of_close`], root translations by their mean.
fn mean_motion(motions: &[Motion]) -> Motion {
    let mut out = motions[0].clone();
    let skeleton = out.skeleton().clone();
    for f in 0..out.frame_count() {
        for k in 0..skeleton.joint_count() {
            if skeleton.joint(k).has_rotation_channels() {
                let q = mean_of_close(motions.iter().map(|m| m.local_rotation(f, k)));
                out.set_local_rotation(f, k, q);
            }
        }
        let t = motions
            .iter()
            .map(|m| m.local_translation(f, 0))
            .sum::<mocap_core::rotation::Vec3>()
            / motions.len() as f32;
        out.set_local_translation(f, 0, t);
    }
    out
}

/// The model's output on the take, backwards, mirrored, and both (mapped
/// back to the take).
fn copies(model: &CleanModel, take: &Motion) -> Result<[Motion; 4], Box<dyn std::error::Error>> {
    let clean = |m: &Motion| model.clean(m, None);
    let forward = clean(take)?;
    let backward = reversed(&clean(&reversed(take))?);
    let mirrored = mirror_auto(&clean(&mirror_auto(take)?)?)?;
    let both = mirror_auto(&reversed(&clean(&reversed(&mirror_auto(take)?))?))?;
    Ok([forward, backward, mirrored, both])
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = support::parse()?;
    let takes = args.validation_takes()?;
    let model = CleanModel::load_default(DeviceChoice::Cpu)?;
    const ROWS: [&str; 5] = [
        "model",
        "mean with backwards",
        "mean with mirrored",
        "mean of the four copies",
        "backwards alone",
    ];
    // [condition][row] sums of per-take errors.
    let mut sums = [[0.0f64; ROWS.len()]; 2];
    for i in 0..takes.len() {
        let noisy = support::spiked_take(&takes, i, None);
        let truth = &takes[i].motion;
        let spikes_bridged = remove_spikes(&noisy.spiked, &DespikeOptions::default()).0;
        for (c, input) in [&noisy.noisy, &spikes_bridged].into_iter().enumerate() {
            let [f, b, m, fb] = copies(&model, input)?;
            let outputs = [
                f.clone(),
                mean_motion(&[f.clone(), b.clone()]),
                mean_motion(&[f.clone(), m.clone()]),
                mean_motion(&[f, b.clone(), m, fb]),
                b,
            ];
            for (s, out) in sums[c].iter_mut().zip(&outputs) {
                *s += rotation_error_deg(truth, out);
            }
        }
        eprint!("\r{} / {}", i + 1, takes.len());
    }
    eprintln!();
    println!(
        "{} validation takes, level drawn in 0-10 degrees; mean rotation error (degrees).\n",
        takes.len()
    );
    println!("| output | random noise | spikes on random noise, found and bridged first |");
    println!("| --- | ---: | ---: |");
    for (r, row) in ROWS.iter().enumerate() {
        println!(
            "| {row} | {:.3} | {:.3} |",
            sums[0][r] / takes.len() as f64,
            sums[1][r] / takes.len() as f64
        );
    }
    Ok(())
}
