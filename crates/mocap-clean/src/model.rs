//! The denoiser: a 1-D convolutional autoencoder over time.
//!
//! The input is a window `[batch, channels, frames]` of joint-rotation
//! features; convolutions run along time only, every joint's features being
//! channels (so nothing is down-sampled across joints). The network is a
//! U-shaped residual encoder-decoder:
//!
//! ```text
//! x ─ conv ─ [res blocks ─ down (stride 2)] x levels ─ res blocks ─┐
//!                 │ skip (same size)                               │
//!             [up (transposed, stride 2) + skip ─ res blocks] x levels
//!                                      ─ conv ─ + x  (global skip)
//! ```
//!
//! Residual blocks are `relu(x + conv(relu(conv(x))))`. The global skip makes
//! the network predict a correction to its input, which is small for random
//! noise. Every skip connection adds tensors of the same size.
//!
//! A denoiser may read more than it outputs ([`DenoiserConfig::extra_inputs`]:
//! the base filter's output and, last, the noise level that filter
//! estimated). Its correction is then multiplied by that last input, so it
//! vanishes on a take the filter found clean.

use burn::module::Module;
use burn::nn::conv::{Conv1d, Conv1dConfig, ConvTranspose1d, ConvTranspose1dConfig};
use burn::nn::PaddingConfig1d;
use burn::tensor::activation::relu;
use burn::tensor::{Device, Tensor};
use serde::{Deserialize, Serialize};

use crate::wiener::WienerTensors;
use crate::{CleanError, Result};

/// Sizes of the network. The defaults are the small CPU setting;
/// [`DenoiserConfig::large`] is the report's deeper, wider setting for a GPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct DenoiserConfig {
    /// Features per frame (joints x representation size).
    pub channels: usize,
    /// Channels after the input convolution; doubled at each level.
    pub width: usize,
    /// Down-sampling levels along time (each halves the frames).
    pub levels: usize,
    /// Residual blocks at each level and in the bottleneck.
    pub blocks: usize,
    /// Kernel size of the convolutions (odd).
    pub kernel: usize,
    /// Frames per window (report: 16); a multiple of `2^levels`.
    pub window: usize,
    /// Input channels after the `channels` features that the network reads
    /// but does not output or add to its output: what it is conditioned on
    /// ([`crate::training::TrainOptions::base_input`]). The last of them is a
    /// noise level, and the correction is multiplied by it (see the module
    /// docs). 0 for models written before this field.
    #[serde(default)]
    pub extra_inputs: usize,
}

impl DenoiserConfig {
    /// The small default: trains on a 2-core CPU in minutes.
    pub fn small(channels: usize) -> DenoiserConfig {
        DenoiserConfig {
            channels,
            width: 32,
            levels: 2,
            blocks: 1,
            kernel: 3,
            window: 16,
            extra_inputs: 0,
        }
    }

    /// The report's large setting (deep residual encoder, for a GPU).
    pub fn large(channels: usize) -> DenoiserConfig {
        DenoiserConfig {
            channels,
            width: 128,
            levels: 3,
            blocks: 4,
            kernel: 3,
            window: 16,
            extra_inputs: 0,
        }
    }

