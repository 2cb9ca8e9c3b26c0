//! `mocap fuse`: multi-sensor skeleton capture (Kinect v2 style sensors).
//! Each subcommand parses its arguments and calls one function of
//! `mocap-fuse`; the work is there.

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context};
use mocap_fuse::{
    BodyCalibrationOptions, BodyCalibrationReport, BoneLengthSource, BvhWorld, CalibrationSource,
    EvalOptions, Evaluation, FuseFilesOptions, FusionOptions, OutputFiles, OutputReport,
    PerJointChart, ReadOptions, ScanPair, SendOptions, ServeFilesOptions, SimulationOptions,
    TimeOffsets, METHOD_NAMES,
};
use serde::Serialize;

use super::args::{FeetArgs, ReportArgs};
use super::GlobalOptions;

#[derive(clap::Args)]
#[command(after_help = "A capture, end to end:\n  \
mocap fuse simulate take.bvh --sensors 3 -o sim/\n  \
mocap fuse calibrate sim/sensor-*.jsonl -o rig.toml\n  \
mocap fuse measure sim/sensor-*.jsonl -o body.json\n  \
mocap fuse run sim/sensor-*.jsonl --calib rig.toml --body body.json -o fused.jsonl -o fused.bvh\n  \
mocap fuse serve --calib rig.toml --body body.json --listen 127.0.0.1:9000 -o live.bvh &\n  \
mocap fuse send sim/sensor-*.jsonl --to 127.0.0.1:9000 --realtime")]
pub struct Args {
    #[command(subcommand)]
    command: FuseCommand,
}

impl Args {
    /// Whether this is the fusion server or a sender (long-running, on the
    /// network), as opposed to a batch command.
    pub fn is_network(&self) -> bool {
        matches!(self.command, FuseCommand::Serve(_) | FuseCommand::Send(_))
    }

    /// Whether this command ends on Ctrl-C by itself, writing what it has
    /// (the server finishes its take).
    pub fn finishes_on_ctrl_c(&self) -> bool {
        matches!(self.command, FuseCommand::Serve(_))
    }
}

#[derive(clap::Subcommand)]
enum FuseCommand {
    /// Simulate Kinect v2 sensors watching a BVH take: their recordings, the true calibration, the measured person and room scans.
    Simulate(SimulateArgs),
    /// Calibrate sensors from the person all of them see (recordings), or one scan of the room against another (--points).
    Calibrate(CalibrateArgs),
    /// Measure the person (bone lengths, joint ranges) from recordings into a body file.
    Measure(MeasureArgs),
    /// Fuse recordings into one skeleton, written as JSON lines and/or BVH.
    Run(RunArgs),
    /// Run the fusion server: sensors stream their frames over UDP; fused frames are written as they come.
    Serve(ServeArgs),
    /// Send recordings to a fusion server as live sensors.
    Send(SendArgs),
    /// Evaluate: BVH takes with simulated sensors against ground truth, or real recordings (NTU .skeleton) by bone-length consistency.
    Eval(EvalArgs),
}

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    match args.command {
        FuseCommand::Simulate(a) => simulate(a, options),
        FuseCommand::Calibrate(a) => calibrate(a, options),
        FuseCommand::Measure(a) => measure(a, options),
        FuseCommand::Run(a) => run_offline(a, options),
        FuseCommand::Serve(a) => serve(a, options),
        FuseCommand::Send(a) => send(a, options),
        FuseCommand::Eval(a) => eval(a, options),
    }
}

/// Prints `value` as pretty JSON on standard output.
fn print_json(value: &impl Serialize) -> anyhow::Result<()> {
    println!(
        "{}",
        serde_json::to_string_pretty(value).context("writing JSON")?
    );
    Ok(())
}

/// The BVH outputs' options of `run` and `serve`.
#[derive(clap::Args)]
struct FusedBvhArgs {
    /// Length unit of the BVH output: cm, m or mm.
    #[arg(long, default_value = "cm")]
    bvh_units: String,
    /// Bone lengths of the BVH skeleton: the median of the fused take, or the body file's.
    #[arg(long, default_value = "fused", value_parser = ["fused", "body"])]
    bvh_lengths: String,
    #[command(flatten)]
    feet: FeetArgs,
}

