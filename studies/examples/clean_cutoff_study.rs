//! Study: how should the low-pass cutoff follow the noise level of a take?
//!
//! For validation takes with random noise of each given sigma, prints the
//! mean rotation error of a zero-phase Butterworth (order 2) at every cutoff
//! of a grid, of the best single cutoff per take (oracle), and of the cutoff
//! chosen by generalised cross-validation (GCV) per take, per joint, and per
//! channel (`butterworth-gcv:2`, on the whole take and on separate 32-frame
//! windows), and the best cutoff of the grid per joint and per channel
//! chosen with the clean take in hand (oracles: how far choosing the cutoff
//! better could take a Butterworth at all).
//!
//! cargo run --release -p mocap-studies --example clean_cutoff_study -- DATA [TAKES] [SIGMAS]

use mocap_studies::clean as support;

use mocap_clean::{
    add_random_noise_sigma, filter_features, gcv_score, gcv_trace_fraction, rotation_error_deg,
    FeatureLayout, Filter, RandomNoise, Representation,
};
use rand::rngs::ChaCha8Rng;
use rand::SeedableRng;
use rayon::prelude::*;

const CUTOFFS: [f32; 13] = [
    0.75, 1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0,
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = support::parse()?;
    if let Some(extra) = args.rest.first() {
        return Err(format!("unexpected argument {extra:?} (DATA [TAKES] [SIGMAS])").into());
    }
    let takes = args.validation_takes()?;
    println!(
        "{} validation takes; Butterworth order 2; mean rotation error (deg)",
        takes.len()
    );
    print!("| sigma | input |");
    for c in CUTOFFS {
        print!(" {c} Hz |");
    }
    println!(" oracle per take | GCV per take | GCV per joint | butterworth-gcv:2 (GCV per channel) | the same on 32-frame windows | oracle per joint | oracle per channel |");
    for &sigma in &args.sigmas {
        let rows: Vec<Vec<f64>> = takes
            .par_iter()
            .enumerate()
            .map(|(i, take)| {
                let mut rng = ChaCha8Rng::seed_from_u64(1000 + i as u64);
                let clean = &take.motion;
                let noisy = add_random_noise_sigma(clean, sigma, &RandomNoise::default(), &mut rng);
                let fps = noisy.fps() as f32;
                let layout = FeatureLayout::new(noisy.skeleton(), Representation::Rot6d).unwrap();
                let x = layout.encode(&noisy);
                let channels = layout.channels();
                let frames = noisy.frame_count();
                let mut row = vec![rotation_error_deg(clean, &noisy)];
                let mut filtered = Vec::new();
                for c in CUTOFFS {
                    let mut y = x.clone();
                    let f = Filter::Butterworth {
                        order: 2,
                        cutoff_hz: c,
                    };
                    filter_features(&mut y, channels, &f, fps);
                    let mut out = noisy.clone();
                    layout.decode_into(&y, &mut out);
                    row.push(rotation_error_deg(clean, &out));
                    filtered.push(y);
                }
                let oracle = row[1..].iter().cloned().fold(f64::INFINITY, f64::min);
                row.push(oracle);
                let dim = 6;
                // GCV (`mocap_clean::gcv_score`) of cutoff `k` over
                // the channels `ch`, for choices coarser than the filter's
                // own per-channel one.
                let score = |k: usize, ch: std::ops::Range<usize>| {
                    let y = &filtered[k];
                    let mut rss = 0.0f64;
                    for f in 0..frames {
                        for c in ch.clone() {
                            let d = (x[f * channels + c] - y[f * channels + c]) as f64;
                            rss += d * d;
                        }
                    }
                    gcv_score(rss, gcv_trace_fraction(2, CUTOFFS[k], fps, frames))
                };
                // The oracle's score: the squared error against the clean
                // features.
                let target = layout.encode(clean);
                let clean_error = |k: usize, ch: std::ops::Range<usize>| {
                    let y = &filtered[k];
                    let mut sum = 0.0f64;
                    for f in 0..frames {
                        for c in ch.clone() {
                            let d = (target[f * channels + c] - y[f * channels + c]) as f64;
                            sum += d * d;
                        }
                    }
                    sum
                };
                let pick_by =
                    |ch: std::ops::Range<usize>,
                     by: &dyn Fn(usize, std::ops::Range<usize>) -> f64| {
                        (0..CUTOFFS.len())
                            .map(|k| (k, by(k, ch.clone())))
                            .min_by(|a, b| a.1.total_cmp(&b.1))
                            .map(|(k, _)| k)
                            .unwrap()
                    };
                let pick = |ch: std::ops::Range<usize>| pick_by(ch, &score);
                let whole = pick(0..channels);
                row.push(row[1 + whole]);
                // Each group of channels (`width` wide) filtered at the
                // cutoff its chooser picks; the rotation error of the result.
                let mut out = noisy.clone();
                let mut mixed_error =
                    |width: usize, by: &dyn Fn(usize, std::ops::Range<usize>) -> f64| {
                        let mut mixed = x.clone();
                        for g in 0..channels / width {
                            let group = g * width..(g + 1) * width;
                            let best = pick_by(group.clone(), by);
                            for f in 0..frames {
                                for c in group.clone() {
                                    mixed[f * channels + c] = filtered[best][f * channels + c];
                                }
                            }
                        }
                        layout.decode_into(&mixed, &mut out);
                        rotation_error_deg(clean, &out)
                    };
                row.push(mixed_error(dim, &score));
                let oracles = [mixed_error(dim, &clean_error), mixed_error(1, &clean_error)];
                // The filter itself, on the whole take and on separate
                // 32-frame windows (as a model's base filter runs).
                let gcv_filter = Filter::ButterworthGcv { order: 2 };
                let mut y = x.clone();
                filter_features(&mut y, channels, &gcv_filter, fps);
                layout.decode_into(&y, &mut out);
                row.push(rotation_error_deg(clean, &out));
                let mut y = x.clone();
                for chunk in y.chunks_mut(32 * channels) {
                    filter_features(chunk, channels, &gcv_filter, fps);
                }
                layout.decode_into(&y, &mut out);
                row.push(rotation_error_deg(clean, &out));
                row.extend(oracles);
                row
            })
            .collect();
        let n = rows.len() as f64;
        print!("| {sigma} |");
        for k in 0..rows[0].len() {
            print!(" {:.3} |", rows.iter().map(|r| r[k]).sum::<f64>() / n);
        }
        println!();
    }
    Ok(())
}
