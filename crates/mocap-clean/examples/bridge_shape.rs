//! Study: does a curved bridge beat the straight one? Spikes (true, or found
//! by the default finder) on the spike studies' validation takes are bridged
//! by slerp between the frames beside them (as `despike` does) or by a cubic
//! Hermite curve whose ends and end tangents come from straight lines fitted
//! to `k` frames on each side (in the tangent space of the frame before the
//! spike), the tangents blended with the chord's by `lambda` (0: a straight
//! path between the fitted ends), then the shipped model runs.
//!
//! cargo run --profile test -p mocap-clean --example bridge_shape -- DATA [TAKES]

mod support;

use mocap_clean::despike::{bridge_spikes, find_spikes, DespikeOptions, FoundSpike};
use mocap_clean::eval::rotation_error_deg;
use mocap_clean::infer::CleanModel;
use mocap_core::rotation::{Quat, Vec3};
use mocap_core::Motion;
use rayon::prelude::*;

/// The value at `at` and the slope per frame of the least-squares line
/// through `points` (frame, value); a single point gives no slope.
fn line_at(points: &[(f32, Vec3)], at: f32) -> (Vec3, Option<Vec3>) {
    let n = points.len() as f32;
    let mean_t = points.iter().map(|p| p.0).sum::<f32>() / n;
    let mean_v = points.iter().map(|p| p.1).sum::<Vec3>() / n;
    let var: f32 = points.iter().map(|p| (p.0 - mean_t).powi(2)).sum();
    if points.len() < 2 || var == 0.0 {
        return (mean_v, None);
    }
    let slope = points
        .iter()
        .map(|p| (p.0 - mean_t) * (p.1 - mean_v))
        .sum::<Vec3>()
        / var;
    (mean_v + slope * (at - mean_t), Some(slope))
}

fn bridge_hermite(motion: &Motion, spikes: &[FoundSpike], k: usize, lambda: f32) -> Motion {
    let mut out = motion.clone();
    let skeleton = motion.skeleton();
    let frames = motion.frame_count();
    for s in spikes {
        let end = (s.start + s.frames).min(frames);
        if s.start >= end || (s.start == 0 && end == frames) {
            continue;
        }
        for j in skeleton.subtree(s.joint) {
            if !skeleton.joint(j).has_rotation_channels() {
                continue;
            }
            let reference = motion.local_rotation(if s.start > 0 { s.start - 1 } else { end }, j);
            let log = |q: Quat| {
                let d = reference.conjugate() * q;
                let d = if d.w < 0.0 { -d } else { d };
                d.to_scaled_axis()
            };
            let side = |r: std::ops::Range<usize>| -> Vec<(f32, Vec3)> {
                r.map(|f| (f as f32, log(motion.local_rotation(f, j))))
                    .collect()
            };
            let before = side(s.start.saturating_sub(k)..s.start);
            let after = side(end..(end + k).min(frames));
            let (ta, tb) = (s.start as f32 - 1.0, end as f32);
            let fitted_a = (!before.is_empty()).then(|| line_at(&before, ta));
            let fitted_b = (!after.is_empty()).then(|| line_at(&after, tb));
            for f in s.start..end {
                let v = match (fitted_a, fitted_b) {
                    (Some((va, sa)), Some((vb, sb))) => {
                        let span = tb - ta;
                        let chord = (vb - va) / span;
                        let ma = lambda * sa.unwrap_or(chord) + (1.0 - lambda) * chord;
                        let mb = lambda * sb.unwrap_or(chord) + (1.0 - lambda) * chord;
                        let x = (f as f32 - ta) / span;
                        let (x2, x3) = (x * x, x * x * x);
                        va * (2.0 * x3 - 3.0 * x2 + 1.0)
                            + ma * span * (x3 - 2.0 * x2 + x)
                            + vb * (-2.0 * x3 + 3.0 * x2)
                            + mb * span * (x3 - x2)
                    }
                    (Some((v, _)), None) | (None, Some((v, _))) => v,
                    (None, None) => unreachable!("checked above"),
                };
                out.set_local_rotation(f, j, reference * Quat::from_scaled_axis(v));
            }
        }
    }
    out
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = support::parse()?;
    let model = CleanModel::load_default(Default::default())?;
    let takes = args.validation_takes()?;
    let variants: Vec<(String, Option<(usize, f32)>)> =
        std::iter::once(("slerp between the frames beside".to_string(), None))
            .chain(
                [
                    (4, 0.0f32),
                    (4, 0.5),
                    (4, 1.0),
                    (6, 0.5),
                    (8, 0.5),
                    (2, 1.0),
                ]
                .into_iter()
                .map(|(k, l)| {
                    (
                        format!("Hermite, lines on {k} frames, tangent weight {l}"),
                        Some((k, l)),
                    )
                }),
            )
            .collect();
    let results: Vec<(usize, Vec<f64>)> = (0..takes.len())
        .into_par_iter()
        .map(|i| {
            let support::SpikedTake { spiked, spikes, .. } = support::spiked_take(&takes, i, None);
            let clean = &takes[i].motion;
            let n = clean.frame_count();
            let truth: Vec<FoundSpike> = spikes.iter().map(|&s| FoundSpike::from(s)).collect();
            let found = find_spikes(&spiked, &DespikeOptions::default());
            let mut errors = Vec::new();
            for list in [&truth, &found] {
                for (_, v) in &variants {
                    let bridged = match v {
                        None => bridge_spikes(&spiked, list),
                        Some((k, l)) => bridge_hermite(&spiked, list, *k, *l),
                    };
                    let out = model.clean(&bridged, None).expect("clean");
                    errors.push(rotation_error_deg(clean, &out) * n as f64);
                }
            }
            (n, errors)
        })
        .collect();
    let frames: usize = results.iter().map(|r| r.0).sum();
    println!("{} validation takes, {frames} frames; mean rotation error (degrees) after the shipped model.\n", takes.len());
    println!("| bridge | true spikes | found spikes |\n| --- | ---: | ---: |");
    for (c, (label, _)) in variants.iter().enumerate() {
        let mean = |col: usize| results.iter().map(|r| r.1[col]).sum::<f64>() / frames as f64;
        println!(
            "| {label} | {:.3} | {:.3} |",
            mean(c),
            mean(variants.len() + c)
        );
    }
    Ok(())
}
