//! Body map detection, mirror pairs and the Kinect v2 layout, on skeletons
//! built in code with the joint names of real rigs.

use mocap_core::bodymap::*;
use mocap_core::rotation::Vec3;
use mocap_core::{Error, Joint, Skeleton};
use mocap_testdata::shared_data;

/// A skeleton from `(name, parent name)` pairs in parent-before-child order,
/// with unit offsets (only the names matter here).
fn skeleton(joints: &[(&str, Option<&str>)]) -> Skeleton {
    let mut out: Vec<Joint> = Vec::new();
    for &(name, parent) in joints {
        let parent = parent.map(|p| {
            out.iter()
                .position(|j| j.name == p)
                .unwrap_or_else(|| panic!("parent {p} of {name} comes first"))
        });
        out.push(Joint::new(name, parent, Vec3::X));
    }
    Skeleton::new(out).unwrap()
}

fn bandai() -> Skeleton {
    skeleton(&[
        ("joint_Root", None),
        ("Hips", Some("joint_Root")),
        ("Spine", Some("Hips")),
        ("Chest", Some("Spine")),
        ("Neck", Some("Chest")),
        ("Head", Some("Neck")),
        ("Shoulder_L", Some("Chest")),
        ("UpperArm_L", Some("Shoulder_L")),
        ("LowerArm_L", Some("UpperArm_L")),
        ("Hand_L", Some("LowerArm_L")),
        ("Shoulder_R", Some("Chest")),
        ("UpperArm_R", Some("Shoulder_R")),
        ("LowerArm_R", Some("UpperArm_R")),
        ("Hand_R", Some("LowerArm_R")),
        ("UpperLeg_L", Some("Hips")),
        ("LowerLeg_L", Some("UpperLeg_L")),
        ("Foot_L", Some("LowerLeg_L")),
        ("Toes_L", Some("Foot_L")),
        ("UpperLeg_R", Some("Hips")),
        ("LowerLeg_R", Some("UpperLeg_R")),
        ("Foot_R", Some("LowerLeg_R")),
        ("Toes_R", Some("Foot_R")),
    ])
}

fn cmu_bvh() -> Skeleton {
    skeleton(&[
        ("Hips", None),
        ("LHipJoint", Some("Hips")),
        ("LeftUpLeg", Some("LHipJoint")),
        ("LeftLeg", Some("LeftUpLeg")),
        ("LeftFoot", Some("LeftLeg")),
        ("LeftToeBase", Some("LeftFoot")),
        ("RHipJoint", Some("Hips")),
        ("RightUpLeg", Some("RHipJoint")),
        ("RightLeg", Some("RightUpLeg")),
        ("RightFoot", Some("RightLeg")),
        ("RightToeBase", Some("RightFoot")),
        ("LowerBack", Some("Hips")),
        ("Spine", Some("LowerBack")),
        ("Spine1", Some("Spine")),
        ("Neck", Some("Spine1")),
        ("Neck1", Some("Neck")),
        ("Head", Some("Neck1")),
        ("LeftShoulder", Some("Spine1")),
        ("LeftArm", Some("LeftShoulder")),
        ("LeftForeArm", Some("LeftArm")),
        ("LeftHand", Some("LeftForeArm")),
        ("LeftFingerBase", Some("LeftHand")),
        ("LeftHandIndex1", Some("LeftFingerBase")),
        ("LThumb", Some("LeftHand")),
        ("RightShoulder", Some("Spine1")),
        ("RightArm", Some("RightShoulder")),
        ("RightForeArm", Some("RightArm")),
        ("RightHand", Some("RightForeArm")),
        ("RightFingerBase", Some("RightHand")),
        ("RightHandIndex1", Some("RightFingerBase")),
        ("RThumb", Some("RightHand")),
    ])
}

