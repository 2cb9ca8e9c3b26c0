//! Retargeting: a motion of one rig played by another rig of the same body
//! map (joint names, hierarchy, bone lengths and rest pose may all differ).
//!
//! The two rigs are matched by their [`BodyMap`]s. A body part both rigs
//! have is *mapped*; its joint on the target takes the global rotation of
//! the source's joint, corrected for how the two rigs' joint axes differ:
//!
//! ```text
//! G_t(j_t, f) = G_s(j_s, f) R_s(j_s)^-1 F_s(p) F_t(p)^-1 R_t(j_t)         (1)
//! ```
//!
//! where `G` are global rotations (forward kinematics), `R` the global
//! rotations of each rig in a *reference pose*, and `F(p)` the frame of part
//! `p` in that pose: its bone's direction (from the part's joint to the next
//! part down the chain, e.g. shoulder to elbow, measured between joint
//! positions so that joints in between do not matter) and, for the twist
//! about it, a body axis of the pose (the forward axis, or the left-right
//! axis where the bone points forward, as a foot does; the pelvis and the
//! chest use the left-right axis of the hips and of the shoulders, taken
//! where the way to them leaves the joint, e.g. at the clavicles' start,
//! which turns with the chest alone). `R^-1 F` is the part's frame in its
//! joint's own axes, so (1) gives the target's bone the source's bone frame:
//! bones keep their directions whatever the rigs' joint axes.
//!
//! The reference pose of a rig is its [`canonical_pose`], a T-pose made
//! from the rig alone ([`Retargeting::new`]), so a motion retargets the same
//! wherever it starts. The frames `F` are only comparable between poses
//! where limbs twist alike: the canonical pose swings each body part's bone
//! from the rest pose (every rotation zero, [`Motion::rest`]) onto its
//! T-pose direction, which keeps the twist the rig's rest has. That is the
//! anatomical twist for rigs built so (CMU's and Mixamo's rest in a T-pose,
//! others in an A-pose), but Bandai's rest has every bone along x and joint
//! axes half a turn about some bones from where captures hold them: its
//! canonical pose starts from a natural pose of it instead. Local rotations
//! retargeted onto Bandai from the bare rest poses are valid but turned far
//! from any Bandai capture (bench/results/retarget.md). Other reference
//! poses can be given ([`Retargeting::with_reference_poses`], e.g. a T-pose
//! frame captured on each rig). A retargeting there and back with the same
//! two references gives the motion back exactly. Two rigs with the same
//! joints (names, hierarchy and bone directions; other bone lengths, as two
//! performers of one capture setup) need no convention: every joint keeps
//! its local rotation. Joints of other names count as the same when both
//! body maps put every part at the same joint (one rig under two naming
//! schemes, one of them described by a rig file). Parts with no part below
//! them (head, hands, toes, or a wrist where one rig has no hand) borrow the
//! frame correction `F_s F_t^-1` of the part above them.
//!
//! Target joints of no part keep their rest rotation relative to their
//! parent, except a joint between two mapped parts (CMU's `LHipJoint`
//! between the pelvis and the hip, a clavicle where the source has none):
//! it is turned so that the next mapped joint below it lands where the
//! source has it relative to the mapped joint above (scaled). Joints above
//! the pelvis keep their rest rotation; the pelvis is put where the source's
//! is, scaled by the ratio of the rigs' leg lengths (hip to knee to ankle),
//! so strides fit the new legs and the floor stays at the height it was.
//!
//! Both rigs are taken to be in the same world frame (the same up axis and
//! units of their own). What is lost: motion of joints the source has and
//! the target has no part for (fingers, extra spine joints are folded into
//! the mapped ones), and twist where the reference poses disagree about it.

use crate::bodymap::{BodyMap, BodyPart};
use crate::error::{Error, Result};
use crate::kinematics::forward_kinematics;
use crate::motion::Motion;
use crate::ops::trim;
use crate::rotation::{frame_from_axes, Quat, Vec3};
use crate::skeleton::Skeleton;

/// What a target joint does during retargeting.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Role {
    /// Keeps its rest rotation relative to its parent (with
    /// [`Retargeting::apply_onto`], its rotation in the motion played onto).
    Rest,
    /// Takes the global rotation of source joint `source`, times `correction`
    /// (`R_s^-1 F_s F_t^-1 R_t` of (1)).
    Mapped { source: usize, correction: Quat },
    /// Turned so that target joint `below` lands where source joint
    /// `source_below` is relative to `source_above`, target joint `above`
    /// standing for it (see the module docs).
    Aimed {
        below: usize,
        above: usize,
        source_below: usize,
        source_above: usize,
    },
}

