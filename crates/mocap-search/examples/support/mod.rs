//! What the dataset-1 content studies share: the clips of the content
//! classes the evaluation keeps (at least two clips), as interval means.

use std::error::Error;
use std::path::{Path, PathBuf};

use mocap_search::intervals::IntervalLayout;
use mocap_search::{load_clips, motion_files, LabelRule, NamePattern};

/// Clips resampled to this many frames, as the shipped forest reads them.
pub const N: usize = 10;

/// The kept clips of a folder of Bandai takes, labelled by content.
pub struct ContentRows {
    /// Every motion file of the folder.
    #[allow(dead_code)] // not every study reads the file names
    pub files: Vec<PathBuf>,
    /// The indices into `files` of the kept clips.
    #[allow(dead_code)]
    pub keep: Vec<usize>,
    /// The content classes with at least two clips, sorted.
    pub classes: Vec<String>,
    /// Per kept clip: its class (an index into `classes`) and its interval
    /// means (`dim` values).
    pub labels: Vec<u32>,
    pub rows: Vec<Vec<f32>>,
    pub dim: usize,
}

pub fn content_rows(dir: &Path) -> Result<ContentRows, Box<dyn Error>> {
    let files = motion_files(&[dir.to_path_buf()])?;
    let rule = LabelRule::FromName(NamePattern::parse("bandai-content")?);
    let clips = load_clips(&files, &rule, false)?;
    // Classes with at least two clips, as the evaluation keeps them.
    let mut classes: Vec<String> = clips.iter().map(|c| c.label.clone()).collect();
    classes.sort();
    classes.dedup();
    classes.retain(|c| clips.iter().filter(|k| &k.label == c).count() >= 2);
    let keep: Vec<usize> = (0..clips.len())
        .filter(|&i| classes.binary_search(&clips[i].label).is_ok())
        .collect();
    let labels = keep
        .iter()
        .map(|&i| classes.binary_search(&clips[i].label).unwrap() as u32)
        .collect();
    let layout = IntervalLayout::all(N, clips[0].features.dim);
    let rows = keep
        .iter()
        .map(|&i| layout.interval_means(&clips[i].features.resample(N)))
        .collect();
    Ok(ContentRows {
        files,
        keep,
        classes,
        labels,
        rows,
        dim: layout.dim(),
    })
}

/// The studies' table: one row of macro F per fold seed (every method's
/// confusion pooled over the folds), then the means over the seeds, over
/// the classes with at least 10 clips and over all classes.
pub struct FTable {
    methods: usize,
    seeds: usize,
    f_sum: Vec<f64>,
    f10_sum: Vec<f64>,
}

impl FTable {
    /// Prints the header.
    pub fn new<S: AsRef<str>>(methods: &[S]) -> FTable {
        let names: Vec<&str> = methods.iter().map(AsRef::as_ref).collect();
        println!("| seed | {} |", names.join(" | "));
        println!("| --- |{}", " ---: |".repeat(names.len()));
        FTable {
            methods: names.len(),
            seeds: 0,
            f_sum: vec![0.0; names.len()],
            f10_sum: vec![0.0; names.len()],
        }
    }

    /// Prints one seed's row (one confusion per method).
    pub fn add_seed(&mut self, seed: u64, confusion: &[mocap_search::scores::ConfusionMatrix]) {
        assert_eq!(confusion.len(), self.methods, "one confusion per method");
        let f: Vec<f64> = confusion
            .iter()
            .map(|m| m.macro_average().f_measure)
            .collect();
        for (i, m) in confusion.iter().enumerate() {
            self.f_sum[i] += f[i];
            self.f10_sum[i] += m.macro_average_over(10).f_measure;
        }
        self.seeds += 1;
        println!("| {seed} | {} |", cells(&f, 1.0, false));
    }

    /// The studies' cross-validation, a row per fold seed `1..=seeds`: the
    /// evaluation's deal of the clips to `k` folds
    /// ([`mocap_search::eval::stratified_folds`]), and for each fold the
    /// forest settings with the fold's own seed; `fold(fold, config,
    /// confusion)` adds the fold's test clips to one confusion per method.
    pub fn cross_validate(
        &mut self,
        labels: &[u32],
        classes: usize,
        seeds: u64,
        k: usize,
        mut fold: impl FnMut(
            &mocap_search::eval::Fold,
            &mocap_search::forest::ForestConfig,
            &mut [mocap_search::scores::ConfusionMatrix],
        ) -> Result<(), Box<dyn Error>>,
    ) -> Result<(), Box<dyn Error>> {
        for seed in 1..=seeds {
            let folds = mocap_search::eval::stratified_folds(labels, classes, k, seed)?;
            let mut confusion: Vec<_> = (0..self.methods)
                .map(|_| mocap_search::scores::ConfusionMatrix::new(classes))
                .collect();
            for (f, one) in folds.iter().enumerate() {
                let config = mocap_search::forest::ForestConfig {
                    seed: seed * 1000 + f as u64,
                    ..Default::default()
                };
                fold(one, &config, &mut confusion)?;
            }
            self.add_seed(seed, &confusion);
        }
        Ok(())
    }

    /// Prints the two rows of means.
    pub fn finish(self) {
        let n = self.seeds.max(1) as f64;
        println!(
            "| mean over the classes with >= 10 clips | {} |",
            cells(&self.f10_sum, n, false)
        );
        println!("| **mean** | {} |", cells(&self.f_sum, n, true));
    }
}

fn cells(values: &[f64], divide_by: f64, bold: bool) -> String {
    values
        .iter()
        .map(|v| {
            let v = v / divide_by;
            if bold {
                format!("**{v:.3}**")
            } else {
                format!("{v:.3}")
            }
        })
        .collect::<Vec<_>>()
        .join(" | ")
}