impl FusedBvhArgs {
    fn outputs(&self, paths: Vec<PathBuf>) -> anyhow::Result<OutputFiles> {
        let bvh_units_per_metre = match self.bvh_units.as_str() {
            "cm" => 100.0,
            "m" => 1.0,
            "mm" => 1000.0,
            other => bail!("--bvh-units {other:?}: expected cm, m or mm"),
        };
        let bvh_lengths = match self.bvh_lengths.as_str() {
            "body" => BoneLengthSource::Body,
            _ => BoneLengthSource::Fused,
        };
        Ok(OutputFiles {
            paths,
            bvh_units_per_metre,
            bvh_lengths,
            feet: self.feet.options(),
            bvh_world: BvhWorld::Floor,
        })
    }
}

// ---------------------------------------------------------------- simulate

#[derive(clap::Args)]
struct SimulateArgs {
    /// The ground-truth take (BVH).
    bvh: PathBuf,
    /// Folder for the files (created if needed).
    #[arg(long, short)]
    output: PathBuf,
    /// Number of sensors, evenly spaced around the person.
    #[arg(long, default_value_t = 3)]
    sensors: usize,
    /// Random seed (sensor places, noise).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Length units per metre of the BVH (guessed from the standing height when absent).
    #[arg(long)]
    units_per_metre: Option<f32>,
    /// Also write each sensor as an NTU RGB+D .skeleton file.
    #[arg(long)]
    ntu: bool,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
}

fn simulate(args: SimulateArgs, _options: &GlobalOptions) -> anyhow::Result<()> {
    if args.sensors == 0 {
        bail!("--sensors must be at least 1");
    }
    let simulation = SimulationOptions {
        sensors: args.sensors,
        seed: args.seed,
        ..Default::default()
    };
    let report = mocap_fuse::simulate_to_folder(
        &args.bvh,
        &args.output,
        &simulation,
        args.units_per_metre,
        args.ntu,
    )?;
    if args.json {
        return print_json(&report);
    }
    println!(
        "{} sensors watching {} ({} frames at {} fps) -> {}",
        report.sensors.len(),
        args.bvh.display(),
        report.truth_frames,
        report.fps,
        args.output.display()
    );
    for s in &report.sensors {
        println!(
            "  sensor {}: {} frames, latency {:.0} ms, {:.1}% dropped",
            s.id,
            s.frames,
            s.latency_seconds * 1000.0,
            s.drop_rate * 100.0
        );
    }
    println!("  true calibration: {}", report.files.calibration.display());
    println!("  body: {}", report.files.body.display());
    println!("  ground truth: {}", report.files.truth.display());
    Ok(())
}

/// How `calibrate`, `measure` and `run` read recordings.
#[derive(clap::Args)]
struct ReadingArgs {
    /// Frames per second of NTU .skeleton files (their frame i is at i / FPS seconds).
    #[arg(long, default_value_t = mocap_fuse::NTU_FPS, value_name = "FPS")]
    input_fps: f64,
    /// Time offsets: auto (each NTU file matched to the lowest camera by its motion), off, or
    /// frames at --input-fps per file, in their order, added to their times (0,2,-1.5).
    #[arg(
        long,
        default_value = "auto",
        value_name = "auto|off|F,F,..",
        allow_hyphen_values = true
    )]
    time_offsets: TimeOffsets,
}

impl ReadingArgs {
    fn options(&self) -> ReadOptions {
        ReadOptions {
            input_fps: self.input_fps,
            time_offsets: self.time_offsets.clone(),
        }
    }
}

/// What reading the recordings did that a person should know, on standard error.
fn print_reading_notes(notes: &[String], options: &GlobalOptions) {
    if !options.quiet {
        for n in notes {
            eprintln!("note: {n}");
        }
    }
}

// --------------------------------------------------------------- calibrate

