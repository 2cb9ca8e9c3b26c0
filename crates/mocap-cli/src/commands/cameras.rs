//! `mocap cameras`: capture from calibrated RGB cameras and a 2D pose
//! estimator. Each subcommand parses its arguments and calls one function
//! of `mocap-cameras`.

use std::path::PathBuf;

use anyhow::{anyhow, Context};
use mocap_cameras::{
    eval_markdown, evaluate_trial, run_capture, simulate_to_folder, CameraEvalOptions,
    CameraSimOptions, CaptureOptions, Layout, Method, TriangulationOptions,
};

use super::args::{FeetArgs, ReportArgs};
use super::GlobalOptions;

#[derive(clap::Args)]
#[command(
    after_help = "A trial is laid out as Pose2Sim lays it out: pose/cam01_json/*.json ... \
(OpenPose JSON, one file a frame), the calibration in a `calibration` folder of the trial or \
above it, Config.toml giving frame_rate and pose_model.\nExamples:\n  \
mocap cameras run S00_P00_T01_BalancingTrial -o balancing.bvh\n  \
mocap cameras simulate take.bvh -o sim-trial\n  \
mocap cameras eval sim-trial --truth sim-trial/truth.trc --markdown cameras.md"
)]
pub struct Args {
    #[command(subcommand)]
    command: CamerasCommand,
}

#[derive(clap::Subcommand)]
enum CamerasCommand {
    /// Triangulate a trial's 2D keypoints by confidence and write each person as BVH.
    Run(RunArgs),
    /// Compare the triangulation methods on a trial: reprojection, bone-length spread, and the truth or another tool's TRC.
    Eval(EvalArgs),
    /// Film a BVH take with virtual calibrated cameras through a simulated 2D pose estimator, as a trial folder.
    Simulate(SimulateArgs),
}

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    match args.command {
        CamerasCommand::Run(a) => run_trial(a, options),
        CamerasCommand::Eval(a) => eval(a, options),
        CamerasCommand::Simulate(a) => simulate(a, options),
    }
}

/// How a trial is read and triangulated (`run` and `eval`).
#[derive(clap::Args)]
struct TrialArgs {
    /// The trial folder (its pose/camNN_json folders, or folders of JSON files).
    trial: PathBuf,
    /// The calibration: Pose2Sim TOML, OpenCV YAML or JSON (default: found beside the trial).
    #[arg(long, value_name = "FILE")]
    calib: Option<PathBuf>,
    /// The keypoint layout: BODY_25, BODY_25B, COCO_17, HALPE_26, BLAZEPOSE (default: Config.toml's pose_model, or told from the keypoints).
    #[arg(long)]
    layout: Option<String>,
    /// Frames per second (default: Config.toml's frame_rate).
    #[arg(long)]
    fps: Option<f64>,
    /// Keypoints scored below this are not used.
    #[arg(long, default_value_t = 0.3)]
    min_score: f32,
    /// Mean reprojection error (pixels) above which the robust method leaves out the worst view.
    #[arg(long, default_value_t = 15.0, value_name = "PX")]
    max_error: f64,
}

impl TrialArgs {
    fn capture(&self, method: Method) -> anyhow::Result<CaptureOptions> {
        let layout = self
            .layout
            .as_deref()
            .map(|l| {
                Layout::parse(l).ok_or_else(|| {
                    anyhow!("--layout {l:?}: expected BODY_25, BODY_25B, COCO_17, HALPE_26 or BLAZEPOSE")
                })
            })
            .transpose()?;
        Ok(CaptureOptions {
            calibration: self.calib.clone(),
            layout,
            fps: self.fps,
            triangulation: TriangulationOptions {
                method,
                min_score: self.min_score,
                max_error: self.max_error,
                ..TriangulationOptions::default()
            },
            ..CaptureOptions::new(&self.trial)
        })
    }
}

#[derive(clap::Args)]
struct RunArgs {
    #[command(flatten)]
    trial: TrialArgs,
    /// The BVH written (more people: NAME-2.bvh, NAME-3.bvh...).
    #[arg(long, short)]
    output: PathBuf,
    /// How views are weighted: plain, scores, bone-length, range-of-motion, robust.
    #[arg(long, default_value = "robust")]
    method: String,
    /// How many people to write, the ones found in the most frames first.
    #[arg(long, default_value_t = 1)]
    people: usize,
    #[command(flatten)]
    feet: FeetArgs,
    /// Print the report as JSON on standard output.
    #[arg(long)]
    json: bool,
}

fn method(text: &str) -> anyhow::Result<Method> {
    Method::parse(text).ok_or_else(|| {
        anyhow!("--method {text:?}: expected plain, scores, bone-length, range-of-motion or robust")
    })
}

