//! Retargeting between rigs: the bundled Bandai walk onto copies of its own
//! rig with other rest poses and sizes, and real Bandai takes played by the
//! CMU-style and Mixamo rigs of the parser cases and back.

use mocap_testdata::{sample_walk, shared_data};

use mocap_core::bodymap::{BodyMap, BodyPart};
use mocap_core::io::bvh::read_bvh;
use mocap_core::metrics::{joint_rotation_errors_degrees, largest_bone_angle_degrees};
use mocap_core::ops::{scale, trim};
use mocap_core::retarget::{canonical_pose, Retargeting};
use mocap_core::rotation::{angle_between, Quat, Vec3};
use mocap_core::{forward_kinematics, Joint, Motion, Skeleton};

/// Largest angle (degrees) between the same limb bone of two motions.
fn worst_bone_angle(a: &Motion, b: &Motion) -> f32 {
    largest_bone_angle_degrees(a, b).unwrap()
}

/// Largest distance between the same joint of two motions of one rig, and
/// that joint's name.
fn worst_joint_distance(a: &Motion, b: &Motion) -> (f32, String) {
    let (pa, pb) = (forward_kinematics(a), forward_kinematics(b));
    let mut worst = (0.0f32, String::new());
    for f in 0..a.frame_count() {
        for j in 0..a.skeleton().joint_count() {
            let d = pa.position(f, j).distance(pb.position(f, j));
            if d > worst.0 {
                worst = (d, a.skeleton().joint(j).name.clone());
            }
        }
    }
    worst
}

/// `skeleton` in another rest pose: the same bones, each joint below the
/// pelvis turned at rest by a rotation of its own (the rest pose of a rig is
/// where every rotation is zero, so the turned pose becomes the offsets).
fn other_rest_pose(skeleton: &Skeleton) -> Skeleton {
    let n = skeleton.joint_count();
    let mut global = vec![Quat::IDENTITY; n];
    let mut joints: Vec<Joint> = skeleton.joints().to_vec();
    for j in 0..n {
        let parent = skeleton.joint(j).parent;
        let above = parent.map_or(Quat::IDENTITY, |p| global[p]);
        let turn = if j > 1 {
            let axis = Vec3::new(1.0, j as f32, 0.5 * j as f32).normalize();
            Quat::from_axis_angle(axis, 0.3 * j as f32)
        } else {
            Quat::IDENTITY
        };
        global[j] = above * turn;
        joints[j].offset = above * skeleton.joint(j).offset;
        for end in &mut joints[j].end_sites {
            *end = global[j] * *end;
        }
    }
    Skeleton::new(joints).unwrap()
}

#[test]
fn a_take_played_by_its_own_rig_in_another_rest_pose_and_size_is_unchanged() {
    let take = read_bvh(&sample_walk()).unwrap();
    let same = Retargeting::detect(take.skeleton(), take.skeleton()).unwrap();
    assert_eq!(same.scale(), 1.0);
    let (d, joint) = worst_joint_distance(&take, &same.apply(&take).unwrap());
    assert!(d < 0.01, "{joint} moved by {d} cm");

    // Other rest pose: the bones keep their directions, so the joints their
    // places (the clavicle is aimed at the shoulder, reachable here).
    let posed = other_rest_pose(take.skeleton());
    let moved = Retargeting::detect(take.skeleton(), &posed)
        .unwrap()
        .apply(&take)
        .unwrap();
    let (a, b) = (forward_kinematics(&take), forward_kinematics(&moved));
    for f in 0..take.frame_count() {
        for j in 1..take.skeleton().joint_count() {
            let d = a.position(f, j).distance(b.position(f, j));
            assert!(
                d < 0.05,
                "frame {f}: {} {d} cm off",
                take.skeleton().joint(j).name
            );
        }
    }

    // Half the size: every position halves, strides included.
    let small = scale(&take, 0.5);
    let halved = Retargeting::detect(take.skeleton(), small.skeleton()).unwrap();
    assert!((halved.scale() - 0.5).abs() < 1e-5);
    let c = forward_kinematics(&halved.apply(&take).unwrap());
    for f in 0..take.frame_count() {
        for j in 1..take.skeleton().joint_count() {
            let d = (0.5 * a.position(f, j)).distance(c.position(f, j));
            assert!(
                d < 0.05,
                "frame {f}: {} {d} cm off",
                take.skeleton().joint(j).name
            );
        }
    }
}

