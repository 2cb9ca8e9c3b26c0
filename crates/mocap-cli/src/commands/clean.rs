//! `mocap clean`: denoise a take with the learned model or a classical filter
//! (`apply`), train a network (`train`), fit a learned Wiener filter
//! (`fit-wiener`), evaluate methods (`eval`); all in `mocap-clean`.

use std::path::PathBuf;

use anyhow::anyhow;
use mocap_clean::{
    clean_file, evaluate, fit_wiener, parse_spike_lengths, train, BridgedSpike, CleanOptions,
    DespikeOptions, EvalOptions, Filter, Method, ModelEntry, Representation, RotationFrame,
    TrainOptions, TrainRecipe, WienerFitOptions,
};

use super::args::{set, DeviceArgs, FeetArgs, ReportArgs, TrainLoopArgs};
use super::{write_output, GlobalOptions};

#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: CleanCommand,
}

#[derive(clap::Subcommand)]
enum CleanCommand {
    /// Clean a take with the shipped model, a model file or a classical filter.
    Apply(CleanApplyArgs),
    /// Train a network on clean takes with synthetic markerless noise.
    Train(Box<CleanTrainArgs>),
    /// Fit a learned multichannel Wiener filter (or a mixture of them) to clean takes.
    FitWiener(FitWienerArgs),
    /// Noisy input, tuned filters and models on held-out takes: rotation, position and acceleration errors.
    Eval(CleanEvalArgs),
}

/// `mocap clean apply IN -o OUT`.
#[derive(clap::Args)]
struct CleanApplyArgs {
    /// The take to clean (BVH).
    input: PathBuf,
    /// The cleaned take (BVH: same skeleton and channel layout; root translation kept unless
    /// --root-filter).
    #[arg(long, short)]
    output: PathBuf,
    /// A file written by `mocap clean train` or `mocap clean fit-wiener`
    /// (default: the model shipped with mocap).
    #[arg(long, conflicts_with = "filter")]
    model: Option<PathBuf>,
    /// A classical filter instead of a model: butterworth:ORDER:HZ,
    /// butterworth-gcv:ORDER (cutoff chosen per channel from the take itself), savitzky-golay:WINDOW:POLYORDER, median:WINDOW or one-euro:MIN_HZ:BETA:D_HZ.
    #[arg(long, value_name = "SPEC")]
    filter: Option<Filter>,
    #[command(flatten)]
    device: DeviceArgs,
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
    /// Also filter the root's translation with this filter (same SPEC as --filter; e.g.
    /// butterworth:2:3 for a fused capture, whose root is as noisy as its joints; by default the
    /// root's translation is kept).
    #[arg(long, value_name = "SPEC")]
    root_filter: Option<Filter>,
    #[command(flatten)]
    feet: FeetArgs,
    /// Print the report as JSON on standard output.
    #[arg(long)]
    json: bool,
}

/// `mocap clean train DIR... -o model.safetensors`.
#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("base").args(["base_filter", "base_wiener"])))]
struct CleanTrainArgs {
    /// Folders or files of clean BVH takes (split by take into train / validation / test).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// The model file to write (safetensors).
    #[arg(long, short)]
    output: PathBuf,
    #[command(flatten)]
    train_loop: TrainLoopArgs,
    #[command(flatten)]
    device: DeviceArgs,
    /// The network's shape and the synthetic noise's settings as TOML (keys: large, width, levels,
    /// blocks, window, spike_probability, max_spikes, spike_sigma, noise_rigs; each optional). The
    /// shipped network's: models/clean-recipe.toml.
    #[arg(long, value_name = "FILE.toml")]
    recipe: Option<PathBuf>,
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
    /// A classical filter (same SPEC as `mocap clean apply --filter`) whose output the network
    /// corrects, instead of correcting its input (see bench/results/clean.md).
    #[arg(long, value_name = "SPEC")]
    base_filter: Option<Filter>,
    /// With --base-filter or --base-wiener: frames of the take the filter sees on each side of a training window;
    /// the trained model then filters whole takes at once (for `butterworth-gcv`, whose cutoff
    /// needs a long stretch to be chosen well). 0: each window alone.
    #[arg(long, value_name = "FRAMES", requires = "base")]
    base_context: Option<usize>,
    /// A Wiener filter (from `mocap clean fit-wiener`) whose output the network corrects, instead
    /// of a classical --base-filter; the model file then holds both. Use with --base-context.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["base_filter", "position_weight"])]
    base_wiener: Option<PathBuf>,
    /// With --base-wiener: the network also reads the filter's output and the noise level it
    /// estimated, and scales its correction by that level, so it leaves a clean take alone (see
    /// bench/results/clean.md).
    #[arg(long, requires = "base_wiener")]
    base_input: bool,
    /// Weight of the joint-position term added to the loss (0: off; see bench/results/clean.md).
    #[arg(long)]
    position_weight: Option<f32>,
    /// Largest standard deviation of the random noise, degrees (report: 10).
    #[arg(long, value_name = "MAX", value_parser = degrees_at_least_zero)]
    max_sigma: Option<f32>,
    /// Also put random noise on the joints above the pelvis (helper joints such as Bandai's
    /// `joint_Root` on the floor; off by default, see bench/results/clean.md).
    #[arg(long)]
    noise_above_pelvis: bool,
    /// Start from this model's weights (the same recipe, rig and base options; e.g.
    /// models/clean-default.safetensors, to train the shipped network on more noise) instead of random ones.
    #[arg(long, value_name = "FILE")]
    init: Option<PathBuf>,
    /// Folder of the resumable training state (default: OUTPUT.state).
    #[arg(long)]
    state: Option<PathBuf>,
    /// Print the report as JSON on standard output.
    #[arg(long)]
    json: bool,
}

