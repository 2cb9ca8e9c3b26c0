//! One sensor's recording as a motion: what `mocap info`, `mocap render`,
//! `mocap view`, `mocap convert` and every other command that reads motions
//! make of a single camera's capture (a `.jsonl` recording or an NTU RGB+D
//! `.skeleton` file), once [`register_recording_readers`] has given the
//! reader to mocap-core.
//!
//! The sensor's skeleton goes through the same fitter as a fused take
//! ([`crate::bvh::poses_to_motion`]): the Kinect v2 joints with bone lengths
//! measured over the recording, in centimetres, positions in the sensor's
//! own camera space. Nothing is calibrated, fused or repaired: a left-right
//! swap the sensor made is in the motion as the sensor made it.

use std::path::Path;

use mocap_core::rotation::Vec3;
use mocap_core::{Error, Motion, Result};

use crate::body::{BodyModel, MeasureOptions};
use crate::bvh::{poses_to_motion, regular_poses, BvhOptions};
use crate::fusion::FusedFrame;
use crate::kinect::{joint::*, TrackingState, JOINT_COUNT, MIRROR, PARENTS, TOPOLOGICAL_ORDER};
use crate::offline::MAX_FUSED_FRAMES;
use crate::recording::{read_any_recording, JointObservation, SensorFrame};

/// Length units per metre of the motion: centimetres, as `mocap fuse run`
/// writes its BVH.
const UNITS_PER_METRE: f32 = 100.0;

/// The skeleton one depth sensor recorded, as a motion on the fitted Kinect
/// v2 skeleton (joint names `SpineBase`, `HipLeft`...; the body map finds it
/// as "Kinect v2"), in centimetres (100 units per metre).
///
/// `path` is a `.jsonl` recording of one sensor (format in
/// [`crate::recording`]) or an NTU RGB+D `.skeleton` file (its main body,
/// [`crate::recording::ntu_sensor_frames`]); read with
/// [`read_any_recording`], joints farther than
/// [`crate::recording::MAX_JOINT_DISTANCE`] from the sensor screened out
/// ([`SensorFrame::screen_implausible_joints`]).
///
/// - **Space**: positions are in the sensor's camera space, not a world
///   frame: Kinect convention, y up, z out of the lens, x to the sensor's
///   left; a person facing the sensor faces -z. No calibration is applied.
/// - **Time**: the frames are placed on the recording's own grid, one frame
///   every median time step between its frames (30 per second for NTU
///   files, and for a recording of a single frame), from its first frame
///   with a tracked joint; an instant with no frame (a dropped frame, a
///   frame in which the sensor saw nobody) holds the previous pose, as a
///   fused take does ([`crate::bvh::regular_poses`]).
/// - **Untracked joints**: a NotTracked joint takes its position from the
///   nearest frame in time in which the sensor tracked it (Tracked or
///   Inferred; Inferred positions are kept as the sensor guessed them); a
///   joint never tracked in the whole recording takes the bone of its
///   mirror joint on the other side, mirrored, or else sits on its parent.
///
/// Fails, naming the file, on a file that cannot be read, a `.jsonl`
/// holding several sensors (fuse them with `mocap fuse run`, which needs
/// their calibration), a fused take, and a recording with no frame in which
/// the sensor tracked a joint.
///
/// ```no_run
/// let motion = mocap_fuse::recording_motion("S001C002P003R001A001.skeleton".as_ref())?;
/// println!("{} frames at {} fps", motion.frame_count(), 1.0 / motion.frame_time());
/// # Ok::<(), mocap_core::Error>(())
/// ```
pub fn recording_motion(path: &Path) -> Result<Motion> {
    let where_ = path.display();
    let mut frames =
        read_any_recording(path, 0).map_err(|e| fused_take_error(path).unwrap_or(e))?;
    let mut sensors: Vec<u16> = frames.iter().map(|f| f.sensor).collect();
    sensors.sort_unstable();
    sensors.dedup();
    if sensors.len() > 1 {
        let ids: Vec<String> = sensors.iter().map(u16::to_string).collect();
        return Err(Error::Invalid(format!(
            "{where_}: the recording holds {} sensors (ids {}); one sensor's recording is read \
             as a motion. Fuse them into one skeleton with `mocap fuse run {where_} --calib \
             rig.toml -o fused.bvh` (calibrate with `mocap fuse calibrate {where_} -o rig.toml`)",
            sensors.len(),
            ids.join(", ")
        )));
    }
    if frames.is_empty() {
        return Err(Error::Invalid(format!(
            "{where_}: the recording holds no frame: there is no skeleton to show"
        )));
    }
    frames.sort_by(|a, b| a.timestamp.total_cmp(&b.timestamp));
    let step = time_step(&frames);
    let total = frames.len();
    for frame in frames.iter_mut() {
        frame.screen_implausible_joints();
    }
    frames.retain(|f| f.joints.iter().any(observed));
    let (Some(first), Some(last)) = (frames.first(), frames.last()) else {
        return Err(Error::Invalid(format!(
            "{where_}: no frame of the recording has a tracked joint ({total} frame{}, every \
             joint NotTracked or too far from the sensor): the sensor saw nobody",
            if total == 1 { "" } else { "s" }
        )));
    };
    let instants = (last.timestamp - first.timestamp) / step;
    if !(instants.is_finite() && instants < MAX_FUSED_FRAMES as f64) {
        return Err(Error::Invalid(format!(
            "{where_}: the recording's times run from {} s (frame {}) to {} s (frame {}): one \
             frame every {step} s, that is more than the {MAX_FUSED_FRAMES} frames a take may \
             have; is a timestamp wrong?",
            first.timestamp, first.seq, last.timestamp, last.seq
        )));
    }
    let poses = filled_poses(&frames);
    let sensor = sensors[0];
    let placed: Vec<FusedFrame> = frames
        .iter()
        .zip(poses)
        .map(|(f, joints)| FusedFrame {
            time: f.timestamp,
            joints,
            confidence: [1.0; JOINT_COUNT],
            sensors: vec![sensor],
            swapped: Vec::new(),
        })
        .collect();
    let fps = 1.0 / step;
    let poses = regular_poses(&placed, fps);
    // Bone lengths come from the poses themselves (BoneLengthSource::Fused):
    // the body model is not consulted.
    let nobody: [[JointObservation; JOINT_COUNT]; 0] = [];
    let body = BodyModel::measure(&nobody, MeasureOptions::default());
    let options = BvhOptions {
        units_per_metre: UNITS_PER_METRE,
        fps,
    };
    poses_to_motion(&poses, &body, &options).map_err(|e| match e {
        Error::Invalid(message) => Error::Invalid(format!("{where_}: {message}")),
        other => other,
    })
}

