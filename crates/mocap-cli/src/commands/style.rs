//! `mocap style`: zero-shot style transfer with elastic patches: train the
//! autoencoder once, apply a style clip, evaluate (all in `mocap-style`).

use std::path::PathBuf;

use anyhow::{bail, Context};
use mocap_style::{
    apply, evaluate, parse_blend, train, ApplyOptions, Asymmetry, EvalOptions, HeldOutTake, Method,
    RootPath, StyleJudge, TrainOptions,
};

use super::args::{set, DeviceArgs, FeetArgs, ReportArgs, TrainLoopArgs};
use super::{write_output, GlobalOptions};

#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: StyleCommand,
}

#[derive(clap::Subcommand)]
enum StyleCommand {
    /// Train the motion autoencoder on many styles (once; no training per style).
    ///
    /// The training loop's defaults are the report's: 30 epochs (the shipped model: 90, whose
    /// validation loss was still falling at 30) of 100 batches, the validation loss measured
    /// after each epoch; 16 windows per batch; Adam with learning rate 1e-4.
    Train(TrainArgs),
    /// Give SOURCE the style (and timing) of one example clip.
    Apply(ApplyArgs),
    /// Style/content accuracy, timing, foot skating and smoothness of every method on held-out takes.
    Eval(EvalArgs),
}

#[derive(clap::Args)]
struct TrainArgs {
    /// Folders or files of BVH clips named `<set>_<content>_<style>_<take>.bvh`.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// The model file to write (safetensors).
    #[arg(long, short)]
    output: PathBuf,
    #[command(flatten)]
    training: TrainLoopArgs,
    #[command(flatten)]
    device: DeviceArgs,
    /// Train on these contents only (comma separated; default: every clip in the folders; the
    /// shipped model: walk,walk-back,walk-left,walk-right,walk-turn-left,walk-turn-right).
    #[arg(long, value_delimiter = ',')]
    contents: Vec<String>,
    /// Window length in frames (default 240, the report's).
    #[arg(long)]
    window: Option<usize>,
    /// Weight of a loss on the feet added to the reconstruction error: flat feet of the clips
    /// stay still in the reconstruction (0: the report's loss; measured with 300 in
    /// bench/results/style.md, "The shipped model").
    #[arg(long, default_value_t = 0.0, value_name = "W")]
    foot_loss: f64,
    /// Do not add mirrored copies of the clips.
    #[arg(long)]
    no_mirror: bool,
    /// Train on every clip (no held-out evaluation takes).
    #[arg(long)]
    no_hold_out: bool,
    /// Which take of each (set, content, style) group of two or more `style eval` holds out:
    /// last (the shipped model's fold) or first (the other fold).
    #[arg(long, default_value = "last", value_name = "last|first")]
    held_out: HeldOutTake,
    /// Print the training report (data, losses per epoch, time) as JSON.
    #[arg(long)]
    json: bool,
}

/// How `style apply` and `style eval` restyle: the model, the patch length,
/// where the body goes, the feet and the asymmetry.
#[derive(clap::Args, Clone, Debug)]
struct RestyleArgs {
    /// The autoencoder (default: the model shipped with mocap).
    #[arg(long)]
    model: Option<PathBuf>,
    /// Patch length in frames (default 48; even; a style clip needs at least this many, and
    /// `eval` leaves out clips shorter than two patches). Longer patches follow the style's
    /// timing more closely, shorter ones (32) less.
    #[arg(long)]
    patch: Option<usize>,
    /// Where the body goes: `feet-along-source` (default: the planted feet carry it within a
    /// stride, the source's path over longer spans), `source` (the source's path, time-warped:
    /// the report's method; the feet slide more) or `feet` (the feet everywhere: no sliding, but
    /// the distance covered follows the strides, reported as the distance ratio).
    #[arg(long, value_name = "PATH", default_value = "feet-along-source")]
    root: RootPath,
    /// Pin the ankles on the ground by turning hips and knees, no further than the legs reach
    /// (keeps the source's path; costs some style, see bench/results/style.md).
    #[arg(long)]
    foot_contacts: bool,
    /// Whose left-right asymmetry the output keeps: `source` (default: the source's, averaged
    /// over two of its strides around each frame, so a turn keeps the feet's sideways placement
    /// where it turns), `source-clip` (the source's, one offset for the whole clip) or `style`
    /// (the style's symmetric mean alone: the report's method, which restyles turns into
    /// near-straight walks).
    #[arg(
        long,
        value_name = "source|source-clip|style",
        default_value = "source"
    )]
    asymmetry: Asymmetry,
}

