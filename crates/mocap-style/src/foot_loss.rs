//! A training loss on the feet: the autoencoder's reconstruction should
//! keep a flat foot as still as the clip it reconstructs.
//!
//! Decoded from its own latent codes, a walk's flat feet slide about 24 cm/s
//! where the real take's stand still (4-7.5 cm/s; bench/results/style.md,
//! "The root and the feet"): each leg rotation comes back a few degrees
//! off, and the error changes from frame to frame. The reconstruction loss
//! weighs every channel alike and does not see that a degree at the hip is
//! 1.5 cm at the ankle. This term does: for the ankles and toes, their
//! positions relative to the pelvis (forward kinematics of the features,
//! heading removed as in [`crate::features`]) are computed for the output
//! and for the target, and on every frame step where the target's foot is
//! flat on the ground (both joints within 2% of the leg length of their
//! lowest height, as `eval::planted_foot_sliding` measures) the change of
//! their difference is penalised:
//!
//! ```text
//! L_feet = sum_{b, j, t in contacts} |d_j(t) - d_j(t-1)|^2 / (n_contacts * leg^2),
//! d_j(t) = p_j(output, t) - p_j(target, t)
//! ```
//!
//! A foot that stands still in the target then stands still in the output
//! (up to the same pelvis motion, which both share), whatever constant
//! offset the reconstruction leaves.
//!
//! Forward kinematics in tensors: a slot's rotation is `r_k exp(v)`, with
//! `v` the de-standardised exponential map and `exp(v)` by Rodrigues'
//! formula, `R = (1 - b t^2) I + a K + b v v^T` (`t = |v|`, `a = sin t / t`,
//! `b = (1 - cos t) / t^2`, `K` the cross-product matrix of `v`); then
//! `x_j = x_p + R_p o_j`, `R_j = R_p L_j` down each leg from the pelvis
//! (`mocap_nn::kinematics`, shared with `mocap-clean`'s position loss).

use burn::tensor::{Device, Tensor, TensorData};
use mocap_core::metrics;
use mocap_core::rotation::{Mat3, Quat};
use mocap_core::{forward_kinematics, Motion, Skeleton};
use mocap_nn::kinematics::{child_position, compose, Columns};

use crate::features::{up_axis, Normalization, RigLayout, SLOT_DIM};

/// Forward kinematics of the feet, from standardised features.
#[derive(Debug, Clone)]
pub struct FootKinematics {
    /// Per foot joint (left ankle, left toe, right ankle, right toe), the
    /// chain below the pelvis down to it: (slot of the joint's rotation, or
    /// `None` for a joint without one; offset from its parent).
    chains: Vec<Vec<(Option<usize>, [f32; 3])>>,
    /// Reference rotation of every slot (row-major 3x3).
    reference: Vec<[[f32; 3]; 3]>,
    mean: Vec<f32>,
    std: Vec<f32>,
    leg: f32,
}

impl FootKinematics {
    /// The feet of `rig` with the bone offsets of `skeleton`.
    pub fn new(skeleton: &Skeleton, rig: &RigLayout, normalization: &Normalization) -> Self {
        let slot_of = |j: usize| rig.joints.iter().position(|&k| k == j).map(|i| i + 1);
        let chains = rig
            .left_foot
            .iter()
            .chain(&rig.right_foot)
            .map(|&foot| {
                let mut chain = Vec::new();
                let mut j = foot;
                while j != rig.pelvis {
                    chain.push((slot_of(j), skeleton.joint(j).offset.to_array()));
                    j = rig.parents[j].expect("a foot joint below the pelvis");
                }
                chain.reverse();
                chain
            })
            .collect();
        let reference = normalization
            .reference
            .iter()
            .map(|q| {
                let m = Mat3::from_quat(Quat::from_array(*q));
                [0, 1, 2].map(|r| [0, 1, 2].map(|c| m.col(c)[r]))
            })
            .collect();
        FootKinematics {
            chains,
            reference,
            mean: normalization.mean.clone(),
            std: normalization.std.clone(),
            leg: rig.leg_length(skeleton).max(1e-6),
        }
    }