#[test]
fn a_motion_of_another_rig_or_a_rig_without_body_parts_is_refused() {
    let take = read_bvh(&sample_walk()).unwrap();
    let same = Retargeting::detect(take.skeleton(), take.skeleton()).unwrap();
    let two = Skeleton::new(vec![
        Joint::new("Base", None, Vec3::ZERO),
        Joint::new("End", Some(0), Vec3::X),
    ])
    .unwrap();
    let other = Motion::rest(two.clone(), 1.0 / 30.0, 3).unwrap();
    let e = same.apply(&other).unwrap_err().to_string();
    assert!(e.contains("not of the rig"), "{e}");
    let e = Retargeting::detect(take.skeleton(), other.skeleton())
        .unwrap_err()
        .to_string();
    assert!(e.contains("target rig") && e.contains("pelvis"), "{e}");
}

#[test]
fn real_takes_played_by_cmu_and_mixamo_rigs_keep_their_bones_and_come_back() {
    let Some(data) = shared_data() else {
        eprintln!("../shared/data is absent: skipped");
        return;
    };
    let takes = [
        "bandai/dataset-1/dataset-1_walk_proud_001.bvh",
        "bandai/dataset-1/dataset-1_bow_old_001.bvh",
        "bandai/dataset-2/dataset-2_run_active_001.bvh",
    ];
    let rigs = [
        "dme_example_crlf_leadingdot_frametime.bvh",
        "bvhpython_test_freebvh.bvh",
        "bvhanim_test_mocapbank.bvh",
    ];
    for name in takes {
        let take = read_bvh(&data.join(name)).unwrap();
        for rig in rigs {
            let other = read_bvh(&data.join("parser-cases").join(rig)).unwrap();
            let there = Retargeting::detect(take.skeleton(), other.skeleton()).unwrap();
            let moved = there.apply(&take).unwrap();
            assert_eq!(moved.skeleton(), other.skeleton());
            assert_eq!(moved.frame_count(), take.frame_count());
            let angle = worst_bone_angle(&take, &moved);
            assert!(
                angle < 0.1,
                "{name} on {rig}: a limb bone turned by {angle} deg"
            );
            // The pelvis follows the source's, scaled.
            let (ps, pt) = (forward_kinematics(&take), forward_kinematics(&moved));
            let (ms, mt) = (
                BodyMap::detect(take.skeleton()).unwrap(),
                BodyMap::detect(moved.skeleton()).unwrap(),
            );
            let pelvis = |m: &BodyMap| m.joint(BodyPart::Pelvis).unwrap();
            for f in 0..take.frame_count() {
                let wanted = there.scale() * ps.position(f, pelvis(&ms));
                let d = wanted.distance(pt.position(f, pelvis(&mt)));
                assert!(
                    d < 1e-3 * there.scale() * 100.0,
                    "{name} on {rig}, frame {f}: pelvis {d} off"
                );
            }
            // And back, with the same two reference poses: every joint
            // comes back, in place and in local rotation (what a model of
            // the rig reads), but a part the other rig lacks (the 19-joint
            // rig has no toes: they come back at rest).
            let back = Retargeting::detect(other.skeleton(), take.skeleton())
                .unwrap()
                .apply(&moved)
                .unwrap();
            let (d, joint) = worst_joint_distance(&take, &back);
            assert!(d < 0.05, "{name} via {rig}: {joint} came back {d} cm off");
            let errors = joint_rotation_errors_degrees(&take, &back).unwrap();
            let lacks_toes = BodyMap::detect(other.skeleton())
                .unwrap()
                .joint(BodyPart::LeftToe)
                .is_none();
            for (j, e) in errors.iter().enumerate() {
                let joint = &take.skeleton().joint(j).name;
                if !(lacks_toes && joint.starts_with("Toes")) {
                    assert!(
                        *e < 0.1,
                        "{name} via {rig}: {joint} came back turned by {e} deg"
                    );
                }
            }
        }
    }
}

/// The CMU-style and the Mixamo take of the parser cases (their first
/// `frames` frames), each with that take played by the Bandai rig and the
/// retargeting back; none without ../shared/data.
fn parser_cases_on_bandai(frames: usize) -> Vec<(&'static str, Motion, Motion, Retargeting)> {
    let Some(data) = shared_data() else {
        eprintln!("../shared/data is absent: skipped");
        return Vec::new();
    };
    let bandai = read_bvh(&sample_walk()).unwrap();
    [
        "dme_example_crlf_leadingdot_frametime.bvh",
        "bvhpython_test_freebvh.bvh",
    ]
    .into_iter()
    .map(|rig| {
        let take = read_bvh(&data.join("parser-cases").join(rig)).unwrap();
        let take = trim(&take, 0..take.frame_count().min(frames)).unwrap();
        let on_bandai = Retargeting::detect(take.skeleton(), bandai.skeleton())
            .unwrap()
            .apply(&take)
            .unwrap();
        let back = Retargeting::detect(bandai.skeleton(), take.skeleton()).unwrap();
        (rig, take, on_bandai, back)
    })
    .collect()
}

