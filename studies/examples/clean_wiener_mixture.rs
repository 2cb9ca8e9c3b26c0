//! Study: one multichannel Wiener filter for every kind of motion against a
//! mixture (`mocap_clean::fit_mixture`: spectra per content named in
//! the file names, contents with fewer than `MIN_SEGMENTS` training segments
//! together, and the single filter's spectra as a last component; the same
//! noise covariance), the component chosen per take by the marginal
//! likelihood (2). Validation takes with random noise of fixed sigma; mean
//! rotation error (degrees), and how often the component of the take's own
//! content was chosen.
//!
//! cargo run --release -p mocap-studies --example clean_wiener_mixture -- DATA [TAKES] [SIGMAS] [MIN_SEGMENTS]

use mocap_studies::clean as support;

use std::collections::BTreeMap;

use mocap_clean::{
    add_random_noise_sigma, fit_mixture, list_bvh, load_takes, paths_in_split, rotation_error_deg,
    RandomNoise, Split, SplitFractions, WienerFilter,
};
use rand::rngs::ChaCha8Rng;
use rand::SeedableRng;
use rayon::prelude::*;

fn content(name: &str) -> String {
    name.split('_').nth(1).unwrap_or("").to_string()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = support::parse()?;
    let min_segments: usize = args.rest.first().map_or(Ok(2000), |s| s.parse())?;
    let all = list_bvh(std::slice::from_ref(&args.data))?;
    let fractions = SplitFractions::default();
    let train = load_takes(&paths_in_split(&all, Split::Train, &fractions))?;
    let single = WienerFilter::fit(
        &train.iter().map(|t| &t.motion).collect::<Vec<_>>(),
        &RandomNoise::default(),
        5.0,
        32,
        7,
    )?;
    let mixture = fit_mixture(&single, &train, min_segments)?;
    for c in &mixture.description.components {
        println!(
            "component {}: {} takes, {} segments",
            c.name, c.takes, c.segments
        );
    }
    let component_of: BTreeMap<String, usize> = mixture
        .description
        .components
        .iter()
        .enumerate()
        .map(|(k, c)| (c.name.clone(), k))
        .collect();
    let valid = load_takes(&paths_in_split(&all, Split::Validation, &fractions))?;
    let valid: Vec<_> = valid
        .iter()
        .filter(|t| single.clean(&t.motion, Some(0.0)).is_ok())
        .take(args.takes)
        .collect();
    println!(
        "{} validation takes; mean rotation error (deg)",
        valid.len()
    );
    println!("| sigma | input | one filter | mixture | the take's own content chosen |");
    println!("| ---: | ---: | ---: | ---: | ---: |");
    for &sigma in &args.sigmas {
        let rows: Vec<[f64; 4]> = valid
            .par_iter()
            .enumerate()
            .map(|(i, take)| {
                let clean = &take.motion;
                let mut rng = ChaCha8Rng::seed_from_u64(1000 + i as u64);
                let noisy = add_random_noise_sigma(clean, sigma, &RandomNoise::default(), &mut rng);
                let (one, _) = single.clean(&noisy, None).unwrap();
                let (mixed, outcome) = mixture.clean(&noisy, None).unwrap();
                let told = component_of.get(&content(&take.name)).copied();
                [
                    rotation_error_deg(clean, &noisy),
                    rotation_error_deg(clean, &one),
                    rotation_error_deg(clean, &mixed),
                    (Some(outcome.component) == told) as u8 as f64,
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