fn asf() -> Skeleton {
    let mut joints = vec![("root", None)];
    for side in ["l", "r"] {
        let leg: Vec<String> = ["hipjoint", "femur", "tibia", "foot", "toes"]
            .iter()
            .map(|b| format!("{side}{b}"))
            .collect();
        joints.push((leak(&leg[0]), Some("root")));
        for k in 1..leg.len() {
            joints.push((leak(&leg[k]), Some(leak(&leg[k - 1]))));
        }
    }
    for (name, parent) in [
        ("lowerback", "root"),
        ("upperback", "lowerback"),
        ("thorax", "upperback"),
        ("lowerneck", "thorax"),
        ("upperneck", "lowerneck"),
        ("head", "upperneck"),
    ] {
        joints.push((name, Some(parent)));
    }
    for side in ["l", "r"] {
        let arm: Vec<String> = ["clavicle", "humerus", "radius", "wrist", "hand", "fingers"]
            .iter()
            .map(|b| format!("{side}{b}"))
            .collect();
        joints.push((leak(&arm[0]), Some("thorax")));
        for k in 1..arm.len() {
            joints.push((leak(&arm[k]), Some(leak(&arm[k - 1]))));
        }
        joints.push((leak(&format!("{side}thumb")), Some(leak(&arm[3]))));
    }
    skeleton(&joints)
}

fn leak(s: &str) -> &'static str {
    Box::leak(s.to_string().into_boxed_str())
}

fn name(skeleton: &Skeleton, joint: Option<usize>) -> &str {
    &skeleton.joint(joint.expect("part located")).name
}

fn pair_names(skeleton: &Skeleton, pairs: &[(usize, usize)]) -> Vec<(String, String)> {
    pairs
        .iter()
        .map(|&(l, r)| {
            (
                skeleton.joint(l).name.clone(),
                skeleton.joint(r).name.clone(),
            )
        })
        .collect()
}

#[test]
fn bandai_shoulder_is_the_upper_arm_not_the_clavicle() {
    let s = bandai();
    let map = BodyMap::detect(&s).unwrap();
    assert_eq!(map.rig(), "Bandai Namco");
    assert_eq!(name(&s, map.joint(BodyPart::LeftShoulder)), "UpperArm_L");
    assert_eq!(name(&s, map.joint(BodyPart::RightShoulder)), "UpperArm_R");
    assert_eq!(name(&s, map.joint(BodyPart::LeftWrist)), "Hand_L");
    assert_eq!(name(&s, map.joint(BodyPart::RightHip)), "UpperLeg_R");
    assert_eq!(name(&s, map.joint(BodyPart::LeftToe)), "Toes_L");
    assert_eq!(name(&s, map.joint(BodyPart::Pelvis)), "Hips");
    assert_eq!(name(&s, map.joint(BodyPart::Chest)), "Chest");
    // Bandai has no joint beyond the wrist.
    assert_eq!(map.missing(), vec![BodyPart::LeftHand, BodyPart::RightHand]);
    let err = map.require(BodyPart::LeftHand).unwrap_err().to_string();
    assert!(err.contains("left hand") && err.contains("Bandai"), "{err}");
}

#[test]
fn bandai_mirror_pairs_cover_every_side_joint() {
    let s = bandai();
    let pairs = mirror_pairs(&s);
    let names = pair_names(&s, &pairs);
    assert_eq!(names.len(), 8, "{names:?}");
    for (l, r) in &names {
        assert!(l.ends_with("_L") && r.ends_with("_R"), "{l} {r}");
        assert_eq!(l.trim_end_matches("_L"), r.trim_end_matches("_R"));
    }
}

