//! `mocap fuse`: multi-sensor skeleton capture (Kinect v2 style sensors).
//! Argument parsing and calls into `mocap-fuse`; the work is there.

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context};
use mocap_fuse::align::{calibrate_from_body, calibrate_from_points, BodyCalibrationOptions};
use mocap_fuse::body::{ranges_from_limits, BodyModel, MeasureOptions};
use mocap_fuse::bvh::BvhOptions;
use mocap_fuse::calib::{Calibration, RigidTransform, SensorPose};
use mocap_fuse::eval::{CalibrationSource, EvalOptions};
use mocap_fuse::fusion::{Fuser, FusionOptions, METHOD_NAMES};
use mocap_fuse::net::{SendOptions, ServeOptions};
use mocap_fuse::offline::SensorStreams;
use mocap_fuse::output::FusedOutputs;
use mocap_fuse::recording::{read_any_recording, SensorFrame};
use serde::Serialize;

use super::GlobalOptions;

#[derive(clap::Args)]
#[command(after_help = "A session, end to end:\n  \
mocap fuse simulate take.bvh --sensors 3 --out sim/\n  \
mocap fuse calibrate sim/sensor-*.jsonl --out rig.toml\n  \
mocap fuse measure sim/sensor-*.jsonl --out body.json\n  \
mocap fuse run sim/sensor-*.jsonl --calib rig.toml --body body.json --out fused.jsonl --out fused.bvh\n  \
mocap fuse serve --calib rig.toml --body body.json --listen 127.0.0.1:9000 --out live.bvh &\n  \
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

fn read_recordings(paths: &[PathBuf]) -> anyhow::Result<Vec<SensorFrame>> {
    let mut frames = Vec::new();
    for (i, path) in paths.iter().enumerate() {
        frames.extend(read_any_recording(path, i as u16)?);
    }
    if frames.is_empty() {
        bail!("the recordings hold no sensor frames");
    }
    Ok(frames)
}

fn parse_method(name: &str) -> anyhow::Result<FusionOptions> {
    Ok(FusionOptions::preset(name)?)
}

fn bvh_units(text: &str) -> anyhow::Result<f32> {
    match text {
        "cm" => Ok(100.0),
        "m" => Ok(1.0),
        "mm" => Ok(1000.0),
        other => bail!("--bvh-units {other:?}: expected cm, m or mm"),
    }
}

fn bvh_lengths(text: &str) -> mocap_fuse::bvh::BoneLengthSource {
    match text {
        "body" => mocap_fuse::bvh::BoneLengthSource::Body,
        _ => mocap_fuse::bvh::BoneLengthSource::Fused,
    }
}

// ---------------------------------------------------------------- simulate