    /// Positions of the foot joints relative to the pelvis (heading
    /// removed), `[batch, 3 * feet, frames]`, in leg lengths.
    pub fn positions(&self, features: Tensor<3>) -> Tensor<3> {
        let [batch, _, frames] = features.dims();
        let device = features.device();
        let slot = |k: usize| -> Columns {
            let channel = |i: usize| {
                let c = k * SLOT_DIM + i;
                features.clone().narrow(1, c, 1) * self.std[c] + self.mean[c]
            };
            let v = [channel(0), channel(1), channel(2)];
            let local = exp_columns(&v);
            // Column i of R_ref R_v is R_ref applied to column i of R_v.
            let r = &self.reference[k];
            local.map(|col| {
                let [x, y, z] = [0, 1, 2].map(|i| col.clone().narrow(1, i, 1));
                Tensor::cat(
                    [0, 1, 2]
                        .map(|row| {
                            x.clone() * r[row][0] + y.clone() * r[row][1] + z.clone() * r[row][2]
                        })
                        .to_vec(),
                    1,
                )
            })
        };
        // Each slot's rotation once: an ankle's and a toe's chains share the
        // hip, knee and ankle. The last joint of a chain needs no rotation.
        let mut locals: Vec<Option<Columns>> = (0..self.reference.len()).map(|_| None).collect();
        locals[0] = Some(slot(0));
        for chain in &self.chains {
            for (slot_index, _) in &chain[..chain.len().saturating_sub(1)] {
                if let Some(k) = *slot_index {
                    if locals[k].is_none() {
                        locals[k] = Some(slot(k));
                    }
                }
            }
        }
        let local = |k: usize| locals[k].as_ref().expect("computed above");
        let mut out = Vec::with_capacity(self.chains.len());
        for chain in &self.chains {
            let mut rotation = local(0).clone();
            let mut position = Tensor::<3>::zeros([batch, 3, frames], &device);
            let last = chain.len().saturating_sub(1);
            for (i, (slot_index, offset)) in chain.iter().enumerate() {
                position = child_position(position, &rotation, *offset);
                if let (Some(k), true) = (slot_index, i < last) {
                    rotation = compose(&rotation, local(*k));
                }
            }
            out.push(position / self.leg);
        }
        Tensor::cat(out, 1)
    }

    /// `L_feet` (module docs) for outputs and targets `[batch, channels,
    /// frames]` and per-step contact weights `[batch, feet, frames - 1]`
    /// (1 where the target's foot is flat on the ground at both frames).
    pub fn loss(&self, output: Tensor<3>, target: Tensor<3>, contacts: Tensor<3>) -> Tensor<1> {
        let [batch, _, frames] = output.dims();
        let feet = self.chains.len();
        let d = self.positions(output) - self.positions(target);
        let step = d.clone().narrow(2, 1, frames - 1) - d.narrow(2, 0, frames - 1);
        // [batch, 3 * feet, frames - 1] -> squared length per foot joint.
        let squared = step
            .powi_scalar(2)
            .reshape([batch, feet, 3, frames - 1])
            .sum_dim(2)
            .reshape([batch, feet, frames - 1]);
        let count = contacts.clone().sum().clamp_min(1.0);
        (squared * contacts).sum() / count
    }

    /// Number of foot joints (ankles and toes).
    pub fn feet(&self) -> usize {
        self.chains.len()
    }
}

/// Columns of `exp(v)` (Rodrigues) for `v = [x, y, z]`, each `[batch, 1,
/// frames]`.
fn exp_columns(v: &[Tensor<3>; 3]) -> Columns {
    let [x, y, z] = v.clone();
    let t2 = (x.clone().powi_scalar(2) + y.clone().powi_scalar(2) + z.clone().powi_scalar(2))
        .clamp_min(1e-12);
    let t = t2.clone().sqrt();
    let a = t.clone().sin() / t.clone();
    let b = (t.cos().neg() + 1.0) / t2.clone();
    let diag = (b.clone() * t2).neg() + 1.0;
    let col = |c: [Tensor<3>; 3]| Tensor::cat(c.to_vec(), 1);
    [
        col([
            diag.clone() + b.clone() * x.clone() * x.clone(),
            a.clone() * z.clone() + b.clone() * x.clone() * y.clone(),
            a.clone().neg() * y.clone() + b.clone() * x.clone() * z.clone(),
        ]),
        col([
            a.clone().neg() * z.clone() + b.clone() * x.clone() * y.clone(),
            diag.clone() + b.clone() * y.clone() * y.clone(),
            a.clone() * x.clone() + b.clone() * y.clone() * z.clone(),
        ]),
        col([
            a.clone() * y.clone() + b.clone() * x.clone() * z.clone(),
            a.neg() * x.clone() + b.clone() * y.clone() * z.clone(),
            diag + b * z.clone() * z,
        ]),
    ]
}

/// Per frame step `f - 1 -> f` (entry `f - 1`) and foot joint (left ankle,
/// left toe, right ankle, right toe), 1 where that joint's foot is flat on
/// the ground at both frames: ankle and toe within 2% of the leg length of
/// their lowest heights (as `eval::planted_foot_sliding`), else 0. Frame
/// after frame, `feet` values per step.
pub fn flat_foot_steps(motion: &Motion, rig: &RigLayout) -> Vec<f32> {
    let poses = forward_kinematics(motion);
    let up = up_axis(&poses.positions, poses.joint_count, rig);
    let feet = [rig.left_foot.as_slice(), rig.right_foot.as_slice()];
    let flat = metrics::flat_foot_steps(&poses, feet, up, rig.leg_length(motion.skeleton()));
    let mut out = Vec::new();
    for step in 0..poses.frame_count.saturating_sub(1) {
        for (steps, foot) in flat.iter().zip([&rig.left_foot, &rig.right_foot]) {
            out.extend(std::iter::repeat_n(steps[step] as u8 as f32, foot.len()));
        }
    }
    out
}