#[derive(clap::Args)]
#[command(
    after_help = "From the body:   mocap fuse calibrate sensor-0.jsonl sensor-1.jsonl -o rig.toml\n\
From room scans: mocap fuse calibrate --points sensor-0.ply sensor-1.ply --pairs pairs-0-1.txt -o rig.toml\n\
With --points, an existing --output file is updated: the second scan's sensor is placed in the world of the first."
)]
struct CalibrateArgs {
    /// Recordings (.jsonl, NTU .skeleton) of every sensor watching the person at the same time.
    #[arg(conflicts_with = "points")]
    recordings: Vec<PathBuf>,
    /// The calibration file to write.
    #[arg(long, short)]
    output: PathBuf,
    /// The sensor whose camera frame is the world (body calibration; default: the lowest id).
    #[arg(long)]
    reference: Option<u16>,
    /// Two room scans (PLY, camera space, metres): the reference's, then the one to place.
    #[arg(long, num_args = 2, value_names = ["A.ply", "B.ply"])]
    points: Option<Vec<PathBuf>>,
    /// Point pairs picked in both scans (`xa ya za xb yb zb` per line) for the rough start.
    #[arg(long, requires = "points")]
    pairs: Option<PathBuf>,
    /// A calibration (e.g. from the body) holding both sensors, for the rough start.
    #[arg(long, requires = "points", conflicts_with = "pairs")]
    initial: Option<PathBuf>,
    /// Sensor ids of the two scans (default: the number in each file name).
    #[arg(long, requires = "points", num_args = 2, value_names = ["A", "B"])]
    ids: Option<Vec<u16>>,
    #[command(flatten)]
    reading: ReadingArgs,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
}

fn calibrate(args: CalibrateArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    if let Some(points) = &args.points {
        return calibrate_points(&args, points, options);
    }
    if args.recordings.is_empty() {
        bail!("give the recordings of the sensors (body calibration) or --points A.ply B.ply");
    }
    let (report, reading) = mocap_fuse::calibrate_recordings_with(
        &args.recordings,
        &args.reading.options(),
        &BodyCalibrationOptions {
            reference: args.reference,
            ..Default::default()
        },
        &args.output,
    )?;
    print_reading_notes(&reading.notes(), options);
    if args.json {
        return print_json(&report);
    }
    println!(
        "calibrated from the body; world = sensor {} -> {}",
        report.reference,
        args.output.display()
    );
    for s in &report.sensors {
        println!(
            "  sensor {}: {} of {} joint pairs fit within 10 cm (RMS {:.1} mm{}), {} of {} frames with settled left/right; pose known to about {:.1} degrees and {:.1} cm (turn about the vertical {:.1} degrees)",
            s.sensor,
            s.inliers,
            s.pairs,
            s.rms * 1000.0,
            if s.refined { ", refined on the other sensors' fused skeleton" } else { "" },
            s.settled_frames,
            s.paired_frames,
            s.rotation_uncertainty_degrees,
            s.translation_uncertainty * 100.0,
            s.yaw_uncertainty_degrees
        );
    }
    if report.is_unsure() {
        println!(
            "warning: the person moved too little for a sure calibration from the body (over {} degrees of doubt); capture a take where they walk and turn, or refine with room scans (--points)",
            BodyCalibrationReport::UNSURE_DEGREES
        );
    }
    for warning in report.warnings() {
        println!("warning: {warning}");
    }
    Ok(())
}

fn calibrate_points(
    args: &CalibrateArgs,
    points: &[PathBuf],
    _options: &GlobalOptions,
) -> anyhow::Result<()> {
    let [a, b] = points else {
        bail!("--points takes two scans");
    };
    let scans = ScanPair {
        scans: [a.clone(), b.clone()],
        pairs: args.pairs.clone(),
        initial: args.initial.clone(),
        ids: args.ids.as_deref().map(|ids| [ids[0], ids[1]]),
    };
    let found = mocap_fuse::calibrate_scans(&scans, &args.output)?;
    if found.from_identity {
        eprintln!("note: no --pairs or --initial: ICP started from the identity, which works only for scans taken from nearly the same place");
    }
    let result = &found.fit;
    if args.json {
        return print_json(result);
    }
    if let Some(fit) = &result.pairs_fit {
        println!(
            "rough start from {} point pairs: RMS {:.1} mm",
            fit.pairs,
            fit.rms * 1000.0
        );
    }
    println!(
        "ICP: {} point pairs, RMS {:.1} mm, {} iterations{} -> sensor {} in {}",
        result.icp.pairs,
        result.icp.rms * 1000.0,
        result.icp.iterations,
        if result.icp.converged {
            ""
        } else {
            " (not converged)"
        },
        found.ids[1],
        args.output.display()
    );
    if !result.icp.unconstrained.is_empty() {
        println!(
            "warning: the scans do not pin down: {}; the result keeps the start there (check it with the body calibration)",
            result.icp.unconstrained.join("; ")
        );
    }
    Ok(())
}

