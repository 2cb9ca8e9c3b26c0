//! Semantic body parts located by joint name, left/right mirror pairs, and the
//! Kinect v2 joint layout.
//!
//! Every rig names its joints differently, and the same anatomical point can
//! carry different names (Bandai's `Shoulder_L` is the *clavicle*, while CMU's
//! `LeftShoulder` is the clavicle too and the shoulder point is `LeftArm`). A
//! [`BodyMap`] says, for a given [`Skeleton`], which joint sits at each
//! [`BodyPart`]. A part is always defined by the **position** of the joint:
//! the joint whose FK position is at that anatomical point.
//!
//! | part | anatomical point | Bandai | CMU-style BVH / Mixamo | CMU/HDM05 ASF | Kinect v2 |
//! | --- | --- | --- | --- | --- | --- |
//! | pelvis | root of the spine, between the hip joints | `Hips` | `Hips` | `root` | `SpineBase` |
//! | spine | lower/middle (lumbar) spine | `Spine` | `Spine` | `upperback` | `SpineMid` |
//! | chest | upper (thoracic) spine joint the shoulder girdle hangs from | `Chest` | `Spine2`, `Spine1` | `thorax` | `SpineShoulder` |
//! | neck | base of the neck | `Neck` | `Neck1`, `Neck` | `lowerneck` | `Neck` |
//! | head | head joint (top of the neck) | `Head` | `Head` | `head` | `Head` |
//! | clavicle | inner end of the collarbone, where the shoulder girdle starts | `Shoulder_L` | `LeftShoulder` | `lclavicle` | - |
//! | shoulder | glenohumeral joint, where the upper arm starts (not the clavicle) | `UpperArm_L` | `LeftArm` | `lhumerus` | `ShoulderLeft` |
//! | elbow | elbow | `LowerArm_L` | `LeftForeArm` | `lradius` | `ElbowLeft` |
//! | wrist | wrist, where the hand starts | `Hand_L` | `LeftHand` | `lwrist` | `WristLeft` |
//! | hand | a point in the hand beyond the wrist (palm or knuckles) | - | `LeftHandMiddle1`, `LeftHandIndex1` | `lhand` | `HandLeft` |
//! | hip | femur head, where the thigh starts | `UpperLeg_L` | `LeftUpLeg` | `lfemur` | `HipLeft` |
//! | knee | knee | `LowerLeg_L` | `LeftLeg` | `ltibia` | `KneeLeft` |
//! | ankle | ankle | `Foot_L` | `LeftFoot` | `lfoot` | `AnkleLeft` |
//! | toe | ball of the foot (toe joint) | `Toes_L` | `LeftToeBase` | `ltoes` | `FootLeft` |
//!
//! Biovision's own sample rig is known too (`Hips`, `Chest`, `Chest2`,
//! `LeftCollar` = clavicle, `LeftShoulder` = shoulder point, `LeftElbow`,
//! `LeftWrist`, `LeftHip`, `LeftKnee`, `LeftAnkle`).
//!
//! (ASF joints sit where their bone starts, so `lhumerus` is the shoulder
//! point and `lradius` the elbow.) In CMU-style BVH files the `Neck` joint has
//! a zero offset from `Spine1`, so it sits at the chest; `Neck1` is the base
//! of the neck and is preferred. Mixamo names carry a namespace prefix
//! (`mixamorig:LeftArm`): any prefix ending in `:` is ignored, and names are
//! compared without regard to case.
//!
//! A rig the built-in tables do not know is described in a small TOML file
//! (see [`BodyMap::from_toml_str`]):
//!
//! ```toml
//! name = "studio rig"          # optional, used in messages
//! [parts]                      # part = "joint name"; parts left out are
//! pelvis = "Hips"              # taken from the closest built-in rig
//! left_shoulder = "L_UpperArm"
//! right_shoulder = "R_UpperArm"
//! [mirror]                     # optional extra left/right joint pairs
//! pairs = [["L_Finger1", "R_Finger1"]]
//! ```
//!
//! Such a file is read for one skeleton with [`BodyMap::from_toml_file`], or
//! given to the whole process with [`register_rig_file`] (what `mocap --rig
//! FILE` does), so that every [`BodyMap::detect`] (search features, style
//! transfer, retargeting, mirroring...) uses it for the skeletons that have
//! the joints it names.

