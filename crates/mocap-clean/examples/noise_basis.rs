//! Study: does filtering in the noise's own channel basis beat filtering each
//! 6D channel on its own?
//!
//! The chain-corrected random noise is correlated across joints (a parent's
//! swing reappears, turned, in its child's local rotation). Per frame, the
//! noise of the 6D features therefore has a covariance `C` that is far from
//! diagonal. Here `C` is estimated by noising takes, its eigenvectors `U`
//! give a basis in which the noise channels are uncorrelated, and the
//! cross-validated Butterworth (`butterworth-gcv:2`) runs on `U^T x` instead
//! of `x`. Printed: the mean rotation error of the input, of GCV per channel,
//! and of GCV in the basis estimated (a) on training takes and (b) on the
//! noisy take itself, noised once more.
//!
//! cargo run --profile test -p mocap-clean --example noise_basis -- DATA [TAKES] [SIGMAS]

use std::path::PathBuf;

use mocap_clean::dataset::{list_bvh, load_takes, paths_in_split, Split, SplitFractions};
use mocap_clean::eval::rotation_error_deg;
use mocap_clean::features::{FeatureLayout, Representation};
use mocap_clean::filters::{filter_features, Filter};
use mocap_clean::noise::{add_random_noise_sigma, RandomNoise};
use mocap_core::Motion;
use nalgebra::{DMatrix, SymmetricEigen};
use rand::rngs::ChaCha8Rng;
use rand::SeedableRng;
use rayon::prelude::*;

/// Noise covariance of the 6D features of `motions`, noised at `sigma_deg`.
fn noise_covariance(motions: &[&Motion], sigma_deg: f32, seed: u64) -> DMatrix<f64> {
    let layout = FeatureLayout::new(motions[0].skeleton(), Representation::Rot6d).unwrap();
    let c = layout.channels();
    let mut cov = DMatrix::<f64>::zeros(c, c);
    let mut count = 0usize;
    for (i, m) in motions.iter().enumerate() {
        let mut rng = ChaCha8Rng::seed_from_u64(seed + i as u64);
        let noisy = add_random_noise_sigma(m, sigma_deg, &RandomNoise::default(), &mut rng);
        let a = layout.encode(m);
        let b = layout.encode(&noisy);
        for f in 0..m.frame_count() {
            let d: Vec<f64> = (0..c)
                .map(|k| (b[f * c + k] - a[f * c + k]) as f64)
                .collect();
            for r in 0..c {
                for s in 0..c {
                    cov[(r, s)] += d[r] * d[s];
                }
            }
        }
        count += m.frame_count();
    }
    cov / count.max(1) as f64
}

/// GCV-filters `x` (frames x c) in the basis `u` (columns): `U (filter(U^T x))`.
fn filter_in_basis(x: &[f32], c: usize, u: &DMatrix<f64>, fps: f32) -> Vec<f32> {
    let frames = x.len() / c;
    let mut y = vec![0.0f32; x.len()];
    for f in 0..frames {
        for k in 0..c {
            y[f * c + k] = (0..c).map(|r| u[(r, k)] * x[f * c + r] as f64).sum::<f64>() as f32;
        }
    }
    filter_features(&mut y, c, &Filter::ButterworthGcv { order: 2 }, fps);
    let mut out = vec![0.0f32; x.len()];
    for f in 0..frames {
        for r in 0..c {
            out[f * c + r] = (0..c).map(|k| u[(r, k)] * y[f * c + k] as f64).sum::<f64>() as f32;
        }
    }
    out
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let data = PathBuf::from(args.first().ok_or("DATA folder needed")?);
    let max_takes: usize = args.get(1).map_or(Ok(40), |s| s.parse())?;
    let sigmas: Vec<f32> = args
        .get(2)
        .map_or("1,2,4,6,8,10", String::as_str)
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let all = list_bvh(&[data])?;
    let fractions = SplitFractions::default();
    let val_paths = paths_in_split(&all, Split::Validation, &fractions);
    let train_paths = paths_in_split(&all, Split::Train, &fractions);
    let takes = load_takes(&val_paths[..max_takes.min(val_paths.len())])?;
    let train = load_takes(&train_paths[..max_takes.min(train_paths.len())])?;
    // Only takes on the first take's skeleton share one feature layout.
    let channels =
        FeatureLayout::new(takes[0].motion.skeleton(), Representation::Rot6d)?.channels();
    let same = |m: &Motion| {
        FeatureLayout::new(m.skeleton(), Representation::Rot6d)
            .is_ok_and(|l| l.channels() == channels)
            && m.skeleton().joint_count() == takes[0].motion.skeleton().joint_count()
    };
    let train_motions: Vec<&Motion> = train
        .iter()
        .map(|t| &t.motion)
        .filter(|m| same(m))
        .collect();
    let cov = noise_covariance(&train_motions, 5.0, 7);
    let eig = SymmetricEigen::new(cov.clone());
    let mut values: Vec<f64> = eig.eigenvalues.iter().cloned().collect();
    values.sort_by(|a, b| b.total_cmp(a));
    let total: f64 = values.iter().sum();
    let mut acc = 0.0;
    print!("noise variance share of the top eigen-directions (of {channels}):");
    for (i, v) in values.iter().enumerate() {
        acc += v;
        if [1, 5, 10, 20, 40, 63, 80, 100].contains(&(i + 1)) {
            print!(" top {}: {:.3}", i + 1, acc / total);
        }
    }
    println!();
    let diag: f64 = (0..channels).map(|k| cov[(k, k)]).sum();
    println!("trace {total:.5} (diagonal sum {diag:.5})");
    let u_train = eig.eigenvectors;
    println!("| sigma | input | GCV per channel | GCV in the training noise basis | GCV in the take's own noise basis |");
    for &sigma in &sigmas {
        let rows: Vec<[f64; 4]> = takes
            .par_iter()
            .enumerate()
            .filter(|(_, t)| same(&t.motion))
            .map(|(i, take)| {
                let mut rng = ChaCha8Rng::seed_from_u64(1000 + i as u64);
                let clean = &take.motion;
                let noisy = add_random_noise_sigma(clean, sigma, &RandomNoise::default(), &mut rng);
                let fps = noisy.fps() as f32;
                let layout = FeatureLayout::new(noisy.skeleton(), Representation::Rot6d).unwrap();
                let x = layout.encode(&noisy);
                let mut out = noisy.clone();
                let mut y = x.clone();
                filter_features(&mut y, channels, &Filter::ButterworthGcv { order: 2 }, fps);
                layout.decode_into(&y, &mut out);
                let per_channel = rotation_error_deg(clean, &out);
                layout.decode_into(&filter_in_basis(&x, channels, &u_train, fps), &mut out);
                let basis_train = rotation_error_deg(clean, &out);
                let own = SymmetricEigen::new(noise_covariance(&[&noisy], 5.0, 99)).eigenvectors;
                layout.decode_into(&filter_in_basis(&x, channels, &own, fps), &mut out);
                let basis_own = rotation_error_deg(clean, &out);
                [
                    rotation_error_deg(clean, &noisy),
                    per_channel,
                    basis_train,
                    basis_own,
                ]
            })
            .collect();
        let n = rows.len() as f64;
        print!("| {sigma} |");
        for k in 0..4 {
            print!(" {:.3} |", rows.iter().map(|r| r[k]).sum::<f64>() / n);
        }
        println!();
    }
    Ok(())
}