// ----------------------------------------------------------------- measure

#[derive(clap::Args)]
struct MeasureArgs {
    /// Recordings (.jsonl, NTU .skeleton) of the person.
    #[arg(required = true)]
    recordings: Vec<PathBuf>,
    /// The body file to write (JSON).
    #[arg(long, short)]
    output: PathBuf,
    /// Take the joint ranges from the limits of an ASF skeleton instead of measuring them.
    #[arg(long, value_name = "SKELETON.asf")]
    limits: Option<PathBuf>,
    #[command(flatten)]
    reading: ReadingArgs,
    /// Print the body as JSON.
    #[arg(long)]
    json: bool,
}

fn measure(args: MeasureArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    let (body, reading) = mocap_fuse::measure_recordings_with(
        &args.recordings,
        &args.reading.options(),
        args.limits.as_deref(),
        &args.output,
    )?;
    print_reading_notes(&reading.notes(), options);
    if args.json {
        return print_json(&body);
    }
    println!(
        "{} bone lengths and {} joint ranges{} -> {}",
        body.bone_lengths.iter().flatten().count(),
        body.ranges.iter().flatten().count(),
        if args.limits.is_some() {
            " (from the ASF limits)"
        } else {
            ""
        },
        args.output.display()
    );
    Ok(())
}

// --------------------------------------------------------------------- run

#[derive(clap::Args)]
struct RunArgs {
    /// Recordings (.jsonl, NTU .skeleton) of the sensors.
    #[arg(required = true)]
    recordings: Vec<PathBuf>,
    /// The calibration file (every sensor's pose).
    #[arg(long)]
    calib: PathBuf,
    /// The person's body file (default: measured from these recordings).
    #[arg(long)]
    body: Option<PathBuf>,
    /// Output: .jsonl (fused joints) or .bvh (a motion on a fitted skeleton); repeat for both.
    #[arg(long, short, required = true)]
    output: Vec<PathBuf>,
    /// Fusion method.
    #[arg(long, default_value = "best", value_parser = clap::builder::PossibleValuesParser::new(METHOD_NAMES))]
    method: String,
    /// Fused frames per second.
    #[arg(long, default_value_t = 30.0)]
    fps: f64,
    #[command(flatten)]
    bvh: FusedBvhArgs,
    /// Write the BVH in the calibration's world (default: upright on the floor found under the feet).
    #[arg(long)]
    calibration_world: bool,
    #[command(flatten)]
    reading: ReadingArgs,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
}

fn print_outputs(outputs: &[OutputReport]) {
    for o in outputs {
        match &o.fit_error {
            Some(e) => println!(
                "  {}: {} frames; its joints are {:.1} mm from the fused ones on average ({:.1} mm on the body without hands and feet, 95% within {:.1} mm, max {:.1} mm)",
                o.path.display(),
                o.frames,
                e.mean_mm,
                e.body_mean_mm,
                e.p95_mm,
                e.max_mm
            ),
            None => println!("  {}: {} frames", o.path.display(), o.frames),
        }
        if let Some(feet) = &o.feet {
            println!("  {}", super::feet::summary(feet));
        }
        if let Some(floor) = &o.floor {
            let f = &floor.floor;
            let side = if f.height <= 0.0 { "below" } else { "above" };
            println!(
                "  stood on the floor ({}; {} foot contacts): {:.1} degrees of tilt removed, the floor ({:.2} m {side} the calibration's origin) put at y = 0, the take moved {:.2} m along it to start at the origin",
                f.method.describe(),
                f.contacts_used,
                f.tilt_degrees,
                f.height.abs(),
                floor.moved_along_floor
            );
        } else if o.format == mocap_fuse::OutputFormat::Bvh {
            println!("  in the calibration's world");
        }
    }
}