/// A retargeting from one rig to another, prepared once and applied to any
/// number of motions of the source rig.
#[derive(Debug, Clone)]
pub struct Retargeting {
    source: Skeleton,
    target: Skeleton,
    roles: Vec<Role>,
    /// Target pelvis joint and source pelvis joint.
    pelvis: (usize, usize),
    /// The target joint whose position channels move the body
    /// ([`BodyMap::position_carrier`], else the root).
    carrier: usize,
    scale: f32,
}

/// The next part down the chain from `part` whose direction gives the
/// part's bone in its frame `F` (the first of the candidates both rigs have).
fn bone_candidates(part: BodyPart) -> &'static [BodyPart] {
    use BodyPart::*;
    match part {
        Pelvis => &[Spine, Chest, Neck, Head],
        Spine => &[Chest, Neck, Head],
        Chest => &[Neck, Head],
        Neck => &[Head],
        LeftClavicle => &[LeftShoulder],
        RightClavicle => &[RightShoulder],
        LeftShoulder => &[LeftElbow],
        LeftElbow => &[LeftWrist],
        LeftWrist => &[LeftHand],
        LeftHip => &[LeftKnee],
        LeftKnee => &[LeftAnkle],
        LeftAnkle => &[LeftToe],
        RightShoulder => &[RightElbow],
        RightElbow => &[RightWrist],
        RightWrist => &[RightHand],
        RightHip => &[RightKnee],
        RightKnee => &[RightAnkle],
        RightAnkle => &[RightToe],
        Head | LeftHand | RightHand | LeftToe | RightToe => &[],
    }
}

/// The part above `part` (whose correction a part without a bone borrows).
fn part_above(part: BodyPart) -> Option<BodyPart> {
    use BodyPart::*;
    Some(match part {
        Pelvis => return None,
        Spine => Pelvis,
        Chest => Spine,
        Neck => Chest,
        Head => Neck,
        LeftClavicle | RightClavicle => Chest,
        LeftShoulder => LeftClavicle,
        RightShoulder => RightClavicle,
        LeftElbow => LeftShoulder,
        LeftWrist => LeftElbow,
        LeftHand => LeftWrist,
        RightElbow => RightShoulder,
        RightWrist => RightElbow,
        RightHand => RightWrist,
        LeftHip | RightHip => Pelvis,
        LeftKnee => LeftHip,
        LeftAnkle => LeftKnee,
        LeftToe => LeftAnkle,
        RightKnee => RightHip,
        RightAnkle => RightKnee,
        RightToe => RightAnkle,
    })
}

/// One rig in its reference pose: joint positions and rotations, and the
/// body's axes.
struct ReferenceRig<'a> {
    skeleton: &'a Skeleton,
    map: &'a BodyMap,
    positions: Vec<Vec3>,
    /// Global joint rotations in the reference pose.
    rotations: Vec<Quat>,
    /// From the right hip to the left, as seen from the pelvis joint.
    lateral: Vec3,
    /// From the right shoulder to the left, as seen from the chest joint.
    shoulders: Option<Vec3>,
    forward: Vec3,
}

