//! Metrics: hand-computed values on tiny inputs, exact invariants on real
//! Bandai takes, and errors on inputs of different shapes.

use mocap_testdata::shared_data;

use mocap_core::io::bvh::read_bvh;
use mocap_core::metrics::*;
use mocap_core::rotation::{Quat, Vec3};
use mocap_core::{forward_kinematics, Channel, GlobalPoses, Joint, Motion, Skeleton};

/// Poses from positions given frame after frame (identity rotations).
fn poses(joint_count: usize, positions: Vec<Vec3>) -> GlobalPoses {
    let frame_count = positions.len() / joint_count;
    GlobalPoses {
        joint_count,
        frame_count,
        rotations: vec![Quat::IDENTITY; positions.len()],
        positions,
    }
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-5 * (1.0 + b.abs())
}

#[test]
fn position_errors_by_hand() {
    let a = poses(2, vec![Vec3::ZERO, Vec3::X, Vec3::ZERO, Vec3::X]);
    // Joint 1 is 5 units off in frame 0 (a 3-4-5 triangle), exact in frame 1.
    let b = poses(
        2,
        vec![Vec3::ZERO, Vec3::new(4.0, 4.0, 0.0), Vec3::ZERO, Vec3::X],
    );
    assert_eq!(joint_position_errors(&a, &b).unwrap(), vec![0.0, 2.5]);
    assert!(close(
        mean_joint_position_error(&a, &b, None).unwrap(),
        1.25
    ));
    assert!(close(
        mean_joint_position_error(&a, &b, Some(&[1])).unwrap(),
        2.5
    ));
    assert_eq!(mean_joint_position_error(&a, &a, None).unwrap(), 0.0);
}

#[test]
fn shapes_must_agree() {
    let a = poses(2, vec![Vec3::ZERO; 4]);
    let b = poses(2, vec![Vec3::ZERO; 6]);
    let c = poses(1, vec![Vec3::ZERO; 2]);
    for err in [
        mean_joint_position_error(&a, &b, None).unwrap_err(),
        joint_position_errors(&a, &c).unwrap_err(),
        acceleration_error(&b, &a, None).unwrap_err(),
    ] {
        let message = err.to_string();
        assert!(message.contains("different shapes"), "{message}");
    }
    let err = mean_joint_position_error(&a, &a, Some(&[2])).unwrap_err();
    assert!(err.to_string().contains("joint index 2"), "{err}");
    assert!(mean_joint_position_error(&a, &a, Some(&[])).is_err());
    let err = acceleration_error(&a, &a, None).unwrap_err().to_string();
    assert!(err.contains("at least 3 frames, got 2"), "{err}");
    assert!(jitter(&b, None)
        .unwrap_err()
        .to_string()
        .contains("at least 4"));
    let empty = poses(2, Vec::new());
    assert!(mean_joint_position_error(&empty, &empty, None).is_err());
}

#[test]
fn acceleration_error_and_jitter_by_hand() {
    // Joint 0 follows x = t^2 (second difference 2, third 0); joint 1 stays.
    let quadratic = |t: f32| Vec3::new(t * t, 0.0, 0.0);
    let a = poses(
        2,
        (0..5)
            .flat_map(|t| [quadratic(t as f32), Vec3::Y])
            .collect(),
    );
    let still = poses(2, vec![Vec3::Y; 10]);
    assert!(close(acceleration_error(&a, &still, None).unwrap(), 1.0));
    assert!(close(
        acceleration_error(&a, &still, Some(&[0])).unwrap(),
        2.0
    ));
    assert!(close(jitter(&a, None).unwrap(), 0.0));
    // x = t^3 has a constant third difference of 6.
    let cubic = poses(
        1,
        (0..6)
            .map(|t| Vec3::new(0.0, 0.0, (t * t * t) as f32))
            .collect(),
    );
    assert!(close(jitter(&cubic, None).unwrap(), 6.0));
}

fn two_joints(child_has_rotations: bool, frames: &[[f32; 6]]) -> Motion {
    let rotations = [Channel::Zrotation, Channel::Xrotation, Channel::Yrotation];
    let mut root = Joint::new("Root", None, Vec3::ZERO);
    root.channels = rotations.to_vec();
    let mut child = Joint::new("Child", Some(0), Vec3::X);
    let width = if child_has_rotations {
        child.channels = rotations.to_vec();
        6
    } else {
        3
    };
    let skeleton = Skeleton::new(vec![root, child]).unwrap();
    let values: Vec<f32> = frames.iter().flat_map(|f| f[..width].to_vec()).collect();
    Motion::new(skeleton, 0.1, frames.len(), values).unwrap()
}