fn run_offline(args: RunArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    let fusion = FusionOptions::preset(&args.method)?;
    let mut outputs = args.bvh.outputs(args.output.clone())?;
    if args.calibration_world {
        outputs.bvh_world = BvhWorld::Calibration;
    }
    if args.body.is_none() && !options.quiet {
        eprintln!("note: no --body: the person's bone lengths and ranges are measured from these recordings");
    }
    let reading = args.reading.options();
    let report = mocap_fuse::fuse_files_with(
        &FuseFilesOptions {
            recordings: args.recordings,
            calibration: args.calib,
            body: args.body,
            outputs,
            fusion,
            fps: args.fps,
        },
        &reading,
    )?;
    print_reading_notes(&report.recordings.notes(), options);
    for n in report.same_person.notes() {
        eprintln!("warning: {n}");
    }
    if args.json {
        return print_json(&report);
    }
    println!(
        "fused {} frames from sensors {:?} ({})",
        report.fused_frames, report.sensors, args.method
    );
    if report.implausible_joints > 0 {
        println!(
            "{} joints farther than {} m from their sensor fused as NotTracked",
            report.implausible_joints,
            mocap_fuse::MAX_JOINT_DISTANCE
        );
    }
    print_outputs(&report.outputs);
    Ok(())
}

// ------------------------------------------------------------------- serve

#[derive(clap::Args)]
struct ServeArgs {
    /// The calibration file (every sensor's pose).
    #[arg(long)]
    calib: PathBuf,
    /// The person's body file (mocap fuse measure).
    #[arg(long)]
    body: PathBuf,
    /// Address and UDP port to listen on (port 0: any free port, printed).
    #[arg(long, default_value = "127.0.0.1:9000")]
    listen: SocketAddr,
    /// Output: .jsonl (written as frames come) or .bvh (written at the end); repeat for both.
    #[arg(long, short, required = true)]
    output: Vec<PathBuf>,
    /// Fused frames per second.
    #[arg(long, default_value_t = 30.0)]
    fps: f64,
    /// Seconds past an instant after which it is fused without waiting for slower sensors.
    #[arg(long, default_value_t = 0.1)]
    wait: f64,
    /// Seconds behind the newest frame after which a sensor counts as gone.
    #[arg(long, default_value_t = 0.5)]
    sensor_timeout: f64,
    /// Seconds a datagram's time may be ahead of or behind the sensors' clock as the server
    /// reckons it; others are dropped as implausible (raise it for replays much faster than real time).
    #[arg(long, default_value_t = mocap_fuse::DEFAULT_MAX_SKEW)]
    max_skew: f64,
    /// Fusion method.
    #[arg(long, default_value = "best", value_parser = clap::builder::PossibleValuesParser::new(METHOD_NAMES))]
    method: String,
    /// Stop after this many seconds (default: at Ctrl-C).
    #[arg(long)]
    duration: Option<f64>,
    /// Stop when no datagram has come for this many seconds after the first.
    #[arg(long)]
    idle_exit: Option<f64>,
    #[command(flatten)]
    bvh: FusedBvhArgs,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
}

fn seconds(name: &str, value: Option<f64>) -> anyhow::Result<Option<Duration>> {
    value
        .map(|s| {
            Duration::try_from_secs_f64(s)
                .with_context(|| format!("--{name} {s}: expected a number of seconds"))
        })
        .transpose()
}