impl<'a> ReferenceRig<'a> {
    fn new(reference: &'a Motion, map: &'a BodyMap, what: &str) -> Result<ReferenceRig<'a>> {
        let skeleton = reference.skeleton();
        // A rig file without frames: its rest pose.
        let first = if reference.frame_count() == 0 {
            Motion::rest(skeleton.clone(), reference.frame_time(), 1)?
        } else {
            trim(reference, 0..1)?
        };
        let poses = forward_kinematics(&first);
        let mut rig = ReferenceRig {
            skeleton,
            map,
            positions: poses.frame_positions(0).to_vec(),
            rotations: poses.frame_rotations(0).to_vec(),
            lateral: Vec3::ZERO,
            shoulders: None,
            forward: Vec3::ZERO,
        };
        let pelvis = map.require(BodyPart::Pelvis)?;
        rig.lateral = rig
            .across(pelvis, BodyPart::LeftHip, BodyPart::RightHip)
            .unwrap_or(Vec3::ZERO)
            .normalize_or_zero();
        let top = [
            BodyPart::Spine,
            BodyPart::Chest,
            BodyPart::Neck,
            BodyPart::Head,
        ]
        .into_iter()
        .find_map(|p| map.joint(p))
        .ok_or_else(|| Error::Invalid(format!("{what} has no spine or head")))?;
        let up = rig.toward(pelvis, top) - rig.positions[pelvis];
        let up = (up - up.dot(rig.lateral) * rig.lateral).normalize_or_zero();
        if rig.lateral == Vec3::ZERO || up == Vec3::ZERO {
            return Err(Error::Invalid(format!(
                "{what}'s reference pose has its hips at one point or its spine along the hips: \
                 cannot tell its body axes"
            )));
        }
        rig.forward = rig.lateral.cross(up);
        rig.shoulders = map
            .joint(BodyPart::Chest)
            .and_then(|chest| rig.across(chest, BodyPart::LeftShoulder, BodyPart::RightShoulder));
        Ok(rig)
    }

    /// The frame `F(p)` of (1) of a part whose bone (to the next part) is
    /// `bone`: for the pelvis and the chest, the bone with the left-right
    /// axis of the hips or the shoulders; for the other parts, the body's
    /// axes (left-right, up, forward) turned by the smallest rotation that
    /// takes the part's anatomical direction in a T-pose (up for the spine
    /// and neck, sideways for a clavicle and an arm, down for a leg,
    /// forward for a foot) onto its bone: its twist follows the body's the
    /// way a limb's does when it is raised or swung from the T-pose.
    fn part_frame(&self, part: BodyPart, bone: Vec3) -> Quat {
        use BodyPart::*;
        let up = self.forward.cross(self.lateral).normalize();
        let body = frame_from_axes(self.lateral, up);
        let anatomical = match part {
            Pelvis => return frame_from_axes(bone, self.lateral),
            Chest => return frame_from_axes(bone, self.shoulders.unwrap_or(self.lateral)),
            Spine | Neck | Head => up,
            LeftClavicle | LeftShoulder | LeftElbow | LeftWrist | LeftHand => self.lateral,
            RightClavicle | RightShoulder | RightElbow | RightWrist | RightHand => -self.lateral,
            LeftHip | LeftKnee | RightHip | RightKnee => -up,
            LeftAnkle | LeftToe | RightAnkle | RightToe => self.forward,
        };
        Quat::from_rotation_arc(anatomical, bone.normalize()) * body
    }

    fn position(&self, part: BodyPart) -> Option<Vec3> {
        self.map.joint(part).map(|j| self.positions[j])
    }

    /// Where the way from `from` to `to` leaves `from`: the child of `from`
    /// on it, if that one is away from `from` (it then turns with `from`
    /// alone, as a clavicle's start turns with the chest), else `to`.
    fn toward(&self, from: usize, to: usize) -> Vec3 {
        let mut k = to;
        while let Some(p) = self.skeleton.joint(k).parent {
            if p == from {
                let start = self.positions[k];
                if start.distance(self.positions[from]) > 1e-4 {
                    return start;
                }
                break;
            }
            k = p;
        }
        self.positions[to]
    }

    /// From part `right` to part `left` as seen from joint `from` (see
    /// [`ReferenceRig::toward`]), if both parts exist and lie apart.
    fn across(&self, from: usize, left: BodyPart, right: BodyPart) -> Option<Vec3> {
        let (l, r) = (self.map.joint(left)?, self.map.joint(right)?);
        let (a, b) = (self.toward(from, l), self.toward(from, r));
        let v = if a.distance(b) > 1e-4 {
            a - b
        } else {
            self.positions[l] - self.positions[r]
        };
        (v.length() > 1e-6).then_some(v)
    }
}

/// The direction a part's bone takes in the canonical T-pose, in the body's
/// axes (left-right `lateral`, `up`, `forward`): up for the spine and neck,
/// sideways for a clavicle and an arm, down for a leg, forward for a foot.
/// The pelvis and the parts without a bone have none: the pelvis stays as
/// the rig has it (it carries the body's axes), the others follow.
fn canonical_direction(part: BodyPart, lateral: Vec3, up: Vec3, forward: Vec3) -> Option<Vec3> {
    use BodyPart::*;
    match part {
        Pelvis | Head | LeftHand | RightHand | LeftToe | RightToe => None,
        Spine | Chest | Neck => Some(up),
        LeftClavicle | LeftShoulder | LeftElbow | LeftWrist => Some(lateral),
        RightClavicle | RightShoulder | RightElbow | RightWrist => Some(-lateral),
        LeftHip | LeftKnee | RightHip | RightKnee => Some(-up),
        LeftAnkle | RightAnkle => Some(forward),
    }
}

