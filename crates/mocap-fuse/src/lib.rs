//! # mocap-fuse
//!
//! Multi-sensor skeleton capture with body-aware confidence: several depth
//! sensors (Kinect v2 style, 25 joints with a tracking state each) watch one
//! person; each is calibrated into a world frame and streams its skeletons to
//! a fusion server, which fuses each joint as a confidence-weighted mean
//!
//! ```text
//! J_n = sum_k C_kn J_kn / sum_k C_kn
//! ```
//!
//! where the confidence `C_kn` of sensor `k` for joint `n` multiplies a
//! tracking-state weight, a bone-length term propagated down the kinematic
//! chain and a range-of-motion term ([`ConfidenceModel`]).
//!
//! What is here, from the bottom up:
//! - the Kinect v2 layout ([`JOINT_NAMES`], [`joint`], [`TrackingState`])
//!   and the Kinect joints of a motion ([`truth_from_motion`]);
//! - recordings ([`SensorFrame`], [`read_recordings`]; NTU RGB+D
//!   `.skeleton` files too) and the person measured beforehand
//!   ([`BodyModel`]);
//! - one sensor's recording as a motion ([`recording_motion`]; what `mocap
//!   info`, `render`... read, [`register_recording_readers`]);
//! - the fusion of one instant ([`Fuser`], [`FusionOptions`]), offline over
//!   recordings ([`fuse_recordings`]) or live over UDP ([`serve`],
//!   [`send`]), written as JSON lines or BVH ([`FusedOutputs`]), the BVH
//!   upright on the floor found under the feet ([`fit_floor`],
//!   [`stand_on_floor`]);
//! - sensor poses ([`Calibration`]) found from the body seen by every sensor
//!   ([`calibrate_from_body`]) or from room scans ([`calibrate_from_points`]);
//! - a Kinect v2 simulator on ground-truth takes ([`simulate_capture`]) and
//!   the evaluation against the truth, or without it by bone-length
//!   consistency ([`evaluate_inputs`]).
//!
//! Each `mocap fuse` subcommand is one function here: [`simulate_to_folder`],
//! [`calibrate_recordings`] and [`calibrate_scans`], [`measure_recordings`],
//! [`fuse_files`], [`serve_files`], [`send_files`], [`evaluate_inputs`].
//!
//! Simulate three sensors watching a take and fuse what they saw:
//!
//! ```no_run
//! use mocap_fuse::{fuse_streams, simulate_capture, Fuser, FusionOptions, SensorStreams, SimulationOptions};
//!
//! let take = std::path::Path::new("samples/dataset-1_walk_normal_001.bvh");
//! let motion = mocap_core::io::bvh::read_bvh(take)?;
//! let options = SimulationOptions { sensors: 3, ..Default::default() };
//! let capture = simulate_capture(&motion, None, &options)?;
//! let streams = SensorStreams::new(
//!     capture.simulation.sensors.iter().flat_map(|s| s.frames.iter().cloned()),
//! );
//! let mut fuser = Fuser::new(FusionOptions::best(), capture.body.clone());
//! let fused = fuse_streams(&streams, &capture.simulation.calibration(), &mut fuser, 30.0, None);
//! println!("{} fused frames", fused.len());
//! # Ok::<(), mocap_core::Error>(())
//! ```
//!
//! Fuse recorded sensors into a BVH file, as `mocap fuse run` does:
//!
//! ```no_run
//! use mocap_fuse::{
//!     fuse_files, BoneLengthSource, BvhWorld, FuseFilesOptions, FusionOptions, OutputFiles,
//! };
//!
//! let report = fuse_files(&FuseFilesOptions {
//!     recordings: vec!["sensor-0.jsonl".into(), "sensor-1.jsonl".into()],
//!     calibration: "rig.toml".into(),
//!     body: Some("body.json".into()),
//!     outputs: OutputFiles {
//!         paths: vec!["fused.bvh".into()],
//!         bvh_units_per_metre: 100.0,
//!         bvh_lengths: BoneLengthSource::Fused,
//!         feet: None,
//!         bvh_world: BvhWorld::Floor,
//!     },
//!     fusion: FusionOptions::best(),
//!     fps: 30.0,
//! })?;
//! println!("{} fused frames", report.fused_frames);
//! # Ok::<(), mocap_core::Error>(())
//! ```
//!
//! Fuse one instant by hand: each sensor's skeleton in the world frame, with
//! its tracking states.
//!
//! ```
//! use mocap_core::rotation::Vec3;
//! use mocap_fuse::{
//!     BodyModel, Fuser, FusionOptions, JointObservation, MeasureOptions, SensorView,
//!     TrackingState, JOINT_COUNT,
//! };
//!
//! let seen_at = |x: f32| {
//!     [JointObservation { position: Vec3::new(x, 1.0, 0.0), state: TrackingState::Tracked };
//!         JOINT_COUNT]
//! };
//! let nobody: [[JointObservation; JOINT_COUNT]; 0] = [];
//! let body = BodyModel::measure(&nobody, MeasureOptions::default());
//! let mut fuser = Fuser::new(FusionOptions::state_only(), body);
//! let views = [
//!     SensorView { sensor: 0, origin: Vec3::new(0.0, 1.0, 3.0), joints: seen_at(0.0) },
//!     SensorView { sensor: 1, origin: Vec3::new(0.0, 1.0, -3.0), joints: seen_at(0.1) },
//! ];
//! let frame = fuser.fuse(0.0, &views).expect("two sensors see the person");
//! assert!((frame.joints[0].x - 0.05).abs() < 1e-6);
//! ```

