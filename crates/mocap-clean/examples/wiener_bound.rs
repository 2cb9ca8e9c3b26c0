//! Study: the learned multichannel Wiener filter ([`mocap_clean::wiener`])
//! against the cross-validated Butterworth, on validation takes with random
//! noise of fixed sigma.
//!
//! Fitted to the training takes (spectra of every take, noise covariance at
//! 5 degrees), then for each sigma: mean rotation error of the input, of
//! `butterworth-gcv:2`, of the Wiener filter with every channel on its own
//! (true sigma), of the multichannel Wiener filter with the true sigma and
//! with the sigma it estimates (marginal likelihood), and the mean
//! estimated sigma.
//!
//! cargo run --profile test -p mocap-clean --example wiener_bound -- DATA [TAKES] [SIGMAS] [SEGMENT]

use std::path::PathBuf;
use std::time::Instant;

use mocap_clean::dataset::{list_bvh, load_takes, paths_in_split, Split, SplitFractions};
use mocap_clean::eval::rotation_error_deg;
use mocap_clean::filters::{filter_motion, Filter};
use mocap_clean::noise::{add_random_noise_sigma, RandomNoise};
use mocap_clean::wiener::WienerFilter;
use mocap_core::Motion;
use rand::rngs::ChaCha8Rng;
use rand::SeedableRng;
use rayon::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let data = PathBuf::from(args.first().ok_or("DATA folder needed")?);
    let max_takes: usize = args.get(1).map_or(Ok(40), |s| s.parse())?;
    let sigmas: Vec<f32> = args
        .get(2)
        .map_or("0,1,2,4,6,8,10", String::as_str)
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let segment: usize = args.get(3).map_or(Ok(32), |s| s.parse())?;
    let all = list_bvh(&[data])?;
    let fractions = SplitFractions::default();
    let train = load_takes(&paths_in_split(&all, Split::Train, &fractions))?;
    let valid = load_takes(&paths_in_split(&all, Split::Validation, &fractions))?;
    let started = Instant::now();
    let train: Vec<&Motion> = train.iter().map(|t| &t.motion).collect();
    let wiener = WienerFilter::fit(&train, &RandomNoise::default(), 5.0, segment, 7)?;
    let per_channel = wiener.per_channel();
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
        .take(max_takes)
        .collect();
    println!(
        "{} validation takes; mean rotation error (deg)",
        valid.len()
    );
    println!("| sigma | input | butterworth-gcv:2 | Wiener per channel (true sigma) | multichannel Wiener (true sigma) | multichannel Wiener (estimated sigma) | mean estimated sigma |");
    println!("| ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for &sigma in &sigmas {
        let rows: Vec<[f64; 6]> = valid
            .par_iter()
            .enumerate()
            .map(|(i, clean)| {
                let mut rng = ChaCha8Rng::seed_from_u64(1000 + i as u64);
                let noisy = add_random_noise_sigma(clean, sigma, &RandomNoise::default(), &mut rng);
                let gcv = filter_motion(&noisy, &Filter::ButterworthGcv { order: 2 }).unwrap();
                let truth = Some(sigma as f64);
                let (diagonal, _) = per_channel.clean(&noisy, truth).unwrap();
                let (oracle, _) = wiener.clean(&noisy, truth).unwrap();
                let (estimated, outcome) = wiener.clean(&noisy, None).unwrap();
                [
                    rotation_error_deg(clean, &noisy),
                    rotation_error_deg(clean, &gcv),
                    rotation_error_deg(clean, &diagonal),
                    rotation_error_deg(clean, &oracle),
                    rotation_error_deg(clean, &estimated),
                    outcome.sigma_deg,
                ]
            })
            .collect();
        let n = rows.len() as f64;
        print!("| {sigma} |");
        for k in 0..6 {
            print!(" {:.3} |", rows.iter().map(|r| r[k]).sum::<f64>() / n);
        }
        println!();
    }
    Ok(())
}
