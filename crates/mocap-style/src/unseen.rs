//! Rotations a capture cannot see, filled in from the style model.
//!
//! A skeleton fitted to captured joint positions (a fused Kinect take) gets
//! from them where each bone points, but not how a limb is turned about its
//! bone, nor how the hands, the head and the toes are turned: no joint
//! position depends on those, so the fitter guesses them. The style model
//! was trained on real rotations, and a take with guessed ones is far from
//! all it knows: on fused takes it gives back 66-74 degrees off
//! ([`crate::source_reconstruction_deg`]), against 3-7
//! for their real takes (docs/research/style.md, "Fused takes").
//!
//! [`fill_unseen_rotations`] replaces only what the capture did not see with
//! what the model decodes, keeping what it saw: each joint with one child
//! keeps its bone's direction in the world and takes its turn about that
//! bone from the decoded take; a joint with no child takes its decoded local
//! rotation; a joint with several children (the pelvis, the chest), whose
//! rotation its children's positions fix, keeps its own. Every joint stays
//! where it was; repeated, the decoded take and the filled one agree more.

use mocap_core::rotation::Quat;
use mocap_core::{forward_kinematics, Motion};
use serde::{Deserialize, Serialize};

use crate::features::{compose, decompose};
use crate::train::StyleModel;
use crate::Result;

/// What [`fill_unseen_rotations`] did.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct UnseenFill {
    /// Rounds of decoding and filling.
    pub iterations: usize,
    /// Joints turned about their bone (one child each), and joints with no
    /// child whose rotation was replaced.
    pub twisted_joints: usize,
    pub end_joints: usize,
    /// The farthest any joint moved (file units): rounding only.
    pub largest_joint_move: f32,
}

/// `motion` (of the model's rig) with the rotations a capture cannot see
/// replaced by the model's, `iterations` times (see the module docs); at
/// the model's frame rate, like every source the model reads.
pub fn fill_unseen_rotations(
    model: &StyleModel,
    motion: &Motion,
    iterations: usize,
) -> Result<(Motion, UnseenFill)> {
    let layout = &model.description.rig;
    let original = model.prepare(motion, "source")?;
    let skeleton = original.skeleton().clone();
    let before = forward_kinematics(&original);
    let in_layout: Vec<bool> = (0..skeleton.joint_count())
        .map(|j| layout.joints.contains(&j))
        .collect();
    let children: Vec<Vec<usize>> = (0..skeleton.joint_count())
        .map(|j| skeleton.children(j).collect())
        .collect();
    let mut filled = original.clone();
    for _ in 0..iterations {
        let (rotations, root) = decompose(&filled, layout);
        let latents = model.encode(&model.features(&rotations))?;
        let decoded_rotations = model
            .description
            .normalization
            .rotations(&model.decode(&latents)?);
        let decoded = compose(
            filled.clone(),
            layout,
            &decoded_rotations,
            &root.position,
            &root.heading,
        )?;
        let decoded_poses = forward_kinematics(&decoded);
        let mut next = filled.clone();
        for f in 0..filled.frame_count() {
            let mut global = vec![Quat::IDENTITY; skeleton.joint_count()];
            for j in 0..skeleton.joint_count() {
                let parent = skeleton.joint(j).parent;
                let parent_global = parent.map_or(Quat::IDENTITY, |p| global[p]);
                global[j] = match (in_layout[j], children[j].as_slice()) {
                    (true, [child]) => {
                        let offset = skeleton.joint(*child).offset;
                        let seen = before.position(f, *child) - before.position(f, j);
                        let guess = decoded_poses.rotation(f, j);
                        if offset.length() < 1e-6 || seen.length() < 1e-6 {
                            before.rotation(f, j)
                        } else {
                            // The decoded rotation, swung the shortest way
                            // onto the bone the capture saw.
                            let swing = Quat::from_rotation_arc(
                                (guess * offset).normalize(),
                                seen.normalize(),
                            );
                            swing * guess
                        }
                    }
                    (true, []) => parent_global * decoded.local_rotation(f, j),
                    _ => before.rotation(f, j),
                };
                next.set_local_rotation(f, j, (parent_global.inverse() * global[j]).normalize());
            }
        }
        filled = next;
    }
    let after = forward_kinematics(&filled);
    let largest_joint_move = before
        .positions
        .iter()
        .zip(&after.positions)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0f32, f32::max);
    let count = |n: usize| {
        (0..skeleton.joint_count())
            .filter(|&j| in_layout[j] && children[j].len() == n)
            .count()
    };
    let report = UnseenFill {
        iterations,
        twisted_joints: count(1),
        end_joints: count(0),
        largest_joint_move,
    };
    Ok((filled, report))
}
