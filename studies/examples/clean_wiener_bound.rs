//! Study: the learned multichannel Wiener filter ([`mocap_clean::WienerFilter`])
//! against the cross-validated Butterworth, on validation takes with random
//! noise of fixed sigma.
//!
//! Fitted to the training takes (spectra of every take, noise covariance at
//! 5 degrees), then for each sigma: mean rotation error of the input, of
//! `butterworth-gcv:2`, of the same filter run in the eigenbasis of the
//! noise covariance (channels whose noise is uncorrelated), of the Wiener filter with every channel on its own
//! (true sigma), of the multichannel Wiener filter with the true sigma and
//! with the sigma it estimates (marginal likelihood), and the mean
//! estimated sigma.
//!
//! cargo run --release -p mocap-studies --example clean_wiener_bound -- DATA [TAKES] [SIGMAS] [SEGMENT]

use mocap_studies::clean as support;

use std::time::Instant;

use mocap_clean::{
    add_random_noise_sigma, filter_features, filter_motion, list_bvh, load_takes, paths_in_split,
    rotation_error_deg, FeatureLayout, Filter, RandomNoise, Representation, Split, SplitFractions,
    WienerFilter,
};
use mocap_core::Motion;
use nalgebra::{DMatrix, SymmetricEigen};
use rand::rngs::ChaCha8Rng;
use rand::SeedableRng;
use rayon::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = support::parse()?;
    let segment: usize = args.rest.first().map_or(Ok(32), |s| s.parse())?;
    let all = list_bvh(std::slice::from_ref(&args.data))?;
    let fractions = SplitFractions::default();
    let train = load_takes(&paths_in_split(&all, Split::Train, &fractions))?;
    let valid = load_takes(&paths_in_split(&all, Split::Validation, &fractions))?;
    let started = Instant::now();
    let train: Vec<&Motion> = train.iter().map(|t| &t.motion).collect();
    let wiener = WienerFilter::fit(&train, &RandomNoise::default(), 5.0, segment, 7)?;
    let per_channel = wiener.per_channel();
    // The eigenvectors of the noise covariance: a basis in which the noise
    // channels are uncorrelated, for GCV per channel in that basis.
    let noise_eigen = SymmetricEigen::new(wiener.noise_covariance().clone());
    let mut variances: Vec<f64> = noise_eigen.eigenvalues.iter().map(|v| v.max(0.0)).collect();
    variances.sort_by(|a, b| b.total_cmp(a));
    let total: f64 = variances.iter().sum();
    let share = |k: usize| variances[..k.min(variances.len())].iter().sum::<f64>() / total;
    println!(
        "noise variance in the top 5 / 10 / 20 / 40 of {} eigen-directions of N: {:.3} / {:.3} / {:.3} / {:.3}",
        variances.len(),
        share(5),
        share(10),
        share(20),
        share(40)
    );
    let noise_basis = noise_eigen.eigenvectors;
    let d = &wiener.description;
    println!(
        "fitted to {} training takes ({} frames, {} segments of {} frames; {} on other rigs left out) in {:.1} s",
        d.takes,
        d.frames,
        d.segments,
        d.segment,
        d.other_rig_takes,
        started.elapsed().as_secs_f64()
    );
    let valid: Vec<&Motion> = valid
        .iter()
        .map(|t| &t.motion)
        .filter(|m| wiener.clean(m, Some(0.0)).is_ok())
        .take(args.takes)
        .collect();
    println!(
        "{} validation takes; mean rotation error (deg)",
        valid.len()
    );
    println!("| sigma | input | butterworth-gcv:2 | the same in the noise's eigenbasis | Wiener per channel (true sigma) | multichannel Wiener (true sigma) | multichannel Wiener (estimated sigma) | mean estimated sigma |");
    println!("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for &sigma in &args.sigmas {
        let rows: Vec<[f64; 7]> = valid
            .par_iter()
            .enumerate()
            .map(|(i, clean)| {
                let mut rng = ChaCha8Rng::seed_from_u64(1000 + i as u64);
                let noisy = add_random_noise_sigma(clean, sigma, &RandomNoise::default(), &mut rng);
                let gcv = filter_motion(&noisy, &Filter::ButterworthGcv { order: 2 }).unwrap();
                let rotated = gcv_in_basis(&noisy, &noise_basis);
                let truth = Some(sigma as f64);
                let (diagonal, _) = per_channel.clean(&noisy, truth).unwrap();
                let (oracle, _) = wiener.clean(&noisy, truth).unwrap();
                let (estimated, outcome) = wiener.clean(&noisy, None).unwrap();
                [
                    rotation_error_deg(clean, &noisy),
                    rotation_error_deg(clean, &gcv),
                    rotation_error_deg(clean, &rotated),
                    rotation_error_deg(clean, &diagonal),
                    rotation_error_deg(clean, &oracle),
                    rotation_error_deg(clean, &estimated),
                    outcome.sigma_deg,
                ]
            })
            .collect();
        let n = rows.len() as f64;
        print!("| {sigma} |");
        for k in 0..7 {
            print!(" {:.3} |", rows.iter().map(|r| r[k]).sum::<f64>() / n);
        }
        println!();
    }
    Ok(())
}

/// `butterworth-gcv:2` run on the features turned into `basis` (columns):
/// `U filter(U^T x)`.
fn gcv_in_basis(noisy: &Motion, basis: &DMatrix<f64>) -> Motion {
    let layout = FeatureLayout::new(noisy.skeleton(), Representation::Rot6d).unwrap();
    let c = layout.channels();
    let x = layout.encode(noisy);
    let turn = |v: &[f32], transpose: bool| -> Vec<f32> {
        v.chunks_exact(c)
            .flat_map(|frame| {
                (0..c).map(move |k| {
                    (0..c)
                        .map(|r| {
                            let u = if transpose {
                                basis[(r, k)]
                            } else {
                                basis[(k, r)]
                            };
                            u * frame[r] as f64
                        })
                        .sum::<f64>() as f32
                })
            })
            .collect()
    };
    let mut y = turn(&x, true);
    filter_features(
        &mut y,
        c,
        &Filter::ButterworthGcv { order: 2 },
        noisy.fps() as f32,
    );
    let mut out = noisy.clone();
    layout.decode_into(&turn(&y, false), &mut out);
    out
}