/// The rotation that swings `from` onto `to` (unit vectors) the shortest
/// way; where they are opposite, half a turn about `axis` (a bone pointing
/// the wrong way along the body, as a leg of a rest pose with every bone
/// along one axis: the shortest way is then any, and the body's own axis
/// keeps the twist the same for every rig).
fn swing(from: Vec3, to: Vec3, axis: Vec3) -> Quat {
    if from.dot(to) < -0.9999 {
        Quat::from_axis_angle(axis, std::f32::consts::PI)
    } else {
        Quat::from_rotation_arc(from, to)
    }
}

/// Bandai's rig in a natural pose: the local rotations (quaternions x, y,
/// z, w) of the first frame of the bundled walk
/// (`samples/dataset-1_walk_normal_001.bvh`; a test checks them against
/// it). Bandai's rest pose has every bone along x and its joints' axes
/// turned about their bones in no anatomical way (its right thigh is half
/// a turn about the bone from where captures hold it), so no rest-pose rule
/// can tell how the rig's limbs twist: its canonical pose starts from this
/// one instead.
const BANDAI_STANDING: [(&str, [f32; 4]); 21] = [
    ("Hips", [0.0172, 0.0026, 0.6849, 0.7284]),
    ("Spine", [0.7160, -0.0072, 0.0173, 0.6979]),
    ("Chest", [0.0255, 0.0143, -0.0331, 0.9990]),
    ("Neck", [-0.0196, -0.0131, -0.0578, 0.9980]),
    ("Head", [-0.0551, -0.0065, 0.0410, 0.9976]),
    ("Shoulder_L", [-0.5033, -0.5141, -0.5001, 0.4820]),
    ("UpperArm_L", [-0.0957, 0.2260, -0.5729, 0.7820]),
    ("LowerArm_L", [0.0602, -0.1254, 0.0076, 0.9902]),
    ("Hand_L", [0.0443, 0.0147, 0.1474, 0.9880]),
    ("Shoulder_R", [0.5353, -0.5054, 0.4544, 0.5015]),
    ("UpperArm_R", [-0.0543, 0.1209, -0.5562, 0.8204]),
    ("LowerArm_R", [0.0652, -0.1673, 0.0111, 0.9837]),
    ("Hand_R", [0.0549, -0.0330, 0.1892, 0.9798]),
    ("UpperLeg_L", [-0.2049, -0.0295, -0.9781, 0.0203]),
    ("LowerLeg_L", [0.0030, 0.5904, -0.0023, 0.8071]),
    ("Foot_L", [-0.0538, -0.3646, 0.0691, 0.9270]),
    ("Toes_L", [-0.0037, -0.1855, 0.0044, 0.9826]),
    ("UpperLeg_R", [0.9895, 0.0880, -0.1140, 0.0089]),
    ("LowerLeg_R", [-0.0000, 0.2564, 0.0003, 0.9666]),
    ("Foot_R", [-0.0854, -0.5608, 0.0922, 0.8184]),
    ("Toes_R", [0.0003, -0.1441, -0.0006, 0.9896]),
];

/// The name [`BodyMap::rig`] gives Bandai's rig.
const BANDAI_RIG: &str = "Bandai Namco";

