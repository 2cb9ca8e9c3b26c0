//! Study: the take's noise level as the median of its segments' levels
//! ([`LevelEstimate::SegmentMedian`]) against the level of all segments
//! together ([`LevelEstimate::Pooled`]), with the shipped
//! model.
//!
//! On the test takes, for each noise draw (the evaluation's conditions,
//! [`mocap_clean::noisy_take`], seed 7 being the evaluation's own):
//! random noise, the model; spikes on random noise, spikes found and
//! bridged (the default finder), then the model; spikes alone, the same;
//! and once, the clean takes themselves and takes with at most 2 degrees of
//! random noise. Each with both estimates, beside the references of the
//! issue's spike target (the cross-validated Butterworth on spikes on
//! random noise, the best tuned filter on spikes alone: a running median of
//! 3 frames, and spike finding alone). Mean rotation error in degrees,
//! frame-weighted, and the mean level the model's Wiener filter estimated.
//!
//! cargo run --release -p mocap-studies --example clean_level_estimate -- DATA [SEEDS]

use mocap_studies::clean as support;

use mocap_clean::{
    bridge_spikes, filter_motion, find_spikes, noisy_take, rotation_error_deg, CleanModel,
    DespikeOptions, EvalOptions, Filter, LevelEstimate, RandomNoise,
};
use mocap_core::Motion;
use rayon::prelude::*;

/// Per condition: error with the pooled and the median level, and the two
/// mean levels.
#[derive(Clone, Copy, Default)]
struct Pair {
    error: [f64; 2],
    level: [f64; 2],
}

impl std::ops::AddAssign for Pair {
    fn add_assign(&mut self, o: Pair) {
        for k in 0..2 {
            self.error[k] += o.error[k];
            self.level[k] += o.level[k];
        }
    }
}

