//! Forward kinematics on batches of 6D features, in burn tensors, for the
//! position term of the loss ([`crate::loss::position_loss`]).
//!
//! The rotation loss treats every joint on its own. The chain-corrected
//! noise (see `noise.rs`) gives parent and child local errors that cancel in
//! positions; a network that removes part of each joint's error
//! independently loses that cancellation and moves the hands and feet away.
//! A loss on joint positions sees the chain as a whole.
//!
//! The math is `mocap_core::kinematics` (root-relative: the root translation
//! is not a feature and is the same in prediction and target, so it is left
//! out):
//!
//! ```text
//! R_j = R_p * L_j          x_j = x_p + R_p * t_j         R_root = L_root, x_root = 0
//! ```
//!
//! with `L_j` the local rotation rebuilt from the joint's 6D features by
//! Gram-Schmidt exactly as `mocap_core::rotation::rot6d_to_quat` does
//! (`b1 = a1/|a1|`, `b2 = normalise(a2 - (b1.a2) b1)`, `b3 = b1 x b2`, the
//! columns of the matrix), and `t_j` the joint's offset. Joints without
//! rotation channels have `L_j = I`. A tensor `[batch, 3, frames]` holds one
//! 3-vector per sample and frame; a rotation is its three columns.

use burn::tensor::Tensor;
use mocap_core::Skeleton;
use mocap_nn::kinematics::{child_position, compose, Columns};

use crate::features::{FeatureLayout, Representation, RotationFrame};
use crate::{CleanError, Result};

/// The skeleton the position loss runs forward kinematics on.
#[derive(Debug, Clone, PartialEq)]
pub struct FkSkeleton {
    parents: Vec<Option<usize>>,
    offsets: Vec<[f32; 3]>,
    /// Feature joint index (in the layout) of each skeleton joint.
    feature: Vec<Option<usize>>,
}

fn norm(v: &Tensor<3>) -> Tensor<3> {
    // The clamp keeps degenerate (zero) columns finite; trained features are
    // far from zero.
    v.clone().powi_scalar(2).sum_dim(1).clamp_min(1e-12).sqrt()
}

/// Components shifted by one (`(y, z, x)`) and by two (`(z, x, y)`).
fn rotate1(v: &Tensor<3>) -> Tensor<3> {
    Tensor::cat(
        vec![v.clone().narrow(1, 1, 2), v.clone().narrow(1, 0, 1)],
        1,
    )
}
fn rotate2(v: &Tensor<3>) -> Tensor<3> {
    Tensor::cat(
        vec![v.clone().narrow(1, 2, 1), v.clone().narrow(1, 0, 2)],
        1,
    )
}

/// The rotation of one joint's 6D features `[batch, 6, frames]`.
fn rot6d_columns(f: Tensor<3>) -> Columns {
    let a1 = f.clone().narrow(1, 0, 3);
    let a2 = f.narrow(1, 3, 3);
    let b1 = a1.clone() / norm(&a1);
    let u = a2.clone() - b1.clone() * (b1.clone() * a2).sum_dim(1);
    let b2 = u.clone() / norm(&u);
    // b1 x b2 = rotate1(b1) * rotate2(b2) - rotate2(b1) * rotate1(b2).
    let b3 = rotate1(&b1) * rotate2(&b2) - rotate2(&b1) * rotate1(&b2);
    [b1, b2, b3]
}

impl FkSkeleton {
    /// The skeleton of `layout` (6D features only).
    pub fn new(skeleton: &Skeleton, layout: &FeatureLayout) -> Result<FkSkeleton> {
        if layout.representation != Representation::Rot6d {
            return Err(CleanError::Invalid(format!(
                "the position loss needs 6D features, not {}",
                layout.representation.name()
            )));
        }
        if layout.frame != RotationFrame::Local {
            return Err(CleanError::Invalid(format!(
                "the position loss needs local rotations, not rotations in the {} frame",
                layout.frame.name()
            )));
        }
        let mut feature = vec![None; skeleton.joint_count()];
        for (k, &j) in layout.joints.iter().enumerate() {
            feature[j] = Some(k);
        }
        Ok(FkSkeleton {
            parents: skeleton.joints().iter().map(|j| j.parent).collect(),
            offsets: skeleton
                .joints()
                .iter()
                .map(|j| j.offset.to_array())
                .collect(),
            feature,
        })
    }

