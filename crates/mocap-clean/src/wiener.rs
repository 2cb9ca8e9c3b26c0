//! A learned multichannel Wiener filter: the best *linear* time-invariant
//! estimate of clean motion from a take with the random noise of
//! [`crate::noise`], given the spectra of clean motion.
//!
//! ## Method
//!
//! The features are the 6D rotations of every joint of a rig
//! ([`crate::features`]), `c` channels per frame, minus their mean over the
//! take. Per frequency `f`:
//!
//! - the clean motion has a cross-spectral matrix `S(f)` (`c x c`, all
//!   channels together), estimated by Welch's method (Hann windows of
//!   [`WienerDescription::segment`] frames, half overlapping) on training
//!   takes;
//! - the random noise is white in time with a per-frame covariance
//!   `s N`, `s = (sigma / sigma_ref)^2`: `N` is measured by noising training
//!   takes at `sigma_ref`. It is far from diagonal: the chain correction
//!   makes a joint's error reappear, turned, in its children's local
//!   rotations.
//!
//! The estimate is Wiener's (1949), per frequency:
//!
//! ```text
//! Y(f) = S(f) (S(f) + s N)^-1 X(f)                                   (1)
//! ```
//!
//! It uses what a per-channel low-pass cannot: which *combinations* of
//! channels carry motion and which carry mostly noise at each frequency.
//! With `N^-1/2 S(f) N^-1/2 = V diag(lambda) V^H` (both whitened by the
//! noise), (1) is `N^1/2 V diag(lambda / (lambda + s)) V^H N^-1/2 X(f)`, so
//! a new noise level costs no matrix inversion. It runs as a short-time
//! Fourier transform: square-root Hann windows half a segment apart (their
//! squares sum to one), the take padded by reflection.
//!
//! ## Noise level
//!
//! `sigma` is chosen per take by maximum marginal likelihood: under the
//! model each whitened coefficient `z = V^H N^-1/2 X(f)` is a complex
//! Gaussian of variance `lambda + s`, so
//!
//! ```text
//! log L(s) = sum over segments, frequencies, coordinates of
//!            -log(lambda + s) - |z|^2 / (lambda + s)                  (2)
//! ```
//!
//! (half weight at the real frequencies 0 and Nyquist), maximised over a
//! grid of `sigma`. Only the segments inside the take count (the mirrored
//! padding bends the channels at its ends) and only the directions the
//! noise model puts noise in (elsewhere any power the training spectra did
//! not foresee would be taken for noise). A clean take gets a `sigma` near 0
//! and is nearly left alone.
//!
//! By default (2) is maximised for each segment on its own and the take's
//! level is the median of those levels ([`LevelEstimate::SegmentMedian`]).
//! One segment's sum runs over its frequencies and every direction the
//! noise model puts noise in, enough for a level of its own: where the
//! noise is the same throughout, the median and the level of all segments
//! together ([`LevelEstimate::Pooled`]) agree. The median is not raised by
//! the few segments that hold a spike; the pooled level is, and the whole
//! take is then smoothed for it. In a take of fewer than three segments
//! (under 64 frames) the median is the mean and no more robust.
//!
//! ## Mixture
//!
//! One `S(f)` for every kind of motion is a compromise: a slow gesture has
//! less power at high frequencies than a run. A filter may hold several
//! sets of spectra (components, e.g. one per content of the training data,
//! all with the same `N`); for each take the component and the level of
//! largest marginal likelihood (2) are chosen together, which compares
//! across components since they share `N` and so the whitening. This is a
//! hard choice per take, not a blend. The choice reads at most 8 segments
//! spread over the take, so that its cost does not grow with the take's
//! length times the number of components; the level is then estimated on
//! every segment with the chosen component.
//!
//! Choosing needs every component's bases of (2), but filtering only the
//! chosen one's bases of (1), the larger share of the work (a full-size
//! eigendecomposition and products per bin): those are built when a
//! component is first chosen, so loading a 13-component mixture takes about
//! a second instead of seven (`bench/clean/speed.txt`).
//!
//! ## Memory
//!
//! A take is filtered [`CHUNK_SEGMENTS`] segments at a time, in place: the
//! level is estimated from the spectra of one chunk after another (keeping
//! a level per segment), then each chunk is transformed again, filtered and
//! added to the overlap, and the frames no later segment touches are
//! written back. Besides the features, memory holds one chunk, whatever the
//! take's length, and the output is the same as from all segments at once
//! (`bench/results/memory.md` has the memory against the take's length).
//!
//! ## Limits
//!
//! It is linear: spikes (another motion pasted on a subtree) are smeared,
//! not removed. It is fitted to one rig (the joints with rotation channels,
//! by name and order) and one frame rate, like a network.

use std::f64::consts::PI;
use std::path::Path;
use std::sync::{Arc, OnceLock};

use burn::module::{Module, Param};
use burn::tensor::{Device, Tensor, TensorData};
use mocap_core::Motion;
use mocap_nn::checkpoint::{
    check_parameter_count, header_from_bytes, load_weights_from_bytes, save_weights,
    CheckpointHeader,
};
use nalgebra::{Complex, DMatrix, DVector, SymmetricEigen};
use rand::rngs::ChaCha8Rng;
use rand::SeedableRng;
use rayon::prelude::*;
use rustfft::{Fft, FftPlanner};
use serde::{Deserialize, Serialize};

use crate::dataset::Take;
use crate::features::{FeatureLayout, Representation};
use crate::noise::{add_random_noise_sigma, RandomNoise};
use crate::{CleanError, Result};

type C64 = Complex<f64>;

/// Kind of a Wiener filter file (the checkpoint header's `kind`).
pub const WIENER_KIND: &str = "mocap-clean/wiener";
/// Version of [`WienerDescription`]'s layout.
pub const WIENER_KIND_VERSION: u32 = 1;

/// A mixture's component is chosen on at most this many segments of a take
/// (about 140 frames' worth; see "Mixture" in the module docs).
const CHOICE_SEGMENTS: usize = 8;

/// Segments filtered at a time (see "Memory" in the module docs): 8,192
/// frames of a 32-frame segment.
const CHUNK_SEGMENTS: usize = 512;

/// The noise levels (degrees) the marginal likelihood (2) is evaluated at:
/// every 0.1 degree from 0.05 to 30.05, and below 0.05 a few levels down to
/// 0.0005, so that a clean segment can be told that it is clean: the filter
/// passes what the clean spectra hold, and at 0.05 degrees it still damps
/// the frequencies where they hold almost nothing (the model moved clean
/// test takes by 0.062 degrees on average with the grid starting at 0.05,
/// 0.043 with these; `docs/research/clean.md`, "The noise level the
/// network reads").
fn sigma_grid_deg() -> impl Iterator<Item = f64> {
    [0.0005, 0.001, 0.002, 0.005, 0.01, 0.02, 0.03, 0.04]
        .into_iter()
        .chain((0..=300).map(|i| 0.05 + 0.1 * i as f64))
}

/// The median of `values` (the mean of the middle two for an even count; 0
/// for none).
fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    let m = values.len() / 2;
    if values.len() % 2 == 1 {
        values[m]
    } else {
        0.5 * (values[m - 1] + values[m])
    }
}

/// What a Wiener filter was fitted to, stored in its file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WienerDescription {
    /// The joints with rotation channels, in feature order.
    pub joints: Vec<String>,
    /// Features per frame (6 per joint).
    pub channels: usize,
    pub fps: f32,
    /// Frames per Fourier segment (even).
    pub segment: usize,
    /// The noise model `N` was measured with, and at which level.
    pub noise: RandomNoise,
    pub noise_sigma_deg: f32,
    /// Training takes, frames and Welch segments the spectra come from.
    pub takes: usize,
    pub frames: usize,
    pub segments: usize,
    /// Takes left out because their rig differs from the first take's.
    pub other_rig_takes: usize,
    /// The components of a mixture, in the order their spectra are stored
    /// (see "Mixture" in the module docs); empty for one set of spectra.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub components: Vec<ComponentInfo>,
    /// The spectra are stored as the upper triangles of their real and
    /// imaginary parts (they are Hermitian), half the size; files written
    /// before this have every entry.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub packed_spectra: bool,
}

/// One component of a mixture: the kind of motion its spectra come from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ComponentInfo {
    pub name: String,
    pub takes: usize,
    pub segments: usize,
}

impl WienerDescription {
    /// Sets of spectra stored (1 unless a mixture).
    pub fn component_count(&self) -> usize {
        self.components.len().max(1)
    }
}

/// The stored numbers: per frequency bin the real and imaginary parts of
/// `S(f)` (`[bins, c, c]`), and `N` (`[c, c]`). A burn module only so that
/// it is written and read by the checkpoint code the networks use.
#[derive(Module, Debug)]
pub(crate) struct WienerTensors {
    spectra_re: Param<Tensor<3>>,
    spectra_im: Param<Tensor<3>>,
    noise: Param<Tensor<2>>,
}

/// One frequency bin of (1), in the noise-whitened eigenbasis.
#[derive(Debug, Clone)]
struct Bin {
    /// `V^H N^-1/2`.
    to_white: DMatrix<C64>,
    /// `N^1/2 V`.
    from_white: DMatrix<C64>,
    /// Eigenvalues of the whitened signal spectrum (>= 0).
    lambda: Vec<f64>,
}

/// One frequency bin of the same decomposition restricted to the
/// directions the noise model puts noise in (no ridge), for estimating the
/// noise level (2): `V'^H D^-1/2 Q^T` with `N = Q D Q^T` over those
/// directions.
#[derive(Debug, Clone)]
struct LevelBin {
    noisy_to_white: DMatrix<C64>,
    noisy_lambda: Vec<f64>,
}

/// The spectra of one kind of motion and the bases of (1) and (2) built
/// from them. Every component's bases for (2) are needed to choose among
/// them, but only the chosen one's bases for (1), the larger part of the
/// work (a full-size eigendecomposition and products per bin): they are
/// built the first time the component is chosen, so that loading a
/// mixture stays quick. The table of (2) over the grid of levels is built
/// the first time a level is estimated with the component.
#[derive(Debug, Clone)]
struct Component {
    spectra: Vec<DMatrix<C64>>,
    level_bins: Vec<LevelBin>,
    bins: OnceLock<Vec<Bin>>,
    level_table: OnceLock<LevelTable>,
}