/// The rig of `skeleton` in the canonical T-pose, one frame: from its rest
/// pose (every rotation zero; for Bandai's rig, a natural pose of it,
/// `BANDAI_STANDING`), each body part's bone swung, parents first,
/// the shortest way onto its direction in a T-pose (`canonical_direction`)
/// in the body's axes of the rest pose (left-right from the hips, up from
/// the pelvis to the top of the spine). A rig whose rest pose is a T-pose
/// (CMU, Mixamo) stays as it is; an A-pose has its arms raised; a rest pose
/// with every bone along one axis (Bandai's) is stood up. Only the bones'
/// directions decide, so every motion of a rig has the same reference pose
/// for (1), wherever the motion starts. Joints of no part keep their rest
/// rotation, and a joint without rotation channels cannot turn.
pub fn canonical_pose(skeleton: &Skeleton, map: &BodyMap) -> Result<Motion> {
    let mut pose = Motion::rest(skeleton.clone(), 1.0 / 30.0, 1)?;
    if map.rig() == BANDAI_RIG {
        for (name, [x, y, z, w]) in BANDAI_STANDING {
            if let Some(j) = skeleton.find(name) {
                pose.set_local_rotation(0, j, Quat::from_xyzw(x, y, z, w).normalize());
            }
        }
    }
    let rest = ReferenceRig::new(&pose, map, "the rig")?;
    let (lateral, forward) = (rest.lateral, rest.forward);
    let up = forward.cross(lateral).normalize();
    let mut parts: Vec<(usize, BodyPart)> = map.parts().map(|(p, j)| (j, p)).collect();
    parts.sort_by_key(|&(j, _)| j); // parents before children
    for (joint, part) in parts {
        let Some(direction) = canonical_direction(part, lateral, up, forward) else {
            continue;
        };
        let Some(below) = bone_candidates(part).iter().find_map(|&p| map.joint(p)) else {
            continue;
        };
        if !skeleton.joint(joint).has_rotation_channels() {
            continue;
        }
        let poses = forward_kinematics(&pose);
        let bone = poses.position(0, below) - poses.position(0, joint);
        if bone.length() < 1e-6 {
            continue;
        }
        // Arms and the spine turn in the body's frontal plane, legs and feet
        // in its sagittal plane, when half a turn is needed.
        let axis = if matches!(
            part,
            BodyPart::LeftAnkle
                | BodyPart::RightAnkle
                | BodyPart::LeftHip
                | BodyPart::RightHip
                | BodyPart::LeftKnee
                | BodyPart::RightKnee
        ) {
            lateral
        } else {
            forward
        };
        let turn = swing(bone.normalize(), direction, axis);
        let global = turn * poses.rotation(0, joint);
        let parent = skeleton
            .joint(joint)
            .parent
            .map_or(Quat::IDENTITY, |p| poses.rotation(0, p));
        pose.set_local_rotation(0, joint, (parent.inverse() * global).normalize());
    }
    Ok(pose)
}

impl Retargeting {
    /// Prepares retargeting from the rig of `source` to the rig of `target`,
    /// located by their body maps, each in its [`canonical_pose`] as the
    /// reference pose of (1): a motion retargets the same wherever it
    /// starts. Fails when a rig's body axes cannot be told from its rest
    /// pose.
    pub fn new(
        source: &Skeleton,
        source_map: &BodyMap,
        target: &Skeleton,
        target_map: &BodyMap,
    ) -> Result<Retargeting> {
        Retargeting::with_reference_poses(
            &canonical_pose(source, source_map)?,
            source_map,
            &canonical_pose(target, target_map)?,
            target_map,
        )
    }

    /// [`Retargeting::new`] with given reference poses: the first frame of
    /// each motion (its rest pose when it has no frame), e.g. a frame where
    /// the performer stood in a T-pose on each rig. Both poses must twist
    /// their limbs alike (see the module docs).
    pub fn with_reference_poses(
        source_reference: &Motion,
        source_map: &BodyMap,
        target_reference: &Motion,
        target_map: &BodyMap,
    ) -> Result<Retargeting> {
        let (source, target) = (source_reference.skeleton(), target_reference.skeleton());
        let reference_s = ReferenceRig::new(source_reference, source_map, "the source rig")?;
        let reference_t = ReferenceRig::new(target_reference, target_map, "the target rig")?;
        let (leg_s, leg_t) = (
            source_map.leg_length(source)?,
            target_map.leg_length(target)?,
        );
        if !(leg_s > 0.0 && leg_t > 0.0) {
            return Err(Error::Invalid(
                "a rig's legs have no length: cannot scale between the rigs".into(),
            ));
        }
        let n = target.joint_count();
        let pelvis_t = target_map.require(BodyPart::Pelvis)?;
        let pelvis_s = source_map.require(BodyPart::Pelvis)?;
        let body = target.subtree(pelvis_t);
        // The same joints with the same axes (another performer on one rig:
        // names, hierarchy and the directions of the bones below the pelvis
        // alike within 5 degrees, lengths free; where the pelvis hangs from a
        // helper root is a placement, not a bone): every joint takes its
        // counterpart's rotation as it is, with no reference-pose convention
        // to turn a forearm where two first frames disagree.
        let same_axes = |j: usize| {
            let (a, b) = (
                source.joint(j).offset.normalize_or_zero(),
                target.joint(j).offset.normalize_or_zero(),
            );
            j == pelvis_t
                || !body.contains(&j)
                || (a == Vec3::ZERO && b == Vec3::ZERO)
                || a.dot(b) > 5.0f32.to_radians().cos()
        };
        // Joints are counterparts by name, or, for one rig under two
        // naming schemes (a rig file says what each name is), where both
        // body maps put every part at the same joint.
        let same_names = source
            .joints()
            .iter()
            .zip(target.joints())
            .all(|(a, b)| a.name == b.name);
        let same_parts = source_map.parts().eq(target_map.parts());
        let same_joints = source.joint_count() == n
            && source
                .joints()
                .iter()
                .zip(target.joints())
                .all(|(a, b)| a.parent == b.parent)
            && (same_names || same_parts)
            && (0..n).all(same_axes);
        let roles = if same_joints {
            (0..n)
                .map(|j| Role::Mapped {
                    source: j,
                    correction: Quat::IDENTITY,
                })
                .collect()
        } else {
            part_roles(&reference_s, &reference_t, &body)
        };
        Ok(Retargeting {
            source: source.clone(),
            target: target.clone(),
            roles,
            pelvis: (pelvis_t, pelvis_s),
            carrier: target_map.position_carrier(target).unwrap_or_else(|| {
                (0..n)
                    .find(|&j| target.joint(j).parent.is_none())
                    .unwrap_or(0)
            }),
            scale: leg_t / leg_s,
        })
    }