#[derive(clap::Args)]
struct ApplyArgs {
    /// The motion to restyle (BVH, or AMC with its ASF beside it).
    source: PathBuf,
    /// One example clip of the style (BVH, or AMC with its ASF beside it; a clip of another rig is
    /// retargeted onto the source's).
    #[arg(long)]
    style: PathBuf,
    /// The restyled motion (BVH, the source's skeleton).
    #[arg(long, short)]
    output: PathBuf,
    /// 1: full style, 0: the source; in between, the pose and (with elastic patches) the timing are
    /// interpolated, so 0.5 lasts about halfway between the source and the full style.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    strength: f32,
    /// elastic-patches (the style's timing is carried over), fixed-patches (the source's timing
    /// is kept), whitening-colouring or adain.
    #[arg(long, default_value = "elastic-patches", value_name = "METHOD")]
    method: Method,
    /// Let the style fade in over this time, e.g. `2s` or `1.5`.
    #[arg(long, value_name = "SECONDS")]
    fade_in: Option<String>,
    /// Blend with a second style: OTHER_STYLE_CLIP:WEIGHT.
    #[arg(long, value_name = "CLIP:WEIGHT")]
    blend: Option<String>,
    #[command(flatten)]
    restyle: RestyleArgs,
    #[command(flatten)]
    feet: FeetArgs,
    #[command(flatten)]
    device: DeviceArgs,
    /// Print what was done (timing, patches, root, retargeting, stage times) as JSON.
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args)]
struct EvalArgs {
    /// Folders or files of labelled clips (`<set>_<content>_<style>_<take>.bvh`).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Which take of each group is held out and tested: last, or first (the other fold; the
    /// model must have been trained with `style train --held-out first`).
    #[arg(long, default_value = "last", value_name = "last|first")]
    held_out: HeldOutTake,
    /// Contents of the source clips (comma separated; default all).
    #[arg(long, value_delimiter = ',')]
    sources: Vec<String>,
    /// Contents of the style clips (comma separated; default all).
    #[arg(long, value_delimiter = ',')]
    styles: Vec<String>,
    /// Methods to compare (comma separated; default all).
    #[arg(long, value_delimiter = ',')]
    methods: Vec<Method>,
    /// Contents the style classifier trains on (comma separated; default all).
    #[arg(long, value_delimiter = ',')]
    classifier_contents: Vec<String>,
    #[command(flatten)]
    restyle: RestyleArgs,
    /// Trees of each classifier's forest.
    #[arg(long, default_value_t = 100)]
    trees: usize,
    /// The classifier that judges the outputs' style: the forest on gait descriptors, a
    /// small conv net on the per-frame pose values (a second opinion; slower to train), or
    /// both with their votes added.
    #[arg(long, default_value = "forest", value_name = "forest|conv-net|both")]
    style_judge: StyleJudge,
    /// Seed of the classifiers.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Write side-by-side filmstrips (source, style, output) here.
    #[arg(long)]
    filmstrips: Option<PathBuf>,
    #[command(flatten)]
    device: DeviceArgs,
    #[command(flatten)]
    report: ReportArgs,
}

/// `2s`, `1.5s` or `1.5` seconds.
fn parse_seconds(text: &str) -> anyhow::Result<f64> {
    let number = text.trim().trim_end_matches('s');
    let seconds: f64 = number
        .parse()
        .with_context(|| format!("--fade-in {text:?}: expected seconds, e.g. 2s"))?;
    if !(seconds.is_finite() && seconds >= 0.0) {
        bail!("--fade-in {text:?}: expected a duration of zero seconds or more");
    }
    Ok(seconds)
}

fn train_options(a: TrainArgs) -> TrainOptions {
    let mut options = TrainOptions {
        inputs: a.inputs,
        out: a.output,
        hold_out: !a.no_hold_out,
        held_out_take: a.held_out,
        mirror: !a.no_mirror,
        seed: a.training.seed,
        device: a.device.device,
        plot: a.training.plot,
        resume: a.training.resume,
        foot_loss_weight: a.foot_loss,
        ..TrainOptions::default()
    };
    set(&mut options.window, a.window);
    set(&mut options.batch_size, a.training.batch);
    set(&mut options.learning_rate, a.training.lr);
    set(&mut options.epochs, a.training.epochs);
    set(&mut options.steps_per_epoch, a.training.steps);
    if !a.contents.is_empty() {
        options.filter.contents = a.contents;
    }
    options
}

