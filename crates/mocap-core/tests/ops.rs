//! Resample, trim, scale and mirror: hand-computed values on tiny
//! skeletons, and geometric invariants on real takes (Bandai Namco, the
//! CMU-style and Mixamo parser cases, HDM05 ASF/AMC).

use mocap_testdata::shared_data;
use std::path::{Path, PathBuf};

use mocap_core::bodymap::{mirror_pairs, BodyMap};
use mocap_core::io::asf_amc::read_asf_amc;
use mocap_core::io::bvh::read_bvh;
use mocap_core::ops::*;
use mocap_core::rotation::{angle_between, Axis, Quat, Vec3};
use mocap_core::{forward_kinematics, Channel, GlobalPoses, Joint, Motion, Skeleton};

/// Every `step`-th Bandai file of a dataset folder, sorted by name.
fn bandai_files(data: &Path, dataset: &str, step: usize) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(data.join("bandai").join(dataset))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .collect();
    files.sort();
    files.into_iter().step_by(step).collect()
}

const ROTATIONS: [Channel; 3] = [Channel::Zrotation, Channel::Xrotation, Channel::Yrotation];
const POSITIONS: [Channel; 3] = [Channel::Xposition, Channel::Yposition, Channel::Zposition];

/// A root with 6 channels and one child 1 unit along X with 3 rotations.
fn two_joints(frames: &[[f32; 9]]) -> Motion {
    let mut root = Joint::new("Root", None, Vec3::ZERO);
    root.channels = [POSITIONS, ROTATIONS].concat();
    let mut child = Joint::new("Child", Some(0), Vec3::X);
    child.channels = ROTATIONS.to_vec();
    child.end_sites = vec![Vec3::new(0.0, 2.0, 0.0)];
    let skeleton = Skeleton::new(vec![root, child]).unwrap();
    Motion::new(skeleton, 0.1, frames.len(), frames.concat()).unwrap()
}

fn same_rotation(a: Quat, b: Quat, degrees: f32) -> bool {
    angle_between(a, b).to_degrees() <= degrees
}

