//! Body parts by joint name: the naming conventions' tables, the index of
//! a skeleton's joint names (namespace and rig-wide prefixes, case), and the
//! left/right side markers of names.

use std::collections::HashMap;

use super::{BodyMap, BodyPart, FoundBy, Side};
use crate::skeleton::Skeleton;

/// A built-in rig: the joint names each part may have, most likely first.
/// Left-side names only; right-side names are derived by [`swap_side`].
struct Rig {
    name: &'static str,
    /// Candidate names of the midline and left parts.
    parts: &'static [(BodyPart, &'static [&'static str])],
}

const BANDAI: Rig = Rig {
    name: "Bandai Namco",
    parts: &[
        (BodyPart::Pelvis, &["Hips"]),
        (BodyPart::Spine, &["Spine"]),
        (BodyPart::Chest, &["Chest"]),
        (BodyPart::Neck, &["Neck"]),
        (BodyPart::Head, &["Head"]),
        // `Shoulder_L` is the clavicle; the upper arm starts at `UpperArm_L`.
        (BodyPart::LeftClavicle, &["Shoulder_L"]),
        (BodyPart::LeftShoulder, &["UpperArm_L"]),
        (BodyPart::LeftElbow, &["LowerArm_L"]),
        (BodyPart::LeftWrist, &["Hand_L"]),
        (BodyPart::LeftHip, &["UpperLeg_L"]),
        (BodyPart::LeftKnee, &["LowerLeg_L"]),
        (BodyPart::LeftAnkle, &["Foot_L"]),
        (BodyPart::LeftToe, &["Toes_L"]),
    ],
};

const CMU_BVH: Rig = Rig {
    name: "CMU-style BVH",
    parts: &[
        (BodyPart::Pelvis, &["Hips"]),
        (BodyPart::Spine, &["Spine"]),
        // Mixamo and LAFAN hang the clavicles from Spine2, CMU from Spine1.
        (BodyPart::Chest, &["Spine2", "Spine1"]),
        // CMU's `Neck` has a zero offset from Spine1 (it sits at the chest);
        // `Neck1` is the base of the neck.
        (BodyPart::Neck, &["Neck1", "Neck"]),
        (BodyPart::Head, &["Head"]),
        (BodyPart::LeftClavicle, &["LeftShoulder"]),
        (BodyPart::LeftShoulder, &["LeftArm"]),
        (BodyPart::LeftElbow, &["LeftForeArm"]),
        (BodyPart::LeftWrist, &["LeftHand"]),
        // CMU's `LeftFingerBase` has a zero offset from the wrist; FAIR's
        // rig (AnimatedDrawings) ends the hand in `LeftHandEnd`.
        (
            BodyPart::LeftHand,
            &[
                "LeftHandMiddle1",
                "LeftHandIndex1",
                "LeftFingerBase",
                "LeftHandEnd",
            ],
        ),
        (BodyPart::LeftHip, &["LeftUpLeg"]),
        (BodyPart::LeftKnee, &["LeftLeg"]),
        (BodyPart::LeftAnkle, &["LeftFoot"]),
        (BodyPart::LeftToe, &["LeftToeBase", "LeftToe"]),
    ],
};

const ASF: Rig = Rig {
    name: "CMU/HDM05 ASF",
    parts: &[
        // `hip` in CMU's mechanical ASF-to-BVH conversions.
        (BodyPart::Pelvis, &["root", "hip"]),
        (BodyPart::Spine, &["upperback"]),
        (BodyPart::Chest, &["thorax"]),
        (BodyPart::Neck, &["lowerneck"]),
        (BodyPart::Head, &["head"]),
        (BodyPart::LeftClavicle, &["lclavicle"]),
        (BodyPart::LeftShoulder, &["lhumerus"]),
        (BodyPart::LeftElbow, &["lradius"]),
        (BodyPart::LeftWrist, &["lwrist"]),
        (BodyPart::LeftHand, &["lhand"]),
        (BodyPart::LeftHip, &["lfemur"]),
        (BodyPart::LeftKnee, &["ltibia"]),
        (BodyPart::LeftAnkle, &["lfoot"]),
        (BodyPart::LeftToe, &["ltoes"]),
    ],
};

const KINECT: Rig = Rig {
    name: "Kinect v2",
    parts: &[
        (BodyPart::Pelvis, &["SpineBase"]),
        (BodyPart::Spine, &["SpineMid"]),
        (BodyPart::Chest, &["SpineShoulder"]),
        (BodyPart::Neck, &["Neck"]),
        (BodyPart::Head, &["Head"]),
        (BodyPart::LeftShoulder, &["ShoulderLeft"]),
        (BodyPart::LeftElbow, &["ElbowLeft"]),
        (BodyPart::LeftWrist, &["WristLeft"]),
        (BodyPart::LeftHand, &["HandLeft"]),
        (BodyPart::LeftHip, &["HipLeft"]),
        (BodyPart::LeftKnee, &["KneeLeft"]),
        (BodyPart::LeftAnkle, &["AnkleLeft"]),
        (BodyPart::LeftToe, &["FootLeft"]),
    ],
};

/// Biovision's own sample files and early MotionBuilder exports
/// (`LeftCollar` is the clavicle, `LeftShoulder` the shoulder point).
const BIOVISION: Rig = Rig {
    name: "Biovision BVH",
    parts: &[
        (BodyPart::Pelvis, &["Hips"]),
        (BodyPart::Spine, &["Chest"]),
        (BodyPart::Chest, &["Chest2", "Chest"]),
        (BodyPart::Neck, &["Neck"]),
        (BodyPart::Head, &["Head"]),
        (BodyPart::LeftClavicle, &["LeftCollar"]),
        (BodyPart::LeftShoulder, &["LeftShoulder"]),
        (BodyPart::LeftElbow, &["LeftElbow"]),
        (BodyPart::LeftWrist, &["LeftWrist"]),
        (BodyPart::LeftHip, &["LeftHip"]),
        (BodyPart::LeftKnee, &["LeftKnee"]),
        (BodyPart::LeftAnkle, &["LeftAnkle"]),
        (BodyPart::LeftToe, &["LeftToe"]),
    ],
};

/// CMU's conversions for 3ds Max (cgspeed's `cmuconvert-max`): Biovision's
/// names for the body, ASF's for the hands (`lhand` sits at the wrist,
/// `LFingers` is the hand point beyond it).
const CMU_MAX: Rig = Rig {
    name: "CMU (3ds Max names)",
    parts: &[
        (BodyPart::Pelvis, &["Hips"]),
        (BodyPart::Spine, &["Chest"]),
        (BodyPart::Chest, &["Chest2"]),
        (BodyPart::Neck, &["Neck"]),
        (BodyPart::Head, &["Head"]),
        (BodyPart::LeftClavicle, &["LeftCollar"]),
        (BodyPart::LeftShoulder, &["LeftShoulder"]),
        (BodyPart::LeftElbow, &["LeftElbow"]),
        (BodyPart::LeftWrist, &["LeftWrist"]),
        (BodyPart::LeftHand, &["LFingers"]),
        (BodyPart::LeftHip, &["LeftHip"]),
        (BodyPart::LeftKnee, &["LeftKnee"]),
        (BodyPart::LeftAnkle, &["LeftAnkle"]),
        (BodyPart::LeftToe, &["LeftToe"]),
    ],
};

/// Daz Studio and Poser figures, and the CMU conversions for them (Genesis
/// 3 and 8 split some bones: `abdomenLower`, `lShldrBend`, `lThighBend`).
/// `lButtock` (CMU's Daz conversions) is a helper above the hip, no part.
const DAZ_POSER: Rig = Rig {
    name: "Daz/Poser",
    parts: &[
        (BodyPart::Pelvis, &["hip"]),
        (BodyPart::Spine, &["abdomen", "abdomenLower"]),
        (BodyPart::Chest, &["chest", "chestUpper"]),
        (BodyPart::Neck, &["neck", "neckLower"]),
        (BodyPart::Head, &["head"]),
        (BodyPart::LeftClavicle, &["lCollar"]),
        (BodyPart::LeftShoulder, &["lShldr", "lShldrBend"]),
        (BodyPart::LeftElbow, &["lForeArm", "lForearmBend"]),
        (BodyPart::LeftWrist, &["lHand"]),
        (BodyPart::LeftHand, &["lMid1", "lIndex1"]),
        (BodyPart::LeftHip, &["lThigh", "lThighBend"]),
        (BodyPart::LeftKnee, &["lShin"]),
        (BodyPart::LeftAnkle, &["lFoot"]),
        (BodyPart::LeftToe, &["lToe"]),
    ],
};

/// 3ds Max Biped, names without their rig-wide prefix (`Bip01 L Thigh`,
/// `Bip001 L Thigh`). Biped hangs the clavicles from `Neck`; the chest is
/// the top spine link.
const BIPED: Rig = Rig {
    name: "3ds Max Biped",
    parts: &[
        (BodyPart::Pelvis, &["Pelvis"]),
        (BodyPart::Spine, &["Spine"]),
        (BodyPart::Chest, &["Spine3", "Spine2", "Spine1"]),
        (BodyPart::Neck, &["Neck"]),
        (BodyPart::Head, &["Head"]),
        (BodyPart::LeftClavicle, &["L Clavicle"]),
        (BodyPart::LeftShoulder, &["L UpperArm"]),
        (BodyPart::LeftElbow, &["L Forearm"]),
        (BodyPart::LeftWrist, &["L Hand"]),
        (BodyPart::LeftHand, &["L Finger2", "L Finger1"]),
        (BodyPart::LeftHip, &["L Thigh"]),
        (BodyPart::LeftKnee, &["L Calf"]),
        (BodyPart::LeftAnkle, &["L Foot"]),
        (BodyPart::LeftToe, &["L Toe0"]),
    ],
};

/// The Unreal Engine mannequin (UE4: `spine_01..03`; UE5: `spine_01..05`,
/// `neck_01..02`).
const UNREAL: Rig = Rig {
    name: "Unreal mannequin",
    parts: &[
        (BodyPart::Pelvis, &["pelvis"]),
        (BodyPart::Spine, &["spine_01"]),
        (BodyPart::Chest, &["spine_05", "spine_03"]),
        (BodyPart::Neck, &["neck_01"]),
        (BodyPart::Head, &["head"]),
        (BodyPart::LeftClavicle, &["clavicle_l"]),
        (BodyPart::LeftShoulder, &["upperarm_l"]),
        (BodyPart::LeftElbow, &["lowerarm_l"]),
        (BodyPart::LeftWrist, &["hand_l"]),
        (BodyPart::LeftHand, &["middle_01_l", "index_01_l"]),
        (BodyPart::LeftHip, &["thigh_l"]),
        (BodyPart::LeftKnee, &["calf_l"]),
        (BodyPart::LeftAnkle, &["foot_l"]),
        (BodyPart::LeftToe, &["ball_l"]),
    ],
};

/// SMPL, SMPL-H and SMPL-X (`left_hip`, and the `L_Hip` spelling of many
/// conversions). SMPL's `left_shoulder` is the shoulder point (the clavicle
/// is `left_collar`) and `left_foot` the ball of the foot.
const SMPL: Rig = Rig {
    name: "SMPL",
    parts: &[
        (BodyPart::Pelvis, &["pelvis"]),
        (BodyPart::Spine, &["spine1"]),
        (BodyPart::Chest, &["spine3"]),
        (BodyPart::Neck, &["neck"]),
        (BodyPart::Head, &["head"]),
        (BodyPart::LeftClavicle, &["left_collar", "L_Collar"]),
        (BodyPart::LeftShoulder, &["left_shoulder", "L_Shoulder"]),
        (BodyPart::LeftElbow, &["left_elbow", "L_Elbow"]),
        (BodyPart::LeftWrist, &["left_wrist", "L_Wrist"]),
        (BodyPart::LeftHand, &["left_hand", "L_Hand"]),
        (BodyPart::LeftHip, &["left_hip", "L_Hip"]),
        (BodyPart::LeftKnee, &["left_knee", "L_Knee"]),
        (BodyPart::LeftAnkle, &["left_ankle", "L_Ankle"]),
        (BodyPart::LeftToe, &["left_foot", "L_Foot"]),
    ],
};

/// Rokoko Studio's Newton skeleton (`LeftThigh`, `LeftShin`, `Spine1..4`,
/// the clavicles hanging from `Spine4`).
const ROKOKO: Rig = Rig {
    name: "Rokoko",
    parts: &[
        (BodyPart::Pelvis, &["Hips"]),
        (BodyPart::Spine, &["Spine1"]),
        (BodyPart::Chest, &["Spine4", "Spine3"]),
        (BodyPart::Neck, &["Neck"]),
        (BodyPart::Head, &["Head"]),
        (BodyPart::LeftClavicle, &["LeftShoulder"]),
        (BodyPart::LeftShoulder, &["LeftArm"]),
        (BodyPart::LeftElbow, &["LeftForeArm"]),
        (BodyPart::LeftWrist, &["LeftHand"]),
        (BodyPart::LeftHip, &["LeftThigh"]),
        (BodyPart::LeftKnee, &["LeftShin"]),
        (BodyPart::LeftAnkle, &["LeftFoot"]),
        (BodyPart::LeftToe, &["LeftToe"]),
    ],
};

/// The naming conventions, tried in this order by [`BodyMap::detect`]; on a
/// tie the first wins. MotionBuilder/HumanIK and Unity/Mixamo share the
/// CMU-style names (`Hips`, `LeftUpLeg`, `LeftArm`...), told apart by
/// their prefix ([`display_name`]).
const RIGS: [&Rig; 11] = [
    &BANDAI, &CMU_BVH, &ASF, &KINECT, &BIOVISION, &CMU_MAX, &DAZ_POSER, &BIPED, &UNREAL, &SMPL,
    &ROKOKO,
];

/// The name a map found with `rig` reports: CMU-style names behind a
/// `prefix:` namespace are Mixamo's, behind a rig-wide `Character1_` style
/// prefix MotionBuilder/HumanIK's.
fn display_name(rig: &Rig, names: &NameIndex) -> &'static str {
    if rig.name != CMU_BVH.name {
        rig.name
    } else if names.namespaced {
        "Mixamo"
    } else if names.prefixed {
        "MotionBuilder/HumanIK"
    } else {
        rig.name
    }
}