impl Pair {
    fn scaled(self, frames: f64, takes: f64) -> Pair {
        Pair {
            error: self.error.map(|e| e / frames),
            level: self.level.map(|l| l / takes),
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let support::TestDraws {
        takes,
        frames,
        seeds,
    } = support::test_draws()?;
    let mut models = [
        CleanModel::load_default(Default::default())?,
        CleanModel::load_default(Default::default())?,
    ];
    models[0].set_level_estimate(LevelEstimate::Pooled);
    models[1].set_level_estimate(LevelEstimate::SegmentMedian);
    let finder = DespikeOptions::default();
    let n = takes.len() as f64;
    let f = frames as f64;

    // Both estimates of one motion: weighted errors against `clean` and levels.
    let both = |clean: &Motion, input: &Motion| -> Pair {
        let weight = clean.frame_count() as f64;
        let mut pair = Pair::default();
        for (k, model) in models.iter().enumerate() {
            let (out, level) = model.clean_reporting(input, None).expect("clean");
            pair.error[k] = rotation_error_deg(clean, &out) * weight;
            pair.level[k] = level.unwrap_or(0.0);
        }
        pair
    };

    println!(
        "{} test takes, {frames} frames. Mean rotation error (degrees) of the shipped model with the \
         take's noise level pooled over its segments and as the median of its segments' levels \
         (the default); in brackets the mean level estimated (degrees).\n",
        takes.len()
    );
    println!(
        "| seed | random: pooled | median | spikes on random, found + model: pooled | median | \
         cross-validated Butterworth | ratio (pooled, median) | spikes alone, found + model: pooled | \
         median | found alone | median of 3 frames | ratio to it (pooled, median, found alone) |"
    );
    println!("| ---: | ---: | ---: | ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: | --- |");
    let mut pooled_rows = [Pair::default(); 3];
    let mut pooled_refs = [0.0f64; 3];
    for &seed in &seeds {
        let options = EvalOptions {
            seed,
            ..EvalOptions::default()
        };
        let (rows, refs) = (0..takes.len())
            .into_par_iter()
            .map(|i| {
                let clean = &takes[i].motion;
                let weight = clean.frame_count() as f64;
                let random = noisy_take(&takes, i, 0, &options).expect("noise").0;
                let spiked = noisy_take(&takes, i, 1, &options).expect("noise").0;
                let alone = noisy_take(&takes, i, 2, &options).expect("noise").0;
                let spiked_bridged = bridge_spikes(&spiked, &find_spikes(&spiked, &finder));
                let alone_bridged = bridge_spikes(&alone, &find_spikes(&alone, &finder));
                let rows = [
                    both(clean, &random),
                    both(clean, &spiked_bridged),
                    both(clean, &alone_bridged),
                ];
                let filtered = |m: &Motion, filter: Filter| {
                    rotation_error_deg(clean, &filter_motion(m, &filter).expect("filter")) * weight
                };
                let refs = [
                    filtered(&spiked, Filter::ButterworthGcv { order: 2 }),
                    rotation_error_deg(clean, &alone_bridged) * weight,
                    filtered(&alone, Filter::Median { window: 3 }),
                ];
                (rows, refs)
            })
            .reduce(
                || ([Pair::default(); 3], [0.0; 3]),
                |(mut ra, mut fa), (rb, fb)| {
                    for (a, b) in ra.iter_mut().zip(rb) {
                        *a += b;
                    }
                    for (a, b) in fa.iter_mut().zip(fb) {
                        *a += b;
                    }
                    (ra, fa)
                },
            );
        let rows = rows.map(|r| r.scaled(f, n));
        let refs = refs.map(|r| r / f);
        for (p, r) in pooled_rows.iter_mut().zip(rows) {
            *p += r.scaled(seeds.len() as f64, seeds.len() as f64);
        }
        for (p, r) in pooled_refs.iter_mut().zip(refs) {
            *p += r / seeds.len() as f64;
        }
        print_row(&seed.to_string(), &rows, &refs);
    }
    print_row("**mean**", &pooled_rows, &pooled_refs);

    println!(
        "\nTakes without spikes at low noise (the evaluation's draw, seed 7): the clean takes \
         themselves (how far the model moves them) and random noise of at most 2 degrees.\n"
    );
    println!("| takes | pooled | median | level: pooled | median |");
    println!("| --- | ---: | ---: | ---: | ---: |");
    for (label, max_sigma) in [("clean", 0.0f32), ("noise of at most 2 deg", 2.0)] {
        let options = EvalOptions {
            random: RandomNoise {
                max_sigma_deg: max_sigma,
                ..RandomNoise::default()
            },
            ..EvalOptions::default()
        };
        let mut sum = Pair::default();
        let parts: Vec<Pair> = (0..takes.len())
            .into_par_iter()
            .map(|i| {
                let clean = &takes[i].motion;
                let input = noisy_take(&takes, i, 0, &options).expect("noise").0;
                both(clean, &input)
            })
            .collect();
        for p in parts {
            sum += p;
        }
        let m = sum.scaled(f, n);
        println!(
            "| {label} | {:.3} | {:.3} | {:.2} | {:.2} |",
            m.error[0], m.error[1], m.level[0], m.level[1]
        );
    }
    Ok(())
}

fn print_row(label: &str, rows: &[Pair; 3], refs: &[f64; 3]) {
    let [random, spiked, alone] = rows;
    let [gcv, found_alone, median3] = refs;
    println!(
        "| {label} | {:.3} ({:.1}) | {:.3} ({:.1}) | {:.3} ({:.1}) | {:.3} ({:.1}) | {gcv:.3} | {:.2}x, {:.2}x \
         | {:.3} ({:.2}) | {:.3} ({:.2}) | {found_alone:.3} | {median3:.3} | {:.2}x, {:.2}x, {:.2}x |",
        random.error[0],
        random.level[0],
        random.error[1],
        random.level[1],
        spiked.error[0],
        spiked.level[0],
        spiked.error[1],
        spiked.level[1],
        gcv / spiked.error[0],
        gcv / spiked.error[1],
        alone.error[0],
        alone.level[0],
        alone.error[1],
        alone.level[1],
        median3 / alone.error[0],
        median3 / alone.error[1],
        median3 / found_alone,
    );
}