use std::collections::{BTreeMap, HashMap};
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::RwLock;

use crate::error::{Error, ParseError, Result};
use crate::skeleton::Skeleton;

/// Left or right side of the body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Side {
    Left,
    Right,
}

/// An anatomical point of the body, located on a rig by a [`BodyMap`]. See
/// the module documentation for the exact point each part stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BodyPart {
    Pelvis,
    Spine,
    Chest,
    Neck,
    Head,
    LeftClavicle,
    LeftShoulder,
    LeftElbow,
    LeftWrist,
    LeftHand,
    LeftHip,
    LeftKnee,
    LeftAnkle,
    LeftToe,
    RightClavicle,
    RightShoulder,
    RightElbow,
    RightWrist,
    RightHand,
    RightHip,
    RightKnee,
    RightAnkle,
    RightToe,
}

impl BodyPart {
    /// Every part, in declaration order.
    pub const ALL: [BodyPart; 23] = [
        BodyPart::Pelvis,
        BodyPart::Spine,
        BodyPart::Chest,
        BodyPart::Neck,
        BodyPart::Head,
        BodyPart::LeftClavicle,
        BodyPart::LeftShoulder,
        BodyPart::LeftElbow,
        BodyPart::LeftWrist,
        BodyPart::LeftHand,
        BodyPart::LeftHip,
        BodyPart::LeftKnee,
        BodyPart::LeftAnkle,
        BodyPart::LeftToe,
        BodyPart::RightClavicle,
        BodyPart::RightShoulder,
        BodyPart::RightElbow,
        BodyPart::RightWrist,
        BodyPart::RightHand,
        BodyPart::RightHip,
        BodyPart::RightKnee,
        BodyPart::RightAnkle,
        BodyPart::RightToe,
    ];

    /// Number of parts.
    pub const COUNT: usize = 23;

    /// Parts every built-in rig has; [`BodyMap::detect`] fails without them.
    /// The others (spine, chest, neck, clavicles, hands, toes) are missing
    /// from some real rigs (Bandai has no joint beyond the wrist, Kinect no
    /// chest and no clavicles).
    pub fn is_required(self) -> bool {
        !matches!(
            self,
            BodyPart::Spine
                | BodyPart::Chest
                | BodyPart::Neck
                | BodyPart::LeftClavicle
                | BodyPart::RightClavicle
                | BodyPart::LeftHand
                | BodyPart::RightHand
                | BodyPart::LeftToe
                | BodyPart::RightToe
        )
    }

    /// Index of the part in [`BodyPart::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The key of the part in rig files: `pelvis`, `left_shoulder`...
    pub fn key(self) -> &'static str {
        match self {
            BodyPart::Pelvis => "pelvis",
            BodyPart::Spine => "spine",
            BodyPart::Chest => "chest",
            BodyPart::Neck => "neck",
            BodyPart::Head => "head",
            BodyPart::LeftClavicle => "left_clavicle",
            BodyPart::LeftShoulder => "left_shoulder",
            BodyPart::LeftElbow => "left_elbow",
            BodyPart::LeftWrist => "left_wrist",
            BodyPart::LeftHand => "left_hand",
            BodyPart::LeftHip => "left_hip",
            BodyPart::LeftKnee => "left_knee",
            BodyPart::LeftAnkle => "left_ankle",
            BodyPart::LeftToe => "left_toe",
            BodyPart::RightClavicle => "right_clavicle",
            BodyPart::RightShoulder => "right_shoulder",
            BodyPart::RightElbow => "right_elbow",
            BodyPart::RightWrist => "right_wrist",
            BodyPart::RightHand => "right_hand",
            BodyPart::RightHip => "right_hip",
            BodyPart::RightKnee => "right_knee",
            BodyPart::RightAnkle => "right_ankle",
            BodyPart::RightToe => "right_toe",
        }
    }

    /// The part of a rig-file key (`left_shoulder`), if there is one.
    pub fn from_key(key: &str) -> Option<BodyPart> {
        BodyPart::ALL.into_iter().find(|p| p.key() == key)
    }

    /// Side of the body, `None` for the parts on the midline.
    pub fn side(self) -> Option<Side> {
        match self.index() {
            0..=4 => None,
            5..=13 => Some(Side::Left),
            _ => Some(Side::Right),
        }
    }

    /// The same part on the other side; a midline part is its own mirror.
    pub fn mirror(self) -> BodyPart {
        match self.side() {
            None => self,
            Some(Side::Left) => BodyPart::ALL[self.index() + 9],
            Some(Side::Right) => BodyPart::ALL[self.index() - 9],
        }
    }
}