fn run_trial(args: RunArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    let mut capture = args.trial.capture(method(&args.method)?)?;
    if args.people == 0 {
        return Err(anyhow!("--people must be at least 1"));
    }
    capture.people = args.people;
    capture.feet = args.feet.options();
    let report = run_capture(&capture, &args.output)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    if options.quiet {
        return Ok(());
    }
    for note in &report.notes {
        eprintln!("note: {note}");
    }
    eprintln!(
        "{} cameras, {} frames at {} fps, {} keypoints, method {}",
        report.cameras.len(),
        report.frames,
        report.fps,
        report.layout,
        report.method
    );
    for person in &report.people {
        eprintln!(
            "wrote {}: found in {} frames; reprojection {:.2} px; bone-length spread {:.1} mm",
            person.output.display(),
            person.found_in,
            person.reprojection_px.unwrap_or(f64::NAN),
            person.mean_bone_spread_mm.unwrap_or(f64::NAN)
        );
        if let Some(feet) = &person.feet {
            eprintln!("  {}", super::feet::summary(feet));
        }
        let worst = person
            .keypoints
            .iter()
            .filter(|k| k.reprojection_px.is_some())
            .max_by(|a, b| {
                a.reprojection_px
                    .partial_cmp(&b.reprojection_px)
                    .expect("finite")
            });
        if let Some(k) = worst {
            eprintln!(
                "  worst keypoint: {} ({:.2} px over {:.1} views, {} frames)",
                k.name,
                k.reprojection_px.unwrap_or(f64::NAN),
                k.views.unwrap_or(f64::NAN),
                k.frames
            );
        }
    }
    Ok(())
}

#[derive(clap::Args)]
struct EvalArgs {
    #[command(flatten)]
    trial: TrialArgs,
    /// The true keypoints as TRC (what `mocap cameras simulate` writes as truth.trc).
    #[arg(long, value_name = "FILE")]
    truth: Option<PathBuf>,
    /// Another tool's triangulation of the same trial as TRC (Pose2Sim's pose-3d/*.trc).
    #[arg(long, value_name = "FILE")]
    reference: Option<PathBuf>,
    /// Which person to measure: 1 is the one found in the most frames.
    #[arg(long, default_value_t = 1)]
    person: usize,
    #[command(flatten)]
    report: ReportArgs,
}

fn eval(args: EvalArgs, _options: &GlobalOptions) -> anyhow::Result<()> {
    if args.person == 0 {
        return Err(anyhow!("--person counts from 1"));
    }
    let report = evaluate_trial(&CameraEvalOptions {
        capture: args.trial.capture(Method::Robust)?,
        truth: args.truth,
        reference: args.reference,
        person: args.person - 1,
    })?;
    let markdown = eval_markdown(&report);
    if let Some(path) = &args.report.markdown {
        mocap_core::io::atomic::write_bytes_atomically(path, markdown.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if args.report.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{markdown}");
    }
    Ok(())
}

#[derive(clap::Args)]
struct SimulateArgs {
    /// The take to film (BVH, or AMC with its ASF beside it).
    input: PathBuf,
    /// The trial folder written (must not exist or be empty).
    #[arg(long, short)]
    output: PathBuf,
    /// Number of cameras, evenly around the person.
    #[arg(long, default_value_t = 4)]
    cameras: usize,
    /// Pixel noise (standard deviation) of a confident keypoint.
    #[arg(long, default_value_t = 2.5, value_name = "PX")]
    pixel_noise: f64,
    /// Share of keypoints the estimator misses.
    #[arg(long, default_value_t = 0.03)]
    miss_rate: f64,
    /// Share of camera frames where the estimator swaps one limb's left and right.
    #[arg(long, default_value_t = 0.02)]
    swap_rate: f64,
    /// Share of keypoints thrown far off with a confident score.
    #[arg(long, default_value_t = 0.02)]
    outlier_rate: f64,
    /// Seed of the cameras' placement and the estimator's errors.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

fn simulate(args: SimulateArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    let sim = CameraSimOptions {
        cameras: args.cameras,
        pixel_noise: args.pixel_noise,
        miss_rate: args.miss_rate,
        swap_rate: args.swap_rate,
        outlier_rate: args.outlier_rate,
        seed: args.seed,
        ..CameraSimOptions::default()
    };
    let report = simulate_to_folder(&args.input, &args.output, &sim)?;
    if !options.quiet {
        eprintln!(
            "wrote {}: {} cameras, {} frames at {} fps ({} keypoints), truth in truth.trc",
            args.output.display(),
            report.cameras,
            report.frames,
            report.fps,
            report.layout
        );
    }
    Ok(())
}
