//! Setup shared by the clean studies (`studies/examples/clean_*.rs`): the
//! command line of the noise-level studies (`DATA [TAKES] [SIGMAS] [MORE...]`),
//! the spike studies' noisy takes, and the loop of the studies that draw the
//! evaluation's noise again.

use std::error::Error;
use std::path::PathBuf;

use mocap_clean::{list_bvh, load_takes, paths_in_split, Split, SplitFractions, Take};

/// Parsed study arguments.
pub struct StudyArgs {
    /// The folder of clean takes.
    pub data: PathBuf,
    /// At most this many validation takes (default 40).
    pub takes: usize,
    /// The noise levels, degrees (default 0,1,2,4,6,8,10).
    pub sigmas: Vec<f32>,
    /// Arguments after SIGMAS, for the study's own.
    pub rest: Vec<String>,
}

pub fn parse() -> Result<StudyArgs, Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let data = PathBuf::from(args.first().ok_or("DATA folder needed")?);
    let takes: usize = args.get(1).map_or(Ok(40), |s| s.parse())?;
    let sigmas = args
        .get(2)
        .map_or("0,1,2,4,6,8,10", String::as_str)
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    Ok(StudyArgs {
        data,
        takes,
        sigmas,
        rest: args.iter().skip(3).cloned().collect(),
    })
}

impl StudyArgs {
    /// The first `takes` validation takes of `data` (the training code's
    /// split by take).
    pub fn validation_takes(&self) -> Result<Vec<Take>, Box<dyn Error>> {
        let paths = paths_in_split(
            &list_bvh(std::slice::from_ref(&self.data))?,
            Split::Validation,
            &SplitFractions::default(),
        );
        Ok(load_takes(&paths[..self.takes.min(paths.len())])?)
    }
}

/// A validation take with the spike studies' noise: random noise (of level
/// `sigma_deg`, or drawn in 0-10 degrees), then 1-3 spikes from other takes.
pub struct SpikedTake {
    /// With the random noise only.
    pub noisy: mocap_core::Motion,
    /// `noisy` with the spikes.
    pub spiked: mocap_core::Motion,
    pub spikes: Vec<mocap_clean::Spike>,
}

/// Take `i` of `takes` with the spike studies' noise, seeded by `i` and the
/// level, so that every study sees the same noisy takes.
pub fn spiked_take(takes: &[Take], i: usize, sigma_deg: Option<f32>) -> SpikedTake {
    use mocap_clean::{
        add_random_noise, add_random_noise_sigma, add_spike_noise, looped_window, RandomNoise,
        SpikeNoise,
    };
    use rand::{RngExt, SeedableRng};
    let key = sigma_deg.map_or(u32::MAX, f32::to_bits) as u64;
    let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(0x5e1ce ^ (i as u64) << 16 ^ key);
    let clean = &takes[i].motion;
    let n = clean.frame_count();
    let noisy = match sigma_deg {
        Some(sigma) => add_random_noise_sigma(clean, sigma, &RandomNoise::default(), &mut rng),
        None => add_random_noise(clean, &RandomNoise::default(), &mut rng).0,
    };
    let donors: Vec<mocap_core::Motion> = (0..3)
        .map(|_| {
            let mut d = rng.random_range(0..takes.len());
            if d == i {
                d = (d + 1) % takes.len();
            }
            let donor = &takes[d].motion;
            looped_window(donor, rng.random_range(0..donor.frame_count()), n)
        })
        .collect();
    let donor_refs: Vec<&mocap_core::Motion> = donors.iter().collect();
    let (spiked, spikes) = add_spike_noise(&noisy, &donor_refs, &SpikeNoise::default(), &mut rng)
        .expect("spikes from takes of the same rig");
    SpikedTake {
        noisy,
        spiked,
        spikes,
    }
}

/// The frames two spikes share over the frames either covers (intersection
/// over union): how the spike studies match a found spike to a true one.
pub fn overlap(a: &mocap_clean::FoundSpike, b: &mocap_clean::FoundSpike) -> f64 {
    let shared_start = a.start.max(b.start);
    let shared_end = (a.start + a.frames).min(b.start + b.frames);
    let union = (a.start + a.frames).max(b.start + b.frames) - a.start.min(b.start);
    shared_end.saturating_sub(shared_start) as f64 / union.max(1) as f64
}

/// The test takes of a study that draws the evaluation's noise again, and
/// the seeds of its draws.
pub struct TestDraws {
    pub takes: Vec<Take>,
    /// Frames of all the takes.
    pub frames: usize,
    pub seeds: Vec<u64>,
}

/// The command line of the studies that draw the evaluation's noise again,
/// `DATA [SEEDS]` (seeds comma-separated, default 7-12, 7 being the
/// evaluation's own), with the test takes of `DATA` (the training code's
/// split by take).
pub fn test_draws() -> Result<TestDraws, Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let data = PathBuf::from(args.next().ok_or("DATA folder needed")?);
    let seeds: Vec<u64> = args
        .next()
        .unwrap_or_else(|| "7,8,9,10,11,12".to_string())
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let paths = paths_in_split(&list_bvh(&[data])?, Split::Test, &SplitFractions::default());
    let takes = load_takes(&paths)?;
    let frames = takes.iter().map(|t| t.motion.frame_count()).sum();
    Ok(TestDraws {
        takes,
        frames,
        seeds,
    })
}

/// Over `takes` takes of `frames` frames in all, the frame-weighted mean of
/// each of the `columns` errors `row(i)` gives for take `i` (each already
/// multiplied by the take's frames); the takes run in parallel.
pub fn mean_over_takes(
    takes: usize,
    frames: usize,
    columns: usize,
    row: impl Fn(usize) -> Vec<f64> + Sync + Send,
) -> Vec<f64> {
    use rayon::prelude::*;
    let sums = (0..takes).into_par_iter().map(row).reduce(
        || vec![0.0; columns],
        |mut a, b| {
            for (x, y) in a.iter_mut().zip(b) {
                *x += y;
            }
            a
        },
    );
    sums.iter().map(|s| s / frames as f64).collect()
}

/// The loop of the studies that draw the evaluation's noise again: for
/// each seed of `draws`, the frame-weighted mean over its takes of the
/// `columns` errors `row(options, i)` gives for take `i` (each multiplied
/// by the take's frames; `options` the evaluation's, with that seed),
/// printed by `print` under the seed; then the mean over the seeds, under
/// `mean_label`.
pub fn over_draws(
    draws: &TestDraws,
    columns: usize,
    row: impl Fn(&mocap_clean::EvalOptions, usize) -> Vec<f64> + Sync + Send,
    print: impl Fn(&str, &[f64]),
    mean_label: &str,
) {
    let mut pooled = vec![0.0f64; columns];
    for &seed in &draws.seeds {
        let options = mocap_clean::EvalOptions {
            seed,
            ..Default::default()
        };
        let mean = mean_over_takes(draws.takes.len(), draws.frames, columns, |i| {
            row(&options, i)
        });
        for (p, m) in pooled.iter_mut().zip(&mean) {
            *p += m / draws.seeds.len() as f64;
        }
        print(&seed.to_string(), &mean);
    }
    print(mean_label, &pooled);
}
