//! The training loss with velocity and acceleration terms:
//!
//! ```text
//! loss = E|G(x) - y|^2 + alpha E|G'(x) - y'|^2 + beta E|G''(x) - y''|^2
//! ```
//!
//! `'` and `''` are first and second finite differences along time divided
//! by the frame interval `dt` (so they are angular velocity and acceleration
//! of the features). The report keeps the three terms on the rotation scale
//! with `alpha = 1/900` and `beta = 1/810000` at 30 fps, i.e. `alpha = dt^2`
//! and `beta = dt^4`; `(alpha, beta) = (0, 0)` is plain MSE.

use burn::tensor::Tensor;
use serde::{Deserialize, Serialize};

use crate::fk::FkSkeleton;

/// Weights of the loss terms and the frame rate the differences use.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LossWeights {
    pub alpha: f32,
    pub beta: f32,
    pub fps: f32,
}

impl LossWeights {
    /// Plain mean squared error.
    pub fn mse(fps: f32) -> LossWeights {
        LossWeights {
            alpha: 0.0,
            beta: 0.0,
            fps,
        }
    }

    /// The report's weights: `alpha = dt^2`, `beta = dt^4` (1/900 and
    /// 1/810000 at 30 fps).
    pub fn derivative(fps: f32) -> LossWeights {
        let dt = 1.0 / fps;
        LossWeights {
            alpha: dt * dt,
            beta: dt * dt * dt * dt,
            fps,
        }
    }

    pub fn is_mse(&self) -> bool {
        self.alpha == 0.0 && self.beta == 0.0
    }
}

/// First finite difference along time (dim 2) divided by `dt`.
fn time_derivative(x: Tensor<3>, fps: f32) -> Tensor<3> {
    let frames = x.dims()[2];
    (x.clone().narrow(2, 1, frames - 1) - x.narrow(2, 0, frames - 1)) * fps
}

/// The loss of a batch `[batch, channels, frames]` (at least 3 frames).
pub fn derivative_loss(pred: Tensor<3>, target: Tensor<3>, w: &LossWeights) -> Tensor<1> {
    let error = pred - target;
    let mut loss = error.clone().powi_scalar(2).mean();
    if w.is_mse() {
        return loss;
    }
    // The difference of the errors is the error of the differences.
    let velocity = time_derivative(error, w.fps);
    if w.alpha != 0.0 {
        loss = loss + velocity.clone().powi_scalar(2).mean() * w.alpha;
    }
    if w.beta != 0.0 {
        let acceleration = time_derivative(velocity, w.fps);
        loss = loss + acceleration.powi_scalar(2).mean() * w.beta;
    }
    loss
}

/// The position term: mean squared difference of the root-relative joint
/// positions that forward kinematics gives for the predicted and the target
/// 6D features (skeleton units squared, per coordinate). The training loss
/// adds it with weight `position_weight` (`TrainOptions`).
pub fn position_loss(fk: &FkSkeleton, pred: Tensor<3>, target: Tensor<3>) -> Tensor<1> {
    (fk.positions(pred) - fk.positions(target))
        .powi_scalar(2)
        .mean()
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::tensor::Device;

    #[test]
    fn matches_a_hand_computation() {
        let device = Device::flex();
        // One channel, 4 frames; error e = [0, 1, 0, 1].
        let pred = Tensor::<1>::from_floats([0.0, 1.0, 0.0, 1.0], &device).reshape([1, 1, 4]);
        let target = Tensor::<3>::zeros([1, 1, 4], &device);
        let w = LossWeights::derivative(30.0);
        // mse 0.5; velocity 30*[1,-1,1] -> mean square 900 -> * 1/900 = 1;
        // acceleration 900*[-2, 2] -> 3_240_000 -> * 1/810000 = 4.
        let loss: f32 = derivative_loss(pred.clone(), target.clone(), &w).into_scalar();
        assert!((loss - 5.5).abs() < 1e-3, "{loss}");
        let mse: f32 = derivative_loss(pred, target, &LossWeights::mse(30.0)).into_scalar();
        assert!((mse - 0.5).abs() < 1e-6);
    }
}