fn apply_options(a: &ApplyArgs) -> anyhow::Result<ApplyOptions> {
    let mut options = ApplyOptions::new(&a.source, &a.style, &a.output);
    options.model = a.restyle.model.clone();
    options.strength = a.strength;
    options.method = a.method;
    if let Some(text) = &a.fade_in {
        options.fade_in_seconds = parse_seconds(text)?;
    }
    if let Some(text) = &a.blend {
        options.blend = Some(parse_blend(text)?);
    }
    set(&mut options.patch, a.restyle.patch);
    options.root = a.restyle.root;
    options.foot_contacts = a.restyle.foot_contacts;
    options.asymmetry = a.restyle.asymmetry;
    options.feet = a.feet.options();
    options.device = a.device.device;
    Ok(options)
}

fn eval_options(a: EvalArgs) -> EvalOptions {
    let mut options = EvalOptions {
        inputs: a.inputs,
        model: a.restyle.model,
        held_out_take: a.held_out,
        source_contents: a.sources,
        style_contents: a.styles,
        trees: a.trees,
        filmstrips: a.filmstrips,
        device: a.device.device,
        ..EvalOptions::default()
    };
    if !a.methods.is_empty() {
        options.methods = a.methods;
    }
    if !a.classifier_contents.is_empty() {
        options.classifier_filter.contents = a.classifier_contents;
    }
    set(&mut options.convert.patch, a.restyle.patch);
    options.convert.root = a.restyle.root;
    options.convert.foot_contacts = a.restyle.foot_contacts;
    options.convert.asymmetry = a.restyle.asymmetry;
    options.set_style_judge(a.style_judge);
    options.seed = a.seed;
    options
}

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    match args.command {
        StyleCommand::Train(a) => {
            let json = a.json;
            let report = train(&train_options(a))?;
            if json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else if !options.quiet {
                let last = report.history.epochs.last();
                eprintln!(
                    "trained {} epochs ({:.0} windows/s); validation MSE {:.4}; wrote {} and {}",
                    report.history.epochs.len(),
                    report.samples_per_second,
                    last.map_or(f64::NAN, |e| e.valid_loss),
                    report.model.display(),
                    report.plot.display()
                );
            }
        }
        StyleCommand::Apply(a) => {
            options.note_if_replacing_an_input(&[&a.source, &a.style], &a.output);
            let report = apply(&apply_options(&a)?)?;
            if a.json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else if !options.quiet {
                for note in &report.retargeted {
                    eprintln!("note: {note}");
                }
                if let Some(note) = report.unfamiliar_source_note() {
                    eprintln!("note: {note}");
                }
                if let Some(c) = &report.contacts {
                    eprintln!(
                        "feet pinned on {} and {} frames (left, right): ankles moved {:.1} on \
                         average, {:.1} at most (the model rig's units); held back by the legs' \
                         reach on {} frames",
                        c.frames_changed[0],
                        c.frames_changed[1],
                        c.mean_shift,
                        c.max_shift,
                        c.frames_out_of_reach
                    );
                }
                eprintln!(
                    "wrote {} ({} frames from {}; time scale {:.2}, distance ratio {:.2})",
                    report.out.display(),
                    report.output_frames,
                    report.source_frames,
                    report.time_scale,
                    report.distance_ratio
                );
                if let Some(feet) = &report.feet {
                    eprintln!("{}", super::feet::summary(feet));
                }
            }
        }
        StyleCommand::Eval(a) => {
            let report_args = a.report.clone();
            let report = evaluate(&eval_options(a))?;
            let markdown = report.to_markdown();
            if let Some(path) = &report_args.markdown {
                write_output(Some(path), |w| w.write_all(markdown.as_bytes()))?;
            }
            let text = if report_args.json {
                serde_json::to_string_pretty(&report)? + "\n"
            } else {
                markdown
            };
            write_output(None, |w| w.write_all(text.as_bytes()))?;
        }
    }
    Ok(())
}
