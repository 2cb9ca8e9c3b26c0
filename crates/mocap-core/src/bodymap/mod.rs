//! Semantic body parts located on any humanoid rig, left/right mirror
//! pairs, and the Kinect v2 joint layout.
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
//! The parts are found, in this order ([`BodyMap::detect`], which records
//! how in [`BodyMap::found_by`]):
//! 1. **from a rig file** given to the process ([`register_rig_file`]);
//! 2. **by joint name**, with the tables of the widespread conventions:
//!    the five above, Biovision (`Hips`, `Chest`, `Chest2`, `LeftCollar` =
//!    clavicle, `LeftShoulder` = shoulder point, `LeftElbow`, `LeftWrist`,
//!    `LeftHip`...), CMU's 3ds Max conversions (Biovision's names and
//!    `LFingers`), Daz/Poser (`hip`, `abdomen`, `chest`, `lCollar`,
//!    `lShldr`, `lForeArm`, `lHand`, `lThigh`, `lShin`, `lFoot`), 3ds Max
//!    Biped (`Bip01 L Thigh`, `Bip01 L Calf`, `Bip01 L UpperArm`...), the
//!    Unreal mannequin (`pelvis`, `spine_03`, `clavicle_l`, `upperarm_l`,
//!    `thigh_l`, `calf_l`, `ball_l`...), SMPL (`pelvis`, `left_hip`,
//!    `left_collar`, `left_shoulder`, `left_foot` = toe; or `L_Hip`...),
//!    Rokoko (`Hips`, `LeftThigh`, `LeftShin`, `Spine1..4`...), and
//!    MotionBuilder/HumanIK and Unity/Mixamo (the CMU-style names behind a
//!    prefix). The convention that finds the most required parts wins;
//! 3. **by the skeleton's shape** when no convention finds them all: the
//!    chains leaving the pelvis, the arms branching from the upper spine,
//!    left and right from the rest pose (or, when it cannot tell, from
//!    joint names with side markers); see `shape.rs` for the rules.
//!
//! When all three fail, the error names the missing parts, points to
//! `--rig`, and carries a rig-file template with the joints that were found
//! filled in.
//!
//! (ASF joints sit where their bone starts, so `lhumerus` is the shoulder
//! point and `lradius` the elbow.) In CMU-style BVH files the `Neck` joint has
//! a zero offset from `Spine1`, so it sits at the chest; `Neck1` is the base
//! of the neck and is preferred. Names are compared without regard to case,
//! without a namespace prefix ending in `:` (Mixamo's `mixamorig:LeftArm`),
//! and also without a prefix every joint name shares up to a space or an
//! underscore (Biped's `Bip01 `, HumanIK's `Character1_`). Right-side names
//! are the left-side ones with the side marker swapped (`Left`/`Right`,
//! `_L`/`_R`, `_l`/`_r`, `L_`/`R_`, ` L `/` R `, `L`/`R` before a capital,
//! `l`/`r` before a letter).
//!
//! A rig none of this finds is described in a small TOML file
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

mod names;
mod rig_file;
mod shape;

use std::fmt;
use std::path::Path;

use crate::error::{Error, Result};
use crate::skeleton::Skeleton;

use names::{add_pair, best_rig, name_pattern_pairs, NameIndex};
pub use rig_file::register_rig_file;
use rig_file::RigFile;

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

    /// The anatomical point the part stands for, in words (the module
    /// documentation's table).
    pub fn point(self) -> &'static str {
        match self {
            BodyPart::Pelvis => "root of the spine, between the hip joints",
            BodyPart::Spine => "lower/middle (lumbar) spine",
            BodyPart::Chest => "upper spine joint the shoulder girdle hangs from",
            BodyPart::Neck => "base of the neck",
            BodyPart::Head => "head joint, at the top of the neck",
            BodyPart::LeftClavicle | BodyPart::RightClavicle => {
                "inner end of the collarbone, where the shoulder girdle starts"
            }
            BodyPart::LeftShoulder | BodyPart::RightShoulder => {
                "where the upper arm starts (not the clavicle)"
            }
            BodyPart::LeftElbow | BodyPart::RightElbow => "elbow",
            BodyPart::LeftWrist | BodyPart::RightWrist => "wrist, where the hand starts",
            BodyPart::LeftHand | BodyPart::RightHand => "a point in the hand beyond the wrist",
            BodyPart::LeftHip | BodyPart::RightHip => "femur head, where the thigh starts",
            BodyPart::LeftKnee | BodyPart::RightKnee => "knee",
            BodyPart::LeftAnkle | BodyPart::RightAnkle => "ankle",
            BodyPart::LeftToe | BodyPart::RightToe => "ball of the foot (toe joint)",
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

/// How a [`BodyMap`]'s parts were found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FoundBy {
    /// By joint name, with a naming convention's table ([`BodyMap::rig`]
    /// names it: `Daz/Poser`, `Mixamo`...).
    Names,
    /// From the skeleton's shape (the rig's names are not a known
    /// convention), left and right told as said.
    Shape(SideEvidence),
    /// From a rig file ([`BodyMap::from_toml_file`], [`register_rig_file`]).
    RigFile,
    /// Joint by joint, in code ([`BodyMap::from_joints`]).
    Given,
}

