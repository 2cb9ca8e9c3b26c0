//! The shipped denoiser on takes it was not made for, on held-out Bandai
//! test takes with the evaluation's random (markerless) noise, level drawn
//! in 0-10 degrees, seeded per take:
//!
//! - `RIG.bvh`: each take played by another rig (the rig of the file; the
//!   rigs in their canonical T-poses), the noise added
//!   on that rig, and cleaned there by the cross-validated and the 2 Hz
//!   Butterworth, or by the shipped model as `mocap clean apply` runs it on
//!   another rig: played by the Bandai rig, cleaned, the change carried
//!   back onto the take (`Retargeting::carry_change`; joints between two
//!   body parts by the cross-validated Butterworth, other joints untouched).
//!   Also the clean takes through the model (how far it moves a clean
//!   take). Errors over every joint with rotation channels and over the
//!   joints of body parts.
//! - `--fps F`: each take resampled to F frames per second first; the
//!   model reading its frames as they are (what `mocap clean apply` does: the
//!   model reads frames, not seconds), and with the take resampled to the
//!   model's 30 fps and back.
//!
//! cargo run --release -p mocap-studies --example clean_foreign_rig_eval -- DATA (RIG.bvh | --fps F) [TAKES]

use std::path::PathBuf;

use mocap_clean::{
    add_random_noise, filter_motion, list_bvh, load_takes, paths_in_split, CleanModel, Filter,
    ModelFile, RandomNoise, Split, SplitFractions,
};
use mocap_core::bodymap::BodyMap;
use mocap_core::io::bvh::read_bvh;
use mocap_core::metrics::joint_rotation_errors_degrees;
use mocap_core::ops::{resample_fps, resample_frames};
use mocap_core::retarget::Retargeting;
use mocap_core::Motion;
use rand::SeedableRng;

type Error = Box<dyn std::error::Error>;

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "DATA (RIG.bvh | --fps F) [TAKES]";
    let data = PathBuf::from(args.first().ok_or(usage)?);
    let (rig, fps, rest) = match args.get(1).map(String::as_str) {
        Some("--fps") => (None, Some(args.get(2).ok_or(usage)?.parse::<f64>()?), 3),
        Some(path) => (Some(read_bvh(&PathBuf::from(path))?), None, 2),
        None => return Err(usage.into()),
    };
    let count: usize = args.get(rest).map_or(Ok(40), |s| s.parse())?;
    let paths = paths_in_split(
        &list_bvh(std::slice::from_ref(&data))?,
        Split::Test,
        &SplitFractions::default(),
    );
    let takes = load_takes(&paths[..count.min(paths.len())])?;
    let model = ModelFile::Network(Box::new(CleanModel::load_default(Default::default())?));
    // The take as the experiment gives it: on the other rig, or resampled.
    let given = |m: &Motion| -> Result<Motion, Error> {
        Ok(match (&rig, fps) {
            (Some(rig), _) => Retargeting::detect(m.skeleton(), rig.skeleton())?.apply(m)?,
            (None, Some(fps)) => resample_fps(m, fps)?,
            _ => unreachable!(),
        })
    };
    // The shipped model on a given take: a take of another rig goes through
    // the model's own (`mocap_clean`'s `rig` module), as in `mocap clean apply`.
    let through_model = |m: &Motion| -> Result<Motion, Error> { Ok(model.clean(m, None)?.0) };
    let mut labels = vec![
        "noisy input",
        "butterworth(order=2, cutoff=2Hz)",
        "butterworth-gcv(order=2)",
    ];
    labels.push(if rig.is_some() {
        "shipped model through retargeting"
    } else {
        "shipped model reading the frames as they are (mocap clean apply)"
    });
    if fps.is_some() {
        labels.push("shipped model, the take resampled to 30 fps and back");
    }
    labels.push("clean take through the model (moved by)");
    let mut sums = vec![[0.0f64; 2]; labels.len()];
    let mut frames = 0usize;
    let mut description = String::new();
    for (i, take) in takes.iter().enumerate() {
        let clean = given(&take.motion)?;
        let skeleton = clean.skeleton();
        let rotating: Vec<usize> = (0..skeleton.joint_count())
            .filter(|&j| skeleton.joint(j).has_rotation_channels())
            .collect();
        let body: Vec<usize> = BodyMap::detect(skeleton)?
            .parts()
            .map(|(_, j)| j)
            .filter(|&j| skeleton.joint(j).has_rotation_channels())
            .collect();
        let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(0xf0 ^ i as u64);
        let (noisy, _) = add_random_noise(&clean, &RandomNoise::default(), &mut rng);
        let mut outputs = vec![
            noisy.clone(),
            filter_motion(
                &noisy,
                &Filter::Butterworth {
                    order: 2,
                    cutoff_hz: 2.0,
                },
            )?,
            filter_motion(&noisy, &Filter::ButterworthGcv { order: 2 })?,
            through_model(&noisy)?,
        ];
        if fps.is_some() {
            let at_30 = model.clean(&resample_fps(&noisy, 30.0)?, None)?.0;
            outputs.push(resample_frames(&at_30, noisy.frame_count())?);
        }
        outputs.push(through_model(&clean)?);
        let n = clean.frame_count();
        for (sum, out) in sums.iter_mut().zip(&outputs) {
            let e = joint_rotation_errors_degrees(&clean, out)?;
            let mean = |joints: &[usize]| {
                joints.iter().map(|&j| e[j] as f64).sum::<f64>() / joints.len() as f64
            };
            sum[0] += mean(&rotating) * n as f64;
            sum[1] += mean(&body) * n as f64;
        }
        frames += n;
        description = format!(
            "{} joints, {} with rotations, {} of body parts, {:.0} fps",
            skeleton.joint_count(),
            rotating.len(),
            body.len(),
            clean.fps()
        );
    }
    println!(
        "{} Bandai test takes ({frames} frames) {} ({description})\n",
        takes.len(),
        match (&rig, fps) {
            (Some(_), _) => format!("played by the rig of {}", args[1]),
            (None, Some(f)) => format!("resampled to {f} fps"),
            _ => unreachable!(),
        }
    );
    println!("| method | rotation error, all joints (deg) | joints of body parts (deg) |");
    println!("| --- | ---: | ---: |");
    for (label, sum) in labels.iter().zip(&sums) {
        println!(
            "| {label} | {:.3} | {:.3} |",
            sum[0] / frames as f64,
            sum[1] / frames as f64
        );
    }
    Ok(())
}