/// Adds `(left, right)` unless one of the joints is already paired.
pub(super) fn add_pair(pairs: &mut Vec<(usize, usize)>, left: usize, right: usize) {
    let taken = |j: usize| pairs.iter().any(|&(l, r)| l == j || r == j);
    if left != right && !taken(left) && !taken(right) {
        pairs.push((left, right));
    }
}

/// The `(left, right)` joint pairs whose names differ only by a side marker
/// ([`swap_side`]), sorted by the left joint.
pub(super) fn name_pattern_pairs(skeleton: &Skeleton) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    for (left, joint) in skeleton.joints().iter().enumerate() {
        let (prefix, name) = split_namespace(&joint.name);
        for right_name in swap_side(name) {
            if let Some(right) = skeleton.find(&format!("{prefix}{right_name}")) {
                add_pair(&mut pairs, left, right);
                break;
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

/// Right-side names of a left-side joint name, one per side-marker pattern
/// that matches (empty when the name carries no left marker).
pub(super) fn swap_side(name: &str) -> Vec<String> {
    let mut out = Vec::new();
    // `LeftArm`, `left_hip`; Biped's `Bip01 L Thigh`.
    for (left, right) in [
        ("Left", "Right"),
        ("left", "right"),
        ("LEFT", "RIGHT"),
        (" L ", " R "),
    ] {
        if name.contains(left) {
            out.push(name.replace(left, right));
        }
    }
    for (left, right) in [
        ("_L", "_R"),
        ("_l", "_r"),
        (".L", ".R"),
        (".l", ".r"),
        ("-L", "-R"),
        (" L", " R"),
    ] {
        if let Some(stem) = name.strip_suffix(left) {
            out.push(format!("{stem}{right}"));
        }
    }
    for (left, right) in [("L_", "R_"), ("l_", "r_"), ("L ", "R ")] {
        if let Some(rest) = name.strip_prefix(left) {
            out.push(format!("{right}{rest}"));
        }
    }
    let mut chars = name.chars();
    if let (Some(first), Some(second)) = (chars.next(), chars.next()) {
        let rest = &name[1..];
        // CMU BVH `LHipJoint`, `LThumb`; ASF `lfemur`, `lhumerus`; Daz
        // `lThigh`, `lShldr`.
        if first == 'L' && second.is_ascii_uppercase() {
            out.push(format!("R{rest}"));
        }
        if first == 'l' && second.is_ascii_alphabetic() {
            out.push(format!("r{rest}"));
        }
    }
    out
}

/// Splits `mixamorig:LeftArm` into `("mixamorig:", "LeftArm")`.
fn split_namespace(name: &str) -> (&str, &str) {
    match name.rfind(':') {
        Some(k) => name.split_at(k + 1),
        None => ("", name),
    }
}

/// The prefix every joint name of a rig starts with, up to a space or an
/// underscore (`Bip01 ` in `Bip01 L Thigh`, `Character1_` in
/// `Character1_LeftUpLeg`), if there is one; a joint named by the prefix
/// alone (Biped's root `Bip01`) does not break it. Names are taken without
/// their namespace.
fn rig_prefix<'a>(names: &[&'a str]) -> Option<&'a str> {
    let sample = names.get(1).or(names.first())?;
    sample
        .char_indices()
        .rev()
        .filter(|&(_, c)| c == ' ' || c == '_')
        .map(|(k, _)| &sample[..=k])
        .find(|prefix| {
            let bare = &prefix[..prefix.len() - 1];
            names
                .iter()
                .all(|n| (n.starts_with(prefix) && n.len() > prefix.len()) || *n == bare)
        })
}