#[test]
fn cmu_bvh_names() {
    let s = cmu_bvh();
    let map = BodyMap::detect(&s).unwrap();
    assert_eq!(map.rig(), "CMU-style BVH");
    assert_eq!(name(&s, map.joint(BodyPart::LeftShoulder)), "LeftArm");
    assert_eq!(name(&s, map.joint(BodyPart::LeftElbow)), "LeftForeArm");
    assert_eq!(name(&s, map.joint(BodyPart::LeftWrist)), "LeftHand");
    assert_eq!(name(&s, map.joint(BodyPart::LeftHand)), "LeftHandIndex1");
    assert_eq!(name(&s, map.joint(BodyPart::LeftHip)), "LeftUpLeg");
    assert_eq!(name(&s, map.joint(BodyPart::RightKnee)), "RightLeg");
    assert_eq!(name(&s, map.joint(BodyPart::RightAnkle)), "RightFoot");
    assert_eq!(name(&s, map.joint(BodyPart::Chest)), "Spine1");
    assert_eq!(name(&s, map.joint(BodyPart::Neck)), "Neck1");
    assert!(map.missing().is_empty());
    let names = pair_names(&s, &mirror_pairs(&s));
    // 5 leg joints, 7 arm joints per side.
    assert_eq!(names.len(), 12, "{names:?}");
    assert!(names.contains(&("LHipJoint".into(), "RHipJoint".into())));
    assert!(names.contains(&("LThumb".into(), "RThumb".into())));
    assert!(names.contains(&("LeftFingerBase".into(), "RightFingerBase".into())));
}

#[test]
fn mixamo_prefix_is_ignored() {
    let base = cmu_bvh();
    let joints: Vec<Joint> = base
        .joints()
        .iter()
        .map(|j| Joint {
            name: format!("mixamorig:{}", j.name),
            ..j.clone()
        })
        .collect();
    let s = Skeleton::new(joints).unwrap();
    let map = BodyMap::detect(&s).unwrap();
    assert_eq!(map.rig(), "Mixamo");
    assert_eq!(
        name(&s, map.joint(BodyPart::RightShoulder)),
        "mixamorig:RightArm"
    );
    let names = pair_names(&s, &mirror_pairs(&s));
    assert!(names.contains(&("mixamorig:LThumb".into(), "mixamorig:RThumb".into())));
    assert_eq!(names.len(), 12);
}

#[test]
fn asf_names() {
    let s = asf();
    let map = BodyMap::detect(&s).unwrap();
    assert_eq!(map.rig(), "CMU/HDM05 ASF");
    assert_eq!(name(&s, map.joint(BodyPart::LeftShoulder)), "lhumerus");
    assert_eq!(name(&s, map.joint(BodyPart::RightElbow)), "rradius");
    assert_eq!(name(&s, map.joint(BodyPart::LeftWrist)), "lwrist");
    assert_eq!(name(&s, map.joint(BodyPart::LeftHand)), "lhand");
    assert_eq!(name(&s, map.joint(BodyPart::RightHip)), "rfemur");
    assert_eq!(name(&s, map.joint(BodyPart::Neck)), "lowerneck");
    assert!(map.missing().is_empty());
    let names = pair_names(&s, &mirror_pairs(&s));
    assert_eq!(names.len(), 12, "{names:?}");
    assert!(names.contains(&("lfemur".into(), "rfemur".into())));
    assert!(names.contains(&("lhipjoint".into(), "rhipjoint".into())));
    // `lowerback`, `lowerneck` have no `r` twin and stay unpaired.
    assert!(names.iter().all(|(l, _)| !l.starts_with("lower")));
}

/// The Kinect skeleton reordered parent-before-child, as a fusion crate
/// would build it.
fn kinect_skeleton() -> (Skeleton, Vec<usize>) {
    let mut order: Vec<usize> = Vec::new();
    while order.len() < 25 {
        for (k, (_, parent)) in KINECT_V2_JOINTS.iter().enumerate() {
            let ready = parent.is_none_or(|p| order.contains(&p));
            if !order.contains(&k) && ready {
                order.push(k);
            }
        }
    }
    let joints = order
        .iter()
        .map(|&k| {
            let (name, parent) = KINECT_V2_JOINTS[k];
            let parent = parent.map(|p| order.iter().position(|&o| o == p).unwrap());
            Joint::new(name, parent, Vec3::Y)
        })
        .collect();
    (Skeleton::new(joints).unwrap(), order)
}