#[test]
fn rotation_errors_by_hand() {
    let a = two_joints(true, &[[0.0; 6], [0.0; 6]]);
    // Root: 30 degrees about Z in both frames; child: 0 then 90 about X.
    let b = two_joints(
        true,
        &[
            [30.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [30.0, 0.0, 0.0, 0.0, 90.0, 0.0],
        ],
    );
    let per_joint = joint_rotation_errors_degrees(&a, &b).unwrap();
    assert!(
        close(per_joint[0], 30.0) && close(per_joint[1], 45.0),
        "{per_joint:?}"
    );
    assert!(close(mean_rotation_error_degrees(&a, &b).unwrap(), 37.5));
    // A whole turn is no error.
    let c = two_joints(true, &[[360.0, 0.0, 0.0, 0.0, -360.0, 0.0]; 2]);
    assert!(mean_rotation_error_degrees(&a, &c).unwrap() < 1e-3);
    // A joint without rotation channels does not dilute the mean.
    let d = two_joints(false, &[[30.0, 0.0, 0.0, 0.0, 0.0, 0.0]; 2]);
    let e = two_joints(false, &[[0.0; 6]; 2]);
    assert!(close(mean_rotation_error_degrees(&d, &e).unwrap(), 30.0));
    let short = two_joints(true, &[[0.0; 6]]);
    assert!(mean_rotation_error_degrees(&a, &short).is_err());
}

#[test]
fn bone_length_stats_by_hand() {
    // One bone of length 1 in frame 0 and 3 in frame 1.
    let p = poses(2, vec![Vec3::ZERO, Vec3::X, Vec3::ZERO, 3.0 * Vec3::Z]);
    let mut child = Joint::new("B", Some(0), Vec3::X);
    child.channels = vec![Channel::Xposition];
    let s = Skeleton::new(vec![Joint::new("A", None, Vec3::ZERO), child]).unwrap();
    let stats = bone_length_stats(&p, &s).unwrap();
    assert_eq!(stats.len(), 1);
    let b = stats[0];
    assert_eq!((b.joint, b.parent), (1, 0));
    assert!(close(b.mean, 2.0) && close(b.std, 1.0), "{b:?}");
    assert_eq!((b.min, b.max), (1.0, 3.0));
    let three = Skeleton::new(vec![
        Joint::new("A", None, Vec3::ZERO),
        Joint::new("B", Some(0), Vec3::X),
        Joint::new("C", Some(1), Vec3::X),
    ])
    .unwrap();
    assert!(bone_length_stats(&p, &three).is_err());
}

#[test]
fn bandai_invariants() {
    let Some(data) = shared_data() else { return };
    let m = read_bvh(&data.join("bandai/dataset-1/dataset-1_walk_normal_001.bvh")).unwrap();
    let p = forward_kinematics(&m);

    // FK on a rigid skeleton: every bone keeps its length. Bandai's joints
    // have position channels that equal their offsets up to float noise.
    // (The "bone" from joint_Root to Hips is the root motion: skipped.)
    let stats = bone_length_stats(&p, m.skeleton()).unwrap();
    assert_eq!(stats.len(), m.skeleton().joint_count() - 1);
    for b in stats.iter().filter(|b| b.parent != 0) {
        let offset = m.skeleton().joint(b.joint).offset.length();
        assert!(b.std < 1e-3 && b.max - b.min < 1e-2, "{b:?}");
        assert!((b.mean - offset).abs() < 1e-2, "{b:?} vs offset {offset}");
    }

    // Moving every joint by (3, 4, 0) cm is an MPJPE of exactly 5 cm and
    // changes no acceleration.
    let mut shifted = p.clone();
    for x in &mut shifted.positions {
        *x += Vec3::new(3.0, 4.0, 0.0);
    }
    assert!(close(
        mean_joint_position_error(&p, &shifted, None).unwrap(),
        5.0
    ));
    assert!(acceleration_error(&p, &shifted, None).unwrap() < 1e-3);

    // Alternating noise of 1 mm along Y has a second difference of 4 mm in
    // every frame, whatever the motion, and raises the jitter.
    let mut noisy = p.clone();
    for f in 0..p.frame_count {
        let sign = if f % 2 == 0 { 0.1 } else { -0.1 };
        for j in 0..p.joint_count {
            noisy.positions[f * p.joint_count + j].y += sign;
        }
    }
    let accel = acceleration_error(&noisy, &p, None).unwrap();
    assert!((accel - 0.4).abs() < 1e-3, "{accel}");
    let (clean, rough) = (jitter(&p, None).unwrap(), jitter(&noisy, None).unwrap());
    eprintln!("jitter {clean} cm/frame^3 clean, {rough} with 1 mm alternating noise");
    // The noise alone has a third difference of 8 mm.
    assert!(rough > 0.8 - clean && rough > clean, "{clean} {rough}");

    // A motion against itself has no rotation error; against the same take
    // with one joint's channel turned by 10 degrees, 10 degrees there.
    assert_eq!(mean_rotation_error_degrees(&m, &m).unwrap(), 0.0);
    let head = m.skeleton().find("Head").unwrap();
    let column = m.skeleton().channel_start(head) + 3; // Zrotation
    let (skeleton, frame_time, frames, mut values) = m.clone().into_parts();
    let width = skeleton.channel_count();
    for f in 0..frames {
        values[f * width + column] += 10.0;
    }
    let turned = Motion::new(skeleton, frame_time, frames, values).unwrap();
    let per_joint = joint_rotation_errors_degrees(&m, &turned).unwrap();
    for (j, e) in per_joint.iter().enumerate() {
        let expected = if j == head { 10.0 } else { 0.0 };
        assert!((e - expected).abs() < 1e-2, "joint {j}: {e}");
    }
}