#[test]
fn a_take_of_another_rig_played_by_bandai_and_back_onto_itself_is_unchanged() {
    let bandai = read_bvh(&sample_walk()).unwrap();
    for (rig, take, on_bandai, back) in parser_cases_on_bandai(usize::MAX) {
        // Played back onto the take: the joints Bandai's rig lacks (fingers,
        // CMU's extra spine and hip joints) keep their own rotations.
        let restored = back.apply_onto(&on_bandai, &take).unwrap();
        let (d, joint) = worst_joint_distance(&take, &restored);
        assert!(d < 1e-3 * 30.0, "{rig}: {joint} moved by {d}");
        let errors = joint_rotation_errors_degrees(&take, &restored).unwrap();
        for (j, e) in errors.iter().enumerate() {
            let name = &take.skeleton().joint(j).name;
            assert!(*e < 0.05, "{rig}: {name} turned by {e} deg");
        }
        // Played back alone, those joints are at rest or aimed instead.
        let alone = back.apply(&on_bandai).unwrap();
        let errors = joint_rotation_errors_degrees(&take, &alone).unwrap();
        assert!(errors.iter().any(|&e| e > 1.0), "{rig}: {errors:?}");
        // The motion to play onto must be of the target rig, frame for frame.
        assert!(back.apply_onto(&on_bandai, &bandai).is_err());
    }
}

#[test]
fn a_change_made_on_bandai_is_carried_to_a_take_of_another_rig() {
    for (rig, take, on_bandai, back) in parser_cases_on_bandai(60) {
        // No change: the take comes back, channel for channel, although
        // the way there and back loses its extra joints' motion.
        let same = back.carry_change(&on_bandai, &on_bandai, &take).unwrap();
        for f in 0..take.frame_count() {
            for (a, b) in take.frame(f).iter().zip(same.frame(f)) {
                assert!((a - b).abs() < 1e-3, "{rig}: frame {f}: {a} became {b}");
            }
        }
        // Bandai's left knee bent by 20 degrees more: the take's knee turns
        // by that in the world, its thigh and its hands' fingers stay.
        let knee_b = on_bandai.skeleton().find("LowerLeg_L").unwrap();
        let mut bent = on_bandai.clone();
        let turn = Quat::from_axis_angle(Vec3::Z, 20f32.to_radians());
        for f in 0..bent.frame_count() {
            let q = bent.local_rotation(f, knee_b) * turn;
            bent.set_local_rotation(f, knee_b, q);
        }
        let carried = back.carry_change(&on_bandai, &bent, &take).unwrap();
        let map = BodyMap::detect(take.skeleton()).unwrap();
        let knee = map.joint(BodyPart::LeftKnee).unwrap();
        let hip = map.joint(BodyPart::LeftHip).unwrap();
        let (g_take, g_carried) = (forward_kinematics(&take), forward_kinematics(&carried));
        let (g_before, g_after) = (forward_kinematics(&on_bandai), forward_kinematics(&bent));
        for f in 0..take.frame_count() {
            let wanted = g_after.rotation(f, knee_b) * g_before.rotation(f, knee_b).inverse();
            let got = g_carried.rotation(f, knee) * g_take.rotation(f, knee).inverse();
            let e = angle_between(wanted, got).to_degrees();
            assert!(e < 0.1, "{rig}: frame {f}: the knee turned {e} deg off");
            let e = angle_between(g_carried.rotation(f, hip), g_take.rotation(f, hip));
            assert!(e.to_degrees() < 0.01, "{rig}: the thigh turned");
        }
        let parts: Vec<usize> = map.parts().map(|(_, j)| j).collect();
        let body = take
            .skeleton()
            .subtree(map.joint(BodyPart::Pelvis).unwrap());
        for j in (0..take.skeleton().joint_count()).filter(|j| !parts.contains(j)) {
            let below_knee = take.skeleton().subtree(knee).contains(&j);
            if below_knee || !body.contains(&j) {
                continue;
            }
            for f in 0..take.frame_count() {
                let e = angle_between(take.local_rotation(f, j), carried.local_rotation(f, j));
                let name = &take.skeleton().joint(j).name;
                assert!(e.to_degrees() < 0.01, "{rig}: {name} turned by {e}");
            }
        }
    }
}