fn serve(args: ServeArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    if !(args.fps.is_finite() && args.fps > 0.0) {
        bail!("--fps must be positive");
    }
    let serve_options = ServeFilesOptions {
        calibration: args.calib,
        body: args.body,
        outputs: args.bvh.outputs(args.output)?,
        listen: args.listen,
        fusion: FusionOptions::preset(&args.method)?,
        fps: args.fps,
        wait: args.wait,
        sensor_timeout: args.sensor_timeout,
        max_skew: args.max_skew,
        duration: seconds("duration", args.duration)?,
        idle_exit: seconds("idle-exit", args.idle_exit)?,
    };
    let quiet = options.quiet;
    let report = mocap_fuse::serve_files(serve_options, |addr| {
        if !quiet {
            eprintln!("fuse serve: listening on {addr} (Ctrl-C to stop)");
        }
    })?;
    if args.json {
        return print_json(&report);
    }
    let s = &report.server;
    println!(
        "{} datagrams: {} frames accepted, {} malformed, {} duplicates, {} late, {} from uncalibrated sensors; {} fused frames from sensors {:?}",
        s.datagrams, s.frames_accepted, s.malformed, s.duplicates, s.late, s.uncalibrated, s.fused_frames, s.sensors_seen
    );
    if s.implausible_time + s.implausible_frames + s.implausible_joints + s.overflow > 0 {
        println!(
            "dropped {} datagrams with an implausible time, {} frames with no joint within {} m of the sensor, {} beyond what a sensor can send; {} joints beyond {} m fused as NotTracked",
            s.implausible_time,
            s.implausible_frames,
            mocap_fuse::MAX_JOINT_DISTANCE,
            s.overflow,
            s.implausible_joints,
            mocap_fuse::MAX_JOINT_DISTANCE
        );
    }
    println!(
        "latency from datagram to fused frame: median {:.1} ms, p99 {:.1} ms",
        s.latency_median_ms, s.latency_p99_ms
    );
    print_outputs(&report.outputs);
    Ok(())
}

// -------------------------------------------------------------------- send

#[derive(clap::Args)]
struct SendArgs {
    /// Recordings (.jsonl, NTU .skeleton) to send.
    #[arg(required = true)]
    recordings: Vec<PathBuf>,
    /// The fusion server's address.
    #[arg(long)]
    to: SocketAddr,
    /// Send each frame when it reached its sensor's computer (else as fast as possible).
    #[arg(long)]
    realtime: bool,
    /// Playback speed with --realtime.
    #[arg(long, default_value_t = 1.0)]
    speed: f64,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
}

fn send(args: SendArgs, _options: &GlobalOptions) -> anyhow::Result<()> {
    if !(args.speed.is_finite() && args.speed > 0.0) {
        bail!("--speed must be positive");
    }
    let report = mocap_fuse::send_files(
        &args.recordings,
        SendOptions {
            to: args.to,
            realtime: args.realtime,
            speed: args.speed,
        },
    )?;
    if args.json {
        return print_json(&report);
    }
    println!(
        "sent {} datagrams ({} bytes) to {} in {:.2} s",
        report.datagrams, report.bytes, args.to, report.seconds
    );
    Ok(())
}

// -------------------------------------------------------------------- eval

#[derive(clap::Args)]
#[command(
    after_help = "BVH takes or folders: sensors are simulated and every method is compared with the ground truth.\n\
Recordings (NTU .skeleton, one file per camera of a take, or .jsonl): no ground truth; sensors are calibrated from \
the body and single sensors are compared with the fused result by bone-length consistency."
)]
struct EvalArgs {
    /// BVH files or folders, or recordings (.skeleton, .jsonl).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Sensor counts to simulate (BVH).
    #[arg(long, default_value = "2,3,4", value_delimiter = ',')]
    sensors: Vec<usize>,
    /// Seeds per take and sensor count (BVH).
    #[arg(long, default_value = "1,2,3", value_delimiter = ',')]
    seeds: Vec<u64>,
    /// How the sensor poses are known: `truth` (BVH takes: the simulator's; recordings: from the body), `body` (calibrated from the body), or a calibration file (recordings).
    #[arg(long, default_value = "truth", value_name = "truth|body|FILE")]
    calib: String,
    /// Also run methods with joint ranges from this ASF skeleton's limits (BVH).
    #[arg(long, value_name = "SKELETON.asf")]
    limits: Option<PathBuf>,
    /// Draw here: per-joint position errors (BVH: `per-joint-<K>-sensors.png`, `.svg`), or a filmstrip of each take of recordings (`filmstrip-<take>.png`: each sensor and the fused skeleton).
    #[arg(long, value_name = "DIR")]
    plots: Option<PathBuf>,
    #[command(flatten)]
    report: ReportArgs,
}