/// How left and right were told when the parts were found by shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SideEvidence {
    /// The rest pose: the body's left is up (pelvis to head) × forward
    /// (where the feet point).
    RestPose,
    /// Joint names that differ only by a side marker (`_L`/`_R`...): the
    /// rest pose could not tell.
    Names,
}

impl FoundBy {
    /// A short key for JSON: `names`, `shape`, `rig_file` or `given`.
    pub fn key(self) -> &'static str {
        match self {
            FoundBy::Names => "names",
            FoundBy::Shape(_) => "shape",
            FoundBy::RigFile => "rig_file",
            FoundBy::Given => "given",
        }
    }
}

impl fmt::Display for FoundBy {
    /// Says how, in words: `by joint name`, `by the skeleton's shape (left
    /// and right from the rest pose)`...
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FoundBy::Names => "by joint name",
            FoundBy::Shape(SideEvidence::RestPose) => {
                "by the skeleton's shape (left and right from the rest pose)"
            }
            FoundBy::Shape(SideEvidence::Names) => {
                "by the skeleton's shape (left and right from the joint names)"
            }
            FoundBy::RigFile => "from a rig file",
            FoundBy::Given => "as given",
        })
    }
}

/// The name [`BodyMap::rig`] reports for a rig found by its shape.
pub const UNNAMED_RIG: &str = "unnamed";

/// Which joint of a skeleton sits at each body part.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyMap {
    rig: String,
    joints: [Option<usize>; BodyPart::COUNT],
    found_by: FoundBy,
    /// Left/right joint pairs given in a rig file, beyond the name patterns.
    extra_pairs: Vec<(usize, usize)>,
}

impl BodyMap {
    /// Finds the body parts of `skeleton` (module documentation): from the
    /// first rig file given with [`register_rig_file`] whose joints the
    /// skeleton all has (with its own errors, e.g. a required part still
    /// missing); else by joint name, with the convention that locates the
    /// most parts, if it locates every required part
    /// ([`BodyPart::is_required`]); else by the skeleton's shape.
    ///
    /// Fails when none of them finds every required part, naming the
    /// missing parts, the names tried and why the shape did not tell, and
    /// pointing to `--rig` with a rig-file template (the joints found
    /// filled in).
    pub fn detect(skeleton: &Skeleton) -> Result<BodyMap> {
        let unfit = match rig_file::registered_map(skeleton) {
            Ok(map) => return map,
            Err(unfit) => unfit,
        };
        let named = best_rig(&NameIndex::new(skeleton));
        let missing_by_name: Vec<BodyPart> = named
            .map
            .missing()
            .into_iter()
            .filter(|p| p.is_required())
            .collect();
        if missing_by_name.is_empty() {
            return Ok(named.map);
        }
        let shape = shape::find(skeleton);
        if let (None, Some(sides)) = (&shape.failure, shape.sides) {
            return Ok(BodyMap {
                rig: UNNAMED_RIG.to_string(),
                joints: shape.joints,
                found_by: FoundBy::Shape(sides),
                extra_pairs: Vec::new(),
            });
        }

        let (found, sides_unknown) = merge_found(&named, &shape);
        let missing: Vec<String> = BodyPart::ALL
            .iter()
            .filter(|p| p.is_required() && found[p.index()].is_none())
            .map(|p| p.to_string())
            .collect();
        const TRIED_SHOWN: usize = 3;
        let mut tried: Vec<String> = missing_by_name
            .iter()
            .take(TRIED_SHOWN)
            .map(|&p| format!("{p} (tried {})", named.candidates(p).join(", ")))
            .collect();
        if missing_by_name.len() > TRIED_SHOWN {
            tried.push(format!(
                "and {} more parts",
                missing_by_name.len() - TRIED_SHOWN
            ));
        }
        let missing = if missing.is_empty() {
            "which limbs are the left ones is not known".to_string()
        } else {
            format!("no joint found for {}", missing.join(", "))
        };
        let given = if unfit.is_empty() {
            String::new()
        } else {
            format!("; a rig file given does not fit it: {}", unfit.join("; "))
        };
        Err(Error::Invalid(format!(
            "cannot find the body parts of this skeleton ({} joints: {}): {missing}. By \
             name, the closest convention, {}, lacks {}. By shape: {}. Describe the rig in \
             a TOML file and give it with `mocap --rig FILE` (docs/rigs.md; in code: \
             register_rig_file or BodyMap::from_toml_file){given}. A template, with the \
             joints found filled in:\n\n{}",
            skeleton.joint_count(),
            joint_list(skeleton),
            named.rig_name(),
            tried.join("; "),
            shape
                .failure
                .as_deref()
                .unwrap_or("left and right cannot be told"),
            rig_file::template(skeleton, &found, sides_unknown),
        )))
    }

