//! `mocap search`: motion retrieval by example (mocap-search).

use std::path::PathBuf;

use anyhow::{bail, Context};
use mocap_search::eval::evaluate_train_test;
use mocap_search::take::{TakeMethod, TakeReport};
use mocap_search::{
    build_index, evaluate, load_clips, load_features, motion_files, search_take, EvalConfig, Index,
    IndexConfig, LabelFile, LabelRule, NamePattern, Ranking, SplitRule, TakeSearchConfig,
};

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

/// Where each clip's category comes from.
#[derive(clap::Args)]
#[group(required = true, multiple = false)]
struct LabelArgs {
    /// A CSV/TSV file of `path,label[,performer]` lines.
    #[arg(long)]
    labels: Option<PathBuf>,
    /// A file-name pattern with `{label}`, `{performer}`, `*`, or a preset:
    /// bandai-content, bandai-style, bandai-content-style, hdm05.
    #[arg(long, value_name = "PATTERN")]
    labels_from_name: Option<String>,
}

impl LabelArgs {
    fn rule(&self) -> anyhow::Result<(LabelRule, String)> {
        Ok(match (&self.labels, &self.labels_from_name) {
            (Some(file), _) => (
                LabelRule::FromFile(LabelFile::read(file)?),
                file.display().to_string(),
            ),
            (None, Some(pattern)) => (
                LabelRule::FromName(NamePattern::parse(pattern)?),
                pattern.clone(),
            ),
            (None, None) => bail!("give --labels FILE or --labels-from-name PATTERN"),
        })
    }
}

/// Forest settings shared by `index` and `eval`.
#[derive(clap::Args)]
struct ForestArgs {
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

impl ForestArgs {
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
    labels: LabelArgs,
    #[command(flatten)]
    forest: ForestArgs,
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
    #[arg(long, default_value = "windows", value_parser = ["windows", "dtw"])]
    method: String,
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
    labels: LabelArgs,
    #[command(flatten)]
    forest: ForestArgs,
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
    /// Print JSON instead of Markdown.
    #[arg(long)]
    json: bool,
    /// Also write the report to this file.
    #[arg(long, short)]
    output: Option<PathBuf>,
    /// Write a confusion matrix per method here (`confusion-<method>.png` and `.svg`).
    #[arg(long, value_name = "DIR")]
    plots: Option<PathBuf>,
}

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    let progress = !options.quiet;
    match args.command {
        SearchCommand::Index(a) => {
            let (rule, rule_name) = a.labels.rule()?;
            let clips = load_clips(&motion_files(&a.inputs)?, &rule, progress)?;
            let index = build_index(&clips, &rule_name, &a.forest.config(), progress)?;
            index.save(&a.output)?;
            if !options.quiet {
                let plural = |n: usize, one: &str, many: &str| {
                    format!("{n} {}", if n == 1 { one } else { many })
                };
                eprintln!(
                    "indexed {} of {} into {}",
                    plural(clips.len(), "clip", "clips"),
                    plural(index.classes.len(), "class", "classes"),
                    a.output.display()
                );
            }
        }
        SearchCommand::Query(a) => {
            let index = Index::load(&a.index)?;
            let (features, _fps) = load_features(&a.clip)?;
            let report = index.query(&a.clip.display().to_string(), &features, a.top, a.rank);
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
            let index = Index::load(&a.index)?;
            let (query, query_fps) = load_features(&a.clip)?;
            let (take, take_fps) = load_features(&a.take)?;
            let method = match a.method.as_str() {
                "windows" => TakeMethod::Windows,
                "dtw" => TakeMethod::SubsequenceDtw,
                other => bail!("--method {other:?}: expected windows or dtw"),
            };
            let config = TakeSearchConfig {
                method,
                ranking: a.rank,
                top: a.top,
                ..TakeSearchConfig::default()
            };
            let matches = search_take(&index, &query, query_fps, &take, take_fps, &config)?;
            let report = TakeReport {
                query: a.clip.display().to_string(),
                take: a.take.display().to_string(),
                take_seconds: take.frame_count() as f64 / take_fps,
                matches,
            };
            print_result(&report, a.json, || report.to_text())?;
        }
        SearchCommand::Eval(a) => {
            let (rule, rule_name) = a.labels.rule()?;
            let mut config = EvalConfig {
                index: a.forest.config(),
                seed: a.forest.seed,
                baselines: !a.no_baselines,
                unseen_classes: !a.no_unseen,
                takes: !a.no_takes,
                progress,
                ..EvalConfig::default()
            };
            config.split = if a.by_performer {
                SplitRule::ByPerformer
            } else {
                SplitRule::Folds { k: a.folds }
            };
            let dataset = a.name.clone().unwrap_or_else(|| {
                let names: Vec<String> = a.inputs.iter().map(|d| d.display().to_string()).collect();
                names.join(" + ")
            });
            let clips = load_clips(&motion_files(&a.inputs)?, &rule, progress)?;
            let report = if a.test.is_empty() {
                evaluate(&clips, &dataset, &rule_name, &config)?
            } else {
                let test = load_clips(&motion_files(&a.test)?, &rule, progress)?;
                evaluate_train_test(&clips, &test, &dataset, &rule_name, &config)?
            };
            let text = if a.json {
                serde_json::to_string_pretty(&report).context("writing JSON")?
            } else {
                report.to_markdown()
            };
            println!("{text}");
            if let Some(path) = &a.output {
                write_output(Some(path), |w| w.write_all(text.as_bytes()))?;
            }
            if let Some(dir) = &a.plots {
                let written = plot_confusions(&report, dir)?;
                if !options.quiet {
                    eprintln!("wrote {written} confusion matrices to {}", dir.display());
                }
            }
        }
    }
    Ok(())
}

/// One confusion matrix per method (rows: true class, as fractions of the
/// row: each row's diagonal is the class's recall), PNG and SVG.
fn plot_confusions(
    report: &mocap_search::EvalReport,
    dir: &std::path::Path,
) -> anyhow::Result<usize> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let classes = report.classes.len();
    let side = (240 + 28 * classes as u32).min(2000);
    let mut written = 0;
    for method in &report.methods {
        let counts = (0..classes)
            .map(|truth| {
                (0..classes)
                    .map(|predicted| method.confusion.count(truth, predicted) as f32)
                    .collect()
            })
            .collect();
        let plot = mocap_view::ConfusionPlot {
            title: format!("{} (accuracy {:.3})", method.method, method.accuracy),
            labels: report.classes.clone(),
            counts,
            normalise_rows: true,
            size: (side, side),
        };
        let stem: String = method
            .method
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() {
                    c.to_ascii_lowercase()
                } else {
                    '-'
                }
            })
            .collect();
        for extension in ["png", "svg"] {
            let path = dir.join(format!("confusion-{stem}.{extension}"));
            mocap_view::plot_confusion(&path, &plot)
                .with_context(|| format!("drawing {}", path.display()))?;
        }
        written += 1;
    }
    Ok(written)
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
