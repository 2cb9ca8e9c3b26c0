//! Experiment (issue 5): does factoring a style offset out of the interval
//! means help the forest tell dataset-1's contents apart?
//!
//! ```text
//! cargo run --profile test -p mocap-search --example style_offsets -- \
//!     ../shared/data/bandai/dataset-1 [SEEDS]
//! ```
//!
//! Every dataset-1 (content, style) pair is one take, so a test clip shows
//! its content in a style the forest never saw with that content, but saw
//! with every other content. The additive model `x = mu_content +
//! d_style` (per interval mean) is fitted on the training clips by
//! alternating means; the forest is trained on `x - d_style`. A test clip's
//! style is unknown, so every style's offset is tried and the results
//! combined in each of the ways the table's columns name (and, as an upper
//! bound, with the true style). Stratified 5-fold cross-validation by take,
//! fold seeds 1..SEEDS, classes with at least 2 clips; macro F over all
//! classes, pooled confusion over the folds, as `mocap search eval`.

use std::path::PathBuf;

use mocap_search::forest::argmax;
use mocap_search::{Forest, ForestConfig, LabelRule, NamePattern};

mod support;

const K: usize = 5;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let dir = PathBuf::from(args.next().ok_or("usage: style_offsets DIR [SEEDS]")?);
    let seeds: u64 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(5);
    let support::ContentRows {
        files,
        keep,
        classes,
        labels,
        rows,
        dim,
    } = support::content_rows(&dir)?;
    let style_rule = LabelRule::FromName(NamePattern::parse("bandai-style")?);
    let styles: Vec<String> = keep
        .iter()
        .map(|&i| style_rule.label_of(&files[i]).map(|l| l.label))
        .collect::<Result<_, _>>()?;
    let mut style_names = styles.clone();
    style_names.sort();
    style_names.dedup();
    let style_of: Vec<usize> = styles
        .iter()
        .map(|s| style_names.binary_search(s).unwrap())
        .collect();
    println!(
        "{} clips, {} classes, {} styles, {} interval means; fold seeds 1..{seeds}\n",
        rows.len(),
        classes.len(),
        style_names.len(),
        dim
    );

    let methods = [
        "forest on x (as shipped)",
        "offsets: max over styles",
        "offsets: mean over styles",
        "offsets: style of least residual",
        "offsets: weighted by a style forest",
        "offsets: the true style (an oracle)",
        "additive model alone: nearest (content, style) mean",
    ];
    let mut table = support::FTable::new(&methods);
    table.cross_validate(
        &labels,
        classes.len(),
        seeds,
        K,
        |fold, config, confusion| {
            let (train, test) = (&fold.train, &fold.test);
            let train_labels: Vec<u32> = train.iter().map(|&i| labels[i]).collect();
            // The forest as shipped.
            let plain_rows: Vec<f32> = train.iter().flat_map(|&i| rows[i].clone()).collect();
            let plain = train_forest(&plain_rows, dim, &train_labels, classes.len(), config);
            // The style forest (for the weighted combination).
            let train_styles: Vec<u32> = train.iter().map(|&i| style_of[i] as u32).collect();
            let style_forest =
                train_forest(&plain_rows, dim, &train_styles, style_names.len(), config);
            // The additive model on the training clips.
            let (mu, offsets) = additive_model(
                train,
                &rows,
                &labels,
                &style_of,
                classes.len(),
                style_names.len(),
            );
            let corrected: Vec<f32> = train
                .iter()
                .flat_map(|&i| subtract(&rows[i], &offsets[style_of[i]]))
                .collect();
            let forest = train_forest(&corrected, dim, &train_labels, classes.len(), config);
            let scale = feature_scale(train, &rows);
            for &i in test {
                let truth = labels[i] as usize;
                confusion[0].add(truth, argmax(&plain.predict(&rows[i])));
                let per_style: Vec<Vec<f32>> = offsets
                    .iter()
                    .map(|d| forest.predict(&subtract(&rows[i], d)))
                    .collect();
                let max_over: Vec<f32> = (0..classes.len())
                    .map(|c| per_style.iter().map(|p| p[c]).fold(0.0, f32::max))
                    .collect();
                confusion[1].add(truth, argmax(&max_over));
                let mean_over: Vec<f32> = (0..classes.len())
                    .map(|c| per_style.iter().map(|p| p[c]).sum::<f32>())
                    .collect();
                confusion[2].add(truth, argmax(&mean_over));
                let p_style = style_forest.predict(&rows[i]);
                let weighted: Vec<f32> = (0..classes.len())
                    .map(|c| {
                        per_style
                            .iter()
                            .zip(&p_style)
                            .map(|(p, w)| p[c] * w)
                            .sum::<f32>()
                    })
                    .collect();
                confusion[4].add(truth, argmax(&weighted));
                confusion[5].add(truth, argmax(&per_style[style_of[i]]));
                // Squared standardised distance of the clip, with style s's
                // offset removed, to content c's mean: residual[c][s], computed
                // once for the two readings below.
                let residual: Vec<Vec<f32>> = mu
                    .iter()
                    .map(|m| {
                        offsets
                            .iter()
                            .map(|d| {
                                (0..dim)
                                    .map(|k| ((rows[i][k] - d[k] - m[k]) / scale[k]).powi(2))
                                    .sum::<f32>()
                            })
                            .collect()
                    })
                    .collect();
                // The style whose offset leaves the clip nearest a content mean.
                let best_style = (0..offsets.len())
                    .min_by(|&a, &b| {
                        let nearest =
                            |s: usize| residual.iter().map(|r| r[s]).fold(f32::INFINITY, f32::min);
                        nearest(a).total_cmp(&nearest(b))
                    })
                    .unwrap();
                confusion[3].add(truth, argmax(&per_style[best_style]));
                // The additive model as a classifier: the content of the
                // nearest (content, style) mean.
                let nearest_content = (0..mu.len())
                    .min_by(|&a, &b| {
                        let nearest =
                            |c: usize| residual[c].iter().copied().fold(f32::INFINITY, f32::min);
                        nearest(a).total_cmp(&nearest(b))
                    })
                    .unwrap();
                confusion[6].add(truth, nearest_content);
            }
            Ok(())
        },
    )?;
    table.finish();
    Ok(())
}

