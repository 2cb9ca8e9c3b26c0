//! A small 1-D convolutional network that classifies windows of per-frame
//! pose features: the judge [`crate::classify::Model::ConvNet`], the "small
//! conv net" the issue offers beside the forest.
//!
//! It sees the same per-frame values as the forests (mocap-search's 56
//! body-relative pose features, never the autoencoder's features or
//! latents), standardised with the training frames' mean and deviation, but
//! no hand-made descriptor: three convolutions along time (the last two with
//! stride 2), then the mean and the maximum of every channel over the
//! window's frames, dropout and one linear layer to the classes:
//!
//! ```text
//! h1 = relu(conv_k(x))   h2 = relu(conv_k,stride 2(h1))   h3 = relu(conv_k,stride 2(h2))
//! logits = W [mean_t h3 ; max_t h3] + b
//! ```
//!
//! The pooling over time makes the answer independent of where in the
//! window a step falls, and lets a window of any length be classified.
//! Trained with Adam on the cross-entropy, on every window of the training
//! clips, from a seeded initialisation and a seeded batch order, so a run
//! is reproducible. A clip's score for a class is the sum over its windows
//! of the softmax probabilities (as the forest sums its leaf histograms).

use burn::module::Module;
use burn::nn::conv::{Conv1d, Conv1dConfig};
use burn::nn::loss::CrossEntropyLossConfig;
use burn::nn::{Dropout, DropoutConfig, Linear, LinearConfig, PaddingConfig1d};
use burn::optim::AdamConfig;
use burn::tensor::activation::{relu, softmax};
use burn::tensor::{Device, Int, Tensor, TensorData};
use mocap_nn::device::seed_device;
use mocap_nn::train::{optimizer_step, work_bar};
use mocap_search::FeatureSequence;
use rand::rngs::ChaCha8Rng;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use serde::{Deserialize, Serialize};

use crate::{invalid, Result};

/// Sizes and training of the window network.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NetConfig {
    /// Channels of every convolution.
    pub width: usize,
    /// Kernel of every convolution, in frames (odd).
    pub kernel: usize,
    /// Passes over all training windows.
    pub epochs: usize,
    /// Windows per optimiser step.
    pub batch_size: usize,
    pub learning_rate: f64,
    /// Dropout before the linear layer.
    pub dropout: f64,
    /// Also feed every value's change from the frame before (how briskly
    /// it moves), as channels of their own.
    #[serde(default)]
    pub velocities: bool,
}

impl Default for NetConfig {
    fn default() -> Self {
        NetConfig {
            width: 64,
            kernel: 7,
            epochs: 30,
            batch_size: 32,
            learning_rate: 1e-3,
            dropout: 0.3,
            velocities: false,
        }
    }
}

#[derive(Module, Debug)]
struct WindowNet {
    conv1: Conv1d,
    conv2: Conv1d,
    conv3: Conv1d,
    dropout: Dropout,
    output: Linear,
}

impl WindowNet {
    fn new(channels: usize, classes: usize, config: &NetConfig, device: &Device) -> WindowNet {
        let pad = config.kernel / 2;
        let conv = |input: usize, stride: usize| {
            Conv1dConfig::new(input, config.width, config.kernel)
                .with_stride(stride)
                .with_padding(PaddingConfig1d::Explicit(pad, pad))
                .init(device)
        };
        WindowNet {
            conv1: conv(channels, 1),
            conv2: conv(config.width, 2),
            conv3: conv(config.width, 2),
            dropout: DropoutConfig::new(config.dropout).init(),
            output: LinearConfig::new(2 * config.width, classes).init(device),
        }
    }

    /// Class logits `[batch, classes]` of windows `[batch, channels, frames]`.
    fn forward(&self, x: Tensor<3>) -> Tensor<2> {
        let h = relu(self.conv1.forward(x));
        let h = relu(self.conv2.forward(h));
        let h = relu(self.conv3.forward(h));
        let [n, c, _] = h.dims();
        let mean = h.clone().mean_dim(2).reshape([n, c]);
        let max = h.max_dim(2).reshape([n, c]);
        self.output
            .forward(self.dropout.forward(Tensor::cat(vec![mean, max], 1)))
    }
}

/// A trained window network and the standardisation of its input.
pub(crate) struct FittedNet {
    net: WindowNet,
    mean: Vec<f32>,
    scale: Vec<f32>,
    velocities: bool,
    device: Device,
}

/// Fewest frames a window may have: two stride-2 convolutions leave at
/// least one frame.
const MIN_FRAMES: usize = 4;