/// Makes every command that reads motions through mocap-core
/// ([`mocap_core::io::read_motion`], [`mocap_core::io::read_motions`]) read
/// sensor recordings, `.skeleton` (NTU RGB+D) and `.jsonl`, with
/// [`recording_motion`] ([`mocap_core::io::register_reader`]). The `mocap`
/// CLI calls it once at start-up. Calling it again is harmless.
pub fn register_recording_readers() {
    mocap_core::io::register_reader(
        &["skeleton", "jsonl"],
        "one depth sensor's recording",
        recording_motion,
    );
}

/// Whether the sensor reported a position for the joint (Tracked or
/// Inferred).
fn observed(joint: &JointObservation) -> bool {
    joint.state != TrackingState::NotTracked
}

/// The median time step between consecutive frames (in time order), in
/// seconds: the recording's own frame time. Frames at the same time are one
/// instant; a recording of one instant gets Kinect v2's 30 Hz.
fn time_step(frames: &[SensorFrame]) -> f64 {
    let mut steps: Vec<f64> = frames
        .windows(2)
        .map(|w| w[1].timestamp - w[0].timestamp)
        .filter(|d| *d > 0.0)
        .collect();
    crate::body::median(&mut steps).unwrap_or(1.0 / crate::recording::NTU_FPS)
}