#[derive(clap::Args)]
struct SimulateArgs {
    /// The ground-truth take (BVH).
    bvh: PathBuf,
    /// Folder for the files (created if needed).
    #[arg(long, short)]
    out: PathBuf,
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

#[derive(Serialize)]
struct SimulateReport {
    sensors: Vec<SimulatedSensorReport>,
    truth_frames: usize,
    fps: f64,
    files: mocap_fuse::sim::SimulationFiles,
}

#[derive(Serialize)]
struct SimulatedSensorReport {
    id: u16,
    frames: usize,
    latency_seconds: f64,
    drop_rate: f64,
}

fn simulate(args: SimulateArgs, _options: &GlobalOptions) -> anyhow::Result<()> {
    use mocap_fuse::sim;
    if args.sensors == 0 {
        bail!("--sensors must be at least 1");
    }
    let motion = mocap_core::io::bvh::read_bvh(&args.bvh)?;
    let mut truth = sim::truth_from_motion(&motion, args.units_per_metre)?;
    let sim_options = sim::SimulationOptions {
        sensors: args.sensors,
        seed: args.seed,
        ..Default::default()
    };
    sim::center_truth(&mut truth, sim_options.treadmill_above);
    let simulation = sim::simulate(&truth, &sim_options);
    // The person, measured beforehand: from a second capture of the take
    // (other sensor places and noise), as `mocap fuse measure` would.
    let body = sim::measure_person(&truth, &sim_options);
    let files = sim::write_simulation(&args.out, &simulation, &body, args.seed, args.ntu)?;
    let report = SimulateReport {
        sensors: simulation
            .sensors
            .iter()
            .map(|s| SimulatedSensorReport {
                id: s.id,
                frames: s.frames.len(),
                latency_seconds: s.latency,
                drop_rate: s.drop_rate,
            })
            .collect(),
        truth_frames: truth.frames.len(),
        fps: truth.fps,
        files,
    };
    if args.json {
        return print_json(&report);
    }
    println!(
        "{} sensors watching {} ({} frames at {} fps) -> {}",
        report.sensors.len(),
        args.bvh.display(),
        report.truth_frames,
        report.fps,
        args.out.display()
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

// --------------------------------------------------------------- calibrate

#[derive(clap::Args)]
#[command(
    after_help = "From the body:   mocap fuse calibrate sensor-0.jsonl sensor-1.jsonl --out rig.toml\n\
From room scans: mocap fuse calibrate --points sensor-0.ply sensor-1.ply --pairs pairs-0-1.txt --out rig.toml\n\
With --points, an existing --out file is updated: the second scan's sensor is placed in the world of the first."
)]
struct CalibrateArgs {
    /// Recordings (.jsonl, NTU .skeleton) of every sensor watching the person at the same time.
    #[arg(conflicts_with = "points")]
    recordings: Vec<PathBuf>,
    /// The calibration file to write.
    #[arg(long, short)]
    out: PathBuf,
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
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
}

/// The sensor id in a file name: its last number (`sensor-2.ply` is 2).
fn id_in_name(path: &Path) -> Option<u16> {
    let stem = path.file_stem()?.to_str()?;
    let digits: String = stem
        .chars()
        .rev()
        .skip_while(|c| !c.is_ascii_digit())
        .take_while(|c| c.is_ascii_digit())
        .collect();
    digits.chars().rev().collect::<String>().parse().ok()
}

fn calibrate(args: CalibrateArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    if let Some(points) = &args.points {
        return calibrate_points(&args, points, options);
    }
    if args.recordings.is_empty() {
        bail!("give the recordings of the sensors (body calibration) or --points A.ply B.ply");
    }
    let frames = read_recordings(&args.recordings)?;
    let streams = SensorStreams::new(frames);
    let found = calibrate_from_body(
        &streams,
        &BodyCalibrationOptions {
            reference: args.reference,
            ..Default::default()
        },
    )?;
    found.calibration.write(&args.out)?;
    #[derive(Serialize)]
    struct Report<'a> {
        calibration: &'a Path,
        reference: u16,
        sensors: &'a [mocap_fuse::align::BodySensorReport],
    }
    let report = Report {
        calibration: &args.out,
        reference: found.reference,
        sensors: &found.sensors,
    };
    if args.json {
        return print_json(&report);
    }
    println!(
        "calibrated from the body; world = sensor {} -> {}",
        found.reference,
        args.out.display()
    );
    for s in &found.sensors {
        println!(
            "  sensor {}: {} of {} joint pairs fit within 10 cm (RMS {:.1} mm), {} of {} frames with settled left/right, turn about the vertical known to about {:.1} degrees",
            s.sensor,
            s.inliers,
            s.pairs,
            s.rms * 1000.0,
            s.settled_frames,
            s.paired_frames,
            s.yaw_uncertainty_degrees
        );
    }
    if found
        .sensors
        .iter()
        .any(|s| s.yaw_uncertainty_degrees > 5.0)
    {
        println!("warning: the person moved too little for a sure calibration from the body (over 5 degrees of doubt); capture a take where they walk and turn, or refine with room scans (--points)");
    }
    Ok(())
}

