//! # mocap-cameras
//!
//! Capture from a few calibrated RGB cameras and a 2D pose estimator
//! (OpenPose, AlphaPose, MediaPipe), as Pose2Sim, FreeMoCap or anipose do:
//! per-camera 2D keypoints are triangulated into 3D joints, each view
//! weighted by the fusion report's confidence (the keypoint's score in place
//! of the tracking state, × bone-length agreement × range of motion), views
//! that disagree are left out, and the joints are fitted to a BVH skeleton
//! with mocap-fuse's fitter.
//!
//! What is here, from the bottom up:
//! - cameras and their calibration ([`Camera`], [`CameraRig`],
//!   [`read_calibration`]: Pose2Sim TOML, OpenCV YAML and JSON);
//! - keypoint layouts and the 2D keypoint files ([`Layout`],
//!   [`read_openpose_folder`]), 3D markers as TRC ([`read_trc`]);
//! - one point from several views ([`triangulate`], [`triangulate_robust`])
//!   and one frame from every camera by confidence ([`triangulate_frame`],
//!   [`Method`]);
//! - a trial folder to BVH ([`run_capture`], `mocap cameras run`), the
//!   simulator ([`simulate_to_folder`], `mocap cameras simulate`) and the
//!   comparison of methods ([`evaluate_trial`], `mocap cameras eval`).
//!
//! Triangulate a Pose2Sim trial into a BVH file:
//!
//! ```no_run
//! use mocap_cameras::{run_capture, CaptureOptions};
//!
//! let report = run_capture(&CaptureOptions::new("S00_P00_T01_BalancingTrial"), "take.bvh".as_ref())?;
//! println!("{:.1} px", report.people[0].reprojection_px.unwrap_or(f64::NAN));
//! # Ok::<(), mocap_core::Error>(())
//! ```

mod associate;
mod camera;
mod capture;
mod eval;
mod keypoints;
mod kinect;
mod layout;
mod sim;
mod solve;
mod trc;
mod triangulate;

// Front door: each module's re-exports.
pub use associate::AssociationOptions;
pub use camera::{read_calibration, write_calibration_toml, Camera, CameraRig};
pub use capture::{
    bone_spread, keypoint_reports, person_motion, read_trial, run_capture, triangulate_trial,
    CaptureOptions, CaptureReport, KeypointReport, Person3d, PersonReport, Trial, SPREAD_BONES,
};
pub use eval::{
    eval_markdown, evaluate_trial, CameraEvalOptions, CameraEvalReport, MethodResult,
    ReferenceResult,
};
pub use keypoints::{
    find_camera_folders, read_openpose_folder, write_openpose_frame, CameraKeypoints, Person2d,
    ViewFrame,
};
pub use layout::{Layout, CANONICAL_NAMES, CANONICAL_PARENTS};
pub use sim::{
    simulate_cameras, simulate_to_folder, write_simulated_trial, CameraSimOptions, SimulatedTrial,
    SimulationReport,
};
pub use solve::{
    measure_person, measure_person_by_scores, triangulate_frame, triangulate_take, Frame3d,
    Keypoint3d, Method, PersonModel, TriangulationOptions,
};
pub use trc::{read_trc, trc_to_zup, write_trc, zup_to_trc, Markers};
pub use triangulate::{
    reprojection_error, triangulate, triangulate_robust, Sighting, Triangulated,
};