#[test]
fn kinect_layout_is_a_tree_rooted_at_spine_base() {
    let roots: Vec<usize> = (0..25)
        .filter(|&k| KINECT_V2_JOINTS[k].1.is_none())
        .collect();
    assert_eq!(roots, vec![0]);
    for (name, parent) in KINECT_V2_JOINTS {
        // Every joint reaches the root in fewer than 25 steps (no cycle).
        let mut parent = parent;
        let mut steps = 0;
        while let Some(p) = parent {
            parent = KINECT_V2_JOINTS[p].1;
            steps += 1;
            assert!(steps < 25, "cycle at {name}");
        }
    }
    assert_eq!(KINECT_V2_JOINTS[2], ("Neck", Some(20)));
    assert_eq!(KINECT_V2_JOINTS[20], ("SpineShoulder", Some(1)));
    assert_eq!(KINECT_V2_JOINTS[22], ("ThumbLeft", Some(6)));
}

#[test]
fn kinect_parts_match_the_layout() {
    let (s, order) = kinect_skeleton();
    let map = BodyMap::detect(&s).unwrap();
    assert_eq!(map.rig(), "Kinect v2");
    for (k, part) in KINECT_V2_BODY_PARTS.iter().enumerate() {
        let joint = order.iter().position(|&o| o == k).unwrap();
        match part {
            Some(p) => {
                assert_eq!(map.joint(*p), Some(joint), "{p}");
                assert_eq!(kinect_v2_joint(*p), Some(k));
            }
            None => assert!(map.parts().all(|(_, j)| j != joint)),
        }
    }
    // Parents in the layout agree with the anatomy of the parts.
    let parent_part = |k: usize| KINECT_V2_BODY_PARTS[KINECT_V2_JOINTS[k].1.unwrap()];
    assert_eq!(parent_part(5), Some(BodyPart::LeftShoulder));
    assert_eq!(parent_part(17), Some(BodyPart::RightHip));
    assert_eq!(parent_part(4), Some(BodyPart::Chest));
    let names = pair_names(&s, &mirror_pairs(&s));
    assert_eq!(names.len(), 10, "{names:?}");
    assert!(names.contains(&("HandTipLeft".into(), "HandTipRight".into())));
}

#[test]
fn unknown_rig_names_the_missing_parts() {
    let s = skeleton(&[
        ("Base", None),
        ("Torso", Some("Base")),
        ("L_Thigh", Some("Base")),
        ("R_Thigh", Some("Base")),
    ]);
    let err = BodyMap::detect(&s).unwrap_err();
    let Error::Invalid(message) = &err else {
        panic!("{err:?}")
    };
    for expected in [
        "left shoulder",
        "right knee",
        "pelvis",
        "tried",
        "from_toml_file",
    ] {
        assert!(message.contains(expected), "{expected}: {message}");
    }
    // Name patterns still pair the thighs.
    assert_eq!(
        pair_names(&s, &mirror_pairs(&s)),
        [("L_Thigh".into(), "R_Thigh".into())]
    );
}

const STUDIO_RIG: &str = r#"
name = "studio"
[parts]
pelvis = "Root"
head = "Skull"
left_shoulder = "ArmA"
right_shoulder = "ArmB"
left_elbow = "ElbowA"
right_elbow = "ElbowB"
left_wrist = "WristA"
right_wrist = "WristB"
left_hip = "ThighA"
right_hip = "ThighB"
left_knee = "ShinA"
right_knee = "ShinB"
left_ankle = "FootA"
right_ankle = "FootB"

[mirror]
pairs = [["FingerA", "FingerB"]]
"#;