/// The joint named `name` exactly, else the one whose name matches without
/// namespace or rig-wide prefix and case.
pub(super) fn find_joint(skeleton: &Skeleton, name: &str) -> Option<usize> {
    skeleton
        .find(name)
        .or_else(|| NameIndex::new(skeleton).get(name))
}

/// Joint indices by lowercase name, without namespace prefix, and also
/// without the rig-wide prefix ([`rig_prefix`]) when there is one.
pub(super) struct NameIndex {
    by_name: HashMap<String, usize>,
    /// Some joint names have a `namespace:` prefix (Mixamo).
    namespaced: bool,
    /// The joint names share a rig-wide prefix.
    prefixed: bool,
}

impl NameIndex {
    pub(super) fn new(skeleton: &Skeleton) -> NameIndex {
        let mut by_name = HashMap::new();
        let mut namespaced = false;
        let mut bare = Vec::with_capacity(skeleton.joint_count());
        for (i, joint) in skeleton.joints().iter().enumerate() {
            let (namespace, name) = split_namespace(&joint.name);
            namespaced |= !namespace.is_empty();
            by_name.entry(name.to_ascii_lowercase()).or_insert(i);
            bare.push(name);
        }
        // Full names first: a name without the prefix never hides one.
        let prefix = rig_prefix(&bare);
        if let Some(prefix) = prefix {
            for (i, name) in bare.iter().enumerate() {
                if let Some(rest) = name.strip_prefix(prefix) {
                    by_name.entry(rest.to_ascii_lowercase()).or_insert(i);
                }
            }
        }
        NameIndex {
            by_name,
            namespaced,
            prefixed: prefix.is_some(),
        }
    }