    /// A rig file for `skeleton` to start from (the format of
    /// [`BodyMap::from_toml_str`]): the parts the names or the shape find
    /// filled in, the others as comments to fill in (the required ones
    /// marked TODO). This is the template [`BodyMap::detect`]'s error
    /// carries; on a rig whose parts are found it lists them all.
    pub fn rig_file_template(skeleton: &Skeleton) -> String {
        let named = best_rig(&NameIndex::new(skeleton));
        if named.map.missing().iter().all(|p| !p.is_required()) {
            return rig_file::template(skeleton, &named.map.joints, false);
        }
        let (found, sides_unknown) = merge_found(&named, &shape::find(skeleton));
        rig_file::template(skeleton, &found, sides_unknown)
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
            found_by: FoundBy::Given,
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
        rig_file::map_from_file(&RigFile::parse(text, path)?, path, skeleton)
    }

    /// Name of the rig the map came from (`Bandai Namco`, `Mixamo`, the
    /// rig file's name, [`UNNAMED_RIG`] for a rig found by its shape...).
    pub fn rig(&self) -> &str {
        &self.rig
    }

    /// How the parts were found.
    pub fn found_by(&self) -> FoundBy {
        self.found_by
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

    /// The joint whose position channels carry the body through the world:
    /// the pelvis, or its nearest ancestor with position channels (Bandai's
    /// rig moves its hips and keeps its root still at the floor; most rigs
    /// move the root above the pelvis). `None` when the rig has no pelvis or
    /// nothing above it can move.
    pub fn position_carrier(&self, skeleton: &Skeleton) -> Option<usize> {
        std::iter::successors(self.joint(BodyPart::Pelvis), |&j| skeleton.joint(j).parent)
            .find(|&j| skeleton.joint(j).has_position_channels())
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
/// `Right` anywhere in the name, ` L `/` R ` as in Biped's `Bip01 L Thigh`,
/// suffixes `_L`/`_R`, `.L`/`.R`, `-L`/`-R`, ` L`/` R`, prefixes `L_`/`R_`,
/// `L `/`R `, `L`/`R` before a capital as in CMU's `LHipJoint`, and `l`/`r`
/// before a letter as in ASF's `lfemur` and Daz's `lThigh`), plus the
/// left/right parts of the detected [`BodyMap`] when detection succeeds.
pub fn mirror_pairs(skeleton: &Skeleton) -> Vec<(usize, usize)> {
    match BodyMap::detect(skeleton) {
        Ok(map) => map.mirror_pairs(skeleton),
        Err(_) => name_pattern_pairs(skeleton),
    }
}

/// The parts found by name (first) and by shape (for the parts the names
/// miss, with joints the names do not already place), and whether some of
/// the sided parts come from a shape that could not tell left from right.
fn merge_found(
    named: &names::NameMatch,
    shape: &shape::ShapeOutcome,
) -> ([Option<usize>; BodyPart::COUNT], bool) {
    let by_name = &named.map.joints;
    let mut found = *by_name;
    let mut guessed_side = false;
    for part in BodyPart::ALL {
        let from_shape = shape.joints[part.index()];
        if found[part.index()].is_none() && from_shape.is_some() && !by_name.contains(&from_shape) {
            found[part.index()] = from_shape;
            guessed_side |= part.side().is_some() && shape.sides.is_none();
        }
    }
    (found, guessed_side)
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
