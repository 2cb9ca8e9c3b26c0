//! Experiment (issue 5): does keeping only the interval means that separate
//! the contents *across styles* help the forest tell dataset-1's contents
//! apart?
//!
//! ```text
//! cargo run --profile test -p mocap-search --example cross_style_features -- \
//!     ../shared/data/bandai/dataset-1 [SEEDS]
//! ```
//!
//! Every dataset-1 (content, style) pair is one take, so the spread of a
//! content's training clips around their mean is the spread its styles
//! give it. The Fisher score of an interval mean (the variance of the
//! content means over the mean squared deviation of a clip from its
//! content's mean, both on the training clips of the fold) is high where
//! the contents differ by more than the styles move them. The forest is
//! trained on the `K` best-scored interval means only; beside it, diagonal
//! linear discriminant analysis (the nearest content mean, each interval
//! mean weighted by one over its within-content variance) on the same
//! features. Stratified 5-fold cross-validation by take, fold seeds
//! 1..SEEDS, classes with at least 2 clips; macro F over all classes and
//! over the classes with at least 10 clips, pooled confusion over the
//! folds, as `mocap search eval`.

use std::path::PathBuf;

use mocap_search::forest::{argmax, Samples};
use mocap_search::Forest;

mod support;

const K: usize = 5;
/// How many of the best-scored interval means are kept.
const KEPT: [usize; 4] = [250, 500, 1000, 2000];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let dir = PathBuf::from(
        args.next()
            .ok_or("usage: cross_style_features DIR [SEEDS]")?,
    );
    let seeds: u64 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(5);
    let support::ContentRows {
        classes,
        labels,
        rows,
        dim,
        ..
    } = support::content_rows(&dir)?;
    println!(
        "{} clips, {} classes, {} interval means; fold seeds 1..{seeds}\n",
        rows.len(),
        classes.len(),
        dim
    );

    let mut methods = vec!["forest, all".to_string()];
    methods.extend(KEPT.iter().map(|k| format!("forest, best {k}")));
    methods.push("diagonal LDA, all".to_string());
    methods.extend(KEPT.iter().map(|k| format!("diagonal LDA, best {k}")));
    let mut table = support::FTable::new(&methods);
    table.cross_validate(
        &labels,
        classes.len(),
        seeds,
        K,
        |fold, config, confusion| {
            let stats = ContentStatistics::fit(&fold.train, &rows, &labels, classes.len());
            let mut order: Vec<usize> = (0..dim).collect();
            order.sort_by(|&a, &b| stats.fisher[b].total_cmp(&stats.fisher[a]));
            let column_sets: Vec<Vec<usize>> = std::iter::once((0..dim).collect())
                .chain(KEPT.iter().map(|&k| order[..k.min(dim)].to_vec()))
                .collect();
            let train_labels: Vec<u32> = fold.train.iter().map(|&i| labels[i]).collect();
            for (m, columns) in column_sets.iter().enumerate() {
                let rows = &rows;
                let pick = |i: usize| columns.iter().map(move |&k| rows[i][k]);
                let train_rows: Vec<f32> = fold.train.iter().flat_map(|&i| pick(i)).collect();
                let samples =
                    Samples::new(&train_rows, columns.len(), &train_labels, classes.len())?;
                let forest = Forest::train(&samples, config, &|| {});
                let lda = column_sets.len() + m;
                for &i in &fold.test {
                    let row: Vec<f32> = pick(i).collect();
                    let truth = labels[i] as usize;
                    confusion[m].add(truth, argmax(&forest.predict(&row)));
                    confusion[lda].add(truth, stats.nearest_content(&rows[i], columns));
                }
            }
            Ok(())
        },
    )?;
    table.finish();
    Ok(())
}

/// Per interval mean, fitted on a fold's training clips: each content's
/// mean, the within-content variance (the mean squared deviation of a clip
/// from its content's mean) and the Fisher score.
struct ContentStatistics {
    means: Vec<Vec<f32>>,
    within: Vec<f32>,
    fisher: Vec<f32>,
}

impl ContentStatistics {
    fn fit(train: &[usize], rows: &[Vec<f32>], labels: &[u32], classes: usize) -> Self {
        let dim = rows[0].len();
        let mut means = vec![vec![0.0f32; dim]; classes];
        let mut counts = vec![0usize; classes];
        for &i in train {
            let c = labels[i] as usize;
            counts[c] += 1;
            for (m, x) in means[c].iter_mut().zip(&rows[i]) {
                *m += x;
            }
        }
        for (m, &n) in means.iter_mut().zip(&counts) {
            for v in m.iter_mut() {
                *v /= n.max(1) as f32;
            }
        }
        let mut within = vec![0.0f32; dim];
        for &i in train {
            let mean = &means[labels[i] as usize];
            for ((w, x), m) in within.iter_mut().zip(&rows[i]).zip(mean) {
                *w += (x - m).powi(2);
            }
        }
        // A small floor keeps constant interval means from dividing by zero.
        for w in within.iter_mut() {
            *w = (*w / train.len() as f32).max(1e-8);
        }
        let present: Vec<usize> = (0..classes).filter(|&c| counts[c] > 0).collect();
        let fisher = (0..dim)
            .map(|k| {
                let grand =
                    present.iter().map(|&c| means[c][k]).sum::<f32>() / present.len() as f32;
                let between = present
                    .iter()
                    .map(|&c| (means[c][k] - grand).powi(2))
                    .sum::<f32>()
                    / present.len() as f32;
                between / within[k]
            })
            .collect();
        ContentStatistics {
            means,
            within,
            fisher,
        }
    }

    /// Diagonal LDA: the content whose mean is nearest `row` over
    /// `columns`, each weighted by one over its within-content variance.
    fn nearest_content(&self, row: &[f32], columns: &[usize]) -> usize {
        let distance = |c: usize| {
            columns
                .iter()
                .map(|&k| (row[k] - self.means[c][k]).powi(2) / self.within[k])
                .sum::<f32>()
        };
        (0..self.means.len())
            .min_by(|&a, &b| distance(a).total_cmp(&distance(b)))
            .unwrap()
    }
}
