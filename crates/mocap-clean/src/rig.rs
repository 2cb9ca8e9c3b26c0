//! Takes of other rigs, cleaned by a model of one rig through retargeting.
//!
//! A network reads its rig's joints in their places, so a model is trained
//! on one rig: the shipped one on Bandai Namco's, which has a joint for
//! every body part and nothing else. A take of any rig whose body parts are
//! found ([`BodyMap::detect`], or a rig file) is played by the model's rig
//! ([`Retargeting::new`]: each rig related to its canonical T-pose, so where
//! the take starts does not matter), cleaned there, and what the cleaning
//! changed is carried back onto the take ([`Retargeting::carry_change`],
//! rule (2) there): each body part of the take turns in the world as the
//! model turned it, so a take the model leaves alone comes back exactly,
//! however much the way there and back loses. The take's other joints:
//!
//! - joints between two body parts (CMU's `LHipJoint` and `LowerBack`, a
//!   Daz buttock, a fourth spine joint), and body parts the model's rig
//!   lacks (a Kinect skeleton's hands, below its wrists) are cleaned by the
//!   cross-validated Butterworth (`butterworth-gcv:2`), and the parts below
//!   them keep the rotations in the world the model gave them: left noisy,
//!   such a joint's noise would stay in the local rotation of every part
//!   below it, or in a hand;
//! - the others (fingers, end and helper joints, joints above the pelvis)
//!   pass through untouched, as do all translations.
//!
//! How well this cleans, rig by rig, is measured in bench/results/clean.md
//! ("Other rigs").

use std::sync::OnceLock;

use mocap_core::bodymap::{BodyMap, BodyPart};
use mocap_core::forward_kinematics;
use mocap_core::io::bvh::read_bvh_from;
use mocap_core::retarget::Retargeting;
use mocap_core::rotation::Quat;
use mocap_core::{Motion, Skeleton};

use crate::filters::{filter_joints, Filter};
use crate::{CleanError, Result};

/// The shipped model's rig: Bandai Namco's, in the first frame of the
/// bundled walk (`samples/dataset-1_walk_normal_001.bvh`, whose licence
/// covers it).
const SHIPPED_RIG_BVH: &str = include_str!("../../../models/clean-rig.bvh");

/// The filter of the joints the model cannot clean ([`filtered_joints`]).
const FALLBACK_FILTER: Filter = Filter::ButterworthGcv { order: 2 };

/// The rig a model was trained on, which takes of other rigs are played by.
#[derive(Debug, Clone)]
pub(crate) struct ModelRig {
    skeleton: Skeleton,
    map: BodyMap,
}

impl ModelRig {
    /// The shipped model's rig, when `joints` (the names of a model's joints
    /// with rotations, in order) are its joints: any model trained on
    /// Bandai takes. Read once per process.
    pub(crate) fn shipped_for(joints: &[String]) -> Option<&'static ModelRig> {
        static SHIPPED: OnceLock<(ModelRig, Vec<String>)> = OnceLock::new();
        let (rig, names) = SHIPPED.get_or_init(|| {
            let skeleton = read_bvh_from(
                SHIPPED_RIG_BVH.as_bytes(),
                "<built-in models/clean-rig.bvh>".as_ref(),
            )
            .expect("the built-in rig reads")
            .skeleton()
            .clone();
            let names = skeleton
                .joints()
                .iter()
                .filter(|j| j.has_rotation_channels())
                .map(|j| j.name.clone())
                .collect();
            let map = BodyMap::detect(&skeleton).expect("the built-in rig's body parts are found");
            (ModelRig { skeleton, map }, names)
        });
        (names == joints).then_some(rig)
    }

    /// Cleans `motion`, a take of another rig, with `clean` (which cleans
    /// takes of this rig), as the module docs say; also passes on what
    /// `clean` says. Fails, naming the missing parts, when the take's body
    /// parts are not found.
    pub(crate) fn clean_through<T>(
        &self,
        motion: &Motion,
        clean: impl FnOnce(&Motion) -> Result<(Motion, T)>,
    ) -> Result<(Motion, T)> {
        let skeleton = motion.skeleton();
        let map = self.body_map(motion)?;
        let there = Retargeting::new(skeleton, &map, &self.skeleton, &self.map)?;
        let back = Retargeting::new(&self.skeleton, &self.map, skeleton, &map)?;
        let played = there.apply(motion)?;
        let (cleaned, said) = clean(&played)?;
        let carried = back.carry_change(&played, &cleaned, motion)?;
        let joints = filtered_joints(motion, &map, &self.map);
        if joints.is_empty() {
            return Ok((carried, said));
        }
        let filtered = filter_joints(motion, &FALLBACK_FILTER, |j| joints.contains(&j))?;
        Ok((with_locals_of(&carried, &filtered, &joints, &map), said))
    }

    /// The rig's name, as the body map's tables give it.
    pub(crate) fn name(&self) -> &str {
        self.map.rig()
    }

    /// `Ok` when takes of `motion`'s rig can be cleaned through this one:
    /// their body parts are found.
    pub(crate) fn check(&self, motion: &Motion) -> Result<()> {
        self.body_map(motion).map(|_| ())
    }

    fn body_map(&self, motion: &Motion) -> Result<BodyMap> {
        BodyMap::detect(motion.skeleton()).map_err(|e| {
            CleanError::Invalid(format!(
                "the model was trained on the {} rig and cleans takes of other rigs through \
                 their body parts, but {e}",
                self.map.rig()
            ))
        })
    }
}

