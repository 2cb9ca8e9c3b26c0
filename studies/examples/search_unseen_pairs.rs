//! Is dataset-1's content F low because each test
//! clip shows its content in a style the forest never saw *with that
//! content*? Measured on dataset-2, whose 70 (content, style) pairs hold
//! about 14 takes each, by splits that put dataset-2 in dataset-1's place.
//!
//! ```text
//! cargo run --profile test -p mocap-studies --example search_unseen_pairs -- \
//!     ../shared/data/bandai/dataset-2 [SEEDS] > bench/search/out/unseen-pairs.md
//! ```
//!
//! Splits (forest as shipped; macro F over the contents, pooled confusion):
//!
//! - **5-fold by take**: the evaluation's split (every pair seen in
//!   training with its other takes);
//! - **one take per pair, pairs seen**: one random take of every pair
//!   trains, every other take tests;
//! - **pair left out**: for every pair in turn, all takes of the other
//!   pairs train and its takes test (the content was seen in the other
//!   styles, the style with the other contents: dataset-1's situation with
//!   14 times its takes);
//! - **pair left out, one take per other pair**: as above with one random
//!   take of each other pair (dataset-1's situation at about half its
//!   training size);
//! - **style left out**: for every style in turn, the other styles train.
//!
//! The 5-fold deals and the random takes use seeds 1..SEEDS; the pair and
//! style left out with all takes draw nothing and run once.

use std::path::PathBuf;

use rand::rngs::Xoshiro256PlusPlus;
use rand::seq::IndexedRandom;
use rand::SeedableRng;

use mocap_search::stratified_folds;
use mocap_search::{
    argmax, load_clips, motion_files, ConfusionMatrix, Forest, ForestConfig, IntervalLayout,
    LabelRule, NamePattern, Samples,
};

const N: usize = 10;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let dir = PathBuf::from(
        args.next()
            .ok_or("usage: search_unseen_pairs DIR [SEEDS]")?,
    );
    let seeds: u64 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(3);
    let files = motion_files(&[dir])?;
    let content_rule = LabelRule::FromName(NamePattern::parse("bandai-content")?);
    let style_rule = LabelRule::FromName(NamePattern::parse("bandai-style")?);
    let clips = load_clips(&files, &content_rule, false)?;
    let index_of = |names: &mut Vec<String>, name: &str| match names.iter().position(|n| n == name)
    {
        Some(i) => i,
        None => {
            names.push(name.to_string());
            names.len() - 1
        }
    };
    let (mut contents, mut styles) = (Vec::new(), Vec::new());
    let content: Vec<usize> = clips
        .iter()
        .map(|c| index_of(&mut contents, &c.label))
        .collect();
    let style: Vec<usize> = files
        .iter()
        .map(|p| Ok(index_of(&mut styles, &style_rule.label_of(p)?.label)))
        .collect::<Result<_, mocap_search::SearchError>>()?;
    let pair: Vec<usize> = (0..clips.len())
        .map(|i| content[i] * styles.len() + style[i])
        .collect();
    let pairs = contents.len() * styles.len();
    let layout = IntervalLayout::all(N, clips[0].features.dim);
    let rows: Vec<Vec<f32>> = clips
        .iter()
        .map(|c| layout.interval_means(&c.features.resample(N)))
        .collect();
    println!(
        "{} clips, {} contents x {} styles, {} interval means; random takes drawn with seeds 1..{seeds}\n",
        rows.len(),
        contents.len(),
        styles.len(),
        layout.dim()
    );
    let classifier = Classifier {
        rows: &rows,
        labels: &content,
        classes: contents.len(),
    };
    let all: Vec<usize> = (0..clips.len()).collect();
    let members = |group: &dyn Fn(usize) -> bool| -> Vec<usize> {
        all.iter().copied().filter(|&i| group(i)).collect()
    };

    println!("| split | training clips per forest | forests | seed | F (contents) | accuracy |");
    println!("| --- | ---: | ---: | ---: | ---: | ---: |");
    let classes = contents.len();

    // The evaluation's split.
    let labels: Vec<u32> = content.iter().map(|&c| c as u32).collect();
    for seed in 1..=seeds {
        let mut tally = Tally::new(classes);
        for (f, fold) in stratified_folds(&labels, classes, 5, seed)?
            .iter()
            .enumerate()
        {
            classifier.add(&fold.train, &fold.test, seed * 1000 + f as u64, &mut tally)?;
        }
        tally.print("5-fold by take", &seed.to_string());
    }
    // Style left out: no random draw.
    let mut tally = Tally::new(classes);
    for s in 0..styles.len() {
        let (train, test) = (members(&|i| style[i] != s), members(&|i| style[i] == s));
        classifier.add(&train, &test, 1000 + s as u64, &mut tally)?;
    }
    tally.print("style left out", "-");
    // Pair left out, all takes of the other pairs.
    let mut tally = Tally::new(classes);
    for p in 0..pairs {
        let (train, test) = (members(&|i| pair[i] != p), members(&|i| pair[i] == p));
        if !test.is_empty() {
            classifier.add(&train, &test, 1000 + p as u64, &mut tally)?;
        }
    }
    tally.print("pair left out", "-");
    for seed in 1..=seeds {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        // One random take of every pair.
        let one_take: Vec<usize> = (0..pairs)
            .filter_map(|p| members(&|i| pair[i] == p).choose(&mut rng).copied())
            .collect();
        let mut tally = Tally::new(classes);
        let rest = members(&|i| !one_take.contains(&i));
        classifier.add(&one_take, &rest, seed, &mut tally)?;
        tally.print("one take per pair, pairs seen", &seed.to_string());
        let mut tally = Tally::new(classes);
        for p in 0..pairs {
            let test = members(&|i| pair[i] == p);
            let train: Vec<usize> = one_take.iter().copied().filter(|&i| pair[i] != p).collect();
            if !test.is_empty() {
                classifier.add(&train, &test, seed * 1000 + p as u64, &mut tally)?;
            }
        }
        tally.print("pair left out, one take per other pair", &seed.to_string());
    }
    Ok(())
}