#[test]
fn resample_frames_interpolates_by_slerp_and_lerp() {
    // Root moves 0 -> 10 along X and turns 0 -> 90 degrees about Z.
    let m = two_joints(&[
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [10.0, 0.0, 0.0, 90.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    ]);
    let r = resample_frames(&m, 3).unwrap();
    assert_eq!(r.frame_count(), 3);
    assert!((r.frame_time() - 0.05).abs() < 1e-12);
    assert_eq!(r.frame(0), m.frame(0));
    assert_eq!(r.frame(2), m.frame(1));
    assert!((r.root_translation(1) - Vec3::new(5.0, 0.0, 0.0)).length() < 1e-5);
    let half_turn = Quat::from_rotation_z(45f32.to_radians());
    assert!(same_rotation(r.local_rotation(1, 0), half_turn, 1e-3));
    // The child joint sits at (5, 0, 0) + Rz(45) X.
    let p = forward_kinematics(&r);
    let expected = Vec3::new(5.0 + 0.5f32.sqrt(), 0.5f32.sqrt(), 0.0);
    assert!((p.position(1, 1) - expected).length() < 1e-5);
}

#[test]
fn resample_takes_the_short_way_round() {
    // 170 -> -170 degrees is a 20 degree turn through 180, not 340 back.
    let m = two_joints(&[
        [0.0, 0.0, 0.0, 170.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, -170.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    ]);
    let r = resample_frames(&m, 3).unwrap();
    let middle = Quat::from_rotation_z(180f32.to_radians());
    assert!(same_rotation(r.local_rotation(1, 0), middle, 1e-3));
    // Written continuously from frame 0 (170), so about 180, not -180.
    assert!(
        (r.joint_values(1, 0)[3] - 180.0).abs() < 1e-3,
        "{:?}",
        r.frame(1)
    );
}

#[test]
fn resample_errors() {
    let m = two_joints(&[[0.0; 9]]);
    assert!(resample_fps(&m, 0.0)
        .unwrap_err()
        .to_string()
        .contains("positive"));
    assert!(resample_fps(&m, f64::NAN).is_err());
    assert!(resample_frames(&m, 0).is_err());
    let err = resample_frames(&m, 5).unwrap_err().to_string();
    assert!(err.contains("one-frame"), "{err}");
    assert_eq!(resample_frames(&m, 1).unwrap(), m);
    let empty = trim_to_nothing(&m);
    assert!(resample_fps(&empty, 30.0).is_err());
}

fn trim_to_nothing(m: &Motion) -> Motion {
    Motion::new(m.skeleton().clone(), m.frame_time(), 0, Vec::new()).unwrap()
}

#[test]
fn trim_keeps_the_frames_asked_for() {
    let frames: Vec<[f32; 9]> = (0..5).map(|k| [k as f32; 9]).collect();
    let m = two_joints(&frames);
    let t = trim(&m, 1..4).unwrap();
    assert_eq!(t.frame_count(), 3);
    assert_eq!(t.frame(0), m.frame(1));
    assert_eq!(t.frame(2), m.frame(3));
    assert_eq!(t.frame_time(), m.frame_time());
    let err = trim(&m, 3..9).unwrap_err().to_string();
    assert!(err.contains("3..9") && err.contains("0..5"), "{err}");
    let err = trim(&m, 2..2).unwrap_err().to_string();
    assert!(err.contains("empty"), "{err}");
    assert_eq!(trim(&m, 0..5).unwrap(), m);
}

#[test]
fn scale_multiplies_every_length() {
    let m = two_joints(&[[1.0, 2.0, 3.0, 30.0, 20.0, 10.0, 5.0, 6.0, 7.0]]);
    let s = scale(&m, 0.01);
    assert_eq!(s.skeleton().joint(1).offset, Vec3::new(0.01, 0.0, 0.0));
    assert_eq!(
        s.skeleton().joint(1).end_sites[0],
        Vec3::new(0.0, 0.02, 0.0)
    );
    assert_eq!(&s.frame(0)[..3], &[0.01, 0.02, 0.03]);
    assert_eq!(&s.frame(0)[3..], &m.frame(0)[3..]);
}

#[test]
fn bandai_resample_and_scale() {
    let Some(data) = shared_data() else { return };
    let path = data.join("bandai/dataset-1/dataset-1_walk_normal_001.bvh");
    let m = read_bvh(&path).unwrap();
    let n = m.frame_count();
    let up = resample_fps(&m, 120.0).unwrap();
    // The file writes 0.0333333 s; 4 new frames per source frame anyway.
    assert_eq!(up.frame_count(), 4 * (n - 1) + 1);
    let back = resample_fps(&up, 30.0).unwrap();
    assert_eq!(back.frame_count(), n);
    assert_eq!(
        back.values(),
        m.values(),
        "frames on source frames are copies"
    );

    // Interpolated poses lie between their neighbours: each joint's FK
    // position at a quarter frame is within a few millimetres of the linear
    // blend of the source positions (30 fps walking).
    let p = forward_kinematics(&m);
    let q = forward_kinematics(&up);
    let mut worst = 0.0f32;
    for f in 0..n - 1 {
        for k in 1..4 {
            let t = k as f32 / 4.0;
            for j in 0..p.joint_count {
                let blend = p.position(f, j).lerp(p.position(f + 1, j), t);
                worst = worst.max(q.position(4 * f + k, j).distance(blend));
            }
        }
    }
    assert!(worst < 1.0, "worst deviation from linear blend {worst} cm");
    // ... and not just copies: the middle frames moved.
    assert_ne!(up.frame(2), m.frame(0));
    // Euler tracks stay continuous where the source's are.
    for k in 1..up.frame_count() {
        let (a, b) = (up.frame(k - 1), up.frame(k));
        let (fa, fb) = (m.frame((k - 1) / 4), m.frame(k.div_ceil(4).min(n - 1)));
        for c in 0..a.len() {
            if (fa[c] - fb[c]).abs() < 180.0 {
                assert!(
                    (a[c] - b[c]).abs() < 180.0,
                    "channel {c} jumps at frame {k}"
                );
            }
        }
    }

    let metres = scale(&m, 0.01);
    let pm = forward_kinematics(&metres);
    for (a, b) in p.positions.iter().zip(&pm.positions) {
        assert!((*a * 0.01 - *b).length() < 1e-5);
    }
}

/// Largest extent of the body in the first frame (its height, standing).
fn body_size(poses: &GlobalPoses) -> f32 {
    let frame = poses.frame_positions(0);
    let (lo, hi) = frame
        .iter()
        .fold((frame[0], frame[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    (hi - lo).max_element()
}

/// Checks the mirror of `m`: FK positions are the reflected positions of
/// the twin joints, and mirroring twice gives back the take. Returns the
/// worst error relative to the body size.
fn check_mirror(m: &Motion, what: &str) -> f32 {
    let map = BodyMap::detect(m.skeleton()).unwrap();
    let pairs = map.mirror_pairs(m.skeleton());
    let axis = lateral_axis(m, &map).unwrap();
    let mirrored = mirror(m, &pairs, axis).unwrap();
    let p = forward_kinematics(m);
    let q = forward_kinematics(&mirrored);
    let size = body_size(&p);
    let mut twin: Vec<usize> = (0..p.joint_count).collect();
    for &(l, r) in &pairs {
        twin[l] = r;
        twin[r] = l;
    }
    let flip = Vec3::ONE - 2.0 * axis.unit();
    let mut worst = 0.0f32;
    for f in 0..p.frame_count {
        for (j, &t) in twin.iter().enumerate() {
            let reflected = flip * p.position(f, t);
            worst = worst.max(q.position(f, j).distance(reflected) / size);
        }
    }
    assert!(
        worst < 1e-3,
        "{what}: mirrored FK off by {worst} of body size"
    );
    let twice = mirror(&mirrored, &pairs, axis).unwrap();
    assert_eq!(twice.skeleton().joint_count(), m.skeleton().joint_count());
    for (a, b) in m.skeleton().joints().iter().zip(twice.skeleton().joints()) {
        assert!(
            (a.offset - b.offset).length() < 1e-6 * size,
            "{what}: {}",
            a.name
        );
    }
    let r = forward_kinematics(&twice);
    for (a, b) in p.positions.iter().zip(&r.positions) {
        assert!(a.distance(*b) < 1e-3 * size, "{what}: twice {a} vs {b}");
    }
    for f in 0..m.frame_count() {
        for j in 0..p.joint_count {
            let (a, b) = (m.local_rotation(f, j), twice.local_rotation(f, j));
            assert!(same_rotation(a, b, 0.05), "{what}: frame {f} joint {j}");
        }
    }
    worst
}

#[test]
fn bandai_mirror_is_the_reflected_swapped_take() {
    let Some(data) = shared_data() else { return };
    let mut files = bandai_files(&data, "dataset-1", 1);
    files.extend(bandai_files(&data, "dataset-2", 3));
    let mut worst = 0.0f32;
    for path in &files {
        let m = read_bvh(path).unwrap();
        worst = worst.max(check_mirror(&m, &path.display().to_string()));
    }
    eprintln!(
        "{} Bandai takes, worst mirror error {worst:e} of body size",
        files.len()
    );
}

#[test]
fn bandai_lateral_axis_is_x_and_frames_follow_the_rig() {
    let Some(data) = shared_data() else { return };
    let m = read_bvh(&data.join("bandai/dataset-1/dataset-1_walk_normal_001.bvh")).unwrap();
    let s = m.skeleton();
    let map = BodyMap::detect(s).unwrap();
    assert_eq!(lateral_axis(&m, &map).unwrap(), Axis::X);
    let pairs = mirror_pairs(s);
    let frames = mirror_frames(&m, &pairs, Axis::X).unwrap();
    let frame = |name: &str| frames[s.find(name).unwrap()];
    use mocap_core::rotation::Mat3;
    let diag = |x: f32, y: f32, z: f32| Mat3::from_diagonal(Vec3::new(x, y, z));
    // Left and right frames are negated along every local axis ("mirror
    // behaviour"); the hips' sagittal plane is local Y, the spine's local Z.
    assert_eq!(frame("joint_Root"), diag(-1.0, 1.0, 1.0));
    assert_eq!(frame("Hips"), diag(1.0, -1.0, 1.0));
    assert_eq!(frame("Chest"), diag(1.0, 1.0, -1.0));
    assert_eq!(frame("LowerLeg_L"), -Mat3::IDENTITY);
    assert_eq!(frame("UpperArm_R"), -Mat3::IDENTITY);

    // So a mirrored knee bends exactly as the other knee did, with no
    // twist: the mirrored left knee's local rotation is the right knee's.
    let mirrored = mirror(&m, &pairs, Axis::X).unwrap();
    let (left, right) = (s.find("LowerLeg_L").unwrap(), s.find("LowerLeg_R").unwrap());
    for f in 0..m.frame_count() {
        let (a, b) = (mirrored.local_rotation(f, left), m.local_rotation(f, right));
        assert!(same_rotation(a, b, 0.01), "frame {f}");
    }
}

fn bundled_walk() -> Motion {
    read_bvh(&mocap_testdata::sample_walk()).unwrap()
}

/// The bundled Bandai walk with the performer turned by `degrees` about
/// the vertical.
fn bundled_walk_turned(degrees: f32) -> Motion {
    turn(&bundled_walk(), Quat::from_rotation_y(degrees.to_radians())).unwrap()
}

#[test]
fn turn_turns_every_global_position_and_keeps_the_rotations_below_the_root() {
    let m = bundled_walk();
    let rotation = Quat::from_rotation_y(1.2);
    let turned = turn(&m, rotation).unwrap();
    let (p, q) = (forward_kinematics(&m), forward_kinematics(&turned));
    for (a, b) in p.positions.iter().zip(&q.positions) {
        assert!((rotation * *a).distance(*b) < 1e-2, "{a} turned is not {b}");
    }
    let hips = m.skeleton().find("Hips").unwrap();
    for f in 0..m.frame_count() {
        let (a, b) = (m.local_rotation(f, hips), turned.local_rotation(f, hips));
        assert!(same_rotation(a, b, 1e-3), "frame {f}");
    }
    // A root that cannot rotate cannot be turned.
    let mut root = Joint::new("Root", None, Vec3::ZERO);
    root.channels = POSITIONS.to_vec();
    let still = Motion::new(Skeleton::new(vec![root]).unwrap(), 0.1, 1, vec![0.0; 3]).unwrap();
    let err = turn(&still, rotation).unwrap_err().to_string();
    assert!(err.contains("no three rotation channels"), "{err}");
}

#[test]
fn mirror_splits_rotations_the_same_way_whichever_way_the_performer_faces() {
    // Judging the midline joints' local planes against the nearest world
    // axis would fail a performer facing 45 degrees off the world axes: the
    // right positions, but a neck twisted half a turn and its children
    // turned back, which a denoiser trained on real takes reads as
    // nonsense.
    for degrees in [0.0f32, 30.0, 45.0, 50.0, 60.0, 90.0, 135.0, 200.0, 315.0] {
        let m = bundled_walk_turned(degrees);
        let s = m.skeleton();
        let mirrored = mirror_auto(&m).unwrap();
        check_mirror(&m, &format!("bundled walk turned {degrees} degrees"));
        // The chest, neck and head share their parent's plane, so their
        // local rotations are mirrored by conjugation: same angle.
        for name in ["Chest", "Neck", "Head"] {
            let j = s.find(name).unwrap();
            for f in 0..m.frame_count() {
                let angle = |q: Quat| angle_between(q, Quat::IDENTITY).to_degrees();
                let (a, b) = (
                    angle(m.local_rotation(f, j)),
                    angle(mirrored.local_rotation(f, j)),
                );
                assert!(
                    (a - b).abs() < 0.05,
                    "turned {degrees}: {name} at frame {f} rotates {a:.2} degrees, mirrored {b:.2}"
                );
            }
        }
        // And each knee bends as the other did.
        let (left, right) = (s.find("LowerLeg_L").unwrap(), s.find("LowerLeg_R").unwrap());
        for f in 0..m.frame_count() {
            let (a, b) = (mirrored.local_rotation(f, left), m.local_rotation(f, right));
            assert!(same_rotation(a, b, 0.01), "turned {degrees}: frame {f}");
        }
    }
}

#[test]
fn parser_case_mirrors() {
    let Some(data) = shared_data() else { return };
    for name in [
        "dme_example_crlf_leadingdot_frametime.bvh",
        "bvhpython_test_freebvh.bvh",
        "bvhanim_test_mocapbank.bvh",
    ] {
        let m = read_bvh(&data.join("parser-cases").join(name)).unwrap();
        check_mirror(&m, name);
    }
    // The CMU-style rig's local frames are the world's: its mirrored left
    // knee is the right knee reflected, S q S.
    let m = read_bvh(&data.join("parser-cases/dme_example_crlf_leadingdot_frametime.bvh")).unwrap();
    let s = m.skeleton();
    let mirrored = mirror_auto(&m).unwrap();
    let (left, right) = (s.find("LeftLeg").unwrap(), s.find("RightLeg").unwrap());
    for f in 0..m.frame_count() {
        let q = m.local_rotation(f, right);
        let reflected = Quat::from_xyzw(q.x, -q.y, -q.z, q.w);
        assert!(same_rotation(
            mirrored.local_rotation(f, left),
            reflected,
            0.01
        ));
    }
}

#[test]
fn hdm05_asf_mirrors() {
    let Some(data) = shared_data() else { return };
    let dir = data.join("hdm05-sample");
    let m = read_asf_amc(
        dir.join("HDM_bd.asf"),
        dir.join("HDM_bd_depositFloorR_001_120.amc"),
    )
    .unwrap();
    // Keep the test quick: a second of the take.
    let m = trim(&m, 0..120.min(m.frame_count())).unwrap();
    check_mirror(&m, "HDM_bd");
}

#[test]
fn mirror_rejects_bad_pairs() {
    let Some(data) = shared_data() else { return };
    let m = read_bvh(&data.join("bandai/dataset-1/dataset-1_walk_normal_001.bvh")).unwrap();
    let m = trim(&m, 0..2).unwrap();
    let s = m.skeleton();
    let j = |name: &str| s.find(name).unwrap();
    let err = mirror(&m, &[(j("UpperArm_L"), j("LowerArm_R"))], Axis::X)
        .unwrap_err()
        .to_string();
    assert!(err.contains("hierarchy"), "{err}");
    let err = mirror(&m, &[(0, 99)], Axis::X).unwrap_err().to_string();
    assert!(err.contains("outside"), "{err}");
    let err = mirror(
        &m,
        &[(j("Foot_L"), j("Foot_R")), (j("Foot_L"), j("Toes_R"))],
        Axis::X,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("more than one"), "{err}");
}

#[test]
fn mirror_refuses_a_rotation_the_channels_cannot_hold() {
    // A hinge with only an X rotation, whose twin turns about Z: the
    // mirrored rotation needs a Z channel the left joint does not have.
    let mut root = Joint::new("Hips", None, Vec3::ZERO);
    root.channels = POSITIONS.to_vec();
    let mut left = Joint::new("LeftKnee", Some(0), Vec3::X);
    left.channels = vec![Channel::Xrotation];
    let mut right = Joint::new("RightKnee", Some(0), -Vec3::X);
    right.channels = vec![Channel::Zrotation];
    let s = Skeleton::new(vec![root, left, right]).unwrap();
    let m = Motion::new(s, 0.1, 1, vec![0.0, 0.0, 0.0, 0.0, 30.0]).unwrap();
    let err = mirror(&m, &[(1, 2)], Axis::X).unwrap_err().to_string();
    assert!(
        err.contains("LeftKnee") && err.contains("Xrotation"),
        "{err}"
    );
}

#[test]
fn bandai_mirrors_keep_midline_rotations_natural() {
    // Every dataset-1 take (35 of them, most of the walks to the side, were
    // mirrored with twisted midline joints before the body's own lateral
    // direction was used) and every third of dataset-2: the chest and neck
    // turn by the angle they turned, and each knee and elbow bends as its
    // twin did. The head is left out: one take (walk-left, normal) starts
    // with the head turned more than 60 degrees, and it gets its own plane.
    let Some(data) = shared_data() else { return };
    let mut files = bandai_files(&data, "dataset-1", 1);
    files.extend(bandai_files(&data, "dataset-2", 3));
    let angle = |q: Quat| angle_between(q, Quat::IDENTITY).to_degrees();
    for path in &files {
        let m = read_bvh(path).unwrap();
        let mirrored = mirror_auto(&m).unwrap();
        let s = m.skeleton();
        for (name, twin) in [
            ("Chest", "Chest"),
            ("Neck", "Neck"),
            ("LowerLeg_L", "LowerLeg_R"),
            ("LowerArm_R", "LowerArm_L"),
        ] {
            let (j, t) = (s.find(name).unwrap(), s.find(twin).unwrap());
            for f in (0..m.frame_count()).step_by(5) {
                let (a, b) = (
                    angle(m.local_rotation(f, t)),
                    angle(mirrored.local_rotation(f, j)),
                );
                assert!(
                    (a - b).abs() < 0.1,
                    "{}: mirrored {name} at frame {f} turns {b:.1} degrees, {twin} turned {a:.1}",
                    path.display()
                );
            }
        }
    }
}

#[test]
fn a_leading_rest_pose_is_found_on_the_cmu_daz_clips_and_nowhere_else() {
    let Some(data) = shared_data() else {
        return;
    };
    let daz = data.join("other-rigs/cmu-daz");
    let mut clips = 0;
    for folder in std::fs::read_dir(&daz).unwrap() {
        for file in std::fs::read_dir(folder.unwrap().path()).unwrap() {
            let path = file.unwrap().path();
            let motion = read_bvh(&path).unwrap();
            let lead = rest_pose_lead_in(&motion);
            // Frame 0 is the rest pose, and the motion blends in from it
            // over four frames (three on runs).
            // 09_10 holds its root still over frames 1-4 and then pops to
            // where the motion is: a pop, not the blend this finds.
            let expected = if path.ends_with("09/09_10.bvh") {
                1..=1
            } else {
                4..=5
            };
            assert!(expected.contains(&lead), "{}: {lead}", path.display());
            clips += 1;
        }
    }
    assert!(clips >= 17, "{clips} clips");
    assert_eq!(
        rest_pose_lead_in(&read_bvh(&daz.join("07/07_01.bvh")).unwrap()),
        5
    );
    // Takes that start with their motion.
    for path in bandai_files(&data, "dataset-1", 50)
        .into_iter()
        .chain(bandai_files(&data, "dataset-2", 50))
        .chain([
            data.join("other-rigs/cmu-max/131_01.bvh"),
            data.join("other-rigs/xia/angry_13_000.bvh"),
            data.join("other-rigs/animated-drawings/fair1/dab.bvh"),
            data.join("parser-cases/bvhanim_test_mocapbank.bvh"),
        ])
    {
        let motion = read_bvh(&path).unwrap();
        assert_eq!(rest_pose_lead_in(&motion), 0, "{}", path.display());
    }
}

#[test]
fn a_take_whose_first_frame_is_the_rest_pose_starts_after_it() {
    // The root turning steadily by 1 degree a frame (the child joint moves
    // with it) and the child joint turned; then the child's frame 0 zeroed.
    let mut frames: Vec<[f32; 9]> = (0..40)
        .map(|f| [0.0, 0.0, 0.0, 30.0 + f as f32, 0.0, 0.0, 20.0, 0.0, 0.0])
        .collect();
    assert_eq!(rest_pose_lead_in(&two_joints(&frames)), 0);
    frames[0] = [0.0; 9];
    assert_eq!(rest_pose_lead_in(&two_joints(&frames)), 1);
    // Frames 1 and 2 still on the way from it: part of the lead-in.
    frames[1][3] = 10.0;
    frames[2][3] = 20.0;
    assert_eq!(rest_pose_lead_in(&two_joints(&frames)), 3);
    // A take at rest throughout has no lead-in.
    assert_eq!(rest_pose_lead_in(&two_joints(&[[0.0; 9]; 10])), 0);
}