/// `mocap clean fit-wiener DIR... -o wiener.safetensors`.
#[derive(clap::Args)]
struct FitWienerArgs {
    /// Folders or files of clean BVH takes (the training split is used).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// The Wiener filter (or, with --rebase, the network on the mixture) to write (safetensors).
    #[arg(long, short)]
    output: PathBuf,
    /// Frames per Fourier segment (default 32).
    #[arg(long, value_name = "FRAMES")]
    segment: Option<usize>,
    /// Fit a mixture, one set of spectra per content named in the file names
    /// (`<set>_<content>_<style>_<take>`) with at least this many training segments (150 for the
    /// shipped one), plus one for the rest and one for all; each take is cleaned with the one
    /// that fits it best.
    #[arg(long, value_name = "MIN_SEGMENTS", value_parser = clap::value_parser!(u32).range(1..))]
    mixture: Option<u32>,
    /// With --mixture: build the mixture from the Wiener filter this network model corrects and
    /// write the network (not retrained) with the mixture under it.
    #[arg(long, value_name = "MODEL", requires = "mixture")]
    rebase: Option<PathBuf>,
    /// Seed of the noise the noise covariance is measured on.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Also put random noise on the joints above the pelvis (see bench/results/clean.md).
    #[arg(long)]
    noise_above_pelvis: bool,
    /// Fit to at most this many takes (quick runs).
    #[arg(long)]
    max_train_takes: Option<usize>,
    /// Print the report as JSON on standard output.
    #[arg(long)]
    json: bool,
}

/// `mocap clean eval DIR...`.
#[derive(clap::Args)]
struct CleanEvalArgs {
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
    /// Also the noise of the capture stage: each take watched by three simulated Kinect sensors,
    /// fused and fitted as a BVH, against its truth on the same fitted skeleton (condition `fused`).
    #[arg(long)]
    fused: bool,
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
    /// Seed of the noise put on the takes (default 7, the seed of the published figures): the same
    /// seed gives the same figures.
    #[arg(long)]
    seed: Option<u64>,
    #[command(flatten)]
    device: DeviceArgs,
    #[command(flatten)]
    report: ReportArgs,
}

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    match args.command {
        CleanCommand::Apply(a) => run_apply(a, options),
        CleanCommand::Train(a) => run_train(*a, options),
        CleanCommand::FitWiener(a) => run_fit_wiener(a, options),
        CleanCommand::Eval(a) => run_eval(a),
    }
}