/// The joints of `motion`'s rig (body parts `map`) that the model cannot
/// clean and the filter does: below the pelvis, with rotation channels,
/// either a body part the model's rig (`model_map`) lacks or no body part
/// but with one below it.
fn filtered_joints(motion: &Motion, map: &BodyMap, model_map: &BodyMap) -> Vec<usize> {
    let skeleton = motion.skeleton();
    let Some(pelvis) = map.joint(BodyPart::Pelvis) else {
        return Vec::new();
    };
    let parts: Vec<usize> = map.parts().map(|(_, j)| j).collect();
    let unmatched: Vec<usize> = map
        .parts()
        .filter(|&(p, _)| model_map.joint(p).is_none())
        .map(|(_, j)| j)
        .collect();
    skeleton
        .subtree(pelvis)
        .into_iter()
        .filter(|&j| {
            skeleton.joint(j).has_rotation_channels()
                && (unmatched.contains(&j)
                    || (!parts.contains(&j)
                        && skeleton.subtree(j).iter().any(|k| parts.contains(k))))
        })
        .collect()
}

/// `motion` with the local rotations of `joints` taken from `from`, and
/// every other body part keeping its rotation in the world (its local
/// rotation made anew under its new parents); the other joints keep their
/// local rotations.
fn with_locals_of(motion: &Motion, from: &Motion, joints: &[usize], map: &BodyMap) -> Motion {
    let skeleton = motion.skeleton();
    let parts: Vec<usize> = map.parts().map(|(_, j)| j).collect();
    let world = forward_kinematics(motion);
    let mut out = motion.clone();
    let mut rotations = vec![Quat::IDENTITY; skeleton.joint_count()];
    for f in 0..motion.frame_count() {
        for j in 0..skeleton.joint_count() {
            let parent = skeleton
                .joint(j)
                .parent
                .map_or(Quat::IDENTITY, |p| rotations[p]);
            if joints.contains(&j) {
                out.set_local_rotation(f, j, from.local_rotation(f, j));
            } else if parts.contains(&j) {
                let angles = motion.rotation_angles(f, j);
                let local = (parent.inverse() * world.rotation(f, j)).normalize();
                out.set_local_rotation_near(f, j, local, Some(angles));
            }
            rotations[j] = parent * out.local_rotation(f, j);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use mocap_core::io::bvh::read_bvh;
    use mocap_core::rotation::angle_between;

    use super::*;

    fn shipped() -> &'static ModelRig {
        let rig = read_bvh_from(SHIPPED_RIG_BVH.as_bytes(), "rig".as_ref()).unwrap();
        let joints: Vec<String> = rig
            .skeleton()
            .joints()
            .iter()
            .filter(|j| j.has_rotation_channels())
            .map(|j| j.name.clone())
            .collect();
        assert!(ModelRig::shipped_for(&joints[1..]).is_none());
        ModelRig::shipped_for(&joints).expect("the shipped rig's own joints")
    }

    #[test]
    fn a_take_left_alone_by_the_model_keeps_its_parts_and_its_fingers() {
        let Some(path) =
            mocap_testdata::shared("parser-cases/dme_example_crlf_leadingdot_frametime.bvh")
        else {
            eprintln!("../shared/data is absent: skipped");
            return;
        };
        let take = read_bvh(&path).unwrap();
        let rig = shipped();
        let (out, ()) = rig.clean_through(&take, |m| Ok((m.clone(), ()))).unwrap();
        let skeleton = take.skeleton();
        let map = BodyMap::detect(skeleton).unwrap();
        let filtered = filtered_joints(&take, &map, &rig.map);
        let names: Vec<&str> = filtered
            .iter()
            .map(|&j| skeleton.joint(j).name.as_str())
            .collect();
        assert!(names.contains(&"LHipJoint"), "{names:?}");
        let (a, b) = (forward_kinematics(&take), forward_kinematics(&out));
        // The parts the model's rig has keep their rotations in the world.
        for (part, j) in map.parts().filter(|(_, j)| !filtered.contains(j)) {
            for f in 0..take.frame_count() {
                let e = angle_between(a.rotation(f, j), b.rotation(f, j)).to_degrees();
                assert!(e < 0.01, "{part:?}: turned by {e} deg in frame {f}");
            }
        }
        let parts: Vec<usize> = map.parts().map(|(_, j)| j).collect();
        let mut untouched = 0;
        for j in (0..skeleton.joint_count()).filter(|j| !parts.contains(j) && !filtered.contains(j))
        {
            for f in 0..take.frame_count() {
                assert_eq!(take.joint_values(f, j), out.joint_values(f, j));
            }
            untouched += 1;
        }
        assert!(untouched > 0);
        // The joints between parts are the filter's.
        let filter_output =
            filter_joints(&take, &FALLBACK_FILTER, |j| filtered.contains(&j)).unwrap();
        for &j in &filtered {
            for f in 0..take.frame_count() {
                let e = angle_between(filter_output.local_rotation(f, j), out.local_rotation(f, j));
                assert!(e.to_degrees() < 0.01);
            }
        }
    }
}