    /// [`Retargeting::new`] for two rigs whose body maps the built-in rig
    /// tables find ([`BodyMap::detect`]).
    pub fn detect(source: &Skeleton, target: &Skeleton) -> Result<Retargeting> {
        let source_map =
            BodyMap::detect(source).map_err(|e| Error::Invalid(format!("the source rig: {e}")))?;
        let target_map =
            BodyMap::detect(target).map_err(|e| Error::Invalid(format!("the target rig: {e}")))?;
        Retargeting::new(source, &source_map, target, &target_map)
    }

    /// Target leg length over source leg length: how root translations are
    /// scaled.
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// `motion` (of the source rig) played by the target rig, at the same
    /// frame rate.
    pub fn apply(&self, motion: &Motion) -> Result<Motion> {
        self.play(motion, None)
    }

    /// `motion` (of the source rig) played onto `onto`, a motion of the
    /// target rig with as many frames: the mapped joints take `motion`'s
    /// rotations, every other joint keeps its local rotation in `onto`, and
    /// the translations are `onto`'s. What changing a take through another
    /// rig needs (e.g. a denoiser of another rig: its output played back
    /// onto the take keeps the joints it does not know as they were).
    pub fn apply_onto(&self, motion: &Motion, onto: &Motion) -> Result<Motion> {
        if onto.skeleton() != &self.target || onto.frame_count() != motion.frame_count() {
            return Err(Error::Invalid(format!(
                "apply_onto: a motion of the target rig with {} frames is needed",
                motion.frame_count()
            )));
        }
        self.play(motion, Some(onto))
    }

    /// A change made on the source rig carried to a take of the target rig:
    /// `before` and `after` are motions of the source rig (e.g. `onto`
    /// retargeted onto it, and that cleaned by a denoiser of that rig), and
    /// each body joint of `onto` (mapped or aimed) turns in the world as
    /// `after` turns from `before`, both played by the target rig:
    ///
    /// ```text
    /// G_out(j, f) = G_after(j, f) G_before(j, f)^-1 G_onto(j, f)          (2)
    /// ```
    ///
    /// The other joints (fingers, helpers, joints above the pelvis) keep
    /// their local rotations in `onto`, as do all translations. Unlike
    /// [`Retargeting::apply_onto`], what retargeting there and back loses
    /// cancels: when `after` is `before`, `onto` comes back exactly; and a
    /// joint between two mapped ones (CMU's `LHipJoint`) takes the change
    /// of its aim without taking the other rig's bone direction.
    pub fn carry_change(&self, before: &Motion, after: &Motion, onto: &Motion) -> Result<Motion> {
        let frames = onto.frame_count();
        if onto.skeleton() != &self.target
            || before.frame_count() != frames
            || after.frame_count() != frames
        {
            return Err(Error::Invalid(format!(
                "carry_change: two motions of the source rig and one of the target rig, with \
                 as many frames, are needed ({}, {} and {} frames)",
                before.frame_count(),
                after.frame_count(),
                frames
            )));
        }
        let (before, after) = (
            forward_kinematics(&self.apply(before)?),
            forward_kinematics(&self.apply(after)?),
        );
        let given = forward_kinematics(onto);
        let mut out = onto.clone();
        let n = self.target.joint_count();
        let mut rotations = vec![Quat::IDENTITY; n];
        for f in 0..frames {
            for j in 0..n {
                let parent_rotation = self
                    .target
                    .joint(j)
                    .parent
                    .map_or(Quat::IDENTITY, |p| rotations[p]);
                if !matches!(self.roles[j], Role::Rest) {
                    let change = after.rotation(f, j) * before.rotation(f, j).inverse();
                    let global = change * given.rotation(f, j);
                    // Euler angles nearest the take's own: unchanged joints
                    // keep their channel values.
                    let angles = onto.rotation_angles(f, j);
                    let local = (parent_rotation.inverse() * global).normalize();
                    out.set_local_rotation_near(f, j, local, Some(angles));
                }
                // What the channels hold (a joint may lack rotation channels).
                rotations[j] = parent_rotation * out.local_rotation(f, j);
            }
        }
        Ok(out)
    }

