//! Body parts found on any humanoid rig without a rig file: by the naming
//! conventions' tables (synthetic hierarchies for each, the real rigs of
//! `../shared/data/other-rigs` and `parser-cases`), and by the skeleton's
//! shape when the names say nothing (the real rigs with their joints
//! renamed `joint_0..N`). Left is checked to be the body's left on the
//! motion itself, frame by frame, not on the names.

use std::path::{Path, PathBuf};

use mocap_core::bodymap::{BodyMap, BodyPart, FoundBy, SideEvidence, UNNAMED_RIG};
use mocap_core::io::bvh::{read_bvh, read_bvh_header};
use mocap_core::kinematics::end_site_positions;
use mocap_core::rotation::Vec3;
use mocap_core::{forward_kinematics, Error, Joint, Motion, Skeleton};
use mocap_testdata::{bvh_files, shared_data};

use BodyPart::*;

// ---------------------------------------------------------------------------
// Synthetic hierarchies, one per naming convention.

/// A humanoid in a T-pose (Y up, facing +Z, its left at +X) named by a
/// convention. Names may hold `{s}`, replaced by the side marker.
struct Convention {
    /// Joints above the pelvis (Biped's `Bip01`, Unreal's `root`).
    above: &'static [&'static str],
    pelvis: &'static str,
    /// Spine joints from the pelvis up; the last is the chest.
    spine: &'static [&'static str],
    /// Neck joints, then the head.
    neck: &'static [&'static str],
    /// The joint the legs hang from (default: the pelvis).
    legs_from: Option<&'static str>,
    /// The joint the arms hang from (default: the chest).
    arms_from: Option<&'static str>,
    /// Clavicle, upper arm, forearm, wrist, finger.
    arm: [&'static str; 5],
    /// Thigh, shin, foot, toe.
    leg: [&'static str; 4],
    /// Left and right markers for `{s}`.
    sides: [&'static str; 2],
    /// A prefix every joint name carries (`Bip001 `, `Character1_`).
    prefix: &'static str,
}

impl Convention {
    fn name(&self, name: &str, side: usize) -> String {
        format!("{}{}", self.prefix, name.replace("{s}", self.sides[side]))
    }

    fn skeleton(&self) -> Skeleton {
        let mut joints: Vec<Joint> = Vec::new();
        let mut add = |name: String, parent: Option<&str>, offset: Vec3| {
            let parent = parent.map(|p| {
                joints
                    .iter()
                    .position(|j| j.name == p)
                    .unwrap_or_else(|| panic!("{p} before {name}"))
            });
            joints.push(Joint::new(name, parent, offset));
        };
        let mut last: Option<String> = None;
        for &name in self.above {
            add(self.name(name, 0), last.as_deref(), Vec3::ZERO);
            last = Some(self.name(name, 0));
        }
        add(
            self.name(self.pelvis, 0),
            last.as_deref(),
            Vec3::new(0.0, 0.95, 0.0),
        );
        last = Some(self.name(self.pelvis, 0));
        let step = 0.45 / self.spine.len() as f32;
        for &name in self.spine.iter().chain(self.neck) {
            add(
                self.name(name, 0),
                last.as_deref(),
                Vec3::new(0.0, step, 0.0),
            );
            last = Some(self.name(name, 0));
        }
        let chest = self.name(self.spine[self.spine.len() - 1], 0);
        let arms_from = self.arms_from.map_or(chest, |n| self.name(n, 0));
        let legs_from = self
            .legs_from
            .map_or(self.name(self.pelvis, 0), |n| self.name(n, 0));
        for side in 0..2 {
            let x = if side == 0 { 1.0 } else { -1.0 };
            let arm = [
                Vec3::new(0.03 * x, 0.05, 0.0),
                Vec3::new(0.15 * x, 0.0, 0.0),
                Vec3::new(0.28 * x, 0.0, 0.0),
                Vec3::new(0.25 * x, 0.0, 0.0),
                Vec3::new(0.09 * x, 0.0, 0.0),
            ];
            let mut parent = arms_from.clone();
            for (name, offset) in self.arm.iter().zip(arm) {
                add(self.name(name, side), Some(&parent), offset);
                parent = self.name(name, side);
            }
            let leg = [
                Vec3::new(0.1 * x, -0.05, 0.0),
                Vec3::new(0.0, -0.45, 0.0),
                Vec3::new(0.0, -0.43, 0.0),
                Vec3::new(0.0, -0.06, 0.13),
            ];
            let mut parent = legs_from.clone();
            for (name, offset) in self.leg.iter().zip(leg) {
                add(self.name(name, side), Some(&parent), offset);
                parent = self.name(name, side);
            }
        }
        for joint in &mut joints {
            if joint
                .name
                .ends_with(self.arm[4].replace("{s}", "").as_str())
            {
                joint.end_sites.push(Vec3::new(0.05, 0.0, 0.0));
            }
        }
        Skeleton::new(joints).unwrap()
    }
}

const DAZ: Convention = Convention {
    above: &[],
    pelvis: "hip",
    spine: &["abdomen", "chest"],
    neck: &["neck", "head"],
    legs_from: None,
    arms_from: None,
    arm: ["{s}Collar", "{s}Shldr", "{s}ForeArm", "{s}Hand", "{s}Mid1"],
    leg: ["{s}Thigh", "{s}Shin", "{s}Foot", "{s}Toe"],
    sides: ["l", "r"],
    prefix: "",
};

const BIPED: Convention = Convention {
    above: &["Bip001"],
    pelvis: "Pelvis",
    spine: &["Spine", "Spine1", "Spine2"],
    neck: &["Neck", "Head"],
    legs_from: Some("Spine"),
    arms_from: Some("Neck"),
    arm: [
        "{s} Clavicle",
        "{s} UpperArm",
        "{s} Forearm",
        "{s} Hand",
        "{s} Finger2",
    ],
    leg: ["{s} Thigh", "{s} Calf", "{s} Foot", "{s} Toe0"],
    sides: ["L", "R"],
    prefix: "Bip001 ",
};

const UNREAL: Convention = Convention {
    above: &["root"],
    pelvis: "pelvis",
    spine: &["spine_01", "spine_02", "spine_03"],
    neck: &["neck_01", "head"],
    legs_from: None,
    arms_from: None,
    arm: [
        "clavicle_{s}",
        "upperarm_{s}",
        "lowerarm_{s}",
        "hand_{s}",
        "middle_01_{s}",
    ],
    leg: ["thigh_{s}", "calf_{s}", "foot_{s}", "ball_{s}"],
    sides: ["l", "r"],
    prefix: "",
};

const SMPL: Convention = Convention {
    above: &[],
    pelvis: "pelvis",
    spine: &["spine1", "spine2", "spine3"],
    neck: &["neck", "head"],
    legs_from: None,
    arms_from: None,
    arm: [
        "{s}_collar",
        "{s}_shoulder",
        "{s}_elbow",
        "{s}_wrist",
        "{s}_hand",
    ],
    leg: ["{s}_hip", "{s}_knee", "{s}_ankle", "{s}_foot"],
    sides: ["left", "right"],
    prefix: "",
};

const SMPL_SHORT: Convention = Convention {
    pelvis: "Pelvis",
    spine: &["Spine1", "Spine2", "Spine3"],
    neck: &["Neck", "Head"],
    arm: [
        "{s}_Collar",
        "{s}_Shoulder",
        "{s}_Elbow",
        "{s}_Wrist",
        "{s}_Hand",
    ],
    leg: ["{s}_Hip", "{s}_Knee", "{s}_Ankle", "{s}_Foot"],
    sides: ["L", "R"],
    ..SMPL
};

const ROKOKO: Convention = Convention {
    above: &[],
    pelvis: "Hips",
    spine: &["Spine1", "Spine2", "Spine3", "Spine4"],
    neck: &["Neck", "Head"],
    legs_from: None,
    arms_from: None,
    arm: [
        "{s}Shoulder",
        "{s}Arm",
        "{s}ForeArm",
        "{s}Hand",
        "{s}Finger3Proximal",
    ],
    leg: ["{s}Thigh", "{s}Shin", "{s}Foot", "{s}Toe"],
    sides: ["Left", "Right"],
    prefix: "",
};

const HUMANIK: Convention = Convention {
    above: &["Reference"],
    pelvis: "Hips",
    spine: &["Spine", "Spine1", "Spine2"],
    neck: &["Neck", "Head"],
    legs_from: None,
    arms_from: None,
    arm: [
        "{s}Shoulder",
        "{s}Arm",
        "{s}ForeArm",
        "{s}Hand",
        "{s}HandMiddle1",
    ],
    leg: ["{s}UpLeg", "{s}Leg", "{s}Foot", "{s}ToeBase"],
    sides: ["Left", "Right"],
    prefix: "Character1_",
};

/// Checks the rig found by name on a convention's hierarchy: the name, and
/// every part at the joint the convention gives it.
fn check_convention(convention: &Convention, rig: &str, chest: &str, neck: Option<&str>) {
    let s = convention.skeleton();
    let map = BodyMap::detect(&s).unwrap_or_else(|e| panic!("{rig}: {e}"));
    assert_eq!(map.rig(), rig);
    assert_eq!(map.found_by(), FoundBy::Names, "{rig}");
    let name = |part: BodyPart| map.joint(part).map(|j| s.joint(j).name.clone());
    let c = |n: &str, side: usize| Some(convention.name(n, side));
    assert_eq!(name(Pelvis), c(convention.pelvis, 0), "{rig}");
    assert_eq!(name(Spine), c(convention.spine[0], 0), "{rig}");
    assert_eq!(name(Chest), c(chest, 0), "{rig}");
    assert_eq!(name(Neck), neck.and_then(|n| c(n, 0)), "{rig}");
    assert_eq!(
        name(Head),
        c(convention.neck[convention.neck.len() - 1], 0),
        "{rig}"
    );
    for (side, parts) in [
        (0, [LeftClavicle, LeftShoulder, LeftElbow, LeftWrist]),
        (1, [RightClavicle, RightShoulder, RightElbow, RightWrist]),
    ] {
        for (part, joint) in parts.into_iter().zip(convention.arm) {
            assert_eq!(name(part), c(joint, side), "{rig} {part}");
        }
    }
    for (side, parts) in [
        (0, [LeftHip, LeftKnee, LeftAnkle, LeftToe]),
        (1, [RightHip, RightKnee, RightAnkle, RightToe]),
    ] {
        for (part, joint) in parts.into_iter().zip(convention.leg) {
            assert_eq!(name(part), c(joint, side), "{rig} {part}");
        }
    }
}

#[test]
fn each_naming_convention_is_found_by_name() {
    check_convention(&DAZ, "Daz/Poser", "chest", Some("neck"));
    check_convention(&BIPED, "3ds Max Biped", "Spine2", Some("Neck"));
    check_convention(&UNREAL, "Unreal mannequin", "spine_03", Some("neck_01"));
    check_convention(&SMPL, "SMPL", "spine3", Some("neck"));
    check_convention(&SMPL_SHORT, "SMPL", "Spine3", Some("Neck"));
    check_convention(&ROKOKO, "Rokoko", "Spine4", Some("Neck"));
    check_convention(&HUMANIK, "MotionBuilder/HumanIK", "Spine2", Some("Neck"));
}

#[test]
fn hands_found_by_name_where_the_convention_names_them() {
    for (convention, left, right) in [
        (&DAZ, "lMid1", "rMid1"),
        (&BIPED, "Bip001 L Finger2", "Bip001 R Finger2"),
        (&UNREAL, "middle_01_l", "middle_01_r"),
        (&SMPL, "left_hand", "right_hand"),
        (
            &HUMANIK,
            "Character1_LeftHandMiddle1",
            "Character1_RightHandMiddle1",
        ),
    ] {
        let s = convention.skeleton();
        let map = BodyMap::detect(&s).unwrap();
        let name = |part| s.joint(map.joint(part).unwrap()).name.as_str();
        assert_eq!((name(LeftHand), name(RightHand)), (left, right));
    }
}

/// The convention's hierarchy with every joint renamed `joint_<index>`.
fn scrambled(s: &Skeleton) -> Skeleton {
    let joints = s
        .joints()
        .iter()
        .enumerate()
        .map(|(i, j)| Joint {
            name: format!("joint_{i}"),
            ..j.clone()
        })
        .collect();
    Skeleton::new(joints).unwrap()
}

#[test]
fn a_synthetic_t_pose_with_meaningless_names_is_found_by_shape() {
    for convention in [&DAZ, &UNREAL, &SMPL, &ROKOKO, &HUMANIK] {
        let named = convention.skeleton();
        let by_name = BodyMap::detect(&named).unwrap();
        let s = scrambled(&named);
        let map = BodyMap::detect(&s).unwrap();
        assert_eq!(map.rig(), UNNAMED_RIG);
        assert_eq!(map.found_by(), FoundBy::Shape(SideEvidence::RestPose));
        for part in [
            Pelvis,
            Chest,
            Head,
            LeftShoulder,
            RightElbow,
            LeftWrist,
            RightHip,
            LeftKnee,
            RightAnkle,
            LeftToe,
            LeftClavicle,
        ] {
            assert_eq!(
                map.joint(part),
                by_name.joint(part),
                "{} {part}",
                by_name.rig()
            );
        }
    }
    // Biped hangs the thighs from its first spine link: the shape sees the
    // pelvis there, and the limbs as the names do.
    let named = BIPED.skeleton();
    let by_name = BodyMap::detect(&named).unwrap();
    let map = BodyMap::detect(&scrambled(&named)).unwrap();
    assert_eq!(named.joint(map.joint(Pelvis).unwrap()).name, "Bip001 Spine");
    for part in [LeftShoulder, RightWrist, LeftHip, RightToe, LeftClavicle] {
        assert_eq!(map.joint(part), by_name.joint(part), "Biped {part}");
    }
}

#[test]
fn a_mirror_image_rest_pose_swaps_the_sides_found_by_shape() {
    // The same T-pose facing -Z: its left is now at -X, where the `l`
    // joints are. Names scrambled, the shape must follow the geometry.
    let named = DAZ.skeleton();
    let joints: Vec<Joint> = scrambled(&named)
        .joints()
        .iter()
        .map(|j| Joint {
            offset: j.offset * Vec3::new(1.0, 1.0, -1.0),
            end_sites: j
                .end_sites
                .iter()
                .map(|e| *e * Vec3::new(1.0, 1.0, -1.0))
                .collect(),
            ..j.clone()
        })
        .collect();
    let s = Skeleton::new(joints).unwrap();
    let map = BodyMap::detect(&s).unwrap();
    let original = |part| named.joint(map.joint(part).unwrap()).name.as_str();
    assert_eq!(original(LeftHip), "rThigh");
    assert_eq!(original(LeftShoulder), "rShldr");
    assert_eq!(original(RightAnkle), "lFoot");
}

// ---------------------------------------------------------------------------
// Real rigs.

/// Every BVH file under `dir`, in every folder below it, sorted.
fn bvh_tree(dir: &Path) -> Vec<PathBuf> {
    let mut out = bvh_files(dir);
    let mut folders: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    folders.sort();
    for folder in folders {
        out.extend(bvh_tree(&folder));
    }
    out
}

/// The point at the tip of the foot below `ankle` in frame `f`: the toe
/// part if the rig has one, else the farthest end site below the ankle.
fn foot_tip(m: &Motion, map: &BodyMap, toe: BodyPart, ankle: usize, f: usize) -> Vec3 {
    let p = forward_kinematics(m);
    if let Some(toe) = map.joint(toe) {
        return p.position(f, toe);
    }
    let below = m.skeleton().subtree(ankle);
    end_site_positions(m, &p, f)
        .into_iter()
        .filter(|(j, _)| below.contains(j))
        .map(|(_, at)| at)
        .max_by(|a, b| {
            let pa = p.position(f, ankle);
            a.distance(pa).total_cmp(&b.distance(pa))
        })
        .expect("an end site below the ankle")
}

/// Checks on the motion that the parts are where they say: in most frames
/// the left hip and shoulder are on the body's left (up, pelvis to head,
/// × forward, where the feet point); the limbs hang in order; the legs
/// are long bones of similar length.
fn check_on_motion(m: &Motion, map: &BodyMap, what: &str) {
    let s = m.skeleton();
    let p = forward_kinematics(m);
    let j = |part: BodyPart| {
        map.joint(part)
            .unwrap_or_else(|| panic!("{what}: no {part}"))
    };
    let frames: Vec<usize> = (0..m.frame_count())
        .step_by((m.frame_count() / 40).max(1))
        .collect();
    let mut left_ok = [0usize; 2];
    for &f in &frames {
        let at = |part: BodyPart| p.position(f, j(part));
        let up = (at(Head) - at(Pelvis)).normalize();
        let mut forward = Vec3::ZERO;
        for (toe, ankle) in [(LeftToe, LeftAnkle), (RightToe, RightAnkle)] {
            let foot = foot_tip(m, map, toe, j(ankle), f) - at(ankle);
            forward += foot - up * foot.dot(up);
        }
        let left = up.cross(forward.normalize());
        for (k, (l, r)) in [(LeftHip, RightHip), (LeftShoulder, RightShoulder)]
            .into_iter()
            .enumerate()
        {
            if (at(l) - at(r)).dot(left) > 0.0 {
                left_ok[k] += 1;
            }
        }
    }
    for (k, what_side) in ["hip", "shoulder"].iter().enumerate() {
        assert!(
            left_ok[k] * 10 >= frames.len() * 9,
            "{what}: the left {what_side} is on the body's left in {} of {} frames",
            left_ok[k],
            frames.len()
        );
    }
    for chain in [
        [LeftShoulder, LeftElbow, LeftWrist],
        [RightShoulder, RightElbow, RightWrist],
        [LeftHip, LeftKnee, LeftAnkle],
        [RightHip, RightKnee, RightAnkle],
    ] {
        assert!(s.subtree(j(chain[0])).contains(&j(chain[1])), "{what}");
        assert!(s.subtree(j(chain[1])).contains(&j(chain[2])), "{what}");
        let at = |part: BodyPart| p.position(0, j(part));
        let ratio = at(chain[0]).distance(at(chain[1])) / at(chain[1]).distance(at(chain[2]));
        assert!(
            (0.6..1.7).contains(&ratio),
            "{what}: {} ratio {ratio}",
            chain[0]
        );
    }
}

/// The joint names of the parts of `map` on `s`, for messages.
fn joint_name(s: &Skeleton, map: &BodyMap, part: BodyPart) -> String {
    map.joint(part)
        .map_or_else(|| "-".to_string(), |j| s.joint(j).name.clone())
}

#[test]
fn every_rig_of_other_rigs_and_parser_cases_has_its_body_parts_found() {
    let Some(data) = shared_data() else { return };
    let mut files = bvh_tree(&data.join("other-rigs"));
    files.extend(bvh_files(&data.join("parser-cases")));
    assert!(files.len() >= 100, "{} files", files.len());
    let mut checked_on_motion = 0;
    for path in &files {
        let what = path.display().to_string();
        let (s, _, _) = read_bvh_header(path).unwrap();
        let detected = BodyMap::detect(&s);
        // The one file that is no body: two joints of a reader test.
        if path.ends_with("bvhanim_test_simple.bvh") {
            let err = detected.unwrap_err().to_string();
            for expected in ["pelvis", "--rig", "[parts]", "# pelvis = \"\""] {
                assert!(err.contains(expected), "{expected}: {err}");
            }
            continue;
        }
        let map = detected.unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_eq!(map.found_by(), FoundBy::Names, "{what}");
        assert!(map.missing().iter().all(|p| !p.is_required()), "{what}");
        let name = |part| joint_name(&s, &map, part);
        // A few joints by name, per rig.
        let folder = path
            .parent()
            .unwrap()
            .file_name()
            .unwrap()
            .to_string_lossy();
        let expected: &[(BodyPart, &str)] = match (map.rig(), &*folder) {
            ("Daz/Poser", _) => &[
                (RightHip, "rThigh"),
                (LeftKnee, "lShin"),
                (LeftShoulder, "lShldr"),
                (RightElbow, "rForeArm"),
                (LeftClavicle, "lCollar"),
                (Spine, "abdomen"),
                (RightAnkle, "rFoot"),
            ],
            ("CMU (3ds Max names)", _) => &[
                (LeftHip, "LeftHip"),
                (LeftClavicle, "LeftCollar"),
                (RightShoulder, "RightShoulder"),
                (Chest, "Chest2"),
                (LeftHand, "LFingers"),
            ],
            ("CMU/HDM05 ASF", "cmu-asf") => &[
                (Pelvis, "hip"),
                (LeftHip, "lfemur"),
                (RightShoulder, "rhumerus"),
                (LeftToe, "ltoes"),
            ],
            ("CMU-style BVH", "xia") => &[
                (LeftHip, "LeftUpLeg"),
                (RightShoulder, "RightArm"),
                (Neck, "Neck1"),
                (Chest, "Spine1"),
            ],
            ("CMU-style BVH", "fair1") => &[
                (LeftHip, "LeftUpLeg"),
                (RightShoulder, "RightArm"),
                (LeftToe, "LeftToeBase"),
                (RightHand, "RightHandEnd"),
            ],
            ("CMU-style BVH" | "Mixamo" | "Biovision BVH", "parser-cases") => &[],
            (rig, folder) => panic!("{what}: unexpected rig {rig} in {folder}"),
        };
        for &(part, joint) in expected {
            assert_eq!(name(part), joint, "{what}: {part}");
        }
        // Left checked on the motion: every file but the many CMU-Daz
        // takes, of which the first of each subject.
        let first_of_subject = path.starts_with(data.join("other-rigs/cmu-daz"))
            && bvh_files(path.parent().unwrap())[0] == *path;
        if !path.starts_with(data.join("other-rigs/cmu-daz")) || first_of_subject {
            let m = read_bvh(path).unwrap();
            check_on_motion(&m, &map, &what);
            checked_on_motion += 1;
        }
    }
    assert!(checked_on_motion >= 20, "{checked_on_motion}");
}

/// `skeleton` with every joint renamed `joint_<index>`.
fn renamed(m: &Motion) -> Motion {
    let s = scrambled(m.skeleton());
    Motion::new(s, m.frame_time(), m.frame_count(), m.values().to_vec()).unwrap()
}

#[test]
fn real_rigs_with_meaningless_names_are_found_by_their_shape() {
    let Some(data) = shared_data() else { return };
    // (file, parts where the shape and the names' tables choose different
    // joints, each for a reason).
    let cases: [(&str, &[BodyPart]); 8] = [
        ("other-rigs/xia/neutral_01_000.bvh", &[]),
        ("other-rigs/cmu-daz/07/07_01.bvh", &[]),
        ("other-rigs/cmu-max/131_01.bvh", &[]),
        // ASF's `lowerneck` sits at the thorax; the shape takes the first
        // joint away from the chest, `upperneck`. This conversion puts
        // `lhand` at the wrist; the shape takes `lfingers`, beyond it.
        ("other-rigs/cmu-asf/16_01.bvh", &[Neck, LeftHand, RightHand]),
        ("other-rigs/animated-drawings/cmu1/jumping_jacks.bvh", &[]),
        // The CMU table's chest is `Spine2`; FAIR's clavicles hang from
        // `Spine3`, which the shape takes.
        ("other-rigs/animated-drawings/fair1/dab.bvh", &[Chest]),
        ("parser-cases/bvhpython_test_freebvh.bvh", &[]),
        ("parser-cases/bvhanim_test_mocapbank.bvh", &[]),
    ];
    for (file, differ) in cases {
        let m = read_bvh(&data.join(file)).unwrap();
        let by_name = BodyMap::detect(m.skeleton()).unwrap();
        let scrambled = renamed(&m);
        let map = BodyMap::detect(scrambled.skeleton()).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(map.rig(), UNNAMED_RIG, "{file}");
        assert_eq!(
            map.found_by(),
            FoundBy::Shape(SideEvidence::RestPose),
            "{file}"
        );
        for part in BodyPart::ALL {
            if differ.contains(&part) {
                assert_ne!(map.joint(part), by_name.joint(part), "{file}: {part}");
            } else {
                assert_eq!(
                    map.joint(part),
                    by_name.joint(part),
                    "{file}: {part} is {} by shape, {} by name",
                    joint_name(m.skeleton(), &map, part),
                    joint_name(m.skeleton(), &by_name, part)
                );
            }
        }
        check_on_motion(&scrambled, &map, file);
    }
}

#[test]
fn bandai_s_rest_pose_cannot_tell_left_from_right_but_side_marked_names_can() {
    let walk = read_bvh(&mocap_testdata::sample_walk()).unwrap();
    let bandai = BodyMap::detect(walk.skeleton()).unwrap();

    // Every bone of Bandai's rest pose lies along x: with no names, the
    // shape is found but not which side is which, and nothing is guessed.
    let scrambled = renamed(&walk);
    let err = BodyMap::detect(scrambled.skeleton()).unwrap_err();
    let Error::Invalid(message) = &err else {
        panic!("{err:?}")
    };
    for expected in [
        "left and right cannot be told",
        "--rig FILE",
        "CHECK: left and right are a guess",
        "pelvis = \"joint_1\"",
        "head = \"joint_5\"",
    ] {
        assert!(message.contains(expected), "{expected}: {message}");
    }
    // The template, with the sides swapped where the guess is wrong, is a
    // rig file that gives Bandai's own map.
    let template = message.split_once("\n\n").unwrap().1;
    assert_eq!(template, BodyMap::rig_file_template(scrambled.skeleton()));
    let from_template = BodyMap::from_toml_str(template, scrambled.skeleton()).unwrap();
    for part in [Pelvis, Spine, Chest, Neck, Head] {
        assert_eq!(from_template.joint(part), bandai.joint(part), "{part}");
    }
    for part in [LeftHip, LeftShoulder, RightKnee, RightWrist] {
        let found = from_template.joint(part);
        assert!(
            found == bandai.joint(part) || found == bandai.joint(part.mirror()),
            "{part}"
        );
    }

    // Names the tables do not know, with side markers: the shape finds
    // the parts, the markers tell the sides.
    let joints: Vec<Joint> = walk
        .skeleton()
        .joints()
        .iter()
        .map(|j| {
            let (_, german) = mocap_testdata::RENAMED_BANDAI_JOINTS
                .iter()
                .find(|(b, _)| *b == j.name)
                .unwrap();
            let name = german.replace("_li", "_L").replace("_re", "_R");
            Joint { name, ..j.clone() }
        })
        .collect();
    let s = Skeleton::new(joints).unwrap();
    let map = BodyMap::detect(&s).unwrap();
    assert_eq!(map.found_by(), FoundBy::Shape(SideEvidence::Names));
    assert_eq!(
        map.parts().collect::<Vec<_>>(),
        bandai.parts().collect::<Vec<_>>()
    );
}

#[test]
fn a_skeleton_that_is_no_body_is_refused_with_a_template() {
    let mut joints = vec![Joint::new("Base", None, Vec3::ZERO)];
    for (k, name) in ["A", "B", "C"].into_iter().enumerate() {
        joints.push(Joint::new(name, Some(k), Vec3::Y));
    }
    let s = Skeleton::new(joints).unwrap();
    let err = BodyMap::detect(&s).unwrap_err().to_string();
    for expected in [
        "no joint found for pelvis, head, left shoulder",
        "no joint where two legs and a spine branch off",
        "mocap --rig FILE",
        "# left_hip = \"\"",
        "TODO, required: femur head",
    ] {
        assert!(err.contains(expected), "{expected}: {err}");
    }
}

/// The joint that moves the body: Bandai's hips (its root stays at the
/// floor), a CMU take's root above the pelvis where the pelvis cannot move.
#[test]
fn the_position_carrier_is_the_pelvis_or_the_nearest_joint_above_it_that_moves() {
    let walk = read_bvh(&mocap_testdata::sample_walk()).unwrap();
    let skeleton = walk.skeleton();
    let map = BodyMap::detect(skeleton).unwrap();
    let carrier = map
        .position_carrier(skeleton)
        .expect("Bandai moves its hips");
    assert_eq!(skeleton.joint(carrier).name, "Hips");
    assert_eq!(Some(carrier), map.joint(Pelvis));

    // The same rig with the hips' position channels taken away: the root.
    let mut joints = skeleton.joints().to_vec();
    joints[carrier].channels.retain(|c| c.is_rotation());
    let still = Skeleton::new(joints).unwrap();
    let map = BodyMap::detect(&still).unwrap();
    assert_eq!(map.position_carrier(&still), Some(0));
}