impl fmt::Display for BodyPart {
    /// Writes the part in words: `left shoulder`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.key().replace('_', " "))
    }
}

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
        // CMU's `LeftFingerBase` has a zero offset from the wrist.
        (
            BodyPart::LeftHand,
            &["LeftHandMiddle1", "LeftHandIndex1", "LeftFingerBase"],
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
        (BodyPart::Pelvis, &["root"]),
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

/// The built-in rigs, tried in this order by [`BodyMap::detect`].
const RIGS: [&Rig; 5] = [&BANDAI, &CMU_BVH, &ASF, &KINECT, &BIOVISION];

/// The Kinect v2 skeleton in `JointType` order: each joint's name and the
/// index of its parent, per the SDK's bone list. Kinect order is not
/// parent-before-child: `SpineShoulder` (20) is the parent of `Neck` (2) and
/// of both shoulders.
pub const KINECT_V2_JOINTS: [(&str, Option<usize>); 25] = [
    ("SpineBase", None),
    ("SpineMid", Some(0)),
    ("Neck", Some(20)),
    ("Head", Some(2)),
    ("ShoulderLeft", Some(20)),
    ("ElbowLeft", Some(4)),
    ("WristLeft", Some(5)),
    ("HandLeft", Some(6)),
    ("ShoulderRight", Some(20)),
    ("ElbowRight", Some(8)),
    ("WristRight", Some(9)),
    ("HandRight", Some(10)),
    ("HipLeft", Some(0)),
    ("KneeLeft", Some(12)),
    ("AnkleLeft", Some(13)),
    ("FootLeft", Some(14)),
    ("HipRight", Some(0)),
    ("KneeRight", Some(16)),
    ("AnkleRight", Some(17)),
    ("FootRight", Some(18)),
    ("SpineShoulder", Some(1)),
    ("HandTipLeft", Some(7)),
    ("ThumbLeft", Some(6)),
    ("HandTipRight", Some(11)),
    ("ThumbRight", Some(10)),
];

/// The body part of each Kinect v2 joint, in `JointType` order (`None` for
/// the hand tips and thumbs, which no part stands for).
pub const KINECT_V2_BODY_PARTS: [Option<BodyPart>; 25] = [
    Some(BodyPart::Pelvis),
    Some(BodyPart::Spine),
    Some(BodyPart::Neck),
    Some(BodyPart::Head),
    Some(BodyPart::LeftShoulder),
    Some(BodyPart::LeftElbow),
    Some(BodyPart::LeftWrist),
    Some(BodyPart::LeftHand),
    Some(BodyPart::RightShoulder),
    Some(BodyPart::RightElbow),
    Some(BodyPart::RightWrist),
    Some(BodyPart::RightHand),
    Some(BodyPart::LeftHip),
    Some(BodyPart::LeftKnee),
    Some(BodyPart::LeftAnkle),
    Some(BodyPart::LeftToe),
    Some(BodyPart::RightHip),
    Some(BodyPart::RightKnee),
    Some(BodyPart::RightAnkle),
    Some(BodyPart::RightToe),
    Some(BodyPart::Chest),
    None,
    None,
    None,
    None,
];

/// The Kinect v2 joint index (`JointType`) of a body part, if Kinect has it.
pub fn kinect_v2_joint(part: BodyPart) -> Option<usize> {
    KINECT_V2_BODY_PARTS.iter().position(|&p| p == Some(part))
}

/// Which joint of a skeleton sits at each body part.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyMap {
    rig: String,
    joints: [Option<usize>; BodyPart::COUNT],
    /// Left/right joint pairs given in a rig file, beyond the name patterns.
    extra_pairs: Vec<(usize, usize)>,
}