/// The pelvis of `moved` (a rig of half the size, the same joints) follows
/// half the path of `take`'s, frame for frame.
fn assert_pelvis_at_half(take: &Motion, moved: &Motion) {
    let (a, b) = (forward_kinematics(take), forward_kinematics(moved));
    let pelvis = BodyMap::detect(take.skeleton())
        .unwrap()
        .require(BodyPart::Pelvis)
        .unwrap();
    for f in 0..take.frame_count() {
        let d = (0.5 * a.position(f, pelvis)).distance(b.position(f, pelvis));
        assert!(d < 0.05, "frame {f}: pelvis {d} cm off");
    }
}

#[test]
fn a_rig_with_the_same_joints_keeps_every_local_rotation() {
    // Another performer of the same rig (half the size), its reference a
    // different clip whose first frame is another pose.
    let take = read_bvh(&sample_walk()).unwrap();
    let other = scale(
        &read_bvh(&mocap_testdata::sample("dataset-1_walk_proud_001.bvh")).unwrap(),
        0.5,
    );
    let moved = Retargeting::detect(take.skeleton(), other.skeleton())
        .unwrap()
        .apply(&take)
        .unwrap();
    assert_every_local_rotation_kept(&take, &moved, &other);
    // Strides scale with the legs: the pelvis at half its path.
    assert_pelvis_at_half(&take, &moved);
}

#[test]
fn one_rig_under_two_naming_schemes_keeps_every_local_rotation() {
    // The same rig with every joint renamed (a rig file says which is
    // which), its reference a different clip whose first frame is another
    // pose: joints are counterparts by body part, not by name, so there is
    // no reference-pose convention to turn a forearm or the spine.
    let take = read_bvh(&sample_walk()).unwrap();
    let other_path = mocap_testdata::sample("dataset-1_walk_proud_001.bvh");
    let text = mocap_testdata::renamed_bandai_bvh(&other_path);
    let other =
        mocap_core::io::bvh::read_bvh_from(std::io::Cursor::new(text), &other_path).unwrap();
    let other_map =
        BodyMap::from_toml_str(mocap_testdata::RENAMED_BANDAI_RIG, other.skeleton()).unwrap();
    let take_map = BodyMap::detect(take.skeleton()).unwrap();
    let moved = Retargeting::new(take.skeleton(), &take_map, other.skeleton(), &other_map)
        .unwrap()
        .apply(&take)
        .unwrap();
    assert_every_local_rotation_kept(&take, &moved, &other);
}

/// `moved` is `take` played by the rig of `other`, every joint with the
/// local rotation it has in `take`.
fn assert_every_local_rotation_kept(take: &Motion, moved: &Motion, other: &Motion) {
    assert_eq!(moved.skeleton(), other.skeleton());
    let errors = joint_rotation_errors_degrees(take, moved).unwrap();
    assert!(errors.iter().all(|&e| e < 0.01), "{errors:?}");
}

#[test]
fn a_turned_helper_root_still_puts_the_pelvis_where_the_source_has_it() {
    // The bundled walk with its helper root (`joint_Root`, above the pelvis)
    // turned a quarter about the vertical: the same joints, so the root's
    // rotation is carried; the pelvis must still follow the source's path.
    let mut take = read_bvh(&sample_walk()).unwrap();
    let turn = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
    for f in 0..take.frame_count() {
        take.set_local_rotation(f, 0, turn);
    }
    let small = scale(&take, 0.5);
    let moved = Retargeting::detect(take.skeleton(), small.skeleton())
        .unwrap()
        .apply(&take)
        .unwrap();
    assert_pelvis_at_half(&take, &moved);
}

/// The angle (degrees) between the local rotations of every joint with
/// rotation channels in frame `fa` of `a` and frame `fb` of `b` (one rig):
/// the largest, and its joint.
fn worst_local_angle(a: &Motion, fa: usize, b: &Motion, fb: usize) -> (f32, String) {
    let mut worst = (0.0f32, String::new());
    for (j, joint) in a.skeleton().joints().iter().enumerate() {
        if joint.has_rotation_channels() {
            let e = angle_between(a.local_rotation(fa, j), b.local_rotation(fb, j)).to_degrees();
            if e > worst.0 {
                worst = (e, joint.name.clone());
            }
        }
    }
    worst
}

