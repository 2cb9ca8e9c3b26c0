//! `mocap style`: zero-shot style transfer with elastic patches: train the
//! autoencoder once, apply a style clip, evaluate (all in `mocap-style`).

use std::path::PathBuf;

use anyhow::{bail, Context};
use mocap_nn::device::DeviceChoice;
use mocap_style::{
    apply, evaluate, parse_blend, train, ApplyOptions, Asymmetry, EvalOptions, HeldOutTake, Method,
    RootPath, StyleJudge, TrainOptions,
};

use super::{write_output, GlobalOptions};

#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: StyleCommand,
}

#[derive(clap::Subcommand)]
enum StyleCommand {
    /// Train the motion autoencoder on many styles (once; no training per style).
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
    /// Train on these contents only (comma separated; default: every clip in the folders; the
    /// shipped model: walk,walk-back,walk-left,walk-right,walk-turn-left,walk-turn-right).
    #[arg(long, value_delimiter = ',')]
    contents: Vec<String>,
    /// Epochs of `--steps` batches (default 30; the shipped model: 90, whose validation loss was
    /// still falling at 30: bench/results/style.md, "Longer training").
    #[arg(long)]
    epochs: Option<usize>,
    /// Batches per epoch (default 100); the validation loss is measured after each epoch.
    #[arg(long)]
    steps: Option<usize>,
    /// Windows per batch (default 16, the report's).
    #[arg(long)]
    batch: Option<usize>,
    /// Window length in frames (default 240, the report's).
    #[arg(long)]
    window: Option<usize>,
    /// Adam's learning rate (default 1e-4, the report's).
    #[arg(long)]
    lr: Option<f64>,
    /// Seed of the initial weights and of the windows drawn; the same seed and data give the
    /// same model.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Weight of a loss on the feet added to the reconstruction error: flat feet of the clips
    /// stay still in the reconstruction (0: the report's loss; measured with 300 in
    /// bench/results/style.md, "A loss on the feet").
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
    /// cpu, or cuda[:N] in a build with the `cuda` feature.
    #[arg(long, default_value = "cpu")]
    device: DeviceChoice,
    /// Loss curve PNG.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Continue from the last checkpoint of an interrupted run.
    #[arg(long)]
    resume: bool,
    /// Print the training report (data, losses per epoch, time) as JSON.
    #[arg(long)]
    json: bool,
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
    /// The autoencoder (default: the model shipped with mocap).
    #[arg(long)]
    model: Option<PathBuf>,
    /// 1: full style, 0: the source; in between, the pose and (with elastic patches) the timing are
    /// interpolated, so 0.5 lasts about halfway between the source and the full style.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    strength: f32,
    /// Fixed patches instead of elastic ones (the style's timing is not carried over).
    #[arg(long)]
    no_elastic: bool,
    /// elastic-patches, fixed-patches, whitening-colouring or adain.
    #[arg(long, conflicts_with = "no_elastic")]
    method: Option<Method>,
    /// Let the style fade in over this time, e.g. `2s` or `1.5`.
    #[arg(long, value_name = "SECONDS")]
    fade_in: Option<String>,
    /// Blend with a second style: OTHER_STYLE_CLIP:WEIGHT.
    #[arg(long, value_name = "CLIP:WEIGHT")]
    blend: Option<String>,
    /// Patch length in frames (default 48; even; the style clip needs at least this many).
    /// Longer patches follow the style's timing more closely, shorter ones (32) its timing less.
    #[arg(long)]
    patch: Option<usize>,
    /// Where the body goes: `feet-along-source` (default: the planted feet carry it within a
    /// stride, the source's path over longer spans), `source` (the source's path, time-warped:
    /// the report's method; the feet slide more) or `feet` (the feet everywhere: no sliding, but
    /// the distance covered follows the strides, reported as the distance ratio).
    #[arg(long, value_name = "PATH", default_value = "feet-along-source")]
    root: RootPath,
    /// Same as `--root feet`.
    #[arg(long, conflicts_with = "root")]
    root_from_feet: bool,
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
    /// cpu, or cuda[:N] in a build with the `cuda` feature.
    #[arg(long, default_value = "cpu")]
    device: DeviceChoice,
    /// Print what was done (timing, patches, root, retargeting, stage times) as JSON.
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args)]
struct EvalArgs {
    /// Folders or files of labelled clips (`<set>_<content>_<style>_<take>.bvh`).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// The autoencoder (default: the shipped model).
    #[arg(long)]
    model: Option<PathBuf>,
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
    /// Patch length in frames (default 48; clips shorter than two patches are left out).
    #[arg(long)]
    patch: Option<usize>,
    /// Where the body goes, as `apply --root`.
    #[arg(long, value_name = "PATH", default_value = "feet-along-source")]
    root: RootPath,
    /// Same as `--root feet`.
    #[arg(long, conflicts_with = "root")]
    root_from_feet: bool,
    /// Restyle with the ankles pinned on the ground (as `apply --foot-contacts`).
    #[arg(long)]
    foot_contacts: bool,
    /// Whose left-right asymmetry the outputs keep, as `apply --asymmetry`.
    #[arg(
        long,
        value_name = "source|source-clip|style",
        default_value = "source"
    )]
    asymmetry: Asymmetry,
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
    judge_seed: u64,
    /// Write side-by-side filmstrips (source, style, output) here.
    #[arg(long)]
    filmstrips: Option<PathBuf>,
    /// cpu, or cuda[:N] in a build with the `cuda` feature.
    #[arg(long, default_value = "cpu")]
    device: DeviceChoice,
    /// Also write the Markdown tables to this file.
    #[arg(long)]
    markdown: Option<PathBuf>,
    /// Print the report as JSON (every pair and method) instead of Markdown.
    #[arg(long)]
    json: bool,
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

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    match args.command {
        StyleCommand::Train(a) => {
            let defaults = TrainOptions::default();
            let mut train_options = TrainOptions {
                inputs: a.inputs,
                out: a.output,
                hold_out: !a.no_hold_out,
                held_out_take: a.held_out,
                mirror: !a.no_mirror,
                window: a.window.unwrap_or(defaults.window),
                batch_size: a.batch.unwrap_or(defaults.batch_size),
                learning_rate: a.lr.unwrap_or(defaults.learning_rate),
                epochs: a.epochs.unwrap_or(defaults.epochs),
                steps_per_epoch: a.steps.unwrap_or(defaults.steps_per_epoch),
                seed: a.seed,
                device: a.device,
                plot: a.plot,
                resume: a.resume,
                foot_loss_weight: a.foot_loss,
                ..defaults
            };
            if !a.contents.is_empty() {
                train_options.filter.contents = a.contents;
            }
            let report = train(&train_options)?;
            if a.json {
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
            let mut apply_options = ApplyOptions::new(&a.source, &a.style, &a.output);
            apply_options.model = a.model;
            apply_options.strength = a.strength;
            apply_options.method = match (a.method, a.no_elastic) {
                (Some(m), _) => m,
                (None, true) => Method::FixedPatches,
                (None, false) => Method::ElasticPatches,
            };
            if let Some(text) = &a.fade_in {
                apply_options.fade_in_seconds = parse_seconds(text)?;
            }
            if let Some(text) = &a.blend {
                apply_options.blend = Some(parse_blend(text)?);
            }
            if let Some(patch) = a.patch {
                apply_options.patch = patch;
            }
            apply_options.root = if a.root_from_feet {
                RootPath::Feet
            } else {
                a.root
            };
            apply_options.foot_contacts = a.foot_contacts;
            apply_options.asymmetry = a.asymmetry;
            apply_options.device = a.device;
            let report = apply(&apply_options)?;
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
            }
        }
        StyleCommand::Eval(a) => {
            let mut eval_options = EvalOptions {
                inputs: a.inputs,
                model: a.model,
                held_out_take: a.held_out,
                source_contents: a.sources,
                style_contents: a.styles,
                trees: a.trees,
                filmstrips: a.filmstrips,
                device: a.device,
                ..EvalOptions::default()
            };
            if !a.methods.is_empty() {
                eval_options.methods = a.methods;
            }
            if !a.classifier_contents.is_empty() {
                eval_options.classifier_filter.contents = a.classifier_contents;
            }
            if let Some(patch) = a.patch {
                eval_options.convert.patch = patch;
            }
            eval_options.convert.root = if a.root_from_feet {
                RootPath::Feet
            } else {
                a.root
            };
            eval_options.convert.foot_contacts = a.foot_contacts;
            eval_options.convert.asymmetry = a.asymmetry;
            eval_options.set_style_judge(a.style_judge);
            eval_options.seed = a.judge_seed;
            let report = evaluate(&eval_options)?;
            let markdown = report.to_markdown();
            if let Some(path) = &a.markdown {
                write_output(Some(path), |w| w.write_all(markdown.as_bytes()))?;
            }
            let text = if a.json {
                serde_json::to_string_pretty(&report)? + "\n"
            } else {
                markdown
            };
            write_output(None, |w| w.write_all(text.as_bytes()))?;
        }
    }
    Ok(())
}