fn studio() -> Skeleton {
    let mut joints = vec![("Root", None), ("Skull", Some("Root"))];
    for side in ["A", "B"] {
        let chain: Vec<&'static str> = ["Arm", "Elbow", "Wrist", "Finger"]
            .iter()
            .map(|b| leak(&format!("{b}{side}")))
            .collect();
        joints.push((chain[0], Some("Root")));
        for k in 1..chain.len() {
            joints.push((chain[k], Some(chain[k - 1])));
        }
        let leg: Vec<&'static str> = ["Thigh", "Shin", "Foot"]
            .iter()
            .map(|b| leak(&format!("{b}{side}")))
            .collect();
        joints.push((leg[0], Some("Root")));
        for k in 1..leg.len() {
            joints.push((leg[k], Some(leg[k - 1])));
        }
    }
    skeleton(&joints)
}

#[test]
fn rig_file_maps_an_unknown_rig() {
    let s = studio();
    assert!(BodyMap::detect(&s).is_err());
    let map = BodyMap::from_toml_str(STUDIO_RIG, &s).unwrap();
    assert_eq!(map.rig(), "studio");
    assert_eq!(name(&s, map.joint(BodyPart::LeftShoulder)), "ArmA");
    assert_eq!(name(&s, map.joint(BodyPart::RightAnkle)), "FootB");
    let names = pair_names(&s, &map.mirror_pairs(&s));
    // 6 pairs from the parts, 1 from [mirror].
    assert_eq!(names.len(), 7, "{names:?}");
    assert!(names.contains(&("FingerA".into(), "FingerB".into())));
    assert!(names.contains(&("ShinA".into(), "ShinB".into())));
}

#[test]
fn rig_file_overrides_a_built_in_rig() {
    let s = bandai();
    // Say the wrist is where the "hand" part is, for a tool that wants it.
    let map = BodyMap::from_toml_str(
        "[parts]\nleft_hand = \"Hand_L\"\nright_hand = \"Hand_R\"\n",
        &s,
    )
    .unwrap();
    assert_eq!(name(&s, map.joint(BodyPart::LeftHand)), "Hand_L");
    assert_eq!(name(&s, map.joint(BodyPart::LeftShoulder)), "UpperArm_L");
    assert!(map.missing().is_empty());
}

#[test]
fn rig_file_errors_are_clear() {
    let s = studio();
    let err = BodyMap::from_toml_str("[parts]\nleft_sholder = \"ArmA\"\n", &s)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("left_sholder") && err.contains("left_shoulder"),
        "{err}"
    );

    let err = BodyMap::from_toml_str("[parts]\npelvis = \"Pelvis\"\n", &s)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("\"Pelvis\"") && err.contains("no such joint"),
        "{err}"
    );

    let err = BodyMap::from_toml_str(&STUDIO_RIG.replace("head = \"Skull\"\n", ""), &s)
        .unwrap_err()
        .to_string();
    assert!(err.contains("required parts head"), "{err}");

    // A syntax error on line 3 is reported there.
    let err = BodyMap::from_toml_str("[parts]\npelvis = \"Root\"\nhead = Skull\n", &s).unwrap_err();
    let Error::Parse(parse) = &err else {
        panic!("{err:?}")
    };
    assert_eq!(parse.location.line, 3, "{err}");

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("studio.toml");
    std::fs::write(&path, STUDIO_RIG.replace("ArmA", "Arm_A")).unwrap();
    let err = BodyMap::from_toml_file(&path, &s).unwrap_err().to_string();
    assert!(
        err.contains("studio.toml") && err.contains("Arm_A"),
        "{err}"
    );
    let err = BodyMap::from_toml_file(dir.path().join("absent.toml"), &s)
        .unwrap_err()
        .to_string();
    assert!(err.contains("absent.toml"), "{err}");
}