fn run_apply(a: CleanApplyArgs, options: &GlobalOptions) -> anyhow::Result<()> {
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
    options.note_if_replacing_an_input(&[&a.input], &a.output);
    let report = clean_file(&CleanOptions {
        input: a.input,
        output: a.output,
        method,
        device: a.device.device,
        hop: a.hop,
        despike,
        root_filter: a.root_filter,
        feet: a.feet.options(),
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
        if a.despike {
            // With --despike-only nothing is cleaned after the bridging.
            let when = if a.despike_only {
                "(no cleaning after)"
            } else {
                "before cleaning"
            };
            eprintln!("bridged {} spikes {when}", report.spikes.len());
            list_spikes(&report.spikes);
        }
        for note in &report.notes {
            eprintln!("note: {note}");
        }
        if let Some(feet) = &report.feet {
            eprintln!("{}", super::feet::summary(feet));
        }
    }
    Ok(())
}

/// The first bridged spikes, one line each, on standard error.
fn list_spikes(spikes: &[BridgedSpike]) {
    const LISTED: usize = 20;
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
}

fn run_train(a: CleanTrainArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    let l = a.train_loop;
    let mut o = TrainOptions {
        inputs: a.inputs,
        out: a.output,
        state_dir: a.state,
        resume: l.resume,
        plot: l.plot,
        device: a.device.device,
        seed: l.seed,
        init: a.init,
        derivative_loss: a.loss == "derivative",
        base_filter: a.base_filter,
        base_wiener: a.base_wiener,
        base_input: a.base_input,
        ..TrainOptions::default()
    };
    if let Some(path) = &a.recipe {
        TrainRecipe::load(path)?.apply_to(&mut o);
    }
    set(&mut o.epochs, l.epochs);
    set(&mut o.steps_per_epoch, l.steps);
    set(&mut o.batch_size, l.batch);
    set(&mut o.learning_rate, l.lr);
    set(&mut o.representation, a.representation);
    set(&mut o.frame, a.rotations);
    set(&mut o.base_context, a.base_context);
    set(&mut o.position_weight, a.position_weight);
    if let Some(random) = o.noise.random.as_mut() {
        set(&mut random.max_sigma_deg, a.max_sigma);
        random.perturb_above_pelvis |= a.noise_above_pelvis;
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
        if o.base_wiener.is_none() && o.base_filter.is_none() {
            eprintln!(
                "note: this is the report's network alone; on the Bandai test takes it measured \
                 behind `--filter butterworth-gcv:2` (bench/results/clean.md). The shipped model \
                 corrects a Wiener filter: `mocap clean fit-wiener DIR -o wiener.safetensors`, \
                 then `--base-wiener wiener.safetensors --base-context 128 --base-input \
                 --recipe models/clean-recipe.toml` \
                 (docs/clean-guide.md, \"Training your own Wiener filter or model\")"
            );
        }
    }
    Ok(())
}

fn run_fit_wiener(a: FitWienerArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    let mut o = WienerFitOptions {
        inputs: a.inputs,
        out: a.output,
        max_train_takes: a.max_train_takes,
        seed: a.seed,
        mixture_min_segments: a.mixture.map(|m| m as usize),
        rebase: a.rebase,
        ..WienerFitOptions::default()
    };
    set(&mut o.segment, a.segment);
    o.noise.perturb_above_pelvis |= a.noise_above_pelvis;
    if !options.quiet && !a.json {
        eprintln!(
            "fitting a Wiener filter to the training takes (about a minute for the Bandai data)"
        );
    }
    let report = fit_wiener(&o)?;
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

fn run_eval(a: CleanEvalArgs) -> anyhow::Result<()> {
    let mut o = EvalOptions {
        inputs: a.inputs,
        test_split_only: !a.all_takes,
        filters: !a.no_filters,
        max_takes: a.max_takes,
        device: a.device.device,
        despike: a.despike,
        fused: a.fused,
        ..EvalOptions::default()
    };
    o.random.perturb_above_pelvis = a.noise_above_pelvis;
    set(&mut o.random.max_sigma_deg, a.max_sigma);
    if a.no_default_model {
        o.models.retain(|m| m.path.is_some());
    }
    for text in &a.models {
        let entry: ModelEntry = text.parse().map_err(|e| anyhow!("--model {e}"))?;
        o.models.push(entry);
    }
    set(&mut o.tune_takes, a.tune_takes);
    set(&mut o.seed, a.seed);
    if let Some(text) = &a.spike_lengths {
        o.spike_lengths = parse_spike_lengths(text).map_err(|e| anyhow!("--spike-lengths {e}"))?;
    }
    let report = evaluate(&o)?;
    let markdown = report.to_markdown();
    if let Some(path) = &a.report.markdown {
        write_output(Some(path), |w| w.write_all(markdown.as_bytes()))?;
    }
    let text = if a.report.json {
        serde_json::to_string_pretty(&report)? + "\n"
    } else {
        markdown
    };
    write_output(None, |w| w.write_all(text.as_bytes()))
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