    /// Root-relative positions of all joints for features `[batch, channels,
    /// frames]`, concatenated as `[batch, 3 * joints, frames]`.
    pub fn positions(&self, features: Tensor<3>) -> Tensor<3> {
        let [batch, _, frames] = features.dims();
        let device = features.device();
        let mut rotations: Vec<Columns> = Vec::with_capacity(self.parents.len());
        let mut positions: Vec<Tensor<3>> = Vec::with_capacity(self.parents.len());
        for (j, parent) in self.parents.iter().enumerate() {
            let local = self
                .feature
                .get(j)
                .copied()
                .flatten()
                .map(|k| rot6d_columns(features.clone().narrow(1, 6 * k, 6)));
            let (rotation, position) = match parent {
                None => {
                    let rotation = local.unwrap_or_else(|| identity(batch, frames, &device));
                    (rotation, Tensor::zeros([batch, 3, frames], &device))
                }
                Some(p) => {
                    let rp = &rotations[*p];
                    let position = child_position(positions[*p].clone(), rp, self.offsets[j]);
                    let rotation = match local {
                        Some(l) => compose(rp, &l),
                        None => rp.clone(),
                    };
                    (rotation, position)
                }
            };
            rotations.push(rotation);
            positions.push(position);
        }
        Tensor::cat(positions, 1)
    }
}

fn identity(batch: usize, frames: usize, device: &burn::tensor::Device) -> Columns {
    let column = |i: usize| {
        let mut data = vec![0.0f32; batch * 3 * frames];
        for b in 0..batch {
            for f in 0..frames {
                data[(b * 3 + i) * frames + f] = 1.0;
            }
        }
        Tensor::from_data(
            burn::tensor::TensorData::new(data, [batch, 3, frames]),
            device,
        )
    };
    [column(0), column(1), column(2)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::synthetic_motion;
    use burn::tensor::{Device, TensorData};
    use mocap_core::kinematics::forward_kinematics;

    #[test]
    fn matches_the_core_forward_kinematics() {
        // A chain of 5 joints with bones along +Y, moving on every axis.
        let mut motion = synthetic_motion(12, 5);
        let layout = FeatureLayout::new(motion.skeleton(), Representation::Rot6d).unwrap();
        // Root-relative: put the root at the origin for the reference.
        for f in 0..motion.frame_count() {
            motion.frame_mut(f)[..3].copy_from_slice(&[0.0, 0.0, 0.0]);
        }
        let (c, t) = (layout.channels(), motion.frame_count());
        let encoded = layout.encode(&motion);
        // [1, channels, frames]; scale the 6D columns to check the
        // Gram-Schmidt (features need not be orthonormal).
        let mut x = vec![0.0; c * t];
        for f in 0..t {
            for ch in 0..c {
                let scale = if ch % 6 < 3 { 1.7 } else { 0.6 };
                x[ch * t + f] = encoded[f * c + ch] * scale;
            }
        }
        let device = Device::flex();
        let features = Tensor::<3>::from_data(TensorData::new(x, [1, c, t]), &device);
        let fk = FkSkeleton::new(motion.skeleton(), &layout).unwrap();
        let out: Vec<f32> = fk.positions(features).into_data().try_to_vec().unwrap();
        let reference = forward_kinematics(&motion);
        let joints = motion.skeleton().joint_count();
        let mut worst = 0.0f32;
        for f in 0..t {
            for j in 0..joints {
                let p = reference.position(f, j);
                for (a, expected) in p.to_array().into_iter().enumerate() {
                    worst = worst.max((out[(3 * j + a) * t + f] - expected).abs());
                }
            }
        }
        // Bones of 10 units, 5 joints: the end is up to 40 units away.
        assert!(worst < 1e-3, "largest difference {worst}");
        // And the chain really moves (the test is not comparing zeros).
        let tip = reference.position(5, joints - 1) - reference.position(0, joints - 1);
        assert!(tip.length() > 0.5);
    }
}