    fn play(&self, motion: &Motion, onto: Option<&Motion>) -> Result<Motion> {
        let skeleton = motion.skeleton();
        if skeleton.joint_count() != self.source.joint_count()
            || skeleton
                .joints()
                .iter()
                .zip(self.source.joints())
                .any(|(a, b)| a.name != b.name || a.parent != b.parent)
        {
            return Err(Error::Invalid(
                "this motion is not of the rig the retargeting was prepared for".into(),
            ));
        }
        let frames = motion.frame_count();
        let source = forward_kinematics(motion);
        let mut out = match onto {
            Some(onto) => onto.clone(),
            None => Motion::rest(self.target.clone(), motion.frame_time(), frames)?,
        };
        let n = self.target.joint_count();
        let (pelvis_t, pelvis_s) = self.pelvis;
        let mut rotations = vec![Quat::IDENTITY; n];
        let mut positions = vec![Vec3::ZERO; n];
        for f in 0..frames {
            for j in 0..n {
                let parent = self.target.joint(j).parent;
                let (parent_rotation, parent_position) = parent
                    .map_or((Quat::IDENTITY, Vec3::ZERO), |p| {
                        (rotations[p], positions[p])
                    });
                let translation = out.local_translation(f, j);
                positions[j] = parent_position + parent_rotation * translation;
                let global = match self.roles[j] {
                    _ if onto.is_some() && !matches!(self.roles[j], Role::Mapped { .. }) => {
                        parent_rotation * out.local_rotation(f, j)
                    }
                    Role::Rest => parent_rotation,
                    Role::Mapped {
                        source: s,
                        correction,
                    } => source.rotation(f, s) * correction,
                    Role::Aimed {
                        below,
                        above,
                        source_below,
                        source_above,
                    } => {
                        // Where `below` hangs from `j` at rest, and where it
                        // should be.
                        let mut rest_vector = Vec3::ZERO;
                        let mut k = below;
                        while k != j {
                            let joint = self.target.joint(k);
                            let parent = joint.parent.expect("below j");
                            rest_vector = out.local_translation(f, k) + rest_vector;
                            k = parent;
                        }
                        let wanted = positions[above]
                            + self.scale
                                * (source.position(f, source_below)
                                    - source.position(f, source_above))
                            - positions[j];
                        let current = parent_rotation * rest_vector;
                        if current.length() < 1e-6 || wanted.length() < 1e-6 {
                            parent_rotation
                        } else {
                            Quat::from_rotation_arc(current.normalize(), wanted.normalize())
                                * parent_rotation
                        }
                    }
                };
                out.set_local_rotation(f, j, parent_rotation.inverse() * global);
                // What the channels hold (a joint may lack rotation channels).
                rotations[j] = parent_rotation * out.local_rotation(f, j);
            }
            if onto.is_some() {
                continue;
            }
            // The pelvis goes where the source's is, by the position
            // channels that carry the body (Bandai's rig keeps its root
            // still and moves the pelvis; most rigs move the root); the
            // world shift is taken into the axes of the moved joint's parent
            // (turned when the joints above the pelvis are the source's own).
            let shift = self.scale * source.position(f, pelvis_s) - positions[pelvis_t];
            let moved = self.carrier;
            let above = self
                .target
                .joint(moved)
                .parent
                .map_or(Quat::IDENTITY, |p| rotations[p]);
            let translation = out.local_translation(f, moved);
            out.set_local_translation(f, moved, translation + above.inverse() * shift);
        }
        Ok(out)
    }
}