    /// Checks that the sizes fit together.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: &str| Err(CleanError::Invalid(format!("model configuration: {m}")));
        if self.channels == 0 || self.width == 0 {
            return bad("channels and width must be positive");
        }
        if self.kernel.is_multiple_of(2) {
            return bad("the kernel size must be odd");
        }
        if self.levels > 6 || self.window == 0 || !self.window.is_multiple_of(1 << self.levels) {
            return bad("the window must be a positive multiple of 2^levels (levels at most 6)");
        }
        Ok(())
    }

    fn width_at(&self, level: usize) -> usize {
        self.width << level
    }

    /// Channels of the input: the features and what the network is
    /// conditioned on.
    pub fn input_channels(&self) -> usize {
        self.channels.saturating_add(self.extra_inputs)
    }

    /// Channels of the output: the features.
    pub fn output_channels(&self) -> usize {
        self.channels
    }

    /// Builds the network with fresh weights on `device`.
    pub fn init(&self, device: &Device) -> Result<Denoiser> {
        self.validate()?;
        let conv = |cin: usize, cout: usize| {
            Conv1dConfig::new(cin, cout, self.kernel)
                .with_padding(PaddingConfig1d::Same)
                .init(device)
        };
        let blocks = |w: usize| -> Vec<ResBlock> {
            (0..self.blocks)
                .map(|_| ResBlock {
                    conv1: conv(w, w),
                    conv2: conv(w, w),
                })
                .collect()
        };
        let mut encoder = Vec::new();
        let mut decoder = Vec::new();
        for level in 0..self.levels {
            let (w, w2) = (self.width_at(level), self.width_at(level + 1));
            encoder.push(EncoderLevel {
                blocks: blocks(w),
                down: Conv1dConfig::new(w, w2, 4)
                    .with_stride(2)
                    .with_padding(PaddingConfig1d::Explicit(1, 1))
                    .init(device),
            });
            decoder.push(DecoderLevel {
                up: ConvTranspose1dConfig::new([w2, w], 4)
                    .with_stride(2)
                    .with_padding(1)
                    .init(device),
                blocks: blocks(w),
            });
        }
        Ok(Denoiser {
            input: conv(self.input_channels(), self.width),
            encoder,
            bottleneck: blocks(self.width_at(self.levels)),
            decoder,
            output: conv(self.width, self.output_channels()),
            features: self.channels,
            base: None,
        })
    }

    /// Number of trainable numbers.
    pub fn parameter_count(&self) -> usize {
        // Saturating: a damaged or hostile model file may ask for sizes whose
        // count overflows; it is compared with the weights the file holds
        // before anything is allocated.
        let k = self.kernel;
        let conv = |cin: usize, cout: usize, k: usize| {
            cin.saturating_mul(cout)
                .saturating_mul(k)
                .saturating_add(cout)
        };
        let block = |w: usize| conv(w, w, k).saturating_mul(2);
        let width_at = |level: usize| self.width.saturating_mul(1 << level.min(63));
        let mut n = conv(self.input_channels(), self.width, k).saturating_add(conv(
            self.width,
            self.output_channels(),
            k,
        ));
        for level in 0..self.levels.min(64) {
            let (w, w2) = (width_at(level), width_at(level + 1));
            n = n
                .saturating_add(self.blocks.saturating_mul(block(w)).saturating_mul(2))
                .saturating_add(conv(w, w2, 4))
                .saturating_add(conv(w2, w, 4));
        }
        n.saturating_add(
            self.blocks
                .saturating_mul(block(width_at(self.levels.min(63)))),
        )
    }
}

/// `relu(x + conv2(relu(conv1(x))))`.
#[derive(Module, Debug)]
pub struct ResBlock {
    conv1: Conv1d,
    conv2: Conv1d,
}

impl ResBlock {
    fn forward(&self, x: Tensor<3>) -> Tensor<3> {
        let y = self.conv2.forward(relu(self.conv1.forward(x.clone())));
        relu(x + y)
    }
}

#[derive(Module, Debug)]
pub struct EncoderLevel {
    blocks: Vec<ResBlock>,
    down: Conv1d,
}

#[derive(Module, Debug)]
pub struct DecoderLevel {
    up: ConvTranspose1d,
    blocks: Vec<ResBlock>,
}

/// The autoencoder (see the module docs).
#[derive(Module, Debug)]
pub struct Denoiser {
    input: Conv1d,
    encoder: Vec<EncoderLevel>,
    bottleneck: Vec<ResBlock>,
    decoder: Vec<DecoderLevel>,
    output: Conv1d,
    /// How many of the input's channels are features (the rest condition
    /// the network): the global skip adds those. Not a weight.
    #[module(skip)]
    features: usize,
    /// The learned Wiener filter the network corrects, when it does
    /// ([`crate::training::ModelDescription::base_wiener`]): not trained and
    /// not used by `forward`; it rides along so that one file holds the
    /// whole model. Attached only when the model is written or read.
    pub(crate) base: Option<WienerTensors>,
}

