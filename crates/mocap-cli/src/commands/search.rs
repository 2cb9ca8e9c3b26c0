//! `mocap search`: motion retrieval by example (mocap-search).

use std::path::PathBuf;

use anyhow::Context;
use mocap_search::{
    evaluate_files, find_in_take, index_files, EvalConfig, Index, IndexConfig, LabelRule, Ranking,
    SplitRule, TakeMethod, TakeSearchConfig,
};

use super::args::ReportArgs;
use super::{write_output, GlobalOptions};

#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: SearchCommand,
}

#[derive(clap::Subcommand)]
enum SearchCommand {
    /// Train the random forest on labelled clips and store the library index.
    Index(IndexArgs),
    /// Classify a clip and rank the library by similarity.
    Query(QueryArgs),
    /// Find the time ranges of a long take where a motion like the query happens.
    Find(FindArgs),
    /// Precision, recall and F per class for the forest and baselines, and ranking quality.
    Eval(EvalArgs),
}

/// Where each clip's category comes from (shared by `index` and `eval`).
#[derive(clap::Args)]
#[group(required = true, multiple = false)]
struct SearchLabelArgs {
    /// A CSV/TSV file of `path,label[,performer]` lines.
    #[arg(long)]
    labels: Option<PathBuf>,
    /// A file-name pattern with `{label}`, `{performer}`, `*`, or a preset:
    /// bandai-content, bandai-style, bandai-content-style, hdm05.
    #[arg(long, value_name = "PATTERN")]
    labels_from_name: Option<String>,
}

impl SearchLabelArgs {
    fn rule(&self) -> anyhow::Result<(LabelRule, String)> {
        Ok(LabelRule::from_options(
            self.labels.as_deref(),
            self.labels_from_name.as_deref(),
        )?)
    }
}

/// Forest settings shared by `index` and `eval`.
#[derive(clap::Args)]
struct SearchForestArgs {
    /// Number of trees.
    #[arg(long, default_value_t = 100)]
    trees: usize,
    /// Random (value, interval) candidates tried at each node.
    #[arg(long, default_value_t = 64)]
    candidates: usize,
    /// A node with at most this class entropy (bits) becomes a leaf.
    #[arg(long, default_value_t = 0.0)]
    min_entropy: f32,
    /// Frames each clip is resampled to.
    #[arg(long, default_value_t = 10)]
    frames: usize,
    /// Seed of the random numbers (same seed and data: same forest).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Train every tree on all clips instead of a bootstrap sample.
    #[arg(long)]
    no_bootstrap: bool,
}

impl SearchForestArgs {
    fn config(&self) -> IndexConfig {
        let mut config = IndexConfig {
            frames: self.frames,
            ..IndexConfig::default()
        };
        config.forest.trees = self.trees;
        config.forest.tree.candidates_per_node = Some(self.candidates);
        config.forest.tree.min_entropy = self.min_entropy;
        config.forest.seed = self.seed;
        config.forest.bootstrap = !self.no_bootstrap;
        config
    }
}

#[derive(clap::Args)]
struct IndexArgs {
    /// Clip files or folders (searched recursively for .bvh and .amc).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    #[command(flatten)]
    labels: SearchLabelArgs,
    #[command(flatten)]
    forest: SearchForestArgs,
    /// The index file to write.
    #[arg(long, short)]
    output: PathBuf,
}