/// Each frame's 25 positions (metres, camera space) with every NotTracked
/// joint taken from the nearest frame in time where it was observed (ties:
/// the earlier frame). A joint never observed gets the bone of its mirror
/// joint, mirrored across the body (left from the hips and shoulders), when
/// that one was observed (so that the fitter's left-right mean length stays
/// the seen side's), else sits on its parent; the root, on the mean of the
/// frame's observed joints. Every frame has at least one observed joint.
fn filled_poses(frames: &[SensorFrame]) -> Vec<[Vec3; JOINT_COUNT]> {
    let mut poses: Vec<[Vec3; JOINT_COUNT]> = frames
        .iter()
        .map(|f| f.joints.map(|j| j.position))
        .collect();
    let mut never_seen = [false; JOINT_COUNT];
    for (n, never) in never_seen.iter_mut().enumerate() {
        // The previous and the next frame that observed joint n.
        let mut previous: Vec<Option<usize>> = vec![None; frames.len()];
        let mut last = None;
        for (i, f) in frames.iter().enumerate() {
            if observed(&f.joints[n]) {
                last = Some(i);
            }
            previous[i] = last;
        }
        if last.is_none() {
            *never = true;
            continue;
        }
        let mut next = None;
        for i in (0..frames.len()).rev() {
            if observed(&frames[i].joints[n]) {
                next = Some(i);
                continue;
            }
            let t = frames[i].timestamp;
            let source = match (previous[i], next) {
                (Some(p), Some(q)) => {
                    if t - frames[p].timestamp <= frames[q].timestamp - t {
                        p
                    } else {
                        q
                    }
                }
                (Some(p), None) => p,
                (None, Some(q)) => q,
                (None, None) => unreachable!("joint {n} is observed in some frame"),
            };
            poses[i][n] = frames[source].joints[n].position;
        }
    }
    if never_seen.iter().any(|&never| never) {
        for (pose, frame) in poses.iter_mut().zip(frames) {
            let seen: Vec<Vec3> = frame
                .joints
                .iter()
                .filter(|j| observed(j))
                .map(|j| j.position)
                .collect();
            let centre = seen.iter().copied().sum::<Vec3>() / seen.len().max(1) as f32;
            // The body's left, to mirror a bone of the other side across.
            let left = (pose[HIP_LEFT] - pose[HIP_RIGHT] + pose[SHOULDER_LEFT]
                - pose[SHOULDER_RIGHT])
                .normalize_or_zero();
            for &n in &TOPOLOGICAL_ORDER {
                if !never_seen[n] {
                    continue;
                }
                let Some(parent) = PARENTS[n] else {
                    pose[n] = centre;
                    continue;
                };
                let mirror = MIRROR[n];
                pose[n] = pose[parent];
                if let (false, Some(mirror_parent)) = (never_seen[mirror], PARENTS[mirror]) {
                    let bone = pose[mirror] - pose[mirror_parent];
                    pose[n] += bone - 2.0 * bone.dot(left) * left;
                }
            }
        }
    }
    poses
}