fn eval(args: EvalArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    let command = format!(
        "mocap fuse eval {}",
        std::env::args().skip(3).collect::<Vec<_>>().join(" ")
    );
    let eval_options = EvalOptions {
        inputs: args.inputs,
        sensor_counts: args.sensors,
        seeds: args.seeds,
        calibration: match args.calib.as_str() {
            "truth" => CalibrationSource::Truth,
            "body" => CalibrationSource::Body,
            file => CalibrationSource::File(file.into()),
        },
        limits: args.limits,
        ..Default::default()
    };
    let progress = options.progress(0, "evaluating");
    let evaluation = mocap_fuse::evaluate_inputs(&eval_options, &mut |done, total| {
        progress.set_length(total as u64);
        progress.set_position(done as u64);
    })?;
    progress.finish_and_clear();
    match (&args.plots, &evaluation) {
        (Some(dir), Evaluation::Truth(report)) => {
            draw_per_joint_charts(&report.per_joint_charts(), dir)?
        }
        (Some(dir), Evaluation::Consistency(reports)) => draw_filmstrips(reports, dir, options)?,
        (None, _) => {}
    }
    let markdown = evaluation.markdown(&command);
    if let Some(path) = &args.report.markdown {
        mocap_core::io::atomic::write_bytes_atomically(path, markdown.as_bytes())?;
    }
    if args.report.json {
        print_json(&evaluation)
    } else {
        println!("{markdown}");
        Ok(())
    }
}

/// Draws each take of recordings as `filmstrip-<take>.png` in `dir`: a row
/// per sensor (in the world, by its calibration) and one for the fused
/// skeleton, at the same moments, joints coloured by confidence.
fn draw_filmstrips(
    reports: &[mocap_fuse::ConsistencyReport],
    dir: &Path,
    options: &GlobalOptions,
) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let names: Vec<String> = mocap_fuse::JOINT_NAMES
        .iter()
        .map(|n| n.to_string())
        .collect();
    for report in reports {
        let motions = report
            .poses
            .iter()
            .map(|poses| {
                mocap_view::ViewMotion::from_positions(
                    poses.source.clone(),
                    names.clone(),
                    mocap_fuse::PARENTS.to_vec(),
                    poses.frame_time,
                    poses.joints.iter().flatten().copied().collect(),
                    Some(1.0),
                )?
                .with_confidence(poses.confidence.iter().flatten().copied().collect())
            })
            .collect::<mocap_core::Result<Vec<_>>>()?;
        let take: String = Path::new(&report.take)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| report.take.clone())
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                    c
                } else {
                    '-'
                }
            })
            .collect();
        let path = dir.join(format!("filmstrip-{take}.png"));
        let render = mocap_view::RenderOptions {
            layout: mocap_view::Layout::Rows,
            ..Default::default()
        };
        mocap_view::render(&mocap_view::Scene::new(motions), &path, &render)
            .with_context(|| format!("drawing {}", path.display()))?;
        if !options.quiet {
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}

/// Draws each chart as `per-joint-<K>-sensors.png` and `.svg` in `dir`.
fn draw_per_joint_charts(charts: &[PerJointChart], dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    for chart in charts {
        let plot = mocap_view::BarPlot {
            title: chart.title.clone(),
            y_label: "mm".into(),
            categories: chart.joints.clone(),
            series: chart
                .series
                .iter()
                .map(|s| mocap_view::BarSeries {
                    label: s.label.clone(),
                    values: s.values.clone(),
                    errors: Some(s.errors.clone()),
                })
                .collect(),
            size: (1600, 600),
        };
        for extension in ["png", "svg"] {
            let path = dir.join(format!("per-joint-{}-sensors.{extension}", chart.sensors));
            mocap_view::plot_bars(&path, &plot)
                .with_context(|| format!("drawing {}", path.display()))?;
        }
    }
    Ok(())
}