impl FittedNet {
    /// Trains on `windows` (all with the same number of values per frame)
    /// labelled `labels` in `0..classes`.
    pub(crate) fn train(
        windows: &[FeatureSequence],
        labels: &[u32],
        classes: usize,
        config: &NetConfig,
        seed: u64,
    ) -> Result<FittedNet> {
        if windows.is_empty() || windows.len() != labels.len() {
            return Err(invalid("classifier: no training windows"));
        }
        if config.kernel % 2 != 1 || config.width == 0 || config.batch_size == 0 {
            return Err(invalid(
                "classifier: the network needs an odd kernel and a positive width and batch",
            ));
        }
        let inputs: Vec<FeatureSequence> = windows
            .iter()
            .map(|w| net_input(w, config.velocities))
            .collect();
        let dim = inputs[0].dim;
        let (mean, scale) = standardisation(&inputs, dim);
        // Standardised once here, not again in every epoch's batches.
        let windows: Vec<FeatureSequence> = inputs
            .iter()
            .map(|w| standardised(w, &mean, &scale))
            .collect();
        let device = Device::flex().autodiff();
        seed_device(&device, seed);
        let mut net = WindowNet::new(dim, classes, config, &device);
        let mut optimizer = AdamConfig::new().init();
        let loss = CrossEntropyLossConfig::new().init(&device);
        // Batches hold windows of one length (a clip shorter than a window
        // is one window of its own length).
        let mut by_length: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
        for (i, w) in windows.iter().enumerate() {
            if w.frame_count() >= MIN_FRAMES {
                by_length.entry(w.frame_count()).or_default().push(i);
            }
        }
        if by_length.is_empty() {
            return Err(invalid(format!(
                "classifier: no training window has the {MIN_FRAMES} frames the network needs"
            )));
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        // Tens of seconds on a 2-core CPU: show it (hidden off a terminal).
        let bar = work_bar(config.epochs as u64, "conv-net judge: training epochs");
        for _ in 0..config.epochs {
            let mut batches: Vec<Vec<usize>> = Vec::new();
            for members in by_length.values() {
                let mut members = members.clone();
                members.shuffle(&mut rng);
                batches.extend(members.chunks(config.batch_size).map(<[usize]>::to_vec));
            }
            batches.shuffle(&mut rng);
            for batch in batches {
                let frames = windows[batch[0]].frame_count();
                let x = input_tensor(batch.iter().map(|&i| &windows[i]), frames, &device);
                let targets: Vec<i64> = batch.iter().map(|&i| labels[i] as i64).collect();
                let targets =
                    Tensor::<1, Int>::from_data(TensorData::new(targets, [batch.len()]), &device);
                let value = loss.forward(net.forward(x), targets);
                let (updated, l) = optimizer_step(net, &mut optimizer, value, config.learning_rate);
                if !l.is_finite() {
                    return Err(invalid(format!(
                        "classifier: the network's training loss became {l}"
                    )));
                }
                net = updated;
            }
            bar.inc(1);
        }
        bar.finish_and_clear();
        Ok(FittedNet {
            net: net.valid(),
            mean,
            scale,
            velocities: config.velocities,
            device: Device::flex(),
        })
    }

    /// Adds the class probabilities of every window to `votes`. Windows
    /// of one length go through the network together (a clip's windows
    /// all have one length but for a clip shorter than a window), which is
    /// what the evaluation's many predictions spend their time on.
    pub(crate) fn add_votes(&self, windows: &[FeatureSequence], votes: &mut [f32]) {
        let mut by_length: std::collections::BTreeMap<usize, Vec<FeatureSequence>> =
            Default::default();
        for w in windows.iter().filter(|w| w.frame_count() >= MIN_FRAMES) {
            let input = standardised(&net_input(w, self.velocities), &self.mean, &self.scale);
            by_length.entry(w.frame_count()).or_default().push(input);
        }
        for (frames, batch) in by_length {
            let x = input_tensor(batch.iter(), frames, &self.device);
            let p = softmax(self.net.forward(x), 1).into_data();
            let p: Vec<f32> = p.try_to_vec().expect("f32 probabilities");
            for window_p in p.chunks(votes.len()) {
                for (v, q) in votes.iter_mut().zip(window_p) {
                    *v += q;
                }
            }
        }
    }
}

/// What the network reads of a window: its values and, with `velocities`,
/// every value's change from the frame before (0 in the first frame).
fn net_input(window: &FeatureSequence, velocities: bool) -> FeatureSequence {
    if !velocities {
        return window.clone();
    }
    let d = window.dim;
    let mut values = Vec::with_capacity(2 * window.values.len());
    for f in 0..window.frame_count() {
        let frame = &window.values[f * d..(f + 1) * d];
        values.extend_from_slice(frame);
        if f == 0 {
            values.extend(std::iter::repeat_n(0.0, d));
        } else {
            let before = &window.values[(f - 1) * d..f * d];
            values.extend(frame.iter().zip(before).map(|(a, b)| a - b));
        }
    }
    FeatureSequence { dim: 2 * d, values }
}

/// Mean and 1 / deviation of every value over all frames of `windows`
/// (scale 0 for a value that never varies).
fn standardisation(windows: &[FeatureSequence], dim: usize) -> (Vec<f32>, Vec<f32>) {
    let mut sum = vec![0.0f64; dim];
    let mut square = vec![0.0f64; dim];
    let mut n = 0usize;
    for w in windows {
        for frame in w.values.chunks(dim) {
            for (i, &v) in frame.iter().enumerate() {
                sum[i] += v as f64;
                square[i] += (v as f64).powi(2);
            }
            n += 1;
        }
    }
    let n = n.max(1) as f64;
    let mean: Vec<f32> = sum.iter().map(|s| (s / n) as f32).collect();
    let scale = sum
        .iter()
        .zip(&square)
        .map(|(s, q)| {
            let var = q / n - (s / n).powi(2);
            if var > 1e-12 {
                (1.0 / var.sqrt()) as f32
            } else {
                0.0
            }
        })
        .collect();
    (mean, scale)
}

/// `(v - mean) * scale` for every value of every frame.
fn standardised(window: &FeatureSequence, mean: &[f32], scale: &[f32]) -> FeatureSequence {
    let values = window
        .values
        .chunks(window.dim)
        .flat_map(|frame| {
            frame
                .iter()
                .zip(mean)
                .zip(scale)
                .map(|((v, m), s)| (v - m) * s)
        })
        .collect();
    FeatureSequence {
        dim: window.dim,
        values,
    }
}

/// `[windows, values, frames]` of windows of `frames` frames (channels
/// first, as the convolutions read them).
fn input_tensor<'a>(
    windows: impl Iterator<Item = &'a FeatureSequence>,
    frames: usize,
    device: &Device,
) -> Tensor<3> {
    let mut data = Vec::new();
    let mut count = 0;
    let mut dim = 0;
    for w in windows {
        dim = w.dim;
        for i in 0..dim {
            data.extend((0..frames).map(|f| w.values[f * dim + i]));
        }
        count += 1;
    }
    Tensor::from_data(TensorData::new(data, [count, dim, frames]), device)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Windows of two classes that differ only in the rhythm of one value
    /// (a slow and a fast sine, random phase): the network must tell them
    /// apart on new windows, which a per-window mean cannot.
    #[test]
    fn learns_a_rhythm_that_the_mean_does_not_show() {
        let window = |frequency: f32, phase: f32| FeatureSequence {
            dim: 2,
            values: (0..40)
                .flat_map(|t| [(frequency * t as f32 + phase).sin(), 0.5])
                .collect(),
        };
        let mut windows = Vec::new();
        let mut labels = Vec::new();
        for k in 0..40 {
            let phase = k as f32 * 0.37;
            windows.push(window(0.2, phase));
            labels.push(0);
            windows.push(window(0.9, phase));
            labels.push(1);
        }
        let config = NetConfig {
            width: 8,
            epochs: 40,
            batch_size: 16,
            ..NetConfig::default()
        };
        let net = FittedNet::train(&windows, &labels, 2, &config, 3).unwrap();
        // Windows too short for the network are refused, not learnt from
        // silently.
        let short = FeatureSequence {
            dim: 2,
            values: vec![0.0; 6],
        };
        assert!(FittedNet::train(&[short], &[0], 2, &config, 3).is_err());
        for (phase, class) in [(2.0, 0), (5.1, 0), (1.3, 1), (4.4, 1)] {
            let mut votes = [0.0f32; 2];
            let frequency = if class == 0 { 0.2 } else { 0.9 };
            net.add_votes(&[window(frequency, phase)], &mut votes);
            let predicted = usize::from(votes[1] > votes[0]);
            assert_eq!(predicted, class, "phase {phase}: {votes:?}");
            assert!((votes[0] + votes[1] - 1.0).abs() < 1e-4);
        }
    }
}