#[test]
fn parts_mirror_and_keys_round_trip() {
    for part in BodyPart::ALL {
        assert_eq!(part.mirror().mirror(), part);
        assert_eq!(BodyPart::from_key(part.key()), Some(part));
        match part.side() {
            None => assert_eq!(part.mirror(), part),
            Some(side) => {
                assert_ne!(part.mirror().side(), Some(side));
                let (left, right) = match side {
                    Side::Left => (part, part.mirror()),
                    Side::Right => (part.mirror(), part),
                };
                assert_eq!(left.key().replace("left", "right"), right.key());
            }
        }
    }
    assert_eq!(BodyPart::LeftShoulder.to_string(), "left shoulder");
}

// ---------------------------------------------------------------------------
// Real rigs: the parts sit where their names say, checked on FK positions.

use mocap_core::io::asf_amc::read_asf_amc;
use mocap_core::io::bvh::read_bvh;
use mocap_core::{forward_kinematics, Motion};
use std::path::PathBuf;

/// Checks, on the first frame of a take that starts standing, that the
/// detected parts are at the anatomical points they stand for.
fn check_anatomy(m: &Motion, rig: &str, what: &str) {
    use BodyPart::*;
    let s = m.skeleton();
    let map = BodyMap::detect(s).unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(map.rig(), rig, "{what}");
    let p = forward_kinematics(m);
    let at = |part: BodyPart| p.position(0, map.joint(part).unwrap());
    let height = at(Head).y - at(LeftAnkle).y.min(at(RightAnkle).y);
    let lateral = (at(LeftHip) - at(RightHip)).normalize();

    // The spine goes up from the pelvis to the head (Y is up in all files).
    let spine: Vec<BodyPart> = [Pelvis, Spine, Chest, Neck, Head]
        .into_iter()
        .filter(|&part| map.joint(part).is_some())
        .collect();
    for pair in spine.windows(2) {
        assert!(
            at(pair[0]).y < at(pair[1]).y,
            "{what}: {} below {}",
            pair[0],
            pair[1]
        );
    }
    for side in [
        [LeftShoulder, LeftElbow, LeftWrist, LeftHand],
        [RightShoulder, RightElbow, RightWrist, RightHand],
        [LeftHip, LeftKnee, LeftAnkle, LeftToe],
        [RightHip, RightKnee, RightAnkle, RightToe],
    ] {
        let chain: Vec<BodyPart> = side
            .into_iter()
            .filter(|&part| map.joint(part).is_some())
            .collect();
        for (k, pair) in chain.windows(2).enumerate() {
            let (a, b) = (map.joint(pair[0]).unwrap(), map.joint(pair[1]).unwrap());
            // Each part hangs below the previous one and is a distinct point:
            // upper arm, forearm, thigh and shin are long bones, the hand
            // and toe points lie a little beyond the wrist and ankle.
            assert!(
                s.subtree(a).contains(&b),
                "{what}: {} under {}",
                pair[1],
                pair[0]
            );
            // The long bones join their two parts directly: the shoulder
            // point is the elbow's parent (a clavicle joint would not be).
            if k < 2 {
                assert_eq!(
                    s.joint(b).parent,
                    Some(a),
                    "{what}: {} to {}",
                    pair[0],
                    pair[1]
                );
            }
            let length = at(pair[0]).distance(at(pair[1])) / height;
            let shortest = if k < 2 { 0.1 } else { 0.02 };
            assert!(
                length > shortest,
                "{what}: {} to {} is {length} of the height",
                pair[0],
                pair[1]
            );
        }
        // Thigh and shin, upper arm and forearm are of similar length.
        let ratio = at(chain[0]).distance(at(chain[1])) / at(chain[1]).distance(at(chain[2]));
        assert!(
            (0.6..1.7).contains(&ratio),
            "{what}: {} segment ratio {ratio}",
            chain[0]
        );
    }
    // The left shoulder is on the left (limbs can cross in a pose, the
    // shoulders cannot; the chains above check the rest hangs from them).
    let across = (at(LeftShoulder) - at(RightShoulder)).dot(lateral);
    assert!(across > 0.0, "{what}: left shoulder is not on the left");
    // The shoulder and hip points are the ball joints, not the clavicle or
    // pelvis joints they hang from: they are further apart than those.
    for (left, right) in [(LeftShoulder, RightShoulder), (LeftHip, RightHip)] {
        let (l, r) = (map.joint(left).unwrap(), map.joint(right).unwrap());
        let (pl, pr) = (s.joint(l).parent.unwrap(), s.joint(r).parent.unwrap());
        let width = at(left).distance(at(right));
        let parent_width = p.position(0, pl).distance(p.position(0, pr));
        assert!(
            width > 1.5 * parent_width && width > 0.05 * height,
            "{what}: {left} width {width}, parents {parent_width}"
        );
    }
}