/// `N`'s square root and inverse square root (with the ridge) and the
/// whitening of its noisy directions: what turns a component's spectra
/// into its bases. Shared by all components, since they share `N`.
#[derive(Debug, Clone)]
struct Whitening {
    half: DMatrix<f64>,
    inverse_half: DMatrix<f64>,
    /// `D^-1/2 Q^T` over the directions with noise (rows).
    noisy: DMatrix<f64>,
}

/// What (2) needs of a component at every level of the grid: over `n`
/// segments whose powers sum to `p`, `log L(s)` is
/// `-n sum w ln(lambda + s) - sum w p / (lambda + s)` over the bins'
/// coordinates (weights `w` of 1/2 at the real frequencies). The first sum
/// depends on the component alone and holds the logarithms, the costly
/// part, so it is kept with the component ([`WienerFilter::level_table`]).
#[derive(Debug, Clone)]
struct LevelTable {
    sigmas: Vec<f64>,
    /// `s` of each level (`(sigma / reference)^2`).
    scales: Vec<f64>,
    /// Per level: `sum w ln(lambda + s)`.
    log_terms: Vec<f64>,
    /// Per coordinate, bins in order: `w` and `lambda`.
    weights: Vec<f64>,
    lambdas: Vec<f64>,
}

impl LevelTable {
    fn new(filter: &WienerFilter, component: &Component) -> LevelTable {
        let len = filter.description.segment;
        let (weights, lambdas): (Vec<f64>, Vec<f64>) = component
            .level_bins
            .iter()
            .enumerate()
            .flat_map(|(b, bin)| {
                let weight = if b == 0 || 2 * b == len { 0.5 } else { 1.0 };
                bin.noisy_lambda.iter().map(move |&l| (weight, l))
            })
            .unzip();
        let reference = filter.description.noise_sigma_deg as f64;
        let sigmas: Vec<f64> = sigma_grid_deg().collect();
        let scales: Vec<f64> = sigmas.iter().map(|s| (s / reference).powi(2)).collect();
        let log_terms = scales
            .iter()
            .map(|s| {
                weights
                    .iter()
                    .zip(&lambdas)
                    .map(|(w, l)| w * (l + s).ln())
                    .sum()
            })
            .collect();
        LevelTable {
            sigmas,
            scales,
            log_terms,
            weights,
            lambdas,
        }
    }

    /// The level of largest likelihood (2) and that log-likelihood, given
    /// `n` and, per level, the sum `fit(level)` of `w p / (lambda + s)`.
    fn best(&self, n: f64, fit: impl Fn(usize) -> f64) -> (f64, f64) {
        (0..self.sigmas.len())
            .map(|g| (self.sigmas[g], -n * self.log_terms[g] - fit(g)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0.0, 0.0))
    }

    /// The level of largest likelihood (2) of `n` segments whose powers
    /// ([`WienerFilter::segment_power`]) sum to `power`, and that
    /// log-likelihood.
    fn most_likely_level(&self, power: &[f64], n: f64) -> (f64, f64) {
        self.best(n, |g| {
            let s = self.scales[g];
            self.weights
                .iter()
                .zip(&self.lambdas)
                .zip(power)
                .map(|((w, l), p)| w * p / (l + s))
                .sum()
        })
    }

    /// The level of largest likelihood (2) of each segment of power
    /// `powers[k]` on its own. The factors `w / (lambda + s)` are the same
    /// for every segment: computed once here, they leave a product per
    /// level and segment.
    fn segment_levels(&self, powers: &[Vec<f64>]) -> Vec<f64> {
        let factors: Vec<Vec<f64>> = self
            .scales
            .iter()
            .map(|s| {
                self.weights
                    .iter()
                    .zip(&self.lambdas)
                    .map(|(w, l)| w / (l + s))
                    .collect()
            })
            .collect();
        powers
            .par_iter()
            .map(|power| {
                self.best(1.0, |g| {
                    factors[g].iter().zip(power).map(|(a, p)| a * p).sum()
                })
                .0
            })
            .collect()
    }
}

/// A fitted filter (see the module docs).
#[derive(Debug, Clone)]
pub struct WienerFilter {
    pub description: WienerDescription,
    /// One set of spectra, or one per kind of motion (a mixture), all with
    /// the same `N`.
    components: Vec<Component>,
    noise: DMatrix<f64>,
    whitening: Arc<Whitening>,
    /// How a take's level is drawn from its segments (a run-time choice,
    /// not stored in the file).
    level_estimate: LevelEstimate,
}

/// How the noise level of a take is estimated from its segments by (2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LevelEstimate {
    /// The level of largest likelihood (2) of each segment on its own, and
    /// the median of those levels (the default). A few
    /// segments that hold something the noise model does not know (a spike
    /// the finder missed, the remains of a bridged one, a burst of motion
    /// faster than the training spectra) then do not raise the level of
    /// the whole take, where the random noise of a capture is the same
    /// throughout. See "The noise level the network reads" in
    /// `docs/research/clean.md`.
    #[default]
    SegmentMedian,
    /// The level of largest likelihood (2) over all segments together: the
    /// most precise estimate when every segment is
    /// noisy alike, but one spiked segment raises it for the whole take.
    Pooled,
}

/// What filtering a take did.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WienerOutcome {
    /// The noise level used (estimated unless given), degrees.
    pub sigma_deg: f64,
    /// The component of a mixture used (0 for a single filter).
    #[serde(default)]
    pub component: usize,
}

/// A joint's 6 features have 3 degrees of freedom, so `N` is singular: a
/// ridge of 1e-6 of its mean variance stands for the directions with
/// (almost) no noise, which the filter then passes through.
fn noise_ridge(noise: &DMatrix<f64>) -> f64 {
    1e-6 * noise.trace() / noise.nrows().max(1) as f64 + 1e-12
}

/// The eigendecomposition of a matrix Hermitian up to rounding (its lower
/// triangle is read): eigenvalues, and eigenvectors as columns. By faer,
/// whose blocked solver is several times faster than nalgebra's on these
/// sizes (a model's load is dozens of them); a failure to converge falls
/// back to nalgebra's.
fn hermitian_eigen(m: DMatrix<C64>) -> (Vec<f64>, DMatrix<C64>) {
    let n = m.nrows();
    let a = faer::Mat::<faer::c64>::from_fn(n, n, |i, j| {
        let v = m[(i, j)];
        faer::c64::new(v.re, v.im)
    });
    match a.self_adjoint_eigen(faer::Side::Lower) {
        Ok(eigen) => {
            let (values, vectors) = (eigen.S(), eigen.U());
            (
                (0..n).map(|i| values[i].re).collect(),
                DMatrix::from_fn(n, n, |i, j| {
                    let v = vectors[(i, j)];
                    C64::new(v.re, v.im)
                }),
            )
        }
        Err(_) => {
            let eigen = SymmetricEigen::new((&m + m.adjoint()) * C64::new(0.5, 0.0));
            (
                eigen.eigenvalues.iter().copied().collect(),
                eigen.eigenvectors,
            )
        }
    }
}

/// The eigenbasis of spectrum `s` seen through whitening `w`
/// (`W S W^T = V diag(lambda) V^H`): `V^H W`, which takes channels to
/// whitened coordinates, `V`, and the eigenvalues (clamped at 0).
fn whitened_eigenbasis(
    w: &DMatrix<f64>,
    s: &DMatrix<C64>,
) -> (DMatrix<C64>, DMatrix<C64>, Vec<f64>) {
    let (values, vectors) = hermitian_eigen(whiten(w, s));
    let to_white = complex_times_real(&vectors.adjoint(), w);
    let lambda = values.iter().map(|&l| l.max(0.0)).collect();
    (to_white, vectors, lambda)
}

/// `W S W^T` for a real `W` and a complex `S`: a spectrum seen through a
/// whitening.
fn whiten(w: &DMatrix<f64>, s: &DMatrix<C64>) -> DMatrix<C64> {
    complex_times_real(&real_times_complex(w, s), &w.transpose())
}

/// `a b` for a real `a`: as two real products, which nalgebra hands to a
/// blocked matrix product (complex products run element by element, ten
/// times slower at these sizes, and most of a mixture's loading time).
fn real_times_complex(a: &DMatrix<f64>, b: &DMatrix<C64>) -> DMatrix<C64> {
    let (re, im) = (a * b.map(|z| z.re), a * b.map(|z| z.im));
    re.zip_map(&im, C64::new)
}

/// `a b` for a real `b` (see [`real_times_complex`]).
fn complex_times_real(a: &DMatrix<C64>, b: &DMatrix<f64>) -> DMatrix<C64> {
    let (re, im) = (a.map(|z| z.re) * b, a.map(|z| z.im) * b);
    re.zip_map(&im, C64::new)
}

/// Periodic Hann window of `len` frames at `t`.
fn hann(t: usize, len: usize) -> f64 {
    0.5 - 0.5 * (2.0 * PI * t as f64 / len as f64).cos()
}

/// The per-channel mean of `x` (frames x c), in f64.
fn channel_means(x: &[f32], c: usize) -> Vec<f64> {
    let frames = x.len() / c;
    let mut mean = vec![0.0; c];
    for frame in x.chunks_exact(c) {
        for (m, &v) in mean.iter_mut().zip(frame) {
            *m += v as f64 / frames as f64;
        }
    }
    mean
}

/// `x` (frames x c) minus its per-channel mean, as f64, and the mean.
fn centred(x: &[f32], c: usize) -> (Vec<f64>, Vec<f64>) {
    let mean = channel_means(x, c);
    let y = x
        .iter()
        .enumerate()
        .map(|(i, &v)| v as f64 - mean[i % c])
        .collect();
    (y, mean)
}

/// The `len` frames from padded frame `start` of `x` (frames x c) minus
/// `mean`, padded with `len` frames mirrored about each end frame
/// ([`reflected_frame`]): one segment, made when it is needed.
fn centred_segment(x: &[f32], mean: &[f64], c: usize, len: usize, start: usize) -> Vec<f64> {
    let frames = x.len() / c;
    let mut out = Vec::with_capacity(len * c);
    for i in start..start + len {
        let f = reflected_frame(i, frames, len);
        out.extend(
            x[f * c..(f + 1) * c]
                .iter()
                .zip(mean)
                .map(|(&v, m)| v as f64 - m),
        );
    }
    out
}