impl BodyMap {
    /// Finds the body parts of `skeleton` with the built-in rigs (Bandai
    /// Namco, CMU-style BVH and Mixamo, CMU/HDM05 ASF, Kinect v2, Biovision)
    /// and keeps
    /// the one that locates the most parts. Fails, naming the missing parts
    /// and the names tried, when no rig locates every required part
    /// ([`BodyPart::is_required`]).
    ///
    /// Rig files given with [`register_rig_file`] come first: the first
    /// whose joints the skeleton all has is used (with its own errors, e.g.
    /// a required part still missing).
    pub fn detect(skeleton: &Skeleton) -> Result<BodyMap> {
        let registered = REGISTERED_RIGS.read().unwrap_or_else(|e| e.into_inner());
        if let Some(rig) = registered.iter().find(|rig| rig.fits(skeleton)) {
            return BodyMap::from_rig_file(&rig.file, &rig.path, skeleton);
        }
        // Rig files given that do not fit, and the joints each lacks: a
        // misspelt name in one would otherwise look like no file at all.
        let unfit: Vec<String> = registered
            .iter()
            .map(|rig| {
                let lacking: Vec<String> = rig
                    .file
                    .joint_names()
                    .filter(|n| find_joint(skeleton, n).is_none())
                    .map(|n| format!("{n:?}"))
                    .take(4)
                    .collect();
                format!(
                    "{} names {}, which this skeleton lacks",
                    rig.path.display(),
                    lacking.join(", ")
                )
            })
            .collect();
        drop(registered);
        let names = NameIndex::new(skeleton);
        let (rig, map) = best_rig(&names);
        let missing: Vec<BodyPart> = map
            .missing()
            .into_iter()
            .filter(|p| p.is_required())
            .collect();
        if missing.is_empty() {
            return Ok(map);
        }
        let tried: Vec<String> = missing
            .iter()
            .map(|&p| format!("{p} (tried {})", rig_candidates(rig, p).join(", ")))
            .collect();
        let given = if unfit.is_empty() {
            String::new()
        } else {
            format!("; a rig file given does not fit it: {}", unfit.join("; "))
        };
        Err(Error::Invalid(format!(
            "cannot find the body parts of this skeleton ({} joints: {}): the closest \
             built-in rig, {}, lacks {}; describe the rig in a TOML file \
             ([parts] {} = \"joint name\") and give it with `mocap --rig FILE` \
             (docs/rigs.md; in code: register_rig_file or BodyMap::from_toml_file){given}",
            skeleton.joint_count(),
            joint_list(skeleton),
            rig.name,
            tried.join("; "),
            missing[0].key(),
        )))
    }

    /// A map from explicit `(part, joint index)` pairs; parts not listed are
    /// missing. Fails when a joint index is outside the skeleton.
    pub fn from_joints(
        skeleton: &Skeleton,
        rig: impl Into<String>,
        parts: impl IntoIterator<Item = (BodyPart, usize)>,
    ) -> Result<BodyMap> {
        let mut joints = [None; BodyPart::COUNT];
        for (part, joint) in parts {
            if joint >= skeleton.joint_count() {
                return Err(Error::Invalid(format!(
                    "{part}: joint index {joint} is outside the skeleton ({} joints)",
                    skeleton.joint_count()
                )));
            }
            joints[part.index()] = Some(joint);
        }
        Ok(BodyMap {
            rig: rig.into(),
            joints,
            extra_pairs: Vec::new(),
        })
    }

    /// Reads a rig file (format in the module documentation) for `skeleton`.
    /// Parts the file lists override the closest built-in rig; parts it
    /// leaves out are taken from that rig. Fails on a TOML syntax error
    /// (with line and column), an unknown part key, a joint name the
    /// skeleton lacks, or a required part that is still missing.
    pub fn from_toml_str(text: &str, skeleton: &Skeleton) -> Result<BodyMap> {
        BodyMap::from_toml_at(text, Path::new("<rig file>"), skeleton)
    }