#[derive(clap::Args)]
struct QueryArgs {
    /// The query clip (BVH, or AMC next to its ASF).
    clip: PathBuf,
    /// The library to search (from `mocap search index`).
    #[arg(long)]
    index: PathBuf,
    /// Number of library clips to list.
    #[arg(long, default_value_t = 10)]
    top: usize,
    /// histogram (the report's eq. 8; measured best, also for classes the forest never saw),
    /// proximity (forest path proximity) or features (distance between the clips' features).
    #[arg(long, default_value = "histogram")]
    rank: Ranking,
    /// Print the result as JSON on standard output.
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args)]
struct FindArgs {
    /// The query clip.
    clip: PathBuf,
    /// The long take to search in.
    #[arg(long = "in", value_name = "TAKE")]
    take: PathBuf,
    /// The library whose forest compares the query and the take's windows.
    #[arg(long)]
    index: PathBuf,
    /// Number of time ranges to list.
    #[arg(long, default_value_t = 10)]
    top: usize,
    /// windows (sliding windows of several lengths) or dtw (subsequence DTW).
    #[arg(long, default_value = "windows")]
    method: TakeMethod,
    /// How windows are compared with the query: histogram, proximity or features (as for query).
    #[arg(long, default_value = "histogram")]
    rank: Ranking,
    /// Print the time ranges as JSON on standard output.
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args)]
struct EvalArgs {
    /// Folders or files of labelled clips (the training clips when --test is given).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    #[command(flatten)]
    labels: SearchLabelArgs,
    #[command(flatten)]
    forest: SearchForestArgs,
    /// Stratified K-fold cross-validation by take.
    #[arg(long, default_value_t = 5)]
    folds: usize,
    /// Split by performer (from the label rule) instead of folds.
    #[arg(long)]
    by_performer: bool,
    /// Test on these clips (files or folders) instead of cross-validating; every path after
    /// --test is a test path, so give the training inputs first.
    #[arg(long, num_args = 1..)]
    test: Vec<PathBuf>,
    /// Skip the deterministic tree, random tree and DTW baselines.
    #[arg(long)]
    no_baselines: bool,
    /// Skip the unseen-class experiment.
    #[arg(long)]
    no_unseen: bool,
    /// Skip the long-take experiment.
    #[arg(long)]
    no_takes: bool,
    /// The data's name in the report.
    #[arg(long)]
    name: Option<String>,
    #[command(flatten)]
    report: ReportArgs,
    /// Write a confusion matrix per method here (`confusion-<method>.png` and `.svg`).
    #[arg(long, value_name = "DIR")]
    plots: Option<PathBuf>,
}

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    let progress = !options.quiet;
    match args.command {
        SearchCommand::Index(a) => {
            let (rule, rule_name) = a.labels.rule()?;
            let index = index_files(&a.inputs, &rule, &rule_name, &a.forest.config(), progress)?;
            index.save(&a.output)?;
            if !options.quiet {
                let plural = |n: usize, one: &str, many: &str| {
                    format!("{n} {}", if n == 1 { one } else { many })
                };
                eprintln!(
                    "indexed {} of {} into {}",
                    plural(index.clips.len(), "clip", "clips"),
                    plural(index.classes.len(), "class", "classes"),
                    a.output.display()
                );
            }
        }
        SearchCommand::Query(a) => {
            let report = Index::load(&a.index)?.query_file(&a.clip, a.top, a.rank)?;
            print_result(&report, a.json, || report.to_text())?;
            let missing = report.missing_clips();
            if missing > 0 && !options.quiet {
                eprintln!(
                    "note: {missing} of the {} clips listed are not where {} says (it stores them \
                     relative to its own folder: was it moved without them?)",
                    report.matches.len(),
                    a.index.display()
                );
            }
        }
        SearchCommand::Find(a) => {
            let config = TakeSearchConfig {
                method: a.method,
                ranking: a.rank,
                top: a.top,
                ..TakeSearchConfig::default()
            };
            let report = find_in_take(&Index::load(&a.index)?, &a.clip, &a.take, &config)?;
            print_result(&report, a.json, || report.to_text())?;
        }
        SearchCommand::Eval(a) => {
            let (rule, rule_name) = a.labels.rule()?;
            let config = EvalConfig {
                index: a.forest.config(),
                split: if a.by_performer {
                    SplitRule::ByPerformer
                } else {
                    SplitRule::Folds { k: a.folds }
                },
                seed: a.forest.seed,
                baselines: !a.no_baselines,
                unseen_classes: !a.no_unseen,
                takes: !a.no_takes,
                progress,
                ..EvalConfig::default()
            };
            let report = evaluate_files(
                &a.inputs,
                &a.test,
                &rule,
                &rule_name,
                a.name.as_deref(),
                &config,
            )?;
            let markdown = report.to_markdown();
            if a.report.json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&report).context("writing JSON")?
                );
            } else {
                println!("{markdown}");
            }
            if let Some(path) = &a.report.markdown {
                write_output(Some(path), |w| w.write_all(markdown.as_bytes()))?;
            }
            if let Some(dir) = &a.plots {
                let written = report.plot_confusions(dir)?;
                if !options.quiet {
                    eprintln!("wrote {written} confusion matrices to {}", dir.display());
                }
            }
        }
    }
    Ok(())
}

/// Prints a result as pretty JSON or as the text `to_text` gives.
fn print_result<T: serde::Serialize>(
    value: &T,
    json: bool,
    to_text: impl FnOnce() -> String,
) -> anyhow::Result<()> {
    let text = if json {
        serde_json::to_string_pretty(value).context("writing JSON")?
    } else {
        to_text()
    };
    write_output(None, |w| writeln!(w, "{text}"))
}