#[test]
fn real_rigs_put_parts_at_their_anatomical_points() {
    let Some(data) = shared_data() else { return };
    for (dataset, step) in [("dataset-1", 5), ("dataset-2", 40)] {
        let mut files: Vec<PathBuf> = std::fs::read_dir(data.join("bandai").join(dataset))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
            .collect();
        files.sort();
        for path in files.iter().step_by(step) {
            let m = read_bvh(path).unwrap();
            check_anatomy(&m, "Bandai Namco", &path.display().to_string());
            assert_eq!(mirror_pairs(m.skeleton()).len(), 8);
        }
    }
    let cases = data.join("parser-cases");
    for (name, rig, pairs) in [
        (
            "dme_example_crlf_leadingdot_frametime.bvh",
            "CMU-style BVH",
            12,
        ),
        ("bvhpython_test_freebvh.bvh", "Mixamo", 24),
        ("bvhanim_test_mocapbank.bvh", "Biovision BVH", 7),
    ] {
        let m = read_bvh(&cases.join(name)).unwrap();
        check_anatomy(&m, rig, name);
        assert_eq!(mirror_pairs(m.skeleton()).len(), pairs, "{name}");
    }
    let hdm = data.join("hdm05-sample");
    let m = read_asf_amc(
        hdm.join("HDM_bd.asf"),
        hdm.join("HDM_bd_depositFloorR_001_120.amc"),
    )
    .unwrap();
    check_anatomy(&m, "CMU/HDM05 ASF", "HDM_bd");
    assert_eq!(mirror_pairs(m.skeleton()).len(), 12);
}

#[test]
fn leg_length_is_the_mean_of_both_legs_hip_to_ankle() {
    // Unit offsets, except the shins: left 3, right 5 (and a long toe and
    // hip offset, which are not part of the leg).
    let mut joints = bandai().into_joints();
    for joint in &mut joints {
        joint.offset = match joint.name.as_str() {
            "Foot_L" => Vec3::new(0.0, -3.0, 0.0),
            "Foot_R" => Vec3::new(0.0, -5.0, 0.0),
            "Toes_L" | "Toes_R" | "UpperLeg_L" | "UpperLeg_R" => Vec3::new(0.0, 0.0, 7.0),
            _ => Vec3::new(0.0, -1.0, 0.0),
        };
    }
    let skeleton = Skeleton::new(joints).unwrap();
    let map = BodyMap::detect(&skeleton).unwrap();
    // Thigh 1 plus shin 3 or 5.
    assert_eq!(map.leg_length(&skeleton).unwrap(), 5.0);
    let (hips, foot) = (
        skeleton.find("Hips").unwrap(),
        skeleton.find("Foot_L").unwrap(),
    );
    assert_eq!(skeleton.chain_length(foot, hips), Some(11.0));
    assert_eq!(skeleton.chain_length(foot, foot), Some(0.0));
    // The hips are not below the foot.
    assert_eq!(skeleton.chain_length(hips, foot), None);
}