    pub(super) fn get(&self, name: &str) -> Option<usize> {
        let (_, name) = split_namespace(name);
        self.by_name.get(&name.to_ascii_lowercase()).copied()
    }
}

/// The names of a naming convention and what it finds on one skeleton.
pub(super) struct NameMatch {
    rig: &'static Rig,
    /// The map of the parts found (some required ones may be missing).
    pub(super) map: BodyMap,
}

impl NameMatch {
    /// Candidate names of `part` in the convention.
    pub(super) fn candidates(&self, part: BodyPart) -> Vec<String> {
        rig_candidates(self.rig, part)
    }

    /// The convention's name, as [`BodyMap::rig`] reports it.
    pub(super) fn rig_name(&self) -> &'static str {
        self.rig.name
    }
}

/// Candidate names of `part` in `rig` (right-side names derived from the
/// left-side ones).
fn rig_candidates(rig: &Rig, part: BodyPart) -> Vec<String> {
    let right = part.side() == Some(Side::Right);
    let left = if right { part.mirror() } else { part };
    let Some((_, names)) = rig.parts.iter().find(|(p, _)| *p == left) else {
        return Vec::new();
    };
    names
        .iter()
        .map(|&n| {
            if right {
                swap_side(n)
                    .into_iter()
                    .next()
                    .unwrap_or_else(|| n.to_string())
            } else {
                n.to_string()
            }
        })
        .collect()
}

/// Locates every part with each naming convention; returns the one that
/// locates the most required parts (then the most parts).
pub(super) fn best_rig(names: &NameIndex) -> NameMatch {
    let mut best: Option<(NameMatch, (usize, usize))> = None;
    for rig in RIGS {
        let mut joints = [None; BodyPart::COUNT];
        for part in BodyPart::ALL {
            joints[part.index()] = rig_candidates(rig, part).iter().find_map(|n| names.get(n));
        }
        let found = |required_only: bool| {
            BodyPart::ALL
                .iter()
                .filter(|p| joints[p.index()].is_some() && (!required_only || p.is_required()))
                .count()
        };
        let score = (found(true), found(false));
        let map = BodyMap {
            rig: display_name(rig, names).to_string(),
            joints,
            found_by: FoundBy::Names,
            extra_pairs: Vec::new(),
        };
        if best.as_ref().is_none_or(|(_, s)| score > *s) {
            best = Some((NameMatch { rig, map }, score));
        }
    }
    best.expect("there are built-in rigs").0
}
