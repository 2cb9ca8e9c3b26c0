//! The take's geometry the feet stage needs: the up axis, the legs, each
//! foot joint's height and horizontal speed, frame by frame.

use mocap_core::bodymap::{BodyMap, BodyPart};
use mocap_core::metrics::{foot_joints, up_axis};
use mocap_core::rotation::Vec3;
use mocap_core::{Error, GlobalPoses, Motion, Result};

/// One leg: the joints of its two-bone chain and its foot.
#[derive(Debug, Clone, PartialEq)]
pub struct Leg {
    pub hip: usize,
    pub knee: usize,
    pub ankle: usize,
    /// The foot's joints: the ankle, then the toe when the rig has one.
    pub foot: Vec<usize>,
}

/// The joints the feet stage moves and reads, found with the body map.
#[derive(Debug, Clone, PartialEq)]
pub struct FeetRig {
    /// Left, right.
    pub legs: [Leg; 2],
    pub pelvis: usize,
    pub head: usize,
    /// The joint whose position channels carry the body (the pelvis or the
    /// nearest joint above it that has position channels); `None` when no
    /// joint from the root down to the pelvis has any: the root cannot be
    /// lowered then.
    pub carrier: Option<usize>,
    /// Rest length of the legs, hip to ankle, averaged over both (file units).
    pub leg_length: f32,
}

impl FeetRig {
    /// The legs of `motion`'s skeleton as `map` locates them. Fails, naming
    /// every missing part and what the stage needs, when the map lacks a
    /// hip, knee or ankle, the pelvis or the head, or when a leg is not one
    /// chain (hip above knee above ankle) that can turn.
    pub fn new(motion: &Motion, map: &BodyMap) -> Result<FeetRig> {
        let skeleton = motion.skeleton();
        let needed = [
            BodyPart::Pelvis,
            BodyPart::Head,
            BodyPart::LeftHip,
            BodyPart::LeftKnee,
            BodyPart::LeftAnkle,
            BodyPart::RightHip,
            BodyPart::RightKnee,
            BodyPart::RightAnkle,
        ];
        let missing: Vec<String> = needed
            .iter()
            .filter(|&&p| map.joint(p).is_none())
            .map(|p| p.key().to_string())
            .collect();
        if !missing.is_empty() {
            return Err(Error::Invalid(format!(
                "the feet stage needs both legs (hip, knee, ankle), the pelvis and the head; \
                 the {} rig has no joint for {}; name them in a rig file ([parts] {} = \
                 \"joint name\") given with `mocap --rig FILE` (docs/rigs.md)",
                map.rig(),
                missing.join(", "),
                missing[0],
            )));
        }
        let part = |p| map.require(p);
        let [left_foot, right_foot] = foot_joints(map)?;
        let leg = |hip, knee, ankle, foot: Vec<usize>| -> Result<Leg> {
            let (hip, knee, ankle) = (part(hip)?, part(knee)?, part(ankle)?);
            let name = |j: usize| skeleton.joint(j).name.clone();
            if skeleton.chain_length(knee, hip).is_none()
                || skeleton.chain_length(ankle, knee).is_none()
                || knee == hip
                || ankle == knee
            {
                return Err(Error::Invalid(format!(
                    "the {} rig's leg is not one chain: hip `{}`, knee `{}` and ankle `{}` \
                     must each be above the next",
                    map.rig(),
                    name(hip),
                    name(knee),
                    name(ankle)
                )));
            }
            for j in [hip, knee, ankle] {
                if !skeleton.joint(j).has_rotation_channels() {
                    return Err(Error::Invalid(format!(
                        "the leg joint `{}` has no rotation channels: the feet stage turns \
                         the hip and the knee and keeps the ankle's orientation",
                        name(j)
                    )));
                }
            }
            Ok(Leg {
                hip,
                knee,
                ankle,
                foot,
            })
        };
        let legs = [
            leg(
                BodyPart::LeftHip,
                BodyPart::LeftKnee,
                BodyPart::LeftAnkle,
                left_foot,
            )?,
            leg(
                BodyPart::RightHip,
                BodyPart::RightKnee,
                BodyPart::RightAnkle,
                right_foot,
            )?,
        ];
        Ok(FeetRig {
            legs,
            pelvis: part(BodyPart::Pelvis)?,
            head: part(BodyPart::Head)?,
            carrier: map.position_carrier(skeleton),
            leg_length: map.leg_length(skeleton)?,
        })
    }

    /// Every foot joint, left foot first.
    pub fn foot_joints(&self) -> [&[usize]; 2] {
        [&self.legs[0].foot, &self.legs[1].foot]
    }
}

/// Per frame, a joint's height along up and its horizontal speed.
#[derive(Debug, Clone)]
pub struct JointTrack {
    pub height: Vec<f32>,
    /// Units per second, central differences (one-sided at the ends).
    pub speed: Vec<f32>,
}

/// The take's up axis (pelvis to head).
pub fn up(poses: &GlobalPoses, rig: &FeetRig) -> Vec3 {
    up_axis(poses, rig.pelvis, rig.head)
}

/// The height and horizontal speed of `joint` in every frame.
pub fn track(poses: &GlobalPoses, joint: usize, up: Vec3, fps: f32) -> JointTrack {
    let n = poses.frame_count;
    let height = (0..n).map(|f| poses.position(f, joint).dot(up)).collect();
    let speed = (0..n)
        .map(|f| {
            let (a, b) = (f.saturating_sub(1), (f + 1).min(n.saturating_sub(1)));
            if b <= a {
                return 0.0;
            }
            let d = poses.position(b, joint) - poses.position(a, joint);
            d.reject_from_normalized(up).length() * fps / (b - a) as f32
        })
        .collect();
    JointTrack { height, speed }
}

/// The `q`-quantile (0..=1) of `values` (nearest rank), `None` when empty.
pub fn quantile(values: &[f32], q: f32) -> Option<f32> {
    if values.is_empty() {
        return None;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(|a, b| a.total_cmp(b));
    let k = ((sorted.len() - 1) as f32 * q.clamp(0.0, 1.0)).round() as usize;
    Some(sorted[k])
}
