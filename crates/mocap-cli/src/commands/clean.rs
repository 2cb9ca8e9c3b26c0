//! `mocap clean`: denoise a take with the learned model or a classical filter,
//! train a denoiser, evaluate methods (all in `mocap-clean`).
//!
//! `mocap clean IN -o OUT` cleans one take; `mocap clean train` and
//! `mocap clean eval` are subcommands. A take literally named `train` or
//! `eval` can be cleaned as `mocap clean ./train -o OUT`.

use std::path::PathBuf;

use anyhow::{bail, Context};
use mocap_clean::despike::DespikeOptions;
use mocap_clean::eval::{evaluate, EvalOptions, ModelEntry};
use mocap_clean::features::{Representation, RotationFrame};
use mocap_clean::filters::Filter;
use mocap_clean::infer::{clean_file, BridgedSpike, CleanOptions, FindSpikes, Method};
use mocap_clean::model::DenoiserConfig;
use mocap_clean::spikes::SpikeOptions;
use mocap_clean::training::{train, TrainOptions};
use mocap_clean::wiener::{fit_files, WienerFitOptions};
use mocap_nn::device::DeviceChoice;

use super::{write_output, GlobalOptions};

#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct Args {
    #[command(subcommand)]
    command: Option<CleanCommand>,
    #[command(flatten)]
    take: TakeArgs,
}

#[derive(clap::Subcommand)]
enum CleanCommand {
    /// Train a denoiser on clean takes with synthetic markerless noise.
    Train(Box<TrainArgs>),
    /// Noisy input, tuned filters and models on held-out takes: rotation, position and acceleration errors.
    Eval(EvalArgs),
}