/// The frame of a take of `frames` frames at index `i` of its copy padded
/// by reflection with `pad` frames on each side, mirrored about the end
/// frames (bouncing again where the take is shorter than `pad`).
fn reflected_frame(i: usize, frames: usize, pad: usize) -> usize {
    let frames = frames as isize;
    let mut f = i as isize - pad as isize;
    if frames == 1 {
        f = 0;
    }
    while f < 0 || f >= frames {
        f = if f < 0 { -f } else { 2 * (frames - 1) - f };
    }
    f as usize
}

/// Forward and inverse Fourier transforms of one segment length
/// (`rustfft` plans, made once per fit or per take).
struct Transforms {
    forward: Arc<dyn Fft<f64>>,
    inverse: Arc<dyn Fft<f64>>,
    len: usize,
}

impl Transforms {
    fn new(len: usize) -> Transforms {
        let mut planner = FftPlanner::new();
        Transforms {
            forward: planner.plan_fft_forward(len),
            inverse: planner.plan_fft_inverse(len),
            len,
        }
    }

    /// The discrete Fourier transform along time, bins `0..=len/2`, of
    /// each channel of the `len` frames from `start`, multiplied by
    /// `window`: a `c x (len/2 + 1)` matrix.
    fn segment_spectrum(&self, x: &[f64], c: usize, start: usize, window: &[f64]) -> DMatrix<C64> {
        let (len, bins) = (self.len, self.len / 2 + 1);
        let mut out = DMatrix::<C64>::zeros(c, bins);
        let mut buffer = vec![C64::new(0.0, 0.0); len];
        for k in 0..c {
            for (t, (b, &w)) in buffer.iter_mut().zip(window).enumerate() {
                *b = C64::new(w * x[(start + t) * c + k], 0.0);
            }
            self.forward.process(&mut buffer);
            for b in 0..bins {
                out[(k, b)] = buffer[b];
            }
        }
        out
    }

    /// The real frames of a segment from its bins `0..=len/2` (the others
    /// are their conjugates): `len x c`, frame-major.
    fn inverse_segment(&self, spectrum: &DMatrix<C64>) -> Vec<f64> {
        let (len, c) = (self.len, spectrum.nrows());
        let mut out = vec![0.0; len * c];
        let mut buffer = vec![C64::new(0.0, 0.0); len];
        for k in 0..c {
            for b in 0..len {
                buffer[b] = if b <= len / 2 {
                    spectrum[(k, b)]
                } else {
                    spectrum[(k, len - b)].conj()
                };
            }
            self.inverse.process(&mut buffer);
            for (t, v) in buffer.iter().enumerate() {
                out[t * c + k] = v.re / len as f64;
            }
        }
        out
    }
}

/// The shapes of one bin's real and imaginary parts in a file: whole
/// `c x c` matrices, or (packed) the upper triangle with the diagonal and
/// the one without it, as `1 x n` rows.
fn spectrum_layout(description: &WienerDescription) -> ((usize, usize), (usize, usize)) {
    let c = description.channels;
    if description.packed_spectra {
        ((1, c * (c + 1) / 2), (1, c * (c - 1) / 2))
    } else {
        ((c, c), (c, c))
    }
}

/// Welch's estimate of the clean cross-spectra `S(f)` of the features of
/// `takes` (all on `layout`'s rig): the mean of `X X^H` over
/// half-overlapping Hann segments. Returns the spectra and the number of
/// segments.
fn welch_spectra(
    takes: &[&Motion],
    layout: &FeatureLayout,
    segment: usize,
) -> Result<(Vec<DMatrix<C64>>, usize)> {
    let c = layout.channels();
    let bins = segment / 2 + 1;
    let window: Vec<f64> = (0..segment).map(|t| hann(t, segment)).collect();
    let window_power: f64 = window.iter().map(|w| w * w).sum();
    let transforms = Transforms::new(segment);
    // Welch: the mean of X X^H over half-overlapping Hann segments.
    let per_take: Vec<(Vec<DMatrix<C64>>, usize)> = takes
        .par_iter()
        .map(|m| {
            let (x, _) = centred(&layout.encode(m), c);
            let frames = x.len() / c;
            let mut sums = vec![DMatrix::<C64>::zeros(c, c); bins];
            let count = segment_count(frames, segment);
            for start in (0..count).map(|k| k * segment / 2) {
                let spectrum = transforms.segment_spectrum(&x, c, start, &window);
                for (b, sum) in sums.iter_mut().enumerate() {
                    let column = spectrum.column(b);
                    sum.ger(
                        C64::new(1.0, 0.0),
                        &column,
                        &column.map(|v| v.conj()),
                        C64::new(1.0, 0.0),
                    );
                }
            }
            (sums, count)
        })
        .collect();
    let segments: usize = per_take.iter().map(|(_, n)| n).sum();
    if segments == 0 {
        return Err(CleanError::Invalid(format!(
            "no take is {segment} frames long: nothing to estimate the spectra from"
        )));
    }
    let mut spectra = vec![DMatrix::<C64>::zeros(c, c); bins];
    for (sums, _) in per_take {
        for (total, sum) in spectra.iter_mut().zip(sums) {
            *total += sum;
        }
    }
    let scale = C64::new(1.0 / (segments as f64 * window_power), 0.0);
    for s in &mut spectra {
        *s *= scale;
    }
    Ok((spectra, segments))
}

