//! Argument groups that several subcommands share, so that one thing has one
//! flag everywhere (`#[command(flatten)]` them). The rules of the command
//! line, checked by the `cli_language` test in `main.rs`:
//!
//! - `-o/--output PATH` names what a command writes (a file or a folder);
//! - `--json` is a switch that prints the result as JSON on standard output;
//! - `--markdown FILE` writes a report's tables as Markdown;
//! - `--device`, `--seed` and the training loop's options come from the groups
//!   below;
//! - one flag per thing (no `--no-x` beside a `--method` that says the same);
//! - at most 15 options of a subcommand's own, besides these groups.

use std::path::PathBuf;

use mocap_nn::device::DeviceChoice;

/// `--feet`: the stage of `mocap feet` run on a command's output before it
/// is written.
#[derive(clap::Args, Clone, Debug)]
pub struct FeetArgs {
    /// Then hold the output's planted feet still and above the floor, as `mocap feet` does
    /// (body parts found by joint name or `--rig`).
    #[arg(long)]
    pub feet: bool,
}

impl FeetArgs {
    /// The feet stage's options, when asked for.
    pub fn options(&self) -> Option<mocap_feet::FeetOptions> {
        self.feet.then(mocap_feet::FeetOptions::default)
    }
}

/// `--device`: where the networks run.
#[derive(clap::Args, Clone, Debug)]
pub struct DeviceArgs {
    /// cpu, or cuda[:N] in a build with the `cuda` feature.
    #[arg(long, default_value = "cpu")]
    pub device: DeviceChoice,
}

/// `--json` and `--markdown FILE`: how an evaluation reports.
#[derive(clap::Args, Clone, Debug)]
pub struct ReportArgs {
    /// Print the report as JSON on standard output instead of Markdown.
    #[arg(long)]
    pub json: bool,
    /// Also write the report's Markdown tables to this file.
    #[arg(long, value_name = "FILE")]
    pub markdown: Option<PathBuf>,
}

/// The training loop of every network (`mocap clean train`, `mocap style train`;
/// flatten [`DeviceArgs`] beside it: clap keeps no options in a group that
/// flattens another).
#[derive(clap::Args, Clone, Debug)]
pub struct TrainLoopArgs {
    /// Training epochs (default: the recipe's).
    #[arg(long)]
    pub epochs: Option<usize>,
    /// Training steps per epoch (default: the recipe's).
    #[arg(long)]
    pub steps: Option<usize>,
    /// Windows per step (default: the recipe's).
    #[arg(long)]
    pub batch: Option<usize>,
    /// Adam learning rate (default: the recipe's).
    #[arg(long)]
    pub lr: Option<f64>,
    /// Seed of the weights, the windows drawn and the noise: the same seed and data give the
    /// same model.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Continue an interrupted run from its state folder.
    #[arg(long)]
    pub resume: bool,
    /// Training and validation curves as PNG (default: OUTPUT with extension png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

/// Overrides a default when the option was given.
pub fn set<T>(slot: &mut T, value: Option<T>) {
    if let Some(v) = value {
        *slot = v;
    }
}