mod align;
mod body;
mod bvh;
mod calib;
mod confidence;
mod eval;
mod floor;
mod fusion;
mod kinect;
mod net;
mod offline;
mod output;
mod ply;
mod recording;
mod sim;
mod single;

pub use align::{
    calibrate_from_body, calibrate_from_points, calibrate_recordings, calibrate_recordings_with,
    calibrate_scans, fit_rigid, icp, read_point_pairs, Alignment, BodyCalibration,
    BodyCalibrationOptions, BodyCalibrationReport, BodySensorReport, IcpMetric, IcpOptions,
    IcpResult, PointCalibration, ScanCalibration, ScanPair,
};
pub use body::{
    measure_recordings, measure_recordings_with, ranges_from_asf, ranges_from_limits,
    AngleDefinition, AngleRange, BodyModel, MeasureOptions, ANGLES,
};
pub use bvh::{
    fit_error, fit_skeleton, fused_to_motion, fused_to_motion_with, poses_on_skeleton,
    poses_to_motion, poses_to_motion_with, regular_poses, BoneLengthSource, BvhOptions, FitError,
    FittedSkeleton,
};
pub use calib::{Calibration, RigidTransform, SensorPose};
pub use confidence::{
    confidences, BoneLengthFunction, ConfidenceModel, RangeOfMotionTerm, StateWeights,
};
pub use eval::{
    consistency_markdown, evaluate, evaluate_consistency, evaluate_inputs, evaluate_recordings,
    evaluate_with, group_takes, report_markdown, simulated_fused_take, CalibrationError,
    CalibrationSource, ConsistencyReport, ConsistencyRow, EvalOptions, EvalReport, Evaluation,
    MethodResult, PerJointChart, PerJointSeries, SourcePoses, CONSISTENCY_BONES,
};
pub use floor::{
    fit_floor, floor_transform, stand_on_floor, BvhWorld, Floor, FloorMethod, FloorReport,
    MIN_SPREAD, MIN_TRAVEL, TRIM_ITERATIONS,
};
pub use fusion::{
    facing_of, FusedFrame, Fuser, FusionOptions, OneEuroParams, SensorView, METHOD_NAMES,
};
pub use kinect::{
    guess_units_per_metre, joint, joint_index, truth_from_motion, GroundTruth, TrackingState,
    JOINT_COUNT, JOINT_NAMES, MIRROR, PARENTS, TOPOLOGICAL_ORDER,
};
#[doc(hidden)]
pub use net::ServerCore;
pub use net::{
    decode_datagram, encode_datagram, runtime, send, send_blocking, send_files, serve,
    serve_blocking, serve_blocking_with, serve_files, SendOptions, SendReport, ServeFilesOptions,
    ServeFilesReport, ServeOptions, ServeReport, DEFAULT_MAX_SKEW, MAGIC, MAX_TIMESTAMP,
};
pub use offline::{
    check_same_person, fuse_files, fuse_files_with, fuse_recordings, fuse_streams, views_at,
    FuseFilesOptions, FuseFilesReport, PelvisDistance, SamePersonReport, SensorAgreement,
    SensorStreams, MAX_FUSED_FRAMES, OTHER_PERSON_DISTANCE, SAME_INSTANT,
};
pub use output::{
    fused_frame_json, FrameSink, FusedOutputs, JsonlSink, MemorySink, OutputFiles, OutputFormat,
    OutputReport,
};
pub use ply::{read_ply_points, write_ply_points, PlyEncoding};
pub use recording::{
    choose_ntu_body, estimate_time_offset, ntu_camera_of, ntu_performer_frames, ntu_sensor_frames,
    read_any_recording, read_ntu_skeleton, read_ntu_skeleton_from, read_recording, read_recordings,
    read_recordings_with, write_ntu_bodies, write_ntu_skeleton, write_recording, FrameRun,
    JointObservation, NtuBody, NtuBodyChoice, NtuStitch, NtuTrack, OffsetEstimate, OffsetSource,
    ReadOptions, RecordingFile, Recordings, RecordingsReport, SensorFrame, SensorIdSource,
    TimeOffsetReport, TimeOffsets, MAX_JOINT_DISTANCE, MAX_OFFSET_FRAMES, MIN_OFFSET_CORRELATION,
    NTU_FPS, PERFORMER_MIN_COVERAGE, RECORDING_VERSION, STITCH_MAX_GAP_SECONDS,
    STITCH_METRES_PER_FRAME,
};
pub use sim::{
    center_truth, measure_person, room_points, sensor_point_cloud, simulate, simulate_capture,
    simulate_to_folder, write_simulation, SensorModel, SimulatedCapture, SimulatedSensor,
    SimulatedSensorReport, Simulation, SimulationFiles, SimulationOptions, SimulationReport,
    SurfacePoint,
};
pub use single::{recording_motion, register_recording_readers};