impl WienerFilter {
    /// Fits the filter to clean takes (all on the rig of the first; others
    /// are counted and left out): the signal spectra from every take, the
    /// noise covariance from noising up to 64 of them at `noise_sigma_deg`
    /// with `noise` (seeded).
    pub fn fit(
        takes: &[&Motion],
        noise: &RandomNoise,
        noise_sigma_deg: f32,
        segment: usize,
        seed: u64,
    ) -> Result<WienerFilter> {
        if segment < 8 || segment % 2 == 1 {
            return Err(CleanError::Invalid(format!(
                "a Wiener segment must be an even number of frames, at least 8 (got {segment})"
            )));
        }
        let first = takes
            .first()
            .ok_or_else(|| CleanError::Invalid("no takes to fit a Wiener filter to".into()))?;
        let layout = FeatureLayout::new(first.skeleton(), Representation::Rot6d)?;
        let joints = layout.joint_names(first.skeleton());
        let same_rig: Vec<&Motion> = takes
            .iter()
            .copied()
            .filter(|m| {
                FeatureLayout::new(m.skeleton(), Representation::Rot6d)
                    .is_ok_and(|l| l.joint_names(m.skeleton()) == joints)
            })
            .collect();
        let c = layout.channels();
        let (spectra, segments) = welch_spectra(&same_rig, &layout, segment)?;
        // N: the per-frame covariance of the noise of the features.
        let noised: Vec<(DMatrix<f64>, usize)> = same_rig
            .par_iter()
            .take(64)
            .enumerate()
            .map(|(i, m)| {
                let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(i as u64));
                let noisy = add_random_noise_sigma(m, noise_sigma_deg, noise, &mut rng);
                let (a, b) = (layout.encode(m), layout.encode(&noisy));
                let mut sum = DMatrix::<f64>::zeros(c, c);
                for (fa, fb) in a.chunks_exact(c).zip(b.chunks_exact(c)) {
                    let d =
                        DVector::from_iterator(c, fa.iter().zip(fb).map(|(p, q)| (q - p) as f64));
                    sum.ger(1.0, &d, &d, 1.0);
                }
                (sum, m.frame_count())
            })
            .collect();
        let noise_frames: usize = noised.iter().map(|(_, n)| n).sum();
        let noise_cov = noised
            .into_iter()
            .fold(DMatrix::<f64>::zeros(c, c), |acc, (s, _)| acc + s)
            / noise_frames.max(1) as f64;
        let description = WienerDescription {
            joints,
            channels: c,
            fps: first.fps() as f32,
            segment,
            noise: *noise,
            noise_sigma_deg,
            takes: same_rig.len(),
            frames: same_rig.iter().map(|m| m.frame_count()).sum(),
            segments,
            other_rig_takes: takes.len() - same_rig.len(),
            components: Vec::new(),
            packed_spectra: true,
        };
        Ok(Self::from_parts(description, vec![spectra], noise_cov))
    }

    /// The same filter with the clean spectra re-estimated from `takes`
    /// (which must be of the filter's rig) and the same noise covariance
    /// `N`, so that the marginal likelihoods (2) of two such filters on one
    /// take compare.
    pub fn with_spectra_of(&self, takes: &[&Motion]) -> Result<WienerFilter> {
        let first = takes
            .first()
            .ok_or_else(|| CleanError::Invalid("no takes to estimate spectra from".into()))?;
        let layout = self.layout_for(first)?;
        for m in takes {
            self.layout_for(m)?;
        }
        let (spectra, segments) = welch_spectra(takes, &layout, self.description.segment)?;
        let description = WienerDescription {
            takes: takes.len(),
            frames: takes.iter().map(|m| m.frame_count()).sum(),
            segments,
            other_rig_takes: 0,
            components: Vec::new(),
            packed_spectra: true,
            ..self.description.clone()
        };
        Ok(Self::from_parts(
            description,
            vec![spectra],
            self.noise.clone(),
        ))
    }

    /// A mixture of named single filters made by
    /// [`WienerFilter::with_spectra_of`] from one filter (the same rig,
    /// segment and `N`); see "Mixture" in the module docs.
    pub fn mixture(parts: Vec<(String, WienerFilter)>) -> Result<WienerFilter> {
        let first = match parts.first() {
            Some((_, f)) => f,
            None => return Err(CleanError::Invalid("a mixture needs components".into())),
        };
        let mut description = WienerDescription {
            takes: 0,
            frames: 0,
            segments: 0,
            components: Vec::new(),
            packed_spectra: true,
            ..first.description.clone()
        };
        let noise = first.noise.clone();
        let mut components = Vec::new();
        for (name, filter) in &parts {
            if filter.components.len() != 1 || !filter.same_noise_model(first) {
                return Err(CleanError::Invalid(format!(
                    "the mixture's component {name} is not a single filter with the same rig, \
                     segment and noise covariance as the first"
                )));
            }
            let d = &filter.description;
            // The components may share takes (an "all" component): the
            // mixture was fitted to as many as its largest one.
            description.takes = description.takes.max(d.takes);
            description.frames = description.frames.max(d.frames);
            description.segments = description.segments.max(d.segments);
            description.components.push(ComponentInfo {
                name: name.clone(),
                takes: d.takes,
                segments: d.segments,
            });
            components.extend(filter.components.iter().cloned());
        }
        Ok(WienerFilter {
            description,
            components,
            noise,
            whitening: first.whitening.clone(),
            level_estimate: first.level_estimate,
        })
    }

    /// The single filter a mixture was made from (its `all` component,
    /// which [`fit_mixture`] adds), or this filter when it is one.
    pub(crate) fn single(&self) -> Result<WienerFilter> {
        if self.components.len() == 1 {
            return Ok(self.clone());
        }
        let k = self
            .description
            .components
            .iter()
            .position(|c| c.name == "all")
            .ok_or_else(|| {
                CleanError::Invalid(
                    "this mixture has no `all` component, the single filter it was made from"
                        .into(),
                )
            })?;
        let info = &self.description.components[k];
        Ok(WienerFilter {
            description: WienerDescription {
                takes: info.takes,
                segments: info.segments,
                components: Vec::new(),
                ..self.description.clone()
            },
            components: vec![self.components[k].clone()],
            noise: self.noise.clone(),
            whitening: self.whitening.clone(),
            level_estimate: self.level_estimate,
        })
    }

    /// Whether `other` reads takes as this filter does: the same rig,
    /// segment and noise covariance `N` at the same level, so that their
    /// levels mean the same and their likelihoods (2) compare.
    pub fn same_noise_model(&self, other: &WienerFilter) -> bool {
        let (a, b) = (&self.description, &other.description);
        a.joints == b.joints
            && a.segment == b.segment
            && a.noise_sigma_deg == b.noise_sigma_deg
            && self.noise == other.noise
    }

    /// Builds the per-bin bases of (2) from each component's spectra and `N`
    /// (those of (1) wait until a component is used: [`Self::bins`]).
    fn from_parts(
        description: WienerDescription,
        spectra_sets: Vec<Vec<DMatrix<C64>>>,
        noise: DMatrix<f64>,
    ) -> WienerFilter {
        let c = noise.nrows();
        let ridge = noise_ridge(&noise);
        // N = Q D Q^T once: its powers with the ridge for (1), and the
        // directions it puts noise in for (2).
        let eigen = SymmetricEigen::new(noise.clone());
        let root = |power: f64| {
            let d = DMatrix::from_diagonal(
                &eigen.eigenvalues.map(|v| (v.max(0.0) + ridge).powf(power)),
            );
            &eigen.eigenvectors * d * eigen.eigenvectors.transpose()
        };
        // The noise level is estimated only in the directions the noise model
        // puts noise in: in the others the whitening has nothing but the
        // ridge to divide by, and any power the training spectra did not
        // foresee there would be taken for noise.
        let largest = eigen.eigenvalues.iter().cloned().fold(0.0, f64::max);
        let noisy: Vec<usize> = (0..c)
            .filter(|&i| eigen.eigenvalues[i] > 1e-6 * largest && largest > 0.0)
            .collect();
        let whitening = Whitening {
            half: root(0.5),
            inverse_half: root(-0.5),
            noisy: DMatrix::from_fn(noisy.len(), c, |k, j| {
                let i = noisy[k];
                eigen.eigenvectors[(j, i)] / eigen.eigenvalues[i].sqrt()
            }),
        };
        let components = spectra_sets
            .into_iter()
            .map(|spectra| {
                let level_bins = spectra
                    .par_iter()
                    .map(|s| {
                        let (noisy_to_white, _, noisy_lambda) =
                            whitened_eigenbasis(&whitening.noisy, s);
                        LevelBin {
                            noisy_to_white,
                            noisy_lambda,
                        }
                    })
                    .collect();
                Component {
                    spectra,
                    level_bins,
                    bins: OnceLock::new(),
                    level_table: OnceLock::new(),
                }
            })
            .collect();
        WienerFilter {
            description,
            components,
            noise,
            whitening: Arc::new(whitening),
            level_estimate: LevelEstimate::default(),
        }
    }

    /// The bases of (1) of `component`, built on first use. Built on one
    /// thread: takes are often filtered in parallel (rayon), and a rayon
    /// thread building them in parallel could, while it waits, pick up
    /// another take's filtering, which would wait on the same cell.
    fn bins<'a>(&self, component: &'a Component) -> &'a [Bin] {
        component.bins.get_or_init(|| {
            let w = &self.whitening;
            component
                .spectra
                .iter()
                .map(|s| {
                    let (to_white, v, lambda) = whitened_eigenbasis(&w.inverse_half, s);
                    Bin {
                        to_white,
                        from_white: real_times_complex(&w.half, &v),
                        lambda,
                    }
                })
                .collect()
        })
    }

    /// The table of (2) of `component`, built on first use (on one thread,
    /// as [`Self::bins`]).
    fn level_table<'a>(&self, component: &'a Component) -> &'a LevelTable {
        component
            .level_table
            .get_or_init(|| LevelTable::new(self, component))
    }

    /// The features of `motion`'s rig, or an error naming both rigs.
    pub(crate) fn layout_for(&self, motion: &Motion) -> Result<FeatureLayout> {
        let layout = FeatureLayout::new(motion.skeleton(), Representation::Rot6d)?;
        let names = layout.joint_names(motion.skeleton());
        if names != self.description.joints {
            let d = &self.description.joints;
            return Err(CleanError::Invalid(format!(
                "the Wiener filter was fitted to a rig of {} joints with rotations ({}, ...), \
                 this take has {} ({}, ...): clean it with --filter, or fit one to this rig \
                 with `mocap clean fit-wiener`",
                d.len(),
                d[..d.len().min(3)].join(", "),
                names.len(),
                names[..names.len().min(3)].join(", "),
            )));
        }
        Ok(layout)
    }

    /// Cleans `motion` (root translation kept); `sigma_deg` forces the noise
    /// level, `None` estimates it by (2).
    pub fn clean(
        &self,
        motion: &Motion,
        sigma_deg: Option<f64>,
    ) -> Result<(Motion, WienerOutcome)> {
        let layout = self.layout_for(motion)?;
        if motion.frame_count() == 0 {
            return Ok((
                motion.clone(),
                WienerOutcome {
                    sigma_deg: 0.0,
                    component: 0,
                },
            ));
        }
        let mut features = layout.encode(motion);
        let outcome = self.filter_features(&mut features, sigma_deg);
        let mut out = motion.clone();
        layout.decode_into(&features, &mut out);
        Ok((out, outcome))
    }

    /// Filters features of the fitted rig in place (frames x channels).
    pub fn filter_features(&self, features: &mut [f32], sigma_deg: Option<f64>) -> WienerOutcome {
        self.filter_features_missing(features, sigma_deg, None)
    }

    /// [`WienerFilter::filter_features`] with some values marked missing
    /// (`missing`: frames x channels, as `features`): in every segment that
    /// holds a missing value of a channel, that channel is not read at all
    /// and is estimated from the others, the conditional mean of the
    /// Gaussian model of (1):
    ///
    /// ```text
    /// Y(f) = S(f) (S(f) + s N + D)^-1 X(f)                              (3)
    /// ```
    ///
    /// `D` being a huge variance on those channels (a direct solve per
    /// segment and bin, where (1) reuses one eigendecomposition). What it
    /// is for: a spike replaces a subtree's rotations with another motion's,
    /// so its values say nothing of the clean ones, but the rest of the body
    /// does (an arm swings with the legs). The noise level is still
    /// estimated on every segment inside the take.
    pub fn filter_features_missing(
        &self,
        features: &mut [f32],
        sigma_deg: Option<f64>,
        missing: Option<&[bool]>,
    ) -> WienerOutcome {
        self.filter_in_chunks(features, sigma_deg, missing, CHUNK_SEGMENTS)
    }

    /// [`WienerFilter::filter_features_missing`], `chunk` segments at a
    /// time (see "Memory" in the module docs): the result does not depend
    /// on `chunk`, every segment being computed alone and added to the
    /// overlap in the same order.
    fn filter_in_chunks(
        &self,
        features: &mut [f32],
        sigma_deg: Option<f64>,
        missing: Option<&[bool]>,
        chunk: usize,
    ) -> WienerOutcome {
        let c = self.description.channels;
        let len = self.description.segment;
        let frames = features.len() / c;
        if frames == 0 {
            return WienerOutcome {
                sigma_deg: sigma_deg.unwrap_or(0.0),
                component: 0,
            };
        }
        // The two segments that read the mirrored start must be in the
        // first chunk.
        let chunk = chunk.max(2);
        let mean = channel_means(&features[..frames * c], c);
        let total = frames + 2 * len;
        let window: Vec<f64> = (0..len).map(|t| hann(t, len).sqrt()).collect();
        let transforms = Transforms::new(len);
        let starts: Vec<usize> = (0..)
            .map(|k| k * len / 2)
            .take_while(|s| s + len <= total)
            .collect();
        let spectrum_at = |features: &[f32], start: usize| {
            let x = centred_segment(features, &mean, c, len, start);
            transforms.segment_spectrum(&x, c, 0, &window)
        };
        let (k, sigma) = match sigma_deg {
            Some(sigma) if self.components.len() == 1 => (0, sigma),
            _ => {
                // Judged on the segments inside the take: the mirrored
                // padding bends every channel at the take's ends, power the
                // clean spectra never had (all segments when the take is
                // shorter than one).
                let mut inside: Vec<usize> = starts
                    .iter()
                    .copied()
                    .filter(|&s| s >= len && s + len <= len + frames)
                    .collect();
                if inside.is_empty() {
                    inside = starts.clone();
                }
                let spectra_of = |starts: &[usize]| -> Vec<DMatrix<C64>> {
                    starts
                        .par_iter()
                        .map(|&s| spectrum_at(features, s))
                        .collect()
                };
                // The component of largest likelihood (each at its own best
                // level), judged on at most `CHOICE_SEGMENTS` segments spread
                // over the take, a cost that does not grow with the take
                // times the components; then its level on every segment.
                let k = if self.components.len() == 1 {
                    0
                } else {
                    let step = inside.len().div_ceil(CHOICE_SEGMENTS);
                    let some: Vec<usize> = inside.iter().step_by(step.max(1)).copied().collect();
                    let spectra = spectra_of(&some);
                    let some: Vec<&DMatrix<C64>> = spectra.iter().collect();
                    self.components
                        .iter()
                        .map(|component| self.estimate_level(component, &some, &window).1)
                        .enumerate()
                        .max_by(|a, b| a.1.total_cmp(&b.1))
                        .map_or(0, |(k, _)| k)
                };
                let estimated = match sigma_deg {
                    Some(sigma) => sigma,
                    None => {
                        // Each chunk's segment powers, from spectra made
                        // and dropped chunk by chunk.
                        let component = &self.components[k];
                        let norm: f64 = window.iter().map(|v| v * v).sum();
                        let powers = inside.chunks(chunk).map(|part| {
                            spectra_of(part)
                                .par_iter()
                                .map(|x| self.segment_power(component, x, norm))
                                .collect::<Vec<Vec<f64>>>()
                        });
                        self.take_level(component, powers, inside.len())
                    }
                };
                (k, estimated)
            }
        };
        let component = &self.components[k];
        let bins = self.bins(component);
        let s = (sigma / self.description.noise_sigma_deg as f64).powi(2);
        // For (3): S(f) + s N per bin, the same for every segment.
        let totals: Vec<DMatrix<C64>> = if missing.is_some() {
            self.signal_plus_noise(component, s)
        } else {
            Vec::new()
        };
        // The take's frames that the mirrored end reads: written last.
        let hold_from = frames.saturating_sub(len + 1);
        // The overlap-add of the segments' outputs, from padded frame `base`.
        let mut sum: Vec<f64> = Vec::new();
        let mut base = 0;
        let parts = starts.len().div_ceil(chunk);
        for (n, part) in starts.chunks(chunk).enumerate() {
            // (1) per segment and bin: whiten (z = V^H N^-1/2 X), scale each
            // coordinate by lambda / (lambda + s), colour back.
            let filtered: Vec<Vec<f64>> = part
                .par_iter()
                .map(|&start| {
                    let x = spectrum_at(features, start);
                    let gone: Vec<usize> = missing.map_or(Vec::new(), |m| {
                        (0..c)
                            .filter(|&k| {
                                (start..start + len)
                                    .any(|t| m[reflected_frame(t, frames, len) * c + k])
                            })
                            .collect()
                    });
                    if !gone.is_empty() {
                        return transforms.inverse_segment(
                            &self.conditional_mean(component, &x, &totals, &gone),
                        );
                    }
                    let mut spectrum = DMatrix::<C64>::zeros(c, bins.len());
                    for (b, bin) in bins.iter().enumerate() {
                        let z = &bin.to_white * x.column(b);
                        let gained = DVector::from_iterator(
                            c,
                            z.iter()
                                .zip(&bin.lambda)
                                .map(|(v, &l)| v * (l / (l + s).max(1e-300))),
                        );
                        spectrum.set_column(b, &(&bin.from_white * gained));
                    }
                    transforms.inverse_segment(&spectrum)
                })
                .collect();
            let last = n + 1 == parts;
            let end = if last {
                total
            } else {
                part[part.len() - 1] + len
            };
            sum.resize((end - base) * c, 0.0);
            // Overlap-add with the synthesis window (analysis x synthesis =
            // Hann).
            for (&start, y) in part.iter().zip(&filtered) {
                for (t, &w) in window.iter().enumerate() {
                    let at = (start - base + t) * c;
                    for (o, &v) in sum[at..at + c].iter_mut().zip(&y[t * c..(t + 1) * c]) {
                        *o += w * v;
                    }
                }
            }
            // Padded frames before the next segment are whole; their take
            // frames are no later segment's input, but for those the
            // mirrored end reads.
            let done = if last {
                end
            } else {
                starts[(n + 1) * chunk].min(len + hold_from).max(base)
            };
            for p in base.max(len)..done.min(len + frames) {
                let (from, to) = ((p - base) * c, (p - len) * c);
                for (k, f) in features[to..to + c].iter_mut().enumerate() {
                    *f = (sum[from + k] + mean[k]) as f32;
                }
            }
            sum.drain(..(done - base) * c);
            base = done;
        }
        WienerOutcome {
            sigma_deg: sigma,
            component: k,
        }
    }

    /// `S(f) + s (N + ridge)` for every bin: the covariance of a noisy
    /// segment's bins at noise level `s`.
    fn signal_plus_noise(&self, component: &Component, s: f64) -> Vec<DMatrix<C64>> {
        let c = self.description.channels;
        let ridge = noise_ridge(&self.noise);
        component
            .spectra
            .iter()
            .map(|spectrum| {
                let mut total = spectrum.clone();
                for i in 0..c {
                    for j in 0..c {
                        total[(i, j)] += C64::new(s * self.noise[(i, j)], 0.0);
                    }
                    total[(i, i)] += C64::new(s * ridge, 0.0);
                }
                total
            })
            .collect()
    }

    /// (3) for one segment's bins `x` (`c x bins`), `totals` being
    /// [`WienerFilter::signal_plus_noise`] at the take's level, the channels
    /// `gone` not read.
    fn conditional_mean(
        &self,
        component: &Component,
        x: &DMatrix<C64>,
        totals: &[DMatrix<C64>],
        gone: &[usize],
    ) -> DMatrix<C64> {
        let c = self.description.channels;
        let ridge = noise_ridge(&self.noise);
        let mut out = DMatrix::<C64>::zeros(c, component.spectra.len());
        for (b, (spectrum, total)) in component.spectra.iter().zip(totals).enumerate() {
            // Far above any channel's power: the channel's value is noise.
            let unknown = 1e6 * (spectrum.trace().re / c as f64 + ridge);
            let mut total = total.clone();
            for &k in gone {
                total[(k, k)] += C64::new(unknown, 0.0);
            }
            let solved = total
                .lu()
                .solve(&x.column(b).into_owned())
                .unwrap_or_else(|| DVector::zeros(c));
            out.set_column(b, &(spectrum * solved));
        }
        out
    }

    /// The power of one segment's bins `x` per bin and coordinate of (2),
    /// in the noise-whitened basis of `component`'s noisy directions.
    fn segment_power(&self, component: &Component, x: &DMatrix<C64>, norm: f64) -> Vec<f64> {
        component
            .level_bins
            .iter()
            .enumerate()
            .flat_map(|(b, bin)| {
                let z = &bin.noisy_to_white * x.column(b);
                z.iter().map(|v| v.norm_sqr() / norm).collect::<Vec<f64>>()
            })
            .collect()
    }

    /// The noise level of largest marginal likelihood (2) over all the
    /// segments `spectra` together, and that log-likelihood.
    fn estimate_level(
        &self,
        component: &Component,
        spectra: &[&DMatrix<C64>],
        window: &[f64],
    ) -> (f64, f64) {
        // Coefficients of a window v have variance (lambda + s) sum(v^2)
        // in the units the spectra were normalised to.
        let norm: f64 = window.iter().map(|v| v * v).sum();
        let coordinates = self.level_table(component).weights.len();
        let power = spectra
            .par_iter()
            .map(|x| self.segment_power(component, x, norm))
            .reduce(
                || vec![0.0; coordinates],
                |mut a, b| {
                    for (x, y) in a.iter_mut().zip(&b) {
                        *x += y;
                    }
                    a
                },
            );
        self.level_table(component)
            .most_likely_level(&power, spectra.len() as f64)
    }

    /// The take's noise level from the powers of its segments
    /// ([`WienerFilter::segment_power`], `segments` of them, given chunk by
    /// chunk), as [`WienerFilter::level_estimate`] says.
    fn take_level(
        &self,
        component: &Component,
        powers: impl Iterator<Item = Vec<Vec<f64>>>,
        segments: usize,
    ) -> f64 {
        let table = self.level_table(component);
        match self.level_estimate {
            LevelEstimate::Pooled => {
                let all: Vec<Vec<f64>> = powers.flatten().collect();
                let power = all.into_par_iter().reduce(
                    || vec![0.0; table.weights.len()],
                    |mut a, b| {
                        for (x, y) in a.iter_mut().zip(&b) {
                            *x += y;
                        }
                        a
                    },
                );
                table.most_likely_level(&power, segments as f64).0
            }
            LevelEstimate::SegmentMedian => {
                // One level per segment: a number each, whatever the
                // take's length.
                let mut levels = Vec::with_capacity(segments);
                for part in powers {
                    levels.extend(table.segment_levels(&part));
                }
                median(&mut levels)
            }
        }
    }

    /// How this filter estimates a take's noise level.
    pub fn level_estimate(&self) -> LevelEstimate {
        self.level_estimate
    }

    /// Sets how this filter estimates a take's noise level (not stored in
    /// its file).
    pub fn set_level_estimate(&mut self, estimate: LevelEstimate) {
        self.level_estimate = estimate;
    }

    /// The stored numbers as a burn module (for a file of their own, or
    /// inside a network's file when the network corrects this filter).
    pub(crate) fn to_tensors(&self) -> WienerTensors {
        let device = Device::flex();
        let c = self.description.channels;
        let (re_len, im_len) = spectrum_layout(&self.description);
        // Every component's bins one after the other, as `from_tensors`
        // reads them: whole matrices row-major, or their upper triangles.
        let spectra: Vec<&DMatrix<C64>> = self.components.iter().flat_map(|k| &k.spectra).collect();
        let packed = self.description.packed_spectra;
        let (mut re, mut im) = (Vec::new(), Vec::new());
        for s in &spectra {
            for i in 0..c {
                for j in 0..c {
                    let v = s[(i, j)];
                    if !packed {
                        re.push(v.re as f32);
                        im.push(v.im as f32);
                    } else if j >= i {
                        re.push(v.re as f32);
                        if j > i {
                            im.push(v.im as f32);
                        }
                    }
                }
            }
        }
        let n = spectra.len();
        let noise: Vec<f32> = self.noise.transpose().iter().map(|&v| v as f32).collect();
        WienerTensors {
            spectra_re: Param::from_tensor(Tensor::from_data(
                TensorData::new(re, [n, re_len.0, re_len.1]),
                &device,
            )),
            spectra_im: Param::from_tensor(Tensor::from_data(
                TensorData::new(im, [n, im_len.0, im_len.1]),
                &device,
            )),
            noise: Param::from_tensor(Tensor::from_data(TensorData::new(noise, [c, c]), &device)),
        }
    }

    /// Checks a stored description before anything is built from it.
    pub(crate) fn check_description(
        description: &WienerDescription,
    ) -> std::result::Result<(), String> {
        if description.segment < 8 || description.segment % 2 == 1 {
            return Err(format!("bad Wiener filter segment {}", description.segment));
        }
        if description.channels == 0 || description.channels != 6 * description.joints.len() {
            return Err(format!(
                "bad Wiener filter description: {} channels for {} joints",
                description.channels,
                description.joints.len()
            ));
        }
        if description.noise_sigma_deg.is_nan() || description.noise_sigma_deg <= 0.0 {
            return Err("bad Wiener filter description: noise level".into());
        }
        Ok(())
    }

    /// How many numbers the tensors of `description` hold (saturating): a
    /// damaged header is refused before [`WienerFilter::empty_tensors`]
    /// allocates them.
    pub(crate) fn stored_value_count(description: &WienerDescription) -> usize {
        let c = description.channels;
        let triangle = c.saturating_mul(c.saturating_add(1)) / 2;
        let per_bin = if description.packed_spectra {
            triangle.saturating_mul(2).saturating_sub(c)
        } else {
            c.saturating_mul(c).saturating_mul(2)
        };
        let bins = description
            .component_count()
            .saturating_mul(description.segment / 2 + 1);
        bins.saturating_mul(per_bin)
            .saturating_add(c.saturating_mul(c))
    }

    /// Zeros of the shapes `description` stores, to load a file into.
    pub(crate) fn empty_tensors(description: &WienerDescription) -> WienerTensors {
        let device = Device::flex();
        let c = description.channels;
        let bins = description.component_count() * (description.segment / 2 + 1);
        let (re, im) = spectrum_layout(description);
        WienerTensors {
            spectra_re: Param::from_tensor(Tensor::zeros([bins, re.0, re.1], &device)),
            spectra_im: Param::from_tensor(Tensor::zeros([bins, im.0, im.1], &device)),
            noise: Param::from_tensor(Tensor::zeros([c, c], &device)),
        }
    }

    /// The filter from loaded tensors (see [`WienerFilter::empty_tensors`]).
    pub(crate) fn from_tensors(
        description: WienerDescription,
        tensors: WienerTensors,
    ) -> std::result::Result<WienerFilter, String> {
        let (c, bins) = (description.channels, description.segment / 2 + 1);
        let read = |t: TensorData, what: &str| -> std::result::Result<Vec<f32>, String> {
            t.try_to_vec::<f32>()
                .map_err(|e| format!("reading the {what}: {e:?}"))
        };
        let re = read(tensors.spectra_re.val().into_data(), "spectra")?;
        let im = read(tensors.spectra_im.val().into_data(), "spectra")?;
        let noise = read(tensors.noise.val().into_data(), "noise covariance")?;
        if re.iter().chain(&im).chain(&noise).any(|v| !v.is_finite()) {
            return Err("the Wiener filter holds non-finite numbers".into());
        }
        let (re_len, im_len) = spectrum_layout(&description);
        let (re_len, im_len) = (re_len.0 * re_len.1, im_len.0 * im_len.1);
        let packed = description.packed_spectra;
        let matrix = |b: usize| -> DMatrix<C64> {
            let (re, im) = (
                &re[b * re_len..(b + 1) * re_len],
                &im[b * im_len..(b + 1) * im_len],
            );
            if !packed {
                return DMatrix::from_fn(c, c, |i, j| {
                    C64::new(re[i * c + j] as f64, im[i * c + j] as f64)
                });
            }
            let mut m = DMatrix::<C64>::zeros(c, c);
            let (mut r, mut q) = (0, 0);
            for i in 0..c {
                for j in i..c {
                    let imag = if j > i {
                        q += 1;
                        im[q - 1] as f64
                    } else {
                        0.0
                    };
                    m[(i, j)] = C64::new(re[r] as f64, imag);
                    m[(j, i)] = m[(i, j)].conj();
                    r += 1;
                }
            }
            m
        };
        let spectra_sets = (0..description.component_count())
            .map(|component| {
                (component * bins..(component + 1) * bins)
                    .map(matrix)
                    .collect()
            })
            .collect();
        let noise = DMatrix::from_fn(c, c, |i, j| noise[i * c + j] as f64);
        Ok(Self::from_parts(description, spectra_sets, noise))
    }

    /// Writes the filter (atomically) in the checkpoint format the networks use.
    pub fn save(&self, path: &Path, data: serde_json::Value) -> Result<()> {
        let header = CheckpointHeader {
            kind: WIENER_KIND.into(),
            kind_version: WIENER_KIND_VERSION,
            config: serde_json::to_value(&self.description)
                .map_err(|e| CleanError::Invalid(format!("describing the filter: {e}")))?,
            data,
            training: serde_json::Value::Null,
        };
        save_weights(path, &self.to_tensors(), &header)?;
        Ok(())
    }

    /// Reads a file written by [`WienerFilter::save`]; `origin` names the
    /// bytes in errors.
    pub fn from_bytes(bytes: Vec<u8>, origin: &Path) -> Result<WienerFilter> {
        let header = header_from_bytes(&bytes, origin)?;
        let bad = |m: String| CleanError::Invalid(format!("{}: {m}", origin.display()));
        header.expect_kind(origin, WIENER_KIND, WIENER_KIND_VERSION, "a Wiener filter")?;
        let description: WienerDescription = serde_json::from_value(header.config)
            .map_err(|e| bad(format!("bad Wiener filter description: {e}")))?;
        Self::check_description(&description).map_err(bad)?;
        check_parameter_count(&bytes, origin, Self::stored_value_count(&description))?;
        let empty = Self::empty_tensors(&description);
        let tensors = load_weights_from_bytes(bytes, origin, empty)?;
        Self::from_tensors(description, tensors).map_err(bad)
    }

    /// What filtering a take did, in words: `noise estimated at 4.2 deg`,
    /// and for a mixture `, spectra of walk` (the component's name).
    pub fn describe(&self, outcome: &WienerOutcome) -> String {
        let level = format!("noise estimated at {:.1} deg", outcome.sigma_deg);
        match self.description.components.get(outcome.component) {
            Some(component) => format!("{level}, spectra of {}", component.name),
            None => level,
        }
    }

    /// `N`, the per-frame covariance of the noise of the features at
    /// [`WienerDescription::noise_sigma_deg`].
    pub fn noise_covariance(&self) -> &DMatrix<f64> {
        &self.noise
    }

    /// The same filter with every channel on its own: only the diagonals
    /// of the spectra and of `N` kept (what a per-channel filter can know;
    /// for comparisons).
    pub fn per_channel(&self) -> WienerFilter {
        let diagonal = |m: &DMatrix<C64>| DMatrix::from_diagonal(&m.diagonal());
        Self::from_parts(
            self.description.clone(),
            self.components
                .iter()
                .map(|k| k.spectra.iter().map(diagonal).collect())
                .collect(),
            DMatrix::from_diagonal(&self.noise.diagonal()),
        )
    }

    /// Reads a Wiener filter file.
    pub fn load(path: &Path) -> Result<WienerFilter> {
        let bytes = std::fs::read(path).map_err(|e| mocap_core::Error::io(path, e))?;
        Self::from_bytes(bytes, path)
    }
}

