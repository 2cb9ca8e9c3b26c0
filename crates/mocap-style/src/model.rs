//! The tied-weight 1-D convolutional autoencoder.
//!
//! Input and output are `[batch, channels, frames]` windows of standardised
//! exponential maps; the convolutions run along time only. With `W1, b1`
//! the first convolution (kernel 15, `channels -> 256`) and `W2, b2` the
//! second (kernel 1, `256 -> 32`):
//!
//! ```text
//! encode:  h = relu(W1 * x + b1)            z = relu(W2 * h + b2)
//! decode:  h' = relu(W2^T * (z - b2))       x' = W1^T * (h' - b1)
//! ```
//!
//! where `*` is a convolution and `W^T *` the transposed convolution with the
//! same weights: the decoder shares the encoder's weights, transposed, with
//! the biases negated, applied in reverse order (as in Holden et al.'s
//! motion manifold autoencoders, `Phi^dagger(H) = W~ * (H - b)`). The output
//! has no activation (exponential maps are signed). Padding keeps the number
//! of frames, so every frame has one 32-number latent vector.

use burn::module::Module;
use burn::nn::conv::{Conv1d, Conv1dConfig};
use burn::nn::PaddingConfig1d;
use burn::tensor::activation::relu;
use burn::tensor::module::conv_transpose1d;
use burn::tensor::ops::ConvTransposeOptions;
use burn::tensor::{Device, Tensor};
use serde::{Deserialize, Serialize};

use crate::{invalid, Result};

/// Sizes of the network (the report's setting by default).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct AutoencoderConfig {
    /// Feature channels per frame (3 per rotation slot).
    pub channels: usize,
    /// Channels of the hidden layer (report: 256).
    pub hidden: usize,
    /// Channels of the latent code (report: 32).
    pub latent: usize,
    /// Kernel of the first convolution, in frames (report: 15; odd).
    pub kernel: usize,
}

impl AutoencoderConfig {
    /// The report's sizes for `channels` input channels.
    pub fn report(channels: usize) -> AutoencoderConfig {
        AutoencoderConfig {
            channels,
            hidden: 256,
            latent: 32,
            kernel: 15,
        }
    }

    pub fn validate(&self) -> Result<()> {
        if self.channels == 0 || self.hidden == 0 || self.latent == 0 {
            return Err(invalid("autoencoder sizes must be positive"));
        }
        if self.kernel % 2 != 1 {
            return Err(invalid(format!(
                "the autoencoder kernel must be odd (got {})",
                self.kernel
            )));
        }
        Ok(())
    }

    /// A network with fresh weights on `device`.
    pub fn init(&self, device: &Device) -> Result<StyleAutoencoder> {
        self.validate()?;
        Ok(StyleAutoencoder {
            conv1: Conv1dConfig::new(self.channels, self.hidden, self.kernel)
                .with_padding(PaddingConfig1d::Same)
                .init(device),
            conv2: Conv1dConfig::new(self.hidden, self.latent, 1).init(device),
        })
    }

    /// Number of trainable numbers. Saturating: a damaged or hostile model
    /// file may ask for sizes whose count overflows; it is compared with the
    /// weights the file holds before anything is allocated.
    pub fn parameter_count(&self) -> usize {
        self.channels
            .saturating_mul(self.hidden)
            .saturating_mul(self.kernel)
            .saturating_add(self.hidden)
            .saturating_add(self.hidden.saturating_mul(self.latent))
            .saturating_add(self.latent)
    }
}

/// The autoencoder (see the module docs).
#[derive(Module, Debug)]
pub struct StyleAutoencoder {
    conv1: Conv1d,
    conv2: Conv1d,
}

/// `x - b` with `b` of shape `[channels]` broadcast over batch and frames.
fn minus_bias(x: Tensor<3>, bias: Tensor<1>) -> Tensor<3> {
    let [n, c, t] = x.dims();
    x - bias.reshape([1, c, 1]).expand([n, c, t])
}

impl StyleAutoencoder {
    /// Latent codes `[batch, latent, frames]` of features `[batch, channels, frames]`.
    pub fn encode(&self, x: Tensor<3>) -> Tensor<3> {
        relu(self.conv2.forward(relu(self.conv1.forward(x))))
    }

    /// Features of latent codes, with the encoder's weights transposed.
    pub fn decode(&self, z: Tensor<3>) -> Tensor<3> {
        let transposed = |padding: usize| ConvTransposeOptions::new([1], [padding], [0], [1], 1);
        let h = match &self.conv2.bias {
            Some(b) => minus_bias(z, b.val()),
            None => z,
        };
        let h = relu(conv_transpose1d(
            h,
            self.conv2.weight.val(),
            None,
            transposed(0),
        ));
        let h = match &self.conv1.bias {
            Some(b) => minus_bias(h, b.val()),
            None => h,
        };
        conv_transpose1d(
            h,
            self.conv1.weight.val(),
            None,
            transposed(self.conv1.kernel_size / 2),
        )
    }

    /// `decode(encode(x))`.
    pub fn forward(&self, x: Tensor<3>) -> Tensor<3> {
        self.decode(self.encode(x))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_and_parameter_count() {
        let device = Device::flex();
        let config = AutoencoderConfig::report(63);
        let model = config.init(&device).unwrap();
        let x = Tensor::<3>::zeros([2, 63, 40], &device);
        let z = model.encode(x.clone());
        assert_eq!(z.dims(), [2, 32, 40]);
        assert_eq!(model.forward(x).dims(), [2, 63, 40]);
        assert_eq!(model.num_params(), config.parameter_count());
    }

    /// The decoder is the encoder transposed: for the linear parts,
    /// <W * x, y> = <x, W^T * y> (adjoint identity), checked on random data
    /// with the biases removed.
    #[test]
    fn decoder_is_the_transpose_of_the_encoder() {
        let device = Device::flex();
        device.seed(3);
        let config = AutoencoderConfig {
            channels: 5,
            hidden: 7,
            latent: 3,
            kernel: 5,
        };
        let model = config.init(&device).unwrap();
        let x = Tensor::<3>::random(
            [1, 5, 20],
            burn::tensor::Distribution::Normal(0.0, 1.0),
            &device,
        );
        let y = Tensor::<3>::random(
            [1, 7, 20],
            burn::tensor::Distribution::Normal(0.0, 1.0),
            &device,
        );
        let conv = burn::tensor::module::conv1d(
            x.clone(),
            model.conv1.weight.val(),
            None,
            burn::tensor::ops::ConvOptions::new([1], [2], [1], 1),
        );
        let back = conv_transpose1d(
            y.clone(),
            model.conv1.weight.val(),
            None,
            ConvTransposeOptions::new([1], [2], [0], [1], 1),
        );
        let a: f32 = (conv * y).sum().into_scalar();
        let b: f32 = (x * back).sum().into_scalar();
        assert!((a - b).abs() < 1e-3 * a.abs().max(1.0), "{a} vs {b}");
    }

    #[test]
    fn even_kernels_are_refused() {
        let mut c = AutoencoderConfig::report(6);
        c.kernel = 4;
        assert!(c.validate().is_err());
    }
}