/// `[batch, feet, steps]` tensor of per-window contact steps (each window
/// `steps * feet` values, step after step).
pub fn contacts_tensor(
    values: &[f32],
    batch: usize,
    feet: usize,
    steps: usize,
    device: &Device,
) -> Tensor<3> {
    let mut t = vec![0.0; batch * feet * steps];
    for b in 0..batch {
        for s in 0..steps {
            for j in 0..feet {
                t[(b * feet + j) * steps + s] = values[(b * steps + s) * feet + j];
            }
        }
    }
    Tensor::from_data(TensorData::new(t, [batch, feet, steps]), device)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::test_support::bandai_walk;
    use crate::features::decompose;
    use crate::train::to_tensor;

    /// The tensor forward kinematics gives the feet where the core's does
    /// (relative to the pelvis, heading removed), on a real walk.
    #[test]
    fn matches_the_core_forward_kinematics_on_a_real_walk() {
        let Some(motion) = bandai_walk("dataset-1_walk_proud_002.bvh") else {
            return;
        };
        let rig = RigLayout::from_skeleton(motion.skeleton()).unwrap();
        let (rotations, root) = decompose(&motion, &rig);
        let normalization = Normalization::fit(&[&rotations], rig.slots()).unwrap();
        let features = normalization.features(&rotations);
        let frames = motion.frame_count();
        let x = to_tensor(&features, frames, rig.channels(), &Device::flex());
        let fk = FootKinematics::new(motion.skeleton(), &rig, &normalization);
        let out: Vec<f32> = fk.positions(x).into_data().try_to_vec().unwrap();
        let poses = forward_kinematics(&motion);
        let leg = rig.leg_length(motion.skeleton());
        let mut worst = 0.0f32;
        for f in 0..frames {
            let to_body = root.heading[f].inverse();
            for (i, &j) in rig.left_foot.iter().chain(&rig.right_foot).enumerate() {
                let expected =
                    to_body * (poses.position(f, j) - poses.position(f, rig.pelvis)) / leg;
                for a in 0..3 {
                    let got = out[(3 * i + a) * frames + f];
                    worst = worst.max((got - expected.to_array()[a]).abs());
                }
            }
        }
        assert!(worst < 1e-3, "largest difference {worst} leg lengths");
    }

    /// The loss is zero for the target itself, small for a constant error
    /// of a hip's rotation, large for one that wobbles from frame to frame.
    #[test]
    fn the_loss_counts_changes_of_the_feet_error_on_contact_steps() {
        let Some(motion) = bandai_walk("dataset-1_walk_proud_002.bvh") else {
            return;
        };
        let rig = RigLayout::from_skeleton(motion.skeleton()).unwrap();
        let (rotations, _) = decompose(&motion, &rig);
        let normalization = Normalization::fit(&[&rotations], rig.slots()).unwrap();
        let features = normalization.features(&rotations);
        let (channels, frames) = (rig.channels(), motion.frame_count());
        let device = Device::flex();
        let tensor = |shift: &dyn Fn(usize, usize) -> f32| {
            let shifted: Vec<f32> = (0..features.len())
                .map(|i| features[i] + shift(i / channels, i % channels))
                .collect();
            to_tensor(&shifted, frames, channels, &device)
        };
        let fk = FootKinematics::new(motion.skeleton(), &rig, &normalization);
        let steps = flat_foot_steps(&motion, &rig);
        let feet = fk.feet();
        assert_eq!(steps.len(), (frames - 1) * feet);
        let on = steps.iter().filter(|&&v| v > 0.0).count();
        assert!(
            on > steps.len() / 10,
            "{on} of {} contact steps",
            steps.len()
        );
        let contacts = contacts_tensor(&steps, 1, feet, frames - 1, &device);
        let loss = |output: Tensor<3>| -> f32 {
            fk.loss(output, tensor(&|_, _| 0.0), contacts.clone())
                .into_scalar()
        };
        // The left hip slot (its first channel) turned by a constant, or
        // wobbling from frame to frame.
        let hip = SLOT_DIM * rig.joints.iter().position(|&j| j == rig.left_hip).unwrap() + SLOT_DIM;
        let constant = loss(tensor(&|_, c| if c == hip { 0.5 } else { 0.0 }));
        let wobble = loss(tensor(&|f, c| {
            if c == hip && f % 2 == 1 {
                0.5
            } else {
                0.0
            }
        }));
        assert_eq!(loss(tensor(&|_, _| 0.0)), 0.0);
        // A constant turn moves the feet's error only as slowly as the leg
        // moves (1.7e-6 against 1.5e-4 for the wobble).
        assert!(
            constant < 0.05 * wobble,
            "constant {constant}, wobble {wobble}"
        );
        assert!(wobble > 1e-5, "{wobble}");
    }
}