/// One split's pooled confusion, with how many forests were trained and on
/// how many clips in all.
struct Tally {
    confusion: ConfusionMatrix,
    forests: usize,
    training_clips: usize,
}

impl Tally {
    fn new(classes: usize) -> Self {
        Tally {
            confusion: ConfusionMatrix::new(classes),
            forests: 0,
            training_clips: 0,
        }
    }

    fn print(&self, split: &str, seed: &str) {
        println!(
            "| {split} | {:.0} | {} | {seed} | {:.3} | {:.3} |",
            self.training_clips as f64 / self.forests.max(1) as f64,
            self.forests,
            self.confusion.macro_average().f_measure,
            self.confusion.accuracy()
        );
    }
}

/// Trains the shipped forest on some clips and tests it on others.
struct Classifier<'a> {
    rows: &'a [Vec<f32>],
    labels: &'a [usize],
    classes: usize,
}

impl Classifier<'_> {
    /// Trains on `train`, adds every clip of `test` to `confusion`.
    fn add(
        &self,
        train: &[usize],
        test: &[usize],
        seed: u64,
        tally: &mut Tally,
    ) -> Result<(), String> {
        let dim = self.rows[0].len();
        let train_rows: Vec<f32> = train.iter().flat_map(|&i| self.rows[i].clone()).collect();
        let train_labels: Vec<u32> = train.iter().map(|&i| self.labels[i] as u32).collect();
        let samples = Samples::new(&train_rows, dim, &train_labels, self.classes)?;
        let config = ForestConfig {
            seed,
            ..ForestConfig::default()
        };
        let forest = Forest::train(&samples, &config, &|| {});
        for &i in test {
            tally
                .confusion
                .add(self.labels[i], argmax(&forest.predict(&self.rows[i])));
        }
        tally.forests += 1;
        tally.training_clips += train.len();
        Ok(())
    }
}