#[test]
fn a_motion_retargets_the_same_wherever_it_starts() {
    let Some(data) = shared_data() else {
        eprintln!("../shared/data is absent: skipped");
        return;
    };
    let bandai = read_bvh(&sample_walk()).unwrap();
    // A real CMU walk that starts in a T-pose, played by Bandai's rig, and
    // the bundled Bandai walk (starting mid-stride) played by the CMU and
    // Mixamo rigs: each cut at five start frames.
    let cmu =
        read_bvh(&data.join("parser-cases/dme_example_crlf_leadingdot_frametime.bvh")).unwrap();
    let mixamo = read_bvh(&data.join("parser-cases/bvhpython_test_freebvh.bvh")).unwrap();
    for (take, rig) in [(&cmu, &bandai), (&bandai, &cmu), (&bandai, &mixamo)] {
        let (source, target) = (take.skeleton(), rig.skeleton());
        let at = 150; // the instant compared, in frames of the whole take
        let starts = [0, 20, 45, 80, 130];
        let whole = Retargeting::detect(source, target)
            .unwrap()
            .apply(take)
            .unwrap();
        let mut first_frame_worst = 0.0f32;
        for start in starts {
            let cut = trim(take, start..take.frame_count()).unwrap();
            let moved = Retargeting::detect(cut.skeleton(), target)
                .unwrap()
                .apply(&cut)
                .unwrap();
            let (e, joint) = worst_local_angle(&whole, at, &moved, at - start);
            assert!(e < 0.1, "cut at {start}: {joint} differs by {e} deg");
            // With each clip's first frame as its reference pose (what
            // retargeting did before), the cuts disagree.
            let maps = (
                BodyMap::detect(source).unwrap(),
                BodyMap::detect(target).unwrap(),
            );
            let by_first = Retargeting::with_reference_poses(&cut, &maps.0, rig, &maps.1)
                .unwrap()
                .apply(&cut)
                .unwrap();
            first_frame_worst =
                first_frame_worst.max(worst_local_angle(&whole, at, &by_first, at - start).0);
        }
        assert!(first_frame_worst > 1.0, "{first_frame_worst}");
    }
}

#[test]
fn every_rig_stands_in_the_same_canonical_pose() {
    let Some(data) = shared_data() else {
        eprintln!("../shared/data is absent: skipped");
        return;
    };
    let mut rigs = vec![read_bvh(&sample_walk()).unwrap()];
    for rig in [
        "dme_example_crlf_leadingdot_frametime.bvh",
        "bvhpython_test_freebvh.bvh",
        "bvhanim_test_mocapbank.bvh",
    ] {
        rigs.push(read_bvh(&data.join("parser-cases").join(rig)).unwrap());
    }
    for take in &rigs {
        let map = BodyMap::detect(take.skeleton()).unwrap();
        let pose = canonical_pose(take.skeleton(), &map).unwrap();
        let p = forward_kinematics(&pose);
        let at = |part: BodyPart| p.position(0, map.joint(part).unwrap());
        let dir = |a: BodyPart, b: BodyPart| (at(b) - at(a)).normalize();
        let lateral = dir(BodyPart::RightHip, BodyPart::LeftHip);
        let down = dir(BodyPart::LeftHip, BodyPart::LeftKnee);
        let name = take.skeleton().joint(0).name.clone();
        let angle = |a: Vec3, b: Vec3| a.angle_between(b).to_degrees();
        // Arms straight out to their side, legs straight down, at right
        // angles to the hips.
        for (a, b, want) in [
            (BodyPart::LeftShoulder, BodyPart::LeftElbow, lateral),
            (BodyPart::LeftElbow, BodyPart::LeftWrist, lateral),
            (BodyPart::RightShoulder, BodyPart::RightElbow, -lateral),
            (BodyPart::RightElbow, BodyPart::RightWrist, -lateral),
            (BodyPart::LeftKnee, BodyPart::LeftAnkle, down),
            (BodyPart::RightHip, BodyPart::RightKnee, down),
            (BodyPart::RightKnee, BodyPart::RightAnkle, down),
        ] {
            let e = angle(dir(a, b), want);
            assert!(e < 0.5, "rig of {name}: {a:?} to {b:?} {e} deg off");
        }
        assert!((angle(down, lateral) - 90.0).abs() < 1.0, "rig of {name}");
    }
}