/// The error for a `.jsonl` file that is a fused take (fused frames have
/// no `sensor`), when it is one: what `mocap fuse run -o fused.jsonl`
/// writes is not one sensor's recording.
fn fused_take_error(path: &Path) -> Option<Error> {
    let text = std::fs::read_to_string(path).ok()?;
    let line = text.lines().find(|l| !l.trim().is_empty())?;
    let value: serde_json::Value = serde_json::from_str(line).ok()?;
    let fused = value.get("sensor").is_none()
        && value.get("joints").is_some()
        && value.get("confidence").is_some();
    fused.then(|| {
        Error::Invalid(format!(
            "{}: a fused take (JSON lines of fused frames), not one sensor's recording: \
             `mocap view` and `mocap render` show it; `mocap fuse run ... -o fused.bvh` writes \
             it as a motion the other commands read",
            path.display()
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinect::JOINT_NAMES;
    use crate::recording::{write_ntu_skeleton, write_recording};
    use crate::sim::{simulate_capture, SimulatedCapture, SimulationOptions};

    fn capture(sensors: usize) -> SimulatedCapture {
        let walk = mocap_core::io::bvh::read_bvh(&mocap_testdata::sample_walk()).unwrap();
        let options = SimulationOptions {
            sensors,
            seed: 3,
            ..Default::default()
        };
        simulate_capture(&walk, None, &options).unwrap()
    }

    /// Distances (m) between the motion's joints and the sensor's Tracked
    /// joints: frame `seq - first seq + shift` of the motion against the
    /// sensor's frame `seq`.
    fn tracked_distances(motion: &Motion, frames: &[SensorFrame], shift: usize) -> Vec<f32> {
        let fk = mocap_core::forward_kinematics(motion);
        let skeleton = motion.skeleton();
        let index: Vec<usize> = JOINT_NAMES
            .iter()
            .map(|name| skeleton.find(name).unwrap())
            .collect();
        let first = frames[0].seq;
        let mut out = Vec::new();
        for f in frames {
            let i = (f.seq - first) as usize + shift;
            if i >= motion.frame_count() {
                continue;
            }
            for (n, j) in f.joints.iter().enumerate() {
                if j.state == TrackingState::Tracked {
                    let p = fk.position(i, index[n]) / UNITS_PER_METRE;
                    out.push(p.distance(j.position));
                }
            }
        }
        out
    }

    fn mean(d: &[f32]) -> f32 {
        d.iter().sum::<f32>() / d.len() as f32
    }

    /// The motion has a frame per instant of the sensor's grid, at its 30
    /// Hz, and its joints are where the sensor tracked them, to the fitter's
    /// error on a single sensor's noisy joints (bones stretch from frame to
    /// frame; the fitter's bones do not): a few centimetres, far less than
    /// one frame later.
    fn check_against(motion: &Motion, frames: &[SensorFrame], what: &str) {
        let (first, last) = (frames[0].seq, frames[frames.len() - 1].seq);
        assert_eq!(
            motion.frame_count() as u64,
            last - first + 1,
            "{what}: one frame per instant of the sensor's grid, dropped ones held"
        );
        assert!(
            (motion.frame_time() - 1.0 / 30.0).abs() < 1e-6,
            "{what}: {}",
            motion.frame_time()
        );
        let mut d = tracked_distances(motion, frames, 0);
        assert!(d.len() > 1000, "{what}: {} tracked joints", d.len());
        let aligned = mean(&d);
        d.sort_by(f32::total_cmp);
        let median = d[d.len() / 2];
        assert!(aligned < 0.05, "{what}: mean distance {aligned} m");
        assert!(median < 0.04, "{what}: median distance {median} m");
        let late = mean(&tracked_distances(motion, frames, 1));
        assert!(
            aligned < 0.8 * late,
            "{what}: {aligned} m on the sensor's frames, {late} m a frame later"
        );
    }

    #[test]
    fn a_simulated_sensor_reads_as_a_motion_through_its_tracked_joints() {
        let capture = capture(2);
        let sensor = &capture.simulation.sensors[0];
        assert!(
            sensor.frames.windows(2).any(|w| w[1].seq > w[0].seq + 1),
            "the sensor dropped frames: the grid must hold them"
        );
        let dir = tempfile::tempdir().unwrap();
        let jsonl = dir.path().join("sensor-0.jsonl");
        write_recording(&jsonl, &sensor.frames).unwrap();
        let motion = recording_motion(&jsonl).unwrap();
        check_against(&motion, &sensor.frames, "jsonl");
        let map = mocap_core::bodymap::BodyMap::detect(motion.skeleton()).unwrap();
        assert_eq!(map.rig(), "Kinect v2");

        // The same frames as an NTU file: its frames are the sensor's `seq`
        // at 30 per second.
        let ntu = dir.path().join("S001C000P001R001A001.skeleton");
        write_ntu_skeleton(&ntu, &sensor.frames, 72057594037927936).unwrap();
        let motion = recording_motion(&ntu).unwrap();
        check_against(&motion, &sensor.frames, "skeleton");

        // Through mocap-core's reader, once registered.
        register_recording_readers();
        let read = mocap_core::io::read_motion(&ntu).unwrap();
        assert_eq!(read.frame_count(), motion.frame_count());
    }

    #[test]
    fn several_sensors_in_one_file_are_refused_naming_them() {
        let capture = capture(2);
        let dir = tempfile::tempdir().unwrap();
        let both = dir.path().join("both.jsonl");
        let frames: Vec<SensorFrame> = capture
            .simulation
            .sensors
            .iter()
            .flat_map(|s| s.frames.iter().cloned())
            .collect();
        write_recording(&both, &frames).unwrap();
        let err = recording_motion(&both).unwrap_err().to_string();
        assert!(err.contains("both.jsonl"), "{err}");
        assert!(err.contains("2 sensors (ids 0, 1)"), "{err}");
        assert!(err.contains("mocap fuse run"), "{err}");
    }

    fn standing_frame(seq: u64) -> SensorFrame {
        // The standing pose 2.5 m in front of the sensor.
        let pose = crate::body::tests::standing_pose();
        SensorFrame {
            sensor: 4,
            seq,
            timestamp: 10.0 + seq as f64 / 15.0,
            arrival: None,
            joints: pose.map(|p| JointObservation {
                position: p + Vec3::new(0.0, -1.0, 2.5),
                state: TrackingState::Tracked,
            }),
        }
    }

    #[test]
    fn recordings_with_no_tracked_joint_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let empty = dir.path().join("empty.jsonl");
        std::fs::write(&empty, "\n").unwrap();
        let err = recording_motion(&empty).unwrap_err().to_string();
        assert!(
            err.contains("empty.jsonl: the recording holds no frame"),
            "{err}"
        );

        let nobody = dir.path().join("nobody.jsonl");
        let frames: Vec<SensorFrame> = (0..5)
            .map(|seq| {
                let mut f = standing_frame(seq);
                for j in f.joints.iter_mut() {
                    j.state = TrackingState::NotTracked;
                }
                f
            })
            .collect();
        write_recording(&nobody, &frames).unwrap();
        let err = recording_motion(&nobody).unwrap_err().to_string();
        assert!(
            err.contains("nobody.jsonl: no frame of the recording has a tracked joint"),
            "{err}"
        );
        assert!(err.contains("5 frames"), "{err}");

        // A NTU file whose frames hold no body.
        let ntu = dir.path().join("S001C001P001R001A001.skeleton");
        std::fs::write(&ntu, "3\n0\n0\n0\n").unwrap();
        let err = recording_motion(&ntu).unwrap_err().to_string();
        assert!(err.contains("S001C001P001R001A001.skeleton"), "{err}");
    }

    #[test]
    fn untracked_joints_come_from_the_nearest_tracked_frame() {
        let mut frames: Vec<SensorFrame> = (0..12).map(standing_frame).collect();
        let hand = frames[0].joints[HAND_LEFT].position;
        // The left hand lost in frames 3 to 5 (the sensor reports the
        // origin), the right thumb never seen, frame 7 with nobody in it, and
        // frame 9 dropped.
        for f in &mut frames[3..6] {
            f.joints[HAND_LEFT] = JointObservation::NOT_TRACKED;
        }
        for f in frames.iter_mut() {
            f.joints[THUMB_RIGHT] = JointObservation::NOT_TRACKED;
        }
        frames[7].joints = [JointObservation::NOT_TRACKED; JOINT_COUNT];
        frames.remove(9);
        // Lines need not be in time order.
        frames.swap(0, 4);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("lost-hand.jsonl");
        write_recording(&path, &frames).unwrap();
        let motion = recording_motion(&path).unwrap();
        assert_eq!(motion.frame_count(), 12);
        assert!((motion.frame_time() - 1.0 / 15.0).abs() < 1e-9);
        let fk = mocap_core::forward_kinematics(&motion);
        let skeleton = motion.skeleton();
        let at =
            |f: usize, n: usize| fk.position(f, skeleton.find(JOINT_NAMES[n]).unwrap()) / 100.0;
        // The pose is symmetric: the right thumb, never seen, is the left
        // one mirrored.
        let thumb = frames[1].joints[THUMB_LEFT].position * Vec3::new(-1.0, 1.0, 1.0);
        for f in 0..12 {
            let h = at(f, HAND_LEFT);
            assert!(h.distance(hand) < 0.01, "frame {f}: hand {h}, not {hand}");
            let t = at(f, THUMB_RIGHT);
            assert!(
                t.distance(thumb) < 0.01,
                "frame {f}: thumb {t}, not {thumb}"
            );
        }
    }

    #[test]
    fn a_fused_take_is_named_as_one() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fused.jsonl");
        let frame = FusedFrame {
            time: 0.0,
            joints: crate::body::tests::standing_pose(),
            confidence: [1.0; JOINT_COUNT],
            sensors: vec![0, 1],
            swapped: Vec::new(),
        };
        std::fs::write(&path, crate::output::fused_frame_json(&frame) + "\n").unwrap();
        let err = recording_motion(&path).unwrap_err().to_string();
        assert!(err.contains("fused.jsonl: a fused take"), "{err}");
    }
}