    /// [`BodyMap::from_toml_str`] on the contents of a file; errors name it.
    pub fn from_toml_file(path: impl AsRef<Path>, skeleton: &Skeleton) -> Result<BodyMap> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        BodyMap::from_toml_at(&text, path, skeleton)
    }

    fn from_toml_at(text: &str, path: &Path, skeleton: &Skeleton) -> Result<BodyMap> {
        BodyMap::from_rig_file(&RigFile::parse(text, path)?, path, skeleton)
    }

    fn from_rig_file(file: &RigFile, path: &Path, skeleton: &Skeleton) -> Result<BodyMap> {
        let where_ = path.display();
        let names = NameIndex::new(skeleton);
        let (_, mut map) = best_rig(&names);
        map.rig = file
            .name
            .clone()
            .unwrap_or_else(|| path.display().to_string());
        for (key, joint_name) in &file.parts {
            let part = BodyPart::from_key(key).expect("part keys are checked when parsed");
            let joint = find_joint(skeleton, joint_name).ok_or_else(|| {
                Error::Invalid(format!(
                    "{where_}: [parts] {key} = {joint_name:?}, but the skeleton has no such \
                     joint (joints: {})",
                    joint_list(skeleton)
                ))
            })?;
            map.joints[part.index()] = Some(joint);
        }
        if let Some(mirror) = &file.mirror {
            for [left, right] in &mirror.pairs {
                let find = |name: &String| {
                    find_joint(skeleton, name).ok_or_else(|| {
                        Error::Invalid(format!(
                            "{where_}: [mirror] pair [{left:?}, {right:?}]: the skeleton has \
                             no joint {name:?}"
                        ))
                    })
                };
                map.extra_pairs.push((find(left)?, find(right)?));
            }
        }
        let missing: Vec<String> = map
            .missing()
            .into_iter()
            .filter(|p| p.is_required())
            .map(|p| p.key().to_string())
            .collect();
        if !missing.is_empty() {
            return Err(Error::Invalid(format!(
                "{where_}: no joint for the required parts {}; add them under [parts]",
                missing.join(", ")
            )));
        }
        Ok(map)
    }

    /// Name of the rig the map came from (`Bandai Namco`, `Mixamo`...).
    pub fn rig(&self) -> &str {
        &self.rig
    }

    /// The joint at `part`, if the rig has one.
    pub fn joint(&self, part: BodyPart) -> Option<usize> {
        self.joints[part.index()]
    }

    /// The joint at `part`, or an error naming the part and the rig.
    pub fn require(&self, part: BodyPart) -> Result<usize> {
        self.joint(part).ok_or_else(|| {
            Error::Invalid(format!("the {} rig has no joint for the {part}", self.rig))
        })
    }

    /// Rest length of the legs, hip to knee to ankle, averaged over both
    /// legs ([`Skeleton::chain_length`], in file units): the scale of strides
    /// and root heights between performers and rigs.
    pub fn leg_length(&self, skeleton: &Skeleton) -> Result<f32> {
        let mut sum = 0.0;
        for (hip, ankle) in [
            (BodyPart::LeftHip, BodyPart::LeftAnkle),
            (BodyPart::RightHip, BodyPart::RightAnkle),
        ] {
            let (hip, ankle) = (self.require(hip)?, self.require(ankle)?);
            sum += skeleton.chain_length(ankle, hip).ok_or_else(|| {
                Error::Invalid(format!(
                    "the {} rig's ankle `{}` is not below its hip `{}`",
                    self.rig,
                    skeleton.joint(ankle).name,
                    skeleton.joint(hip).name
                ))
            })?;
        }
        Ok(sum / 2.0)
    }

    /// The located parts and their joints, in [`BodyPart::ALL`] order.
    pub fn parts(&self) -> impl Iterator<Item = (BodyPart, usize)> + '_ {
        BodyPart::ALL
            .into_iter()
            .filter_map(|p| self.joint(p).map(|j| (p, j)))
    }

    /// The parts this rig has no joint for.
    pub fn missing(&self) -> Vec<BodyPart> {
        BodyPart::ALL
            .into_iter()
            .filter(|&p| self.joint(p).is_none())
            .collect()
    }

    /// Every left/right joint pair of `skeleton`: the name patterns of
    /// [`mirror_pairs`], then the left/right parts of this map and the
    /// rig file's `[mirror]` pairs for joints not yet paired. Pairs are
    /// `(left, right)`, sorted by the left joint.
    pub fn mirror_pairs(&self, skeleton: &Skeleton) -> Vec<(usize, usize)> {
        let mut pairs = name_pattern_pairs(skeleton);
        let map_pairs = BodyPart::ALL
            .into_iter()
            .filter(|p| p.side() == Some(Side::Left))
            .filter_map(|p| Some((self.joint(p)?, self.joint(p.mirror())?)));
        for (left, right) in map_pairs.chain(self.extra_pairs.iter().copied()) {
            add_pair(&mut pairs, left, right);
        }
        pairs.sort_unstable();
        pairs
    }
}