/// `mocap clean IN -o OUT`.
#[derive(clap::Args)]
struct TakeArgs {
    /// The take to clean (BVH).
    #[arg(required = true)]
    input: Option<PathBuf>,
    /// The cleaned take (BVH: same skeleton and channel layout, root translation kept).
    #[arg(long, short, required = true)]
    output: Option<PathBuf>,
    /// A file written by `mocap clean train`: a network, or a Wiener filter (`--wiener`)
    /// (default: the model shipped with mocap).
    #[arg(long, conflicts_with = "filter")]
    model: Option<PathBuf>,
    /// A classical filter instead of a model: butterworth:ORDER:HZ,
    /// butterworth-gcv:ORDER (cutoff chosen per channel from the take itself), savitzky-golay:WINDOW:POLYORDER, median:WINDOW or one-euro:MIN_HZ:BETA:D_HZ.
    #[arg(long, value_name = "SPEC")]
    filter: Option<Filter>,
    /// cpu, or cuda[:N] in a build with the `cuda` feature.
    #[arg(long, default_value = "cpu")]
    device: DeviceChoice,
    /// Frames between window starts (default: a quarter window).
    #[arg(long)]
    hop: Option<usize>,
    /// Before cleaning, find spikes (a joint and its subtree jumping away and back) in the take and
    /// bridge them; see bench/results/clean.md for what it gains and costs.
    #[arg(long)]
    despike: bool,
    /// Only find and bridge spikes (with --despike), no denoising: for takes with spikes and little
    /// random noise (see bench/results/clean.md).
    #[arg(long, requires = "despike", conflicts_with_all = ["model", "filter"])]
    despike_only: bool,
    /// Spike finding: a boundary is a subtree jump this many times the joints' upper-quartile jump
    /// (default 3).
    #[arg(long, requires = "despike")]
    despike_threshold: Option<f32>,
    /// Spike finding: frames averaged on each side of a boundary (default 1).
    #[arg(long, requires = "despike", value_name = "FRAMES", value_parser = frames_at_least_one)]
    despike_span: Option<usize>,
    /// Spike finding: the longest spike looked for, in frames (default 90).
    #[arg(long, requires = "despike", value_name = "FRAMES", value_parser = frames_at_least_one)]
    despike_max_frames: Option<usize>,
    /// Before cleaning, find spikes (a joint and its subtree taking another motion's rotations) with
    /// this learned detector, written by `mocap clean train --spike-detector`, and bridge them.
    /// Experimental, none ships: see bench/results/clean.md.
    #[arg(long, value_name = "FILE")]
    spike_model: Option<PathBuf>,
    /// Probability from which the detector's marks are bridged (default 0.5).
    #[arg(long, requires = "spike_model")]
    spike_threshold: Option<f32>,
    /// Print the report as JSON on standard output.
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("base").args(["base_filter", "base_wiener"])))]
struct TrainArgs {
    /// Folders or files of clean BVH takes (split by take into train / validation / test).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// The model file to write (safetensors).
    #[arg(long, short)]
    output: PathBuf,
    /// Training epochs (default 20).
    #[arg(long)]
    epochs: Option<usize>,
    /// Training steps per epoch.
    #[arg(long)]
    steps: Option<usize>,
    /// Windows per step (report: 512).
    #[arg(long)]
    batch: Option<usize>,
    /// Adam learning rate (report: 1e-3).
    #[arg(long)]
    lr: Option<f64>,
    /// Seed of the weights, the windows drawn and the noise (default 1): the same seed and data
    /// give the same model.
    #[arg(long)]
    seed: Option<u64>,
    /// `derivative` (rotation + velocity + acceleration terms, alpha = dt^2, beta = dt^4) or `mse`.
    #[arg(long, default_value = "derivative", value_parser = ["derivative", "mse"])]
    loss: String,
    /// rot6d, expmap or euler.
    #[arg(long)]
    representation: Option<Representation>,
    /// Which rotation of each joint the network sees: `local` (relative to the parent, as in BVH) or
    /// `pelvis` (relative to the pelvis; see bench/results/clean.md).
    #[arg(long)]
    rotations: Option<RotationFrame>,
    /// A classical filter (same SPEC as `mocap clean --filter`) whose output the network corrects,
    /// instead of correcting its input (see bench/results/clean.md).
    #[arg(long, value_name = "SPEC")]
    base_filter: Option<Filter>,
    /// With --base-filter or --base-wiener: frames of the take the filter sees on each side of a training window;
    /// the trained model then filters whole takes at once (for `butterworth-gcv`, whose cutoff
    /// needs a long stretch to be chosen well). 0: each window alone.
    #[arg(long, value_name = "FRAMES", requires = "base")]
    base_context: Option<usize>,
    /// A Wiener filter (from `mocap clean train --wiener`) whose output the network corrects, instead
    /// of a classical --base-filter; the model file then holds both. Use with --base-context.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["base_filter", "spike_detector", "position_weight"])]
    base_wiener: Option<PathBuf>,
    /// With --base-wiener: the network also reads the filter's output and the noise level it
    /// estimated, and scales its correction by that level, so it leaves a clean take alone (see
    /// bench/results/clean.md).
    #[arg(long, requires = "base_wiener")]
    base_input: bool,
    /// Weight of the joint-position term added to the loss (0: off; see bench/results/clean.md).
    #[arg(long)]
    position_weight: Option<f32>,
    /// The report's large network (for a GPU) instead of the small default.
    #[arg(long)]
    large: bool,
    /// Channels of the first level.
    #[arg(long)]
    width: Option<usize>,
    /// Times the network halves the time axis.
    #[arg(long)]
    levels: Option<usize>,
    /// Residual blocks per level.
    #[arg(long)]
    blocks: Option<usize>,
    /// Window length in frames (report: 16).
    #[arg(long)]
    window: Option<usize>,
    /// Largest standard deviation of the random noise, degrees (report: 10).
    #[arg(long, value_name = "MAX", value_parser = degrees_at_least_zero)]
    max_sigma: Option<f32>,
    /// Also put random noise on the joints above the pelvis (helper joints such as Bandai's
    /// `joint_Root` on the floor; off by default, see bench/results/clean.md).
    #[arg(long)]
    noise_above_pelvis: bool,
    /// Probability that a training window gets spikes.
    #[arg(long)]
    spike_probability: Option<f32>,
    /// At most this many simultaneous spikes (report: 3).
    #[arg(long)]
    max_spikes: Option<usize>,
    /// Standard deviation of a spike's duration in frames (report: 16).
    #[arg(long)]
    spike_sigma: Option<f32>,
    /// Train on at most this many takes (quick runs).
    #[arg(long)]
    max_train_takes: Option<usize>,
    /// Folder of the resumable training state (default: OUTPUT.state).
    #[arg(long)]
    state: Option<PathBuf>,
    /// Continue an interrupted run from its state folder.
    #[arg(long)]
    resume: bool,
    /// Train a spike detector (for `mocap clean --spike-model`) instead of a denoiser:
    /// the same network with one output per joint and frame, trained to mark the synthetic spikes.
    #[arg(long, conflicts_with_all = ["base_filter", "position_weight"])]
    spike_detector: bool,
    /// Fit a learned multichannel Wiener filter instead of training a network (a minute, not
    /// twenty: the spectra of the clean training takes and the covariance of the random noise;
    /// `mocap clean --model` and `mocap clean eval --model` take the file; see
    /// bench/results/clean.md).
    #[arg(long, conflicts_with_all = [
        "spike_detector", "base_filter", "resume", "large", "epochs", "steps", "batch", "lr",
        "representation", "rotations", "position_weight", "width", "levels", "blocks", "window",
        "max_sigma", "spike_probability", "max_spikes", "spike_sigma", "plot", "state", "base_wiener",
        "base_context", "base_input",
    ])]
    wiener: bool,
    /// With --wiener: frames per Fourier segment (default 32).
    #[arg(long, value_name = "FRAMES", requires = "wiener")]
    segment: Option<usize>,
    /// With --wiener: fit a mixture, one set of spectra per content named in the file names
    /// (`<set>_<content>_<style>_<take>`) with at least this many training segments (150 for the
    /// shipped one), plus one for the rest and one for all; each take is cleaned with the one
    /// that fits it best.
    #[arg(long, value_name = "MIN_SEGMENTS", requires = "wiener", value_parser = clap::value_parser!(u32).range(1..))]
    mixture: Option<u32>,
    /// With --mixture: build the mixture from the Wiener filter this network model corrects and
    /// write the network (not retrained) with the mixture under it.
    #[arg(long, value_name = "MODEL", requires = "mixture")]
    rebase: Option<PathBuf>,
    /// Training and validation curves as PNG (default: OUTPUT with extension png).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// cpu, or cuda[:N] in a build with the `cuda` feature.
    #[arg(long, default_value = "cpu")]
    device: DeviceChoice,
    /// Print the report as JSON on standard output.
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args)]
struct EvalArgs {
    /// Folders or files of clean BVH takes.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// A model to compare, as LABEL=FILE or FILE (repeatable; the shipped model is always included
    /// unless --no-default-model).
    #[arg(long = "model", value_name = "[LABEL=]FILE")]
    models: Vec<String>,
    /// Leave out the shipped model.
    #[arg(long)]
    no_default_model: bool,
    /// Leave out the classical filters.
    #[arg(long)]
    no_filters: bool,
    /// Also run every method after spike finding on the noisy input (settings tuned per method on
    /// validation takes).
    #[arg(long)]
    despike: bool,
    /// Also run this learned spike detector (from `mocap clean train --spike-detector`) alone and
    /// before the first filter and every model.
    #[arg(long, value_name = "FILE")]
    spike_model: Option<PathBuf>,
    /// Evaluate every take, not only the test split (for data the models were not trained on);
    /// the filters and spike finding are then tuned on the first --tune-takes of those same takes,
    /// which flatters them (the report says so).
    #[arg(long)]
    all_takes: bool,
    /// Evaluate at most this many takes.
    #[arg(long)]
    max_takes: Option<usize>,
    /// Validation takes used to tune the filters.
    #[arg(long)]
    tune_takes: Option<usize>,
    /// Spike lengths (frames) of the spike-survival study, comma separated; `none` to skip.
    #[arg(long, value_name = "N,N,...")]
    spike_lengths: Option<String>,
    /// Also put random noise on the joints above the pelvis (the noise of models trained before
    /// this became the default; see bench/results/clean.md).
    #[arg(long)]
    noise_above_pelvis: bool,
    /// Largest standard deviation of the random noise, degrees; each take draws its own in
    /// [0, MAX] (default: the report's 10; 0 measures what a method does to clean takes).
    #[arg(long, value_name = "MAX", value_parser = degrees_at_least_zero)]
    max_sigma: Option<f32>,
    /// Seed of the noise put on the takes (default 1): the same seed gives the same figures.
    #[arg(long)]
    seed: Option<u64>,
    /// cpu, or cuda[:N] in a build with the `cuda` feature.
    #[arg(long, default_value = "cpu")]
    device: DeviceChoice,
    /// Also write the Markdown tables to this file.
    #[arg(long)]
    markdown: Option<PathBuf>,
    /// Print the report as JSON (one entry per method and noise condition) instead of Markdown.
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    match args.command {
        Some(CleanCommand::Train(a)) => run_train(*a, options),
        Some(CleanCommand::Eval(a)) => run_eval(a),
        None => run_clean(args.take, options),
    }
}

