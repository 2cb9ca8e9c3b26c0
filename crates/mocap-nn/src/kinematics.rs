//! Forward kinematics on batches of tensors, for losses on joint positions:
//! `mocap-clean`'s position term (6D features) and `mocap-style`'s loss on
//! the feet (exponential maps). Each builds its joints' local rotations from
//! its own features; the steps down the chain are these.
//!
//! The math is `mocap_core::kinematics`'s:
//!
//! ```text
//! R_j = R_p * L_j          x_j = x_p + R_p * t_j
//! ```
//!
//! A tensor `[batch, 3, frames]` holds one 3-vector per sample and frame; a
//! rotation is its three columns.

use burn::tensor::Tensor;

/// Columns of a batch of rotation matrices, each `[batch, 3, frames]`.
pub type Columns = [Tensor<3>; 3];

/// `R v` for rotations given by columns and vectors `[batch, 3, frames]`.
pub fn apply(r: &Columns, v: &Tensor<3>) -> Tensor<3> {
    r[0].clone() * v.clone().narrow(1, 0, 1)
        + r[1].clone() * v.clone().narrow(1, 1, 1)
        + r[2].clone() * v.clone().narrow(1, 2, 1)
}

/// The global rotation of a child, `R_p L` (column `i` of it is `R_p`
/// applied to column `i` of `L`).
pub fn compose(parent: &Columns, local: &Columns) -> Columns {
    local.clone().map(|column| apply(parent, &column))
}

/// The position of a child joint, `x_p + R_p t`, for its offset `t` from its
/// parent (a constant).
pub fn child_position(parent_position: Tensor<3>, parent: &Columns, offset: [f32; 3]) -> Tensor<3> {
    parent_position
        + parent[0].clone() * offset[0]
        + parent[1].clone() * offset[1]
        + parent[2].clone() * offset[2]
}