impl Denoiser {
    /// Runs a batch `[batch, channels, frames]` (`frames` a multiple of
    /// `2^levels`): the cleaned batch.
    pub fn forward(&self, x: Tensor<3>) -> Tensor<3> {
        let mut h = relu(self.input.forward(x.clone()));
        let mut skips = Vec::with_capacity(self.encoder.len());
        for level in &self.encoder {
            for b in &level.blocks {
                h = b.forward(h);
            }
            skips.push(h.clone());
            h = relu(level.down.forward(h));
        }
        for b in &self.bottleneck {
            h = b.forward(h);
        }
        for level in self.decoder.iter().rev() {
            let skip = skips.pop().expect("one skip per level");
            h = relu(level.up.forward(h)) + skip;
            for b in &level.blocks {
                h = b.forward(h);
            }
        }
        let mut out = self.output.forward(h);
        let inputs = x.dims()[1];
        if inputs > self.features {
            // The last input is the noise level: the correction scales with it.
            out = out * x.clone().narrow(1, inputs - 1, 1);
        }
        x.narrow(1, 0, self.features) + out
    }

    /// Zeroes the output layer: a denoiser then returns its input unchanged
    /// (the global skip), so a test can check what is around the network.
    #[cfg(test)]
    pub(crate) fn zero_output(&mut self) {
        use burn::module::Param;
        let weight = self.output.weight.val();
        self.output.weight = Param::from_tensor(weight.zeros_like());
        if let Some(bias) = self.output.bias.take() {
            self.output.bias = Some(Param::from_tensor(bias.val().zeros_like()));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_has_the_input_shape() {
        let device = Device::flex();
        let config = DenoiserConfig::small(12);
        let model = config.init(&device).unwrap();
        let x = Tensor::<3>::zeros([2, 12, 16], &device);
        assert_eq!(model.forward(x).dims(), [2, 12, 16]);
        assert_eq!(model.num_params(), config.parameter_count());
    }

    #[test]
    fn a_conditioned_denoiser_outputs_and_skips_only_the_features() {
        let device = Device::flex();
        let config = DenoiserConfig {
            extra_inputs: 5,
            ..DenoiserConfig::small(12)
        };
        let mut model = config.init(&device).unwrap();
        assert_eq!(model.num_params(), config.parameter_count());
        // Features 1..=12 per channel, conditioning channels far off: with
        // its output layer zeroed the network gives back the features only.
        let values: Vec<f32> = (0..17)
            .flat_map(|ch| std::iter::repeat_n(if ch < 12 { ch as f32 } else { 100.0 }, 16))
            .collect();
        let x = Tensor::<3>::from_data(burn::tensor::TensorData::new(values, [1, 17, 16]), &device);
        model.zero_output();
        let y: Vec<f32> = model.forward(x).into_data().try_to_vec().unwrap();
        assert_eq!(y.len(), 12 * 16);
        for (i, v) in y.iter().enumerate() {
            assert_eq!(*v, (i / 16) as f32);
        }
    }

    #[test]
    fn extra_inputs_scale_the_correction_by_the_last_one() {
        let device = Device::flex();
        let config = DenoiserConfig {
            extra_inputs: 2,
            ..DenoiserConfig::small(4)
        };
        let model = config.init(&device).unwrap();
        let input = |level: f32| {
            let values: Vec<f32> = (0..6 * 16)
                .map(|i| {
                    if i >= 5 * 16 {
                        level
                    } else {
                        (i as f32 * 0.37).sin()
                    }
                })
                .collect();
            Tensor::<3>::from_data(burn::tensor::TensorData::new(values, [1, 6, 16]), &device)
        };
        let correction = |level: f32| -> Vec<f32> {
            let x = input(level);
            let features = x.clone().narrow(1, 0, 4);
            (model.forward(x) - features)
                .into_data()
                .try_to_vec()
                .unwrap()
        };
        // At level 0 nothing changes; the correction grows with the level
        // (the network reads the level too, so not exactly in proportion).
        assert!(correction(0.0).iter().all(|&v| v == 0.0));
        let size = |v: Vec<f32>| v.iter().map(|x| x.abs()).sum::<f32>();
        assert!(size(correction(0.5)) > 0.0);
        assert!(size(correction(0.01)) < 0.1 * size(correction(0.5)));
    }

    #[test]
    fn bad_sizes_are_errors() {
        let mut c = DenoiserConfig::small(12);
        c.window = 10;
        assert!(c.validate().is_err());
        c.window = 16;
        c.kernel = 4;
        assert!(c.validate().is_err());
    }
}