/// The content of a take named `<set>_<content>_<style>_<take>` (Bandai's
/// scheme; HDM05's `HDM_<actor>_<class>_...` gives the actor), or `None`
/// for a name with fewer parts.
fn content_of(name: &str) -> Option<&str> {
    let parts: Vec<&str> = name.split('_').collect();
    (parts.len() >= 3).then_some(parts[1])
}

/// Welch segments of `segment` frames, half overlapping, in `frames`.
fn segment_count(frames: usize, segment: usize) -> usize {
    if frames < segment {
        0
    } else {
        (frames - segment) / (segment / 2) + 1
    }
}

/// A mixture (see "Mixture" in the module docs) made from `single`, a
/// filter fitted to all of `takes`: one component per content named in the
/// take names (`<set>_<content>_<style>_<take>`) with at least
/// `min_segments` Welch segments, one for the other takes together, and
/// `single`'s own spectra as the last component ("all"), for takes unlike
/// any one content. Takes of another rig than `single`'s are left out.
pub fn fit_mixture(
    single: &WienerFilter,
    takes: &[Take],
    min_segments: usize,
) -> Result<WienerFilter> {
    // A mixture is refitted from the single filter it was made from.
    let single = &single.single()?;
    let segment = single.description.segment;
    let mut groups: std::collections::BTreeMap<&str, Vec<&Motion>> = Default::default();
    for take in takes {
        if single.layout_for(&take.motion).is_ok() {
            let content = content_of(&take.name).unwrap_or("");
            groups.entry(content).or_default().push(&take.motion);
        }
    }
    let mut parts = Vec::new();
    let mut other: Vec<&Motion> = Vec::new();
    for (content, motions) in groups {
        let segments: usize = motions
            .iter()
            .map(|m| segment_count(m.frame_count(), segment))
            .sum();
        if !content.is_empty() && segments >= min_segments {
            parts.push((content.to_string(), single.with_spectra_of(&motions)?));
        } else {
            other.extend(motions);
        }
    }
    if other
        .iter()
        .any(|m| segment_count(m.frame_count(), segment) > 0)
    {
        parts.push(("other".to_string(), single.with_spectra_of(&other)?));
    }
    parts.push(("all".to_string(), single.clone()));
    WienerFilter::mixture(parts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::rotation_error_deg;
    use crate::test_support::synthetic_motion_phase;

    /// Fitted to eight 8-s takes of the synthetic 5-joint chain.
    fn fitted() -> WienerFilter {
        let takes: Vec<Motion> = (0..8)
            .map(|k| synthetic_motion_phase(240, 5, 0.7 * k as f32))
            .collect();
        let refs: Vec<&Motion> = takes.iter().collect();
        WienerFilter::fit(&refs, &RandomNoise::default(), 5.0, 32, 1).unwrap()
    }

    #[test]
    fn real_by_complex_products_match_the_complex_product() {
        let real = DMatrix::from_fn(5, 7, |i, j| ((i * 7 + j) as f64 * 0.37).sin());
        let complex = DMatrix::from_fn(7, 4, |i, j| {
            C64::new((i as f64 - j as f64) * 0.3, ((i * j) as f64).cos())
        });
        let as_complex = |m: &DMatrix<f64>| m.map(|v| C64::new(v, 0.0));
        let expected = &as_complex(&real) * &complex;
        assert!((real_times_complex(&real, &complex) - &expected).norm() < 1e-12);
        let expected = &complex.adjoint() * &as_complex(&real.transpose());
        let got = complex_times_real(&complex.adjoint(), &real.transpose());
        assert!((got - &expected).norm() < 1e-12);
        // W S W^T, a spectrum seen through a whitening.
        let s = DMatrix::from_fn(7, 7, |i, j| C64::new((i + j) as f64, i as f64 - j as f64));
        let expected = &as_complex(&real) * &s * as_complex(&real.transpose());
        assert!((whiten(&real, &s) - expected).norm() < 1e-9);
    }

    #[test]
    fn the_short_time_transform_gives_back_its_input() {
        // With every gain 1 the analysis, synthesis and overlap-add must
        // return the features, for takes shorter and longer than a segment.
        let c = 6;
        let bins: Vec<Bin> = (0..17)
            .map(|_| Bin {
                to_white: DMatrix::identity(c, c),
                from_white: DMatrix::identity(c, c),
                lambda: vec![1e30; c],
            })
            .collect();
        let level_bins = (0..17)
            .map(|_| LevelBin {
                noisy_to_white: DMatrix::identity(c, c),
                noisy_lambda: vec![1e30; c],
            })
            .collect();
        let filter = WienerFilter {
            description: WienerDescription {
                joints: vec!["j".into()],
                channels: c,
                fps: 30.0,
                segment: 32,
                noise: RandomNoise::default(),
                noise_sigma_deg: 5.0,
                takes: 0,
                frames: 0,
                segments: 0,
                other_rig_takes: 0,
                components: Vec::new(),
                packed_spectra: false,
            },
            components: vec![Component {
                spectra: Vec::new(),
                level_bins,
                bins: OnceLock::from(bins),
                level_table: OnceLock::new(),
            }],
            noise: DMatrix::zeros(c, c),
            whitening: Arc::new(Whitening {
                half: DMatrix::identity(c, c),
                inverse_half: DMatrix::identity(c, c),
                noisy: DMatrix::identity(c, c),
            }),
            level_estimate: LevelEstimate::default(),
        };
        for frames in [0, 1, 5, 31, 32, 33, 100] {
            let x: Vec<f32> = (0..frames * c)
                .map(|i| ((i * 37 % 101) as f32 / 50.0 - 1.0) + (i / c) as f32 * 0.01)
                .collect();
            let mut y = x.clone();
            filter.filter_features(&mut y, Some(1.0));
            let most = x
                .iter()
                .zip(&y)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f32::max);
            assert!(most < 1e-5, "{frames} frames: off by {most}");
        }
    }

    #[test]
    fn values_marked_missing_are_estimated_from_the_other_channels() {
        let filter = fitted();
        let layout = FeatureLayout::new(
            synthetic_motion_phase(2, 5, 0.0).skeleton(),
            Representation::Rot6d,
        )
        .unwrap();
        let c = layout.channels();
        let clean = layout.encode(&synthetic_motion_phase(300, 5, 0.35));
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let noisy = layout.encode(&add_random_noise_sigma(
            &synthetic_motion_phase(300, 5, 0.35),
            2.0,
            &RandomNoise::default(),
            &mut rng,
        ));
        // Nothing missing: exactly the plain filter.
        let (mut plain, mut none) = (noisy.clone(), noisy.clone());
        filter.filter_features(&mut plain, Some(2.0));
        filter.filter_features_missing(&mut none, Some(2.0), Some(&vec![false; noisy.len()]));
        assert_eq!(plain, none);
        // A joint's 6 channels taken from another motion for 40 frames.
        let other = layout.encode(&synthetic_motion_phase(300, 5, 2.1));
        let (joint, frames) = (2, 130..170);
        let mut spiked = noisy.clone();
        let mut missing = vec![false; noisy.len()];
        for f in frames.clone() {
            for k in joint * 6..joint * 6 + 6 {
                spiked[f * c + k] = other[f * c + k];
                missing[f * c + k] = true;
            }
        }
        let error = |y: &[f32]| -> f32 {
            frames
                .clone()
                .flat_map(|f| (joint * 6..joint * 6 + 6).map(move |k| f * c + k))
                .map(|i| (y[i] - clean[i]).powi(2))
                .sum::<f32>()
                .sqrt()
        };
        let (mut blind, mut told) = (spiked.clone(), spiked.clone());
        filter.filter_features(&mut blind, Some(2.0));
        filter.filter_features_missing(&mut told, Some(2.0), Some(&missing));
        assert!(
            error(&told) < 0.3 * error(&blind),
            "missing values: {} against {} read as they are",
            error(&told),
            error(&blind)
        );
        // Away from the marked segments nothing changes.
        assert_eq!(&told[..64 * c], &blind[..64 * c]);
    }

    /// `x` (frames x c) padded with `pad` frames on each side, mirrored
    /// about the end frames.
    fn reflect_pad<T: Copy>(x: &[T], c: usize, pad: usize) -> Vec<T> {
        let frames = x.len() / c;
        let mut out = Vec::with_capacity(x.len() + 2 * pad * c);
        for i in 0..frames + 2 * pad {
            let f = reflected_frame(i, frames, pad);
            out.extend_from_slice(&x[f * c..(f + 1) * c]);
        }
        out
    }

    /// The filter as it was written before it worked in chunks: every
    /// segment's spectrum at once, over a padded copy of the take (a level
    /// by the default estimate). The chunked filter must give the same bits.
    fn whole_take(
        filter: &WienerFilter,
        features: &mut [f32],
        sigma_deg: Option<f64>,
        missing: Option<&[bool]>,
    ) -> WienerOutcome {
        let c = filter.description.channels;
        let len = filter.description.segment;
        let frames = features.len() / c;
        let (x, mean) = centred(features, c);
        let padded = reflect_pad(&x, c, len);
        let total = padded.len() / c;
        let window: Vec<f64> = (0..len).map(|t| hann(t, len).sqrt()).collect();
        let transforms = Transforms::new(len);
        let starts: Vec<usize> = (0..)
            .map(|k| k * len / 2)
            .take_while(|s| s + len <= total)
            .collect();
        let spectra: Vec<DMatrix<C64>> = starts
            .iter()
            .map(|&s| transforms.segment_spectrum(&padded, c, s, &window))
            .collect();
        let (k, sigma) = match sigma_deg {
            Some(sigma) if filter.components.len() == 1 => (0, sigma),
            _ => {
                let mut inside: Vec<&DMatrix<C64>> = starts
                    .iter()
                    .zip(&spectra)
                    .filter(|(&s, _)| s >= len && s + len <= len + frames)
                    .map(|(_, spectrum)| spectrum)
                    .collect();
                if inside.is_empty() {
                    inside = spectra.iter().collect();
                }
                let k = if filter.components.len() == 1 {
                    0
                } else {
                    let step = inside.len().div_ceil(CHOICE_SEGMENTS);
                    let some: Vec<&DMatrix<C64>> =
                        inside.iter().step_by(step.max(1)).copied().collect();
                    filter
                        .components
                        .iter()
                        .map(|component| filter.estimate_level(component, &some, &window).1)
                        .enumerate()
                        .max_by(|a, b| a.1.total_cmp(&b.1))
                        .map_or(0, |(k, _)| k)
                };
                let component = &filter.components[k];
                let norm: f64 = window.iter().map(|v| v * v).sum();
                let powers: Vec<Vec<f64>> = inside
                    .iter()
                    .map(|x| filter.segment_power(component, x, norm))
                    .collect();
                let level = median(&mut filter.level_table(component).segment_levels(&powers));
                (k, sigma_deg.unwrap_or(level))
            }
        };
        let component = &filter.components[k];
        let bins = filter.bins(component);
        let s = (sigma / filter.description.noise_sigma_deg as f64).powi(2);
        let padded_missing = missing.map(|m| reflect_pad(&m[..frames * c], c, len));
        let totals = filter.signal_plus_noise(component, s);
        let filtered: Vec<Vec<f64>> = starts
            .iter()
            .zip(&spectra)
            .map(|(&start, x)| {
                let gone: Vec<usize> = padded_missing.as_ref().map_or(Vec::new(), |m| {
                    (0..c)
                        .filter(|&k| (start..start + len).any(|t| m[t * c + k]))
                        .collect()
                });
                if !gone.is_empty() {
                    return transforms
                        .inverse_segment(&filter.conditional_mean(component, x, &totals, &gone));
                }
                let mut spectrum = DMatrix::<C64>::zeros(c, bins.len());
                for (b, bin) in bins.iter().enumerate() {
                    let z = &bin.to_white * x.column(b);
                    let gained = DVector::from_iterator(
                        c,
                        z.iter()
                            .zip(&bin.lambda)
                            .map(|(v, &l)| v * (l / (l + s).max(1e-300))),
                    );
                    spectrum.set_column(b, &(&bin.from_white * gained));
                }
                transforms.inverse_segment(&spectrum)
            })
            .collect();
        let mut sum = vec![0.0f64; padded.len()];
        for (&start, y) in starts.iter().zip(&filtered) {
            for (t, &w) in window.iter().enumerate() {
                let out = &mut sum[(start + t) * c..(start + t + 1) * c];
                for (o, &v) in out.iter_mut().zip(&y[t * c..(t + 1) * c]) {
                    *o += w * v;
                }
            }
        }
        for (i, f) in features.iter_mut().enumerate().take(frames * c) {
            *f = (sum[len * c + i] + mean[i % c]) as f32;
        }
        WienerOutcome {
            sigma_deg: sigma,
            component: k,
        }
    }

    /// Filtering chunk by chunk gives the bits of filtering the whole take
    /// at once, whatever the chunk, with the level estimated or given and
    /// with values missing: on a real take (the shipped model's mixture)
    /// and on takes of the synthetic rig from 1 frame to many chunks.
    #[test]
    fn chunks_give_the_bits_of_the_whole_take() {
        let check = |filter: &WienerFilter, x: &[f32], missing: Option<&[bool]>, what: &str| {
            for sigma in [None, Some(3.0)] {
                let mut expected = x.to_vec();
                let outcome = whole_take(filter, &mut expected, sigma, missing);
                for chunk in [1, 2, 3, 7, 64, CHUNK_SEGMENTS] {
                    let mut y = x.to_vec();
                    let got = filter.filter_in_chunks(&mut y, sigma, missing, chunk);
                    assert_eq!(got, outcome, "{what}, chunks of {chunk}, sigma {sigma:?}");
                    let same = y
                        .iter()
                        .zip(&expected)
                        .all(|(a, b)| a.to_bits() == b.to_bits());
                    assert!(
                        same,
                        "{what}, chunks of {chunk}, sigma {sigma:?}: other values"
                    );
                }
            }
        };
        let walk = mocap_core::io::read_motion(&mocap_testdata::sample_walk()).unwrap();
        let model = crate::CleanModel::load_default(Default::default()).unwrap();
        let shipped = model
            .base_wiener()
            .expect("the shipped model corrects a Wiener filter");
        let layout = shipped.layout_for(&walk).unwrap();
        check(shipped, &layout.encode(&walk), None, "the sample walk");

        let filter = fitted();
        let layout = FeatureLayout::new(
            synthetic_motion_phase(2, 5, 0.0).skeleton(),
            Representation::Rot6d,
        )
        .unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        for frames in [1, 20, 33, 97, 700] {
            let noisy = add_random_noise_sigma(
                &synthetic_motion_phase(frames, 5, 0.2),
                3.0,
                &RandomNoise::default(),
                &mut rng,
            );
            let x = layout.encode(&noisy);
            check(&filter, &x, None, &format!("{frames} frames"));
            let missing: Vec<bool> = (0..x.len()).map(|i| (i / 6) % 37 == 3).collect();
            check(
                &filter,
                &x,
                Some(&missing),
                &format!("{frames} frames, some missing"),
            );
        }
    }

    #[test]
    fn it_removes_random_noise_and_leaves_clean_takes_nearly_alone() {
        let filter = fitted();
        let clean = synthetic_motion_phase(300, 5, 0.35);
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let noisy = add_random_noise_sigma(&clean, 5.0, &RandomNoise::default(), &mut rng);
        let (cleaned, outcome) = filter.clean(&noisy, None).unwrap();
        let before = rotation_error_deg(&clean, &noisy);
        let after = rotation_error_deg(&clean, &cleaned);
        assert!(after < 0.4 * before, "{before} -> {after} degrees");
        assert!(
            (2.5..10.0).contains(&outcome.sigma_deg),
            "noise of 5 degrees estimated at {}",
            outcome.sigma_deg
        );
        for f in 0..noisy.frame_count() {
            assert_eq!(cleaned.root_translation(f), noisy.root_translation(f));
        }
        let (untouched, outcome) = filter.clean(&clean, None).unwrap();
        let change = rotation_error_deg(&clean, &untouched);
        assert!(
            change < 0.25 * after,
            "a clean take changed by {change} degrees"
        );
        assert!(
            outcome.sigma_deg < 1.0,
            "a clean take's noise: {}",
            outcome.sigma_deg
        );
    }

    /// The take's level with both estimates, forced on a copy of `filter`.
    fn levels(filter: &WienerFilter, motion: &Motion) -> (f64, f64) {
        let mut f = filter.clone();
        f.set_level_estimate(LevelEstimate::Pooled);
        let pooled = f.clean(motion, None).unwrap().1.sigma_deg;
        f.set_level_estimate(LevelEstimate::SegmentMedian);
        let median = f.clean(motion, None).unwrap().1.sigma_deg;
        (pooled, median)
    }

    #[test]
    fn a_spike_does_not_raise_the_median_level_of_a_take() {
        let filter = fitted();
        assert_eq!(filter.level_estimate(), LevelEstimate::SegmentMedian);
        let clean = synthetic_motion_phase(300, 5, 0.35);
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let noisy = add_random_noise_sigma(&clean, 2.0, &RandomNoise::default(), &mut rng);
        // Alike where the noise is the same throughout.
        let (pooled, median) = levels(&filter, &noisy);
        assert!(
            (median - pooled).abs() <= 0.15 * pooled,
            "stationary noise: pooled {pooled}, median {median}"
        );
        // A spike: 30 frames of the joints below the second taken from
        // another motion, as the spike noise does. Measured: the pooled
        // level 2.45 -> 3.55 degrees, the median 2.35 -> 2.65.
        let other = synthetic_motion_phase(300, 5, 2.5);
        let (skeleton, frame_time, frames, mut values) = noisy.clone().into_parts();
        let c = skeleton.channel_count();
        let first_channel = skeleton.joints()[..2]
            .iter()
            .map(|j| j.channels.len())
            .sum::<usize>();
        for f in 120..150 {
            for k in first_channel..c {
                values[f * c + k] = other.values()[f * c + k];
            }
        }
        let spiked = Motion::new(skeleton, frame_time, frames, values).unwrap();
        let (spiked_pooled, spiked_median) = levels(&filter, &spiked);
        assert!(
            spiked_pooled > 1.3 * pooled,
            "the spike should raise the pooled level: {pooled} -> {spiked_pooled}"
        );
        assert!(
            (spiked_median - median).abs() <= 0.2 * median,
            "the spike moved the median level: {median} -> {spiked_median}"
        );
    }

    fn refs(motions: &[Motion]) -> Vec<&Motion> {
        motions.iter().collect()
    }

    /// A take of `frames` frames moving ten times as fast as
    /// `synthetic_motion_phase` (every tenth frame of a longer one), so its
    /// spectra reach frequencies where the slow one has no power.
    fn fast_motion(frames: usize, phase: f32) -> Motion {
        let (skeleton, frame_time, _, values) =
            synthetic_motion_phase(4 * frames, 5, phase).into_parts();
        let c = skeleton.channel_count();
        let kept: Vec<f32> = (0..frames)
            .flat_map(|f| values[4 * f * c..(4 * f + 1) * c].to_vec())
            .collect();
        Motion::new(skeleton, frame_time, frames, kept).unwrap()
    }

    #[test]
    fn a_mixture_picks_the_kind_of_motion_of_a_take() {
        let slow: Vec<Motion> = (0..6)
            .map(|k| synthetic_motion_phase(240, 5, 0.7 * k as f32))
            .collect();
        let fast: Vec<Motion> = (0..6)
            .map(|k| fast_motion(240, 0.7 * k as f32 + 0.3))
            .collect();
        let all: Vec<&Motion> = slow.iter().chain(&fast).collect();
        let single = WienerFilter::fit(&all, &RandomNoise::default(), 5.0, 32, 1).unwrap();
        let mixture = WienerFilter::mixture(vec![
            ("slow".into(), single.with_spectra_of(&refs(&slow)).unwrap()),
            ("fast".into(), single.with_spectra_of(&refs(&fast)).unwrap()),
            ("all".into(), single.clone()),
        ])
        .unwrap();
        assert_eq!(mixture.description.component_count(), 3);
        assert_eq!(mixture.description.takes, 12);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("mixture.safetensors");
        mixture.save(&path, serde_json::Value::Null).unwrap();
        let loaded = WienerFilter::load(&path).unwrap();
        assert_eq!(loaded.description, mixture.description);
        for (kind, clean) in [
            (0, synthetic_motion_phase(240, 5, 2.45)),
            (1, fast_motion(240, 2.75)),
        ] {
            let mut rng = ChaCha8Rng::seed_from_u64(11);
            let noisy = add_random_noise_sigma(&clean, 3.0, &RandomNoise::default(), &mut rng);
            let (one, _) = single.clean(&noisy, None).unwrap();
            let (mixed, outcome) = mixture.clean(&noisy, None).unwrap();
            assert_eq!(outcome.component, kind);
            let (one, mixed) = (
                rotation_error_deg(&clean, &one),
                rotation_error_deg(&clean, &mixed),
            );
            // The slow kind's own spectra hold no power where the fast
            // kind's do, so there its component removes more noise than one
            // filter for both; the fast kind's component is chosen for
            // fitting best, which here denoises about as well as one filter.
            if kind == 0 {
                assert!(mixed < 0.8 * one, "slow: mixture {mixed}, one filter {one}");
            } else {
                assert!(mixed < 0.8 * rotation_error_deg(&clean, &noisy) && mixed < 1.2 * one);
            }
            let (again, outcome_again) = loaded.clean(&noisy, None).unwrap();
            assert_eq!(outcome_again.component, kind);
            assert!((rotation_error_deg(&clean, &again) - mixed).abs() < 0.01);
        }
        // Components of other filters do not mix.
        let other = WienerFilter::fit(&refs(&slow), &RandomNoise::default(), 5.0, 32, 2).unwrap();
        assert!(WienerFilter::mixture(vec![
            ("a".into(), single.with_spectra_of(&refs(&slow)).unwrap()),
            ("b".into(), other),
        ])
        .is_err());
    }

    #[test]
    fn files_round_trip_and_other_rigs_are_refused() {
        let filter = fitted();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("wiener.safetensors");
        filter.save(&path, serde_json::Value::Null).unwrap();
        let loaded = WienerFilter::load(&path).unwrap();
        assert_eq!(loaded.description, filter.description);
        let clean = synthetic_motion_phase(120, 5, 0.35);
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let noisy = add_random_noise_sigma(&clean, 3.0, &RandomNoise::default(), &mut rng);
        let (a, sa) = filter.clean(&noisy, None).unwrap();
        let (b, sb) = loaded.clean(&noisy, None).unwrap();
        // The file keeps the spectra in f32.
        assert!(rotation_error_deg(&a, &b) < 0.01);
        assert!((sa.sigma_deg - sb.sigma_deg).abs() < 0.15);
        // Files of before packing (every entry of the spectra) still read,
        // to the same filter; packed ones are about half their size.
        let mut unpacked = filter.clone();
        unpacked.description.packed_spectra = false;
        let old_path = dir.path().join("unpacked.safetensors");
        unpacked.save(&old_path, serde_json::Value::Null).unwrap();
        let (c, _) = WienerFilter::load(&old_path)
            .unwrap()
            .clean(&noisy, None)
            .unwrap();
        assert!(rotation_error_deg(&a, &c) < 0.01);
        let size = |p: &Path| std::fs::metadata(p).unwrap().len() as f64;
        assert!(size(&path) < 0.6 * size(&old_path));
        // A network reader refuses it by name, and the dispatcher knows it.
        let error = crate::model_file::CleanModel::load(&path, Default::default())
            .unwrap_err()
            .to_string();
        assert!(error.contains(WIENER_KIND), "{error}");
        assert!(matches!(
            crate::model_file::ModelFile::load(&path, Default::default()).unwrap(),
            crate::model_file::ModelFile::Wiener(_)
        ));
        let error = filter
            .clean(&synthetic_motion_phase(50, 4, 0.0), None)
            .unwrap_err()
            .to_string();
        assert!(error.contains("fitted to a rig of 5 joints"), "{error}");
        // Truncated files are errors, not panics.
        let bytes = std::fs::read(&path).unwrap();
        assert!(WienerFilter::from_bytes(bytes[..bytes.len() / 2].to_vec(), &path).is_err());
    }
}