fn run_clean(a: TakeArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    // clap enforces both (`required = true`); the options only exist so that
    // the subcommands can go without them.
    let (Some(input), Some(output)) = (a.input, a.output) else {
        bail!("mocap clean needs a take and -o OUTPUT");
    };
    let method = match (a.model, a.filter) {
        _ if a.despike_only => Method::SpikesOnly,
        (Some(model), _) => Method::Model(model),
        (None, Some(filter)) => Method::Filter(filter),
        (None, None) => Method::DefaultModel,
    };
    let despike = a.despike.then(|| {
        let mut d = DespikeOptions::default();
        set(&mut d.threshold, a.despike_threshold);
        set(&mut d.span, a.despike_span);
        set(&mut d.max_frames, a.despike_max_frames);
        d
    });
    let find_spikes = a.spike_model.map(|model| {
        let mut options = SpikeOptions::default();
        set(&mut options.threshold, a.spike_threshold);
        FindSpikes { model, options }
    });
    let find_spikes_asked = find_spikes.is_some();
    let report = clean_file(&CleanOptions {
        input,
        output,
        method,
        device: a.device,
        hop: a.hop,
        despike,
        find_spikes,
    })?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else if !options.quiet {
        eprintln!(
            "wrote {} ({} frames, {}, mean rotation change {:.2} degrees, {:.0} frames/s)",
            report.output.display(),
            report.frames,
            report.method,
            report.mean_change_deg,
            report.frames_per_second
        );
        const LISTED: usize = 20;
        let list = |spikes: &[BridgedSpike]| {
            if spikes.len() > LISTED {
                eprintln!(
                    "  (the first {LISTED} of {}; --json lists them all)",
                    spikes.len()
                );
            }
            for s in spikes.iter().take(LISTED) {
                eprintln!(
                    "  {} and below: frames {}-{} ({:.2}-{:.2} s)",
                    s.joint,
                    s.start,
                    s.start + s.frames - 1,
                    s.start_seconds,
                    s.start_seconds + s.seconds
                );
            }
        };
        // With --despike-only nothing is cleaned after the bridging.
        let when = if a.despike_only {
            "(no cleaning after)"
        } else {
            "before cleaning"
        };
        if find_spikes_asked {
            eprintln!(
                "spike detector: bridged {} spikes {when}",
                report.detected_spikes.len()
            );
            list(&report.detected_spikes);
        }
        if a.despike {
            eprintln!("bridged {} spikes {when}", report.spikes.len());
            list(&report.spikes);
        }
    }
    Ok(())
}