fn calibrate_points(
    args: &CalibrateArgs,
    points: &[PathBuf],
    _options: &GlobalOptions,
) -> anyhow::Result<()> {
    let [a_path, b_path] = points else {
        bail!("--points takes two scans");
    };
    let (a_id, b_id) = match &args.ids {
        Some(ids) => (ids[0], ids[1]),
        None => match (id_in_name(a_path), id_in_name(b_path)) {
            (Some(a), Some(b)) => (a, b),
            _ => bail!(
                "cannot tell the sensor ids from the names {} and {}: give --ids A B",
                a_path.display(),
                b_path.display()
            ),
        },
    };
    if a_id == b_id {
        bail!("both scans are of sensor {a_id}: give --ids A B");
    }
    let a = mocap_fuse::ply::read_ply_points(a_path)?;
    let b = mocap_fuse::ply::read_ply_points(b_path)?;
    let pairs = match &args.pairs {
        Some(p) => mocap_fuse::align::read_point_pairs(p)?,
        None => Vec::new(),
    };
    let initial = match &args.initial {
        Some(path) => {
            let c = Calibration::read(path)?;
            let (Some(wa), Some(wb)) = (c.get(a_id), c.get(b_id)) else {
                bail!(
                    "{}: --initial must hold both sensor {a_id} and sensor {b_id}",
                    path.display()
                );
            };
            Some(wa.inverse().then_after(wb))
        }
        None => None,
    };
    if pairs.is_empty() && initial.is_none() {
        eprintln!("note: no --pairs or --initial: ICP starts from the identity, which works only for scans taken from nearly the same place");
    }
    let result = calibrate_from_points(&a, &b, &pairs, initial, &Default::default())?;
    // Place B in the world of the output file (A's pose there, or A as the
    // world when the file is new).
    let mut calibration = if args.out.exists() {
        Calibration::read(&args.out)?
    } else {
        Calibration::default()
    };
    let world_from_a = match calibration.get(a_id) {
        Some(t) => *t,
        None => {
            calibration.set(SensorPose {
                id: a_id,
                transform: RigidTransform::IDENTITY,
                method: Some("reference".into()),
                rms_residual: None,
                pairs: None,
            });
            RigidTransform::IDENTITY
        }
    };
    calibration.set(SensorPose {
        id: b_id,
        transform: world_from_a.then_after(&result.transform),
        method: Some("icp".into()),
        rms_residual: Some(result.icp.rms),
        pairs: Some(result.icp.pairs),
    });
    calibration.write(&args.out)?;
    if args.json {
        return print_json(&result);
    }
    if let Some(fit) = &result.pairs_fit {
        println!(
            "rough start from {} point pairs: RMS {:.1} mm",
            fit.pairs,
            fit.rms * 1000.0
        );
    }
    println!(
        "ICP: {} point pairs, RMS {:.1} mm, {} iterations{} -> sensor {b_id} in {}",
        result.icp.pairs,
        result.icp.rms * 1000.0,
        result.icp.iterations,
        if result.icp.converged {
            ""
        } else {
            " (not converged)"
        },
        args.out.display()
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
    out: PathBuf,
    /// Take the joint ranges from the limits of an ASF skeleton instead of measuring them.
    #[arg(long, value_name = "SKELETON.asf")]
    limits: Option<PathBuf>,
    /// Print the body as JSON.
    #[arg(long)]
    json: bool,
}

fn measure(args: MeasureArgs, _options: &GlobalOptions) -> anyhow::Result<()> {
    let frames = read_recordings(&args.recordings)?;
    let mut body = BodyModel::measure(frames.iter().map(|f| &f.joints), MeasureOptions::default());
    if let Some(asf) = &args.limits {
        let skeleton = mocap_core::io::asf_amc::read_asf(asf)?
            .to_skeleton(mocap_core::io::asf_amc::LengthUnit::Centimetres)?;
        body.ranges = ranges_from_limits(&skeleton)?;
    }
    body.write(&args.out)?;
    if args.json {
        return print_json(&body);
    }
    let measured = body.bone_lengths.iter().flatten().count();
    let ranges = body.ranges.iter().flatten().count();
    println!(
        "{measured} bone lengths and {ranges} joint ranges{} -> {}",
        if args.limits.is_some() {
            " (from the ASF limits)"
        } else {
            ""
        },
        args.out.display()
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
    out: Vec<PathBuf>,
    /// Fusion method.
    #[arg(long, default_value = "best", value_parser = clap::builder::PossibleValuesParser::new(METHOD_NAMES))]
    method: String,
    /// Fused frames per second.
    #[arg(long, default_value_t = 30.0)]
    fps: f64,
    /// Length unit of the BVH output: cm, m or mm.
    #[arg(long, default_value = "cm")]
    bvh_units: String,
    /// Bone lengths of the BVH skeleton: the median of the fused take, or the body file's.
    #[arg(long, default_value = "fused", value_parser = ["fused", "body"])]
    bvh_lengths: String,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct RunReport {
    fused_frames: usize,
    sensors: Vec<u16>,
    body_measured_from_recordings: bool,
    outputs: Vec<mocap_fuse::output::OutputReport>,
}

/// The body from its file, or measured from the recordings.
fn body_of(path: Option<&Path>, frames: &[SensorFrame]) -> anyhow::Result<BodyModel> {
    Ok(match path {
        Some(p) => BodyModel::read(p)?,
        None => BodyModel::measure(frames.iter().map(|f| &f.joints), MeasureOptions::default()),
    })
}

fn print_outputs(outputs: &[mocap_fuse::output::OutputReport]) {
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
    }
}

fn run_offline(args: RunArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    let calibration = Calibration::read(&args.calib)?;
    let fusion = parse_method(&args.method)?;
    let frames = read_recordings(&args.recordings)?;
    let mut sensors: Vec<u16> = frames.iter().map(|f| f.sensor).collect();
    sensors.sort();
    sensors.dedup();
    let body = body_of(args.body.as_deref(), &frames)?;
    if args.body.is_none() && !options.quiet {
        eprintln!("note: no --body: the person's bone lengths and ranges are measured from these recordings");
    }
    let bvh = BvhOptions {
        units_per_metre: bvh_units(&args.bvh_units)?,
        fps: args.fps,
    };
    let mut outputs = FusedOutputs::create(&args.out, body.clone(), bvh)?
        .with_bone_lengths(bvh_lengths(&args.bvh_lengths));
    let mut fuser = Fuser::new(fusion, body);
    let count = mocap_fuse::offline::fuse_recordings(
        frames,
        &calibration,
        &mut fuser,
        args.fps,
        &mut outputs,
    )?;
    let report = RunReport {
        fused_frames: count,
        sensors,
        body_measured_from_recordings: args.body.is_none(),
        outputs: outputs.reports().to_vec(),
    };
    if args.json {
        return print_json(&report);
    }
    println!(
        "fused {} frames from sensors {:?} ({})",
        report.fused_frames, report.sensors, args.method
    );
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
    out: Vec<PathBuf>,
    /// Fused frames per second.
    #[arg(long, default_value_t = 30.0)]
    fps: f64,
    /// Seconds past an instant after which it is fused without waiting for slower sensors.
    #[arg(long, default_value_t = 0.1)]
    wait: f64,
    /// Seconds behind the newest frame after which a sensor counts as gone.
    #[arg(long, default_value_t = 0.5)]
    sensor_timeout: f64,
    /// Fusion method.
    #[arg(long, default_value = "best", value_parser = clap::builder::PossibleValuesParser::new(METHOD_NAMES))]
    method: String,
    /// Stop after this many seconds (default: at Ctrl-C).
    #[arg(long)]
    duration: Option<f64>,
    /// Stop when no datagram has come for this many seconds after the first.
    #[arg(long)]
    idle_exit: Option<f64>,
    /// Length unit of the BVH output: cm, m or mm.
    #[arg(long, default_value = "cm")]
    bvh_units: String,
    /// Bone lengths of the BVH skeleton: the median of the fused take, or the body file's.
    #[arg(long, default_value = "fused", value_parser = ["fused", "body"])]
    bvh_lengths: String,
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
    let calibration = Calibration::read(&args.calib)?;
    let body = BodyModel::read(&args.body)?;
    if !(args.fps.is_finite() && args.fps > 0.0) {
        bail!("--fps must be positive");
    }
    let bvh = BvhOptions {
        units_per_metre: bvh_units(&args.bvh_units)?,
        fps: args.fps,
    };
    let mut outputs = FusedOutputs::create(&args.out, body.clone(), bvh)?
        .with_bone_lengths(bvh_lengths(&args.bvh_lengths));
    let serve_options = ServeOptions {
        listen: args.listen,
        calibration,
        body,
        fusion: parse_method(&args.method)?,
        fps: args.fps,
        wait: args.wait,
        sensor_timeout: args.sensor_timeout,
        duration: seconds("duration", args.duration)?,
        idle_exit: seconds("idle-exit", args.idle_exit)?,
    };
    let quiet = options.quiet;
    let report = mocap_fuse::net::serve_blocking_with(serve_options, &mut outputs, |addr| {
        if !quiet {
            eprintln!("fuse serve: listening on {addr} (Ctrl-C to stop)");
        }
    })?;
    #[derive(Serialize)]
    struct Report {
        server: mocap_fuse::net::ServeReport,
        outputs: Vec<mocap_fuse::output::OutputReport>,
    }
    let report = Report {
        server: report,
        outputs: outputs.reports().to_vec(),
    };
    if args.json {
        return print_json(&report);
    }
    let s = &report.server;
    println!(
        "{} datagrams: {} frames accepted, {} malformed, {} duplicates, {} late, {} from uncalibrated sensors; {} fused frames from sensors {:?}",
        s.datagrams, s.frames_accepted, s.malformed, s.duplicates, s.late, s.uncalibrated, s.fused_frames, s.sensors_seen
    );
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
    let frames = read_recordings(&args.recordings)?;
    let report = mocap_fuse::net::send_blocking(
        &frames,
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
    /// How the sensor poses are known (BVH): the simulator's truth, or calibrated from the body.
    #[arg(long, default_value = "truth", value_parser = ["truth", "body"])]
    calib: String,
    /// Also run methods with joint ranges from this ASF skeleton's limits (BVH).
    #[arg(long, value_name = "SKELETON.asf")]
    limits: Option<PathBuf>,
    /// Write the results as JSON here (`-`: standard output).
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write the results as a Markdown table here.
    #[arg(long)]
    md: Option<PathBuf>,
    /// Draw per-joint position errors (BVH) here: `per-joint-<K>-sensors.png` and `.svg`.
    #[arg(long, value_name = "DIR")]
    plots: Option<PathBuf>,
}

fn eval(args: EvalArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    let is_recording = |p: &PathBuf| {
        p.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("skeleton") || e.eq_ignore_ascii_case("jsonl"))
    };
    let recordings = args.inputs.iter().filter(|p| is_recording(p)).count();
    let command = format!(
        "mocap fuse eval {}",
        std::env::args().skip(3).collect::<Vec<_>>().join(" ")
    );
    let (markdown, json) = if recordings == args.inputs.len() {
        let takes = mocap_fuse::eval::group_takes(&args.inputs);
        let methods: Vec<(String, FusionOptions)> = ["state", "report", "best"]
            .iter()
            .map(|m| Ok((format!("fused ({m})"), FusionOptions::preset(m)?)))
            .collect::<anyhow::Result<_>>()?;
        let progress = options.progress(takes.len(), "evaluating");
        let mut reports = Vec::new();
        for (take, files) in &takes {
            let frames = read_recordings(files)?;
            reports.push(mocap_fuse::eval::evaluate_consistency(
                take, frames, &methods, 30.0,
            )?);
            progress.inc(1);
        }
        progress.finish_and_clear();
        (
            mocap_fuse::eval::consistency_markdown(&reports, &command),
            serde_json::to_string_pretty(&reports)?,
        )
    } else if recordings == 0 {
        let limit_ranges = match &args.limits {
            Some(asf) => Some(ranges_from_limits(
                &mocap_core::io::asf_amc::read_asf(asf)?
                    .to_skeleton(mocap_core::io::asf_amc::LengthUnit::Centimetres)?,
            )?),
            None => None,
        };
        let eval_options = EvalOptions {
            inputs: args.inputs.clone(),
            sensor_counts: args.sensors.clone(),
            seeds: args.seeds.clone(),
            calibration: if args.calib == "body" {
                CalibrationSource::Body
            } else {
                CalibrationSource::Truth
            },
            limit_ranges,
            ..Default::default()
        };
        let files = mocap_fuse::eval::collect_bvh_files(&args.inputs)?;
        let progress = options.progress(files.len(), "evaluating");
        let report = mocap_fuse::eval::evaluate_with(&eval_options, &mut |done, _| {
            progress.set_position(done as u64)
        })?;
        progress.finish_and_clear();
        if let Some(dir) = &args.plots {
            plot_per_joint_errors(&report, dir)?;
        }
        (
            mocap_fuse::eval::report_markdown(&report, &command),
            serde_json::to_string_pretty(&report)?,
        )
    } else {
        bail!("give either BVH takes (simulated sensors, ground truth) or recordings (.skeleton, .jsonl), not both");
    };
    match args.json.as_deref() {
        Some(p) if p == Path::new("-") => println!("{json}"),
        Some(p) => mocap_core::io::atomic::write_bytes_atomically(p, json.as_bytes())?,
        None => {}
    }
    if let Some(p) = &args.md {
        mocap_core::io::atomic::write_bytes_atomically(p, markdown.as_bytes())?;
    }
    if args.json.as_deref() != Some(Path::new("-")) {
        println!("{markdown}");
    }
    Ok(())
}

/// Per sensor count, grouped bars of each joint's mean position error for
/// the best single sensor, the report's baseline and method, and our best
/// version, with the standard deviation over runs as error bars.
fn plot_per_joint_errors(report: &mocap_fuse::eval::EvalReport, dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let shown = |name: &str| {
        name == "best single sensor"
            || name.starts_with("state only (")
            || name.contains("(report method)")
            || name.starts_with("best:")
    };
    let joints: Vec<String> = mocap_core::bodymap::KINECT_V2_JOINTS
        .iter()
        .map(|(name, _)| name.to_string())
        .collect();
    let mut counts: Vec<usize> = report.results.iter().map(|r| r.sensors).collect();
    counts.dedup();
    for k in counts {
        let series: Vec<mocap_view::BarSeries> = report
            .results
            .iter()
            .filter(|r| r.sensors == k && shown(&r.method) && r.per_joint_mm.len() == joints.len())
            .map(|r| mocap_view::BarSeries {
                label: format!("{} ({:.1} mm)", r.method, r.mpjpe_mm),
                values: r.per_joint_mm.iter().map(|&v| v as f32).collect(),
                errors: Some(r.per_joint_sd_mm.iter().map(|&v| v as f32).collect()),
            })
            .collect();
        if series.is_empty() {
            continue;
        }
        let plot = mocap_view::BarPlot {
            title: format!(
                "position error per joint, {k} sensors ({} takes x {} seeds; bars: sd over runs)",
                report.clips.len(),
                report.seeds.len()
            ),
            y_label: "mm".into(),
            categories: joints.clone(),
            series,
            size: (1600, 600),
        };
        for extension in ["png", "svg"] {
            let path = dir.join(format!("per-joint-{k}-sensors.{extension}"));
            mocap_view::plot_bars(&path, &plot)
                .with_context(|| format!("drawing {}", path.display()))?;
        }
    }
    Ok(())
}