fn train_forest(
    rows: &[f32],
    dim: usize,
    labels: &[u32],
    classes: usize,
    config: &ForestConfig,
) -> Forest {
    let samples = mocap_search::forest::Samples::new(rows, dim, labels, classes).unwrap();
    Forest::train(&samples, config, &|| {})
}

/// `x = mu[content] + d[style]`, fitted by alternating means (a two-way
/// additive model without interaction); the offsets average to zero over
/// the styles.
fn additive_model(
    train: &[usize],
    rows: &[Vec<f32>],
    labels: &[u32],
    style_of: &[usize],
    classes: usize,
    styles: usize,
) -> (Vec<Vec<f32>>, Vec<Vec<f32>>) {
    let dim = rows[0].len();
    let mut mu = vec![vec![0.0f32; dim]; classes];
    let mut d = vec![vec![0.0f32; dim]; styles];
    for _ in 0..10 {
        mu = group_means(
            train,
            classes,
            dim,
            |i| labels[i] as usize,
            |i, k| rows[i][k] - d[style_of[i]][k],
        );
        d = group_means(
            train,
            styles,
            dim,
            |i| style_of[i],
            |i, k| rows[i][k] - mu[labels[i] as usize][k],
        );
        for k in 0..dim {
            let mean = d.iter().map(|v| v[k]).sum::<f32>() / styles as f32;
            for v in d.iter_mut() {
                v[k] -= mean;
            }
        }
    }
    (mu, d)
}

fn group_means(
    members: &[usize],
    groups: usize,
    dim: usize,
    group: impl Fn(usize) -> usize,
    value: impl Fn(usize, usize) -> f32,
) -> Vec<Vec<f32>> {
    let mut sums = vec![vec![0.0f32; dim]; groups];
    let mut counts = vec![0usize; groups];
    for &i in members {
        let g = group(i);
        counts[g] += 1;
        for (k, s) in sums[g].iter_mut().enumerate() {
            *s += value(i, k);
        }
    }
    for (s, &n) in sums.iter_mut().zip(&counts) {
        if n > 0 {
            for v in s.iter_mut() {
                *v /= n as f32;
            }
        }
    }
    sums
}

fn feature_scale(train: &[usize], rows: &[Vec<f32>]) -> Vec<f32> {
    let dim = rows[0].len();
    let n = train.len() as f32;
    (0..dim)
        .map(|k| {
            let mean = train.iter().map(|&i| rows[i][k]).sum::<f32>() / n;
            let var = train
                .iter()
                .map(|&i| (rows[i][k] - mean).powi(2))
                .sum::<f32>()
                / n;
            var.sqrt().max(1e-6)
        })
        .collect()
}

fn subtract(x: &[f32], d: &[f32]) -> Vec<f32> {
    x.iter().zip(d).map(|(a, b)| a - b).collect()
}