fn run_train(a: TrainArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    if a.wiener {
        return run_fit_wiener(a, options);
    }
    let mut o = TrainOptions {
        inputs: a.inputs,
        out: a.output,
        state_dir: a.state,
        resume: a.resume,
        plot: a.plot,
        device: a.device,
        max_train_takes: a.max_train_takes,
        derivative_loss: a.loss == "derivative",
        spike_detector: a.spike_detector,
        ..TrainOptions::default()
    };
    if a.large {
        o.network = DenoiserConfig::large(0);
    }
    set(&mut o.epochs, a.epochs);
    set(&mut o.steps_per_epoch, a.steps);
    set(&mut o.batch_size, a.batch);
    set(&mut o.learning_rate, a.lr);
    set(&mut o.seed, a.seed);
    set(&mut o.representation, a.representation);
    set(&mut o.frame, a.rotations);
    o.base_filter = a.base_filter;
    o.base_wiener = a.base_wiener;
    o.base_input = a.base_input;
    set(&mut o.base_context, a.base_context);
    set(&mut o.position_weight, a.position_weight);
    set(&mut o.network.width, a.width);
    set(&mut o.network.levels, a.levels);
    set(&mut o.network.blocks, a.blocks);
    set(&mut o.network.window, a.window);
    set(&mut o.noise.spike_probability, a.spike_probability);
    if let Some(random) = o.noise.random.as_mut() {
        set(&mut random.max_sigma_deg, a.max_sigma);
        random.perturb_above_pelvis |= a.noise_above_pelvis;
    }
    if let Some(spikes) = o.noise.spikes.as_mut() {
        set(&mut spikes.max_spikes, a.max_spikes);
        set(&mut spikes.duration_sigma_frames, a.spike_sigma);
    }
    let report = train(&o)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else if !options.quiet {
        let last = report.history.epochs.last();
        eprintln!(
            "trained {} epochs ({:.0} samples/s); validation MSE {:.6}; wrote {} and {}",
            report.history.epochs.len(),
            report.samples_per_second,
            last.map_or(f64::NAN, |e| e.valid_loss),
            report.model.display(),
            report.plot.display()
        );
        // The report's network on its own is not the shipped recipe, and
        // measured behind a per-take Butterworth: say so where it is made.
        if o.base_wiener.is_none() && o.base_filter.is_none() && !o.spike_detector {
            eprintln!(
                "note: this is the report's network alone; on the Bandai test takes it measured \
                 behind `--filter butterworth-gcv:2` (bench/results/clean.md). The shipped model \
                 corrects a Wiener filter: `mocap clean train DIR --wiener -o wiener.safetensors`, \
                 then `--base-wiener wiener.safetensors --base-context 128 --base-input` \
                 (docs/clean-guide.md, \"Training your own Wiener filter or model\")"
            );
        }
    }
    Ok(())
}