/// Every left/right joint pair of `skeleton` `(left, right)`, sorted by the
/// left joint: joints whose names differ only by a side marker (`Left`/
/// `Right` anywhere in the name, suffixes `_L`/`_R`, `.L`/`.R`, `-L`/`-R`,
/// prefixes `L_`/`R_`, `L`/`R` before a capital as in CMU's `LHipJoint`, and
/// `l`/`r` before a lowercase letter as in ASF's `lfemur`), plus the
/// left/right parts of the detected [`BodyMap`] when detection succeeds.
pub fn mirror_pairs(skeleton: &Skeleton) -> Vec<(usize, usize)> {
    match BodyMap::detect(skeleton) {
        Ok(map) => map.mirror_pairs(skeleton),
        Err(_) => name_pattern_pairs(skeleton),
    }
}

/// Adds `(left, right)` unless one of the joints is already paired.
fn add_pair(pairs: &mut Vec<(usize, usize)>, left: usize, right: usize) {
    let taken = |j: usize| pairs.iter().any(|&(l, r)| l == j || r == j);
    if left != right && !taken(left) && !taken(right) {
        pairs.push((left, right));
    }
}

fn name_pattern_pairs(skeleton: &Skeleton) -> Vec<(usize, usize)> {
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
fn swap_side(name: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (left, right) in [("Left", "Right"), ("left", "right"), ("LEFT", "RIGHT")] {
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
    ] {
        if let Some(stem) = name.strip_suffix(left) {
            out.push(format!("{stem}{right}"));
        }
    }
    for (left, right) in [("L_", "R_"), ("l_", "r_")] {
        if let Some(rest) = name.strip_prefix(left) {
            out.push(format!("{right}{rest}"));
        }
    }
    let mut chars = name.chars();
    if let (Some(first), Some(second)) = (chars.next(), chars.next()) {
        let rest = &name[1..];
        // CMU BVH `LHipJoint`, `LThumb`; ASF `lfemur`, `lhumerus`.
        if first == 'L' && second.is_ascii_uppercase() {
            out.push(format!("R{rest}"));
        }
        if first == 'l' && second.is_ascii_lowercase() {
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

/// The joint named `name` exactly, else the one whose name matches without
/// namespace prefix and case.
fn find_joint(skeleton: &Skeleton, name: &str) -> Option<usize> {
    skeleton
        .find(name)
        .or_else(|| NameIndex::new(skeleton).get(name))
}

/// Joint indices by lowercase name without namespace prefix.
struct NameIndex {
    by_name: HashMap<String, usize>,
    namespaced: bool,
}

impl NameIndex {
    fn new(skeleton: &Skeleton) -> NameIndex {
        let mut by_name = HashMap::new();
        let mut namespaced = false;
        for (i, joint) in skeleton.joints().iter().enumerate() {
            let (prefix, name) = split_namespace(&joint.name);
            namespaced |= !prefix.is_empty();
            by_name.entry(name.to_ascii_lowercase()).or_insert(i);
        }
        NameIndex {
            by_name,
            namespaced,
        }
    }

    fn get(&self, name: &str) -> Option<usize> {
        let (_, name) = split_namespace(name);
        self.by_name.get(&name.to_ascii_lowercase()).copied()
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

/// Locates every part with each built-in rig; returns the rig that locates
/// the most required parts (then the most parts).
fn best_rig(names: &NameIndex) -> (&'static Rig, BodyMap) {
    let mut best: Option<(&Rig, BodyMap, (usize, usize))> = None;
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
        let name = if rig.name == CMU_BVH.name && names.namespaced {
            "Mixamo"
        } else {
            rig.name
        };
        let map = BodyMap {
            rig: name.to_string(),
            joints,
            extra_pairs: Vec::new(),
        };
        if best.as_ref().is_none_or(|(_, _, s)| score > *s) {
            best = Some((rig, map, score));
        }
    }
    let (rig, map, _) = best.expect("there are built-in rigs");
    (rig, map)
}

/// The first joint names of a skeleton, for error messages.
fn joint_list(skeleton: &Skeleton) -> String {
    const SHOWN: usize = 12;
    let names: Vec<&str> = skeleton
        .joints()
        .iter()
        .take(SHOWN)
        .map(|j| j.name.as_str())
        .collect();
    let more = skeleton.joint_count().saturating_sub(SHOWN);
    if more > 0 {
        format!("{}, ... and {more} more", names.join(", "))
    } else {
        names.join(", ")
    }
}

/// 1-based line and column of a byte offset.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

/// A rig file, as written by users.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RigFile {
    name: Option<String>,
    #[serde(default)]
    parts: BTreeMap<String, String>,
    mirror: Option<MirrorSection>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct MirrorSection {
    pairs: Vec<[String; 2]>,
}

impl RigFile {
    /// Parses a rig file and checks its part keys; errors name `path`,
    /// with line and column for TOML syntax.
    fn parse(text: &str, path: &Path) -> Result<RigFile> {
        let file: RigFile = toml::from_str(text).map_err(|e| {
            let (line, column) = match e.span() {
                Some(span) => line_column(text, span.start),
                None => (1, 1),
            };
            ParseError::new(path, line, column, format!("rig file: {}", e.message()))
        })?;
        if let Some(key) = file.parts.keys().find(|k| BodyPart::from_key(k).is_none()) {
            let keys: Vec<&str> = BodyPart::ALL.iter().map(|p| p.key()).collect();
            return Err(Error::Invalid(format!(
                "{}: [parts] has unknown part {key:?}; the parts are {}",
                path.display(),
                keys.join(", ")
            )));
        }
        Ok(file)
    }

    /// Every joint name the file gives (parts and mirror pairs).
    fn joint_names(&self) -> impl Iterator<Item = &String> {
        self.parts
            .values()
            .chain(self.mirror.iter().flat_map(|m| m.pairs.iter().flatten()))
    }
}

/// A rig file given to the whole process ([`register_rig_file`]).
struct RegisteredRig {
    path: PathBuf,
    file: RigFile,
}

impl RegisteredRig {
    /// Whether `skeleton` has every joint the file names (a file with no
    /// names fits nothing: it would take over every skeleton).
    fn fits(&self, skeleton: &Skeleton) -> bool {
        let mut names = self.file.joint_names().peekable();
        names.peek().is_some() && names.all(|n| find_joint(skeleton, n).is_some())
    }
}

/// Rig files [`BodyMap::detect`] tries before the built-in rigs, in the
/// order they were given.
static REGISTERED_RIGS: RwLock<Vec<RegisteredRig>> = RwLock::new(Vec::new());

/// Reads a rig file (format in the module documentation) and makes every
/// later [`BodyMap::detect`] in this process use it for the skeletons that
/// have all the joints it names (files given earlier are tried first).
/// This is how a rig the built-in tables do not know reaches every
/// capability (`mocap --rig FILE`). Fails, naming the file (and line and
/// column for TOML syntax), on a file that cannot be read or parsed, an
/// unknown part key, or a file that names no joint.
pub fn register_rig_file(path: impl AsRef<Path>) -> Result<()> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let file = RigFile::parse(&text, path)?;
    if file.joint_names().next().is_none() {
        return Err(Error::Invalid(format!(
            "{}: the rig file names no joint: list the rig's joints under [parts] \
             (e.g. pelvis = \"Hips\")",
            path.display()
        )));
    }
    REGISTERED_RIGS
        .write()
        .unwrap_or_else(|e| e.into_inner())
        .push(RegisteredRig {
            path: path.to_path_buf(),
            file,
        });
    Ok(())
}