/// The roles of the target's joints from the body parts both rigs have (see
/// the module docs): mapped parts with their corrections of (1), joints
/// between two mapped ones aimed, the others at rest. `body` lists the
/// target's pelvis and the joints below it.
fn part_roles(reference_s: &ReferenceRig, reference_t: &ReferenceRig, body: &[usize]) -> Vec<Role> {
    let (source_map, target_map) = (reference_s.map, reference_t.map);
    let target = reference_t.skeleton;
    let n = target.joint_count();
    let both = |p: BodyPart| source_map.joint(p).is_some() && target_map.joint(p).is_some();
    // Reference-frame corrections F_s F_t^-1 of (1) in world axes,
    // parts in order so that a part without a bone finds its parent's.
    let mut corrections: [Option<Quat>; BodyPart::COUNT] = [None; BodyPart::COUNT];
    for part in BodyPart::ALL.into_iter().filter(|&p| both(p)) {
        let below = bone_candidates(part).iter().copied().find(|&p| both(p));
        let correction = match below {
            Some(below) => {
                let bone = |rig: &ReferenceRig| {
                    rig.position(below).unwrap_or_default() - rig.position(part).unwrap_or_default()
                };
                let (bone_s, bone_t) = (bone(reference_s), bone(reference_t));
                if bone_s.length() < 1e-6 || bone_t.length() < 1e-6 {
                    None
                } else {
                    let f_s = reference_s.part_frame(part, bone_s);
                    let f_t = reference_t.part_frame(part, bone_t);
                    Some(f_s * f_t.inverse())
                }
            }
            None => None,
        };
        corrections[part.index()] = correction.or_else(|| {
            let mut above = part_above(part);
            while let Some(a) = above {
                if let Some(c) = corrections[a.index()] {
                    return Some(c);
                }
                above = part_above(a);
            }
            Some(Quat::IDENTITY)
        });
    }
    let mut roles = vec![Role::Rest; n];
    // Target joint -> source joint, for mapped parts.
    let mut counterpart = vec![None; n];
    for part in BodyPart::ALL.into_iter().filter(|&p| both(p)) {
        let (j_t, j_s) = (target_map.joint(part), source_map.joint(part));
        if let (Some(j_t), Some(j_s), Some(world)) = (j_t, j_s, corrections[part.index()]) {
            // In the joints' own axes (their reference rotations undone).
            let correction =
                (reference_s.rotations[j_s].inverse() * world * reference_t.rotations[j_t])
                    .normalize();
            roles[j_t] = Role::Mapped {
                source: j_s,
                correction,
            };
            counterpart[j_t] = Some(j_s);
        }
    }
    // Joints between two mapped ones are aimed at the one below.
    for j in 0..n {
        if counterpart[j].is_some() || !body.contains(&j) {
            continue;
        }
        let mut above = target.joint(j).parent;
        while let Some(a) = above {
            if counterpart[a].is_some() {
                break;
            }
            above = target.joint(a).parent;
        }
        // The nearest mapped joint below, breadth first.
        let below = target
            .subtree(j)
            .into_iter()
            .filter(|&k| counterpart[k].is_some())
            .min_by_key(|&k| depth(target, k));
        if let (Some(a), Some(b)) = (above, below) {
            roles[j] = Role::Aimed {
                below: b,
                above: a,
                source_below: counterpart[b].expect("mapped"),
                source_above: counterpart[a].expect("mapped"),
            };
        }
    }
    roles
}

/// Number of joints above `joint`.
fn depth(skeleton: &Skeleton, joint: usize) -> usize {
    let mut d = 0;
    let mut j = joint;
    while let Some(p) = skeleton.joint(j).parent {
        d += 1;
        j = p;
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bandais_standing_pose_is_the_bundled_walks_first_frame() {
        let walk = crate::io::bvh::read_bvh(&mocap_testdata::sample_walk()).unwrap();
        for (name, [x, y, z, w]) in BANDAI_STANDING {
            let j = walk.skeleton().find(name).unwrap();
            let q = Quat::from_xyzw(x, y, z, w).normalize();
            let angle = crate::rotation::angle_between(q, walk.local_rotation(0, j));
            assert!(
                angle.to_degrees() < 0.05,
                "{name}: {} deg",
                angle.to_degrees()
            );
        }
    }
}