fn run_fit_wiener(a: TrainArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    let mut o = WienerFitOptions {
        inputs: a.inputs,
        out: a.output,
        max_train_takes: a.max_train_takes,
        ..WienerFitOptions::default()
    };
    set(&mut o.segment, a.segment);
    set(&mut o.seed, a.seed);
    o.mixture_min_segments = a.mixture.map(|m| m as usize);
    o.rebase = a.rebase;
    o.noise.perturb_above_pelvis |= a.noise_above_pelvis;
    if !options.quiet && !a.json {
        eprintln!(
            "fitting a Wiener filter to the training takes (about a minute for the Bandai data)"
        );
    }
    let report = fit_files(&o)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else if !options.quiet {
        let d = &report.description;
        if !d.components.is_empty() {
            let names: Vec<&str> = d.components.iter().map(|c| c.name.as_str()).collect();
            eprintln!("{} components: {}", names.len(), names.join(", "));
        }
        eprintln!(
            "fitted to {} takes ({} frames, {} segments of {} frames{}) in {:.1} s; wrote {}",
            d.takes,
            d.frames,
            d.segments,
            d.segment,
            if d.other_rig_takes > 0 {
                format!("; {} takes on other rigs left out", d.other_rig_takes)
            } else {
                String::new()
            },
            report.seconds,
            report.model.display()
        );
    }
    Ok(())
}

fn run_eval(a: EvalArgs) -> anyhow::Result<()> {
    let mut o = EvalOptions {
        inputs: a.inputs,
        test_split_only: !a.all_takes,
        filters: !a.no_filters,
        max_takes: a.max_takes,
        device: a.device,
        ..EvalOptions::default()
    };
    o.random.perturb_above_pelvis = a.noise_above_pelvis;
    set(&mut o.random.max_sigma_deg, a.max_sigma);
    o.despike = a.despike;
    o.spike_detector = a.spike_model.map(|path| ModelEntry {
        label: "spike detector".into(),
        path: Some(path),
    });
    if a.no_default_model {
        o.models.retain(|m| m.path.is_some());
    }
    for text in &a.models {
        let (label, path) = text.split_once('=').unwrap_or((text, text));
        if path.is_empty() {
            bail!("--model {text:?}: expected LABEL=FILE or FILE");
        }
        o.models.push(ModelEntry {
            label: label.into(),
            path: Some(PathBuf::from(path)),
        });
    }
    set(&mut o.tune_takes, a.tune_takes);
    set(&mut o.seed, a.seed);
    if let Some(text) = &a.spike_lengths {
        o.spike_lengths = parse_lengths(text)?;
    }
    if o.models.is_empty() && !o.filters {
        bail!("nothing to evaluate: --no-default-model and --no-filters with no --model");
    }
    let report = evaluate(&o)?;
    let markdown = report.to_markdown();
    if let Some(path) = &a.markdown {
        write_output(Some(path), |w| w.write_all(markdown.as_bytes()))?;
    }
    let text = if a.json {
        serde_json::to_string_pretty(&report)? + "\n"
    } else {
        markdown
    };
    write_output(None, |w| w.write_all(text.as_bytes()))
}

/// `2,4,8` or `none`.
fn parse_lengths(text: &str) -> anyhow::Result<Vec<usize>> {
    if text.trim() == "none" {
        return Ok(Vec::new());
    }
    text.split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| {
            let n: usize = s.trim().parse().with_context(|| {
                format!("--spike-lengths {text:?}: expected frame counts like 2,4,8 or none")
            })?;
            if n == 0 {
                bail!("--spike-lengths {text:?}: a spike lasts at least one frame");
            }
            Ok(n)
        })
        .collect()
}

/// Parses a noise level: a finite number of degrees, zero or more.
fn degrees_at_least_zero(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!(
            "expected a number of degrees, 0 or more, got `{text}`"
        )),
    }
}

/// Parses a number of frames, one or more.
fn frames_at_least_one(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(v) if v >= 1 => Ok(v),
        _ => Err(format!(
            "expected a number of frames, 1 or more, got `{text}`"
        )),
    }
}

/// Overrides a default when the option was given.
fn set<T>(slot: &mut T, value: Option<T>) {
    if let Some(v) = value {
        *slot = v;
    }
}
