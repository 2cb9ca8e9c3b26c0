//! Classical baselines, for comparison and for users without a model.
//!
//! Each filter runs on every feature channel of the continuous 6D rotation
//! representation (no wrap-around at +-180 degrees), and the filtered
//! features are turned back into rotations (Gram-Schmidt), so the output has
//! the input's skeleton and channel layout. Root translation is kept.
//!
//! - [`Filter::Butterworth`]: zero-phase low-pass (forward-backward
//!   second-order sections, `sci-rs`'s port of SciPy's `butter` +
//!   `sosfiltfilt`);
//! - [`Filter::ButterworthGcv`]: the same low-pass with its cutoff chosen
//!   per channel and per take by generalised cross-validation (Craven and
//!   Wahba 1979), so that clean takes are left nearly alone and noisy ones
//!   are smoothed hard;
//! - [`Filter::SavitzkyGolay`]: local polynomial least squares (coefficients
//!   from `sci-rs`'s `savgol_coeffs`, edges padded with the nearest frame);
//! - [`Filter::Median`]: running median, the classical remedy for spikes;
//! - [`Filter::OneEuro`]: the One Euro filter (Casiez, Roussel, Vogel,
//!   CHI 2012), a causal low-pass whose cutoff rises with speed.

use mocap_core::rotation::Vec3;
use mocap_core::Motion;
use sci_rs::signal::filter::design::{butter_dyn, DigitalFilter, FilterBandType, FilterOutputType};
use sci_rs::signal::filter::{savgol_coeffs_dyn, sosfiltfilt_dyn};
use serde::{Deserialize, Serialize};

use crate::features::{FeatureLayout, Representation};
use crate::{CleanError, Result};

/// A classical filter and its settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Filter {
    /// Zero-phase Butterworth low-pass of `order` (applied forward and
    /// backward, so the effective order doubles) with cutoff in Hz.
    Butterworth { order: usize, cutoff_hz: f32 },
    /// Zero-phase Butterworth low-pass of `order` whose cutoff is chosen for
    /// each channel of each take among 0.5-12 Hz (14 cutoffs) by generalised
    /// cross-validation (see [`gcv_trace_fraction`]).
    ButterworthGcv { order: usize },
    /// Savitzky-Golay smoothing over an odd `window` of frames with a
    /// polynomial of degree `polyorder`.
    SavitzkyGolay { window: usize, polyorder: usize },
    /// Running median over an odd `window` of frames.
    Median { window: usize },
    /// One Euro filter: minimum cutoff (Hz), speed coefficient, and cutoff of
    /// the speed estimate (Hz).
    OneEuro {
        min_cutoff_hz: f32,
        beta: f32,
        d_cutoff_hz: f32,
    },
}

impl Filter {
    /// Short name with settings, e.g. `butterworth(order=2, cutoff=6Hz)`.
    pub fn label(&self) -> String {
        match *self {
            Filter::Butterworth { order, cutoff_hz } => {
                format!("butterworth(order={order}, cutoff={cutoff_hz}Hz)")
            }
            Filter::ButterworthGcv { order } => format!("butterworth-gcv(order={order})"),
            Filter::SavitzkyGolay { window, polyorder } => {
                format!("savitzky-golay(window={window}, polyorder={polyorder})")
            }
            Filter::Median { window } => format!("median(window={window})"),
            Filter::OneEuro {
                min_cutoff_hz,
                beta,
                d_cutoff_hz,
            } => format!(
                "one-euro(min_cutoff={min_cutoff_hz}Hz, beta={beta}, d_cutoff={d_cutoff_hz}Hz)"
            ),
        }
    }

    /// The family name (`butterworth`, `savitzky-golay`, `median`, `one-euro`).
    pub fn family(&self) -> &'static str {
        match self {
            Filter::Butterworth { .. } => "butterworth",
            Filter::ButterworthGcv { .. } => "butterworth-gcv",
            Filter::SavitzkyGolay { .. } => "savitzky-golay",
            Filter::Median { .. } => "median",
            Filter::OneEuro { .. } => "one-euro",
        }
    }

    /// Checks the settings against the frame rate.
    pub fn validate(&self, fps: f32) -> Result<()> {
        let bad = |m: String| Err(CleanError::Invalid(format!("{}: {m}", self.label())));
        match *self {
            Filter::Butterworth { order, cutoff_hz } => {
                if !(1..=8).contains(&order) {
                    return bad("order must be 1 to 8".into());
                }
                if !(cutoff_hz > 0.0 && cutoff_hz < 0.5 * fps) {
                    return bad(format!(
                        "cutoff must be between 0 and the Nyquist frequency {} Hz",
                        0.5 * fps
                    ));
                }
            }
            Filter::ButterworthGcv { order } => {
                if !(1..=8).contains(&order) {
                    return bad("order must be 1 to 8".into());
                }
                if fps <= 2.0 * GCV_CUTOFFS_HZ[0] {
                    return bad(format!(
                        "needs a frame rate above {} fps (the lowest cutoff it tries is {} Hz)",
                        2.0 * GCV_CUTOFFS_HZ[0],
                        GCV_CUTOFFS_HZ[0]
                    ));
                }
            }
            Filter::SavitzkyGolay { window, polyorder } => {
                if window.is_multiple_of(2) || window < polyorder + 2 {
                    return bad("window must be odd and at least polyorder + 2".into());
                }
            }
            Filter::Median { window } => {
                if window.is_multiple_of(2) {
                    return bad("window must be odd".into());
                }
            }
            Filter::OneEuro {
                min_cutoff_hz,
                beta,
                d_cutoff_hz,
            } => {
                if !(min_cutoff_hz > 0.0 && d_cutoff_hz > 0.0 && beta >= 0.0) {
                    return bad("cutoffs must be positive and beta non-negative".into());
                }
            }
        }
        Ok(())
    }

    /// Filters one channel sampled at `fps` in place.
    pub fn apply_track(&self, track: &mut [f32], fps: f32) {
        match *self {
            Filter::Butterworth { order, cutoff_hz } => butterworth(track, order, cutoff_hz, fps),
            Filter::ButterworthGcv { order } => butterworth_gcv(track, order, fps),
            Filter::SavitzkyGolay { window, polyorder } => savitzky_golay(track, window, polyorder),
            Filter::Median { window } => median(track, window),
            Filter::OneEuro {
                min_cutoff_hz,
                beta,
                d_cutoff_hz,
            } => one_euro(track, min_cutoff_hz, beta, d_cutoff_hz, fps),
        }
    }

    /// The settings tried when tuning a family on validation data.
    pub fn tuning_grid(family: &str) -> Vec<Filter> {
        match family {
            "butterworth" => [1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0]
                .into_iter()
                .flat_map(|c| {
                    [2, 4].map(|o| Filter::Butterworth {
                        order: o,
                        cutoff_hz: c,
                    })
                })
                .collect(),
            "butterworth-gcv" => [2, 4]
                .map(|order| Filter::ButterworthGcv { order })
                .to_vec(),
            "savitzky-golay" => [5, 7, 9, 11, 15, 21, 31]
                .into_iter()
                .flat_map(|w| {
                    [2, 3].map(move |p| Filter::SavitzkyGolay {
                        window: w,
                        polyorder: p,
                    })
                })
                .collect(),
            "median" => [3, 5, 7, 9, 11, 15, 21, 31, 45]
                .map(|w| Filter::Median { window: w })
                .to_vec(),
            "one-euro" => [0.3, 0.6, 1.0, 2.0, 4.0]
                .into_iter()
                .flat_map(|m| {
                    [0.0, 0.05, 0.3, 1.0].map(|b| Filter::OneEuro {
                        min_cutoff_hz: m,
                        beta: b,
                        d_cutoff_hz: 1.0,
                    })
                })
                .collect(),
            _ => Vec::new(),
        }
    }

    /// Every family name.
    pub const FAMILIES: [&'static str; 5] = [
        "butterworth",
        "butterworth-gcv",
        "savitzky-golay",
        "median",
        "one-euro",
    ];
}

impl std::str::FromStr for Filter {
    type Err = CleanError;

    /// Parses `butterworth:ORDER:CUTOFF_HZ`, `butterworth-gcv:ORDER`, `savitzky-golay:WINDOW:POLYORDER`,
    /// `median:WINDOW` or `one-euro:MIN_CUTOFF_HZ:BETA:D_CUTOFF_HZ`.
    fn from_str(text: &str) -> Result<Filter> {
        let parts: Vec<&str> = text.split(':').collect();
        let bad = |m: String| CleanError::Invalid(format!("filter `{text}`: {m}"));
        let num = |k: usize| -> Result<f32> {
            parts
                .get(k)
                .ok_or_else(|| bad(format!("missing setting {k}")))?
                .parse::<f32>()
                .map_err(|e| bad(format!("setting {k}: {e}")))
        };
        let count = |n: usize| {
            if parts.len() == n + 1 {
                Ok(())
            } else {
                Err(bad(format!("expected {n} settings after the name")))
            }
        };
        let filter = match parts[0] {
            "butterworth" => {
                count(2)?;
                Filter::Butterworth { order: num(1)? as usize, cutoff_hz: num(2)? }
            }
            "butterworth-gcv" => {
                count(1)?;
                Filter::ButterworthGcv { order: num(1)? as usize }
            }
            "savitzky-golay" => {
                count(2)?;
                Filter::SavitzkyGolay { window: num(1)? as usize, polyorder: num(2)? as usize }
            }
            "median" => {
                count(1)?;
                Filter::Median { window: num(1)? as usize }
            }
            "one-euro" => {
                count(3)?;
                Filter::OneEuro { min_cutoff_hz: num(1)?, beta: num(2)?, d_cutoff_hz: num(3)? }
            }
            other => {
                return Err(bad(format!(
                    "unknown filter `{other}`: expected butterworth, butterworth-gcv, savitzky-golay, median or one-euro"
                )))
            }
        };
        // What does not depend on the frame rate is checked now, so that a
        // command line with an even median window is refused as such; the
        // cutoffs are checked against the take's frame rate when it is read.
        filter.validate(f32::INFINITY)?;
        Ok(filter)
    }
}

/// Filters the joint rotations of `motion` (see the module docs).
pub fn filter_motion(motion: &Motion, filter: &Filter) -> Result<Motion> {
    filter_joints(motion, filter, |_| true)
}

/// Filters the local rotations of the joints `chosen` says (joint indices),
/// the others left as they are.
pub(crate) fn filter_joints(
    motion: &Motion,
    filter: &Filter,
    chosen: impl Fn(usize) -> bool,
) -> Result<Motion> {
    let fps = motion.fps() as f32;
    filter.validate(fps)?;
    let layout = FeatureLayout::new(motion.skeleton(), Representation::Rot6d)?;
    let mut out = motion.clone();
    // A joint at a time: every channel is filtered on its own and every
    // joint's local rotations decoded on their own, so this is the take's
    // features filtered at once, without holding them.
    for k in (0..layout.joints.len()).filter(|&k| chosen(layout.joints[k])) {
        let mut features = layout
            .encode_joint(motion, k)
            .expect("a layout of local 6D rotations");
        filter_features(&mut features, 6, filter, fps);
        layout.decode_joint_into(&features, k, &mut out);
    }
    Ok(out)
}

/// Filters the translations of the joints with position channels (the
/// root's, and Bandai's pelvis) of `motion`, each axis on its own; rotations
/// are left as they are. Optical captures' roots are clean, but a fused
/// capture's root is as noisy as any joint, and most of its jitter is there
/// (docs/research/clean.md, "Fused captures").
pub fn filter_translations(motion: &Motion, filter: &Filter) -> Result<Motion> {
    let fps = motion.fps() as f32;
    filter.validate(fps)?;
    let mut out = motion.clone();
    let skeleton = motion.skeleton();
    for j in (0..skeleton.joint_count()).filter(|&j| skeleton.joint(j).has_position_channels()) {
        let mut xyz: Vec<f32> = (0..motion.frame_count())
            .flat_map(|f| motion.local_translation(f, j).to_array())
            .collect();
        filter_features(&mut xyz, 3, filter, fps);
        for (f, p) in xyz.chunks_exact(3).enumerate() {
            out.set_local_translation(f, j, Vec3::from_slice(p));
        }
    }
    Ok(out)
}

/// Filters every channel of `features` (frame after frame, `channels` per
/// frame) along time.
pub fn filter_features(features: &mut [f32], channels: usize, filter: &Filter, fps: f32) {
    let frames = features.len() / channels.max(1);
    let mut track = vec![0.0; frames];
    for ch in 0..channels {
        for f in 0..frames {
            track[f] = features[f * channels + ch];
        }
        filter.apply_track(&mut track, fps);
        for f in 0..frames {
            features[f * channels + ch] = track[f];
        }
    }
}

/// The cutoffs [`Filter::ButterworthGcv`] chooses from (those below the
/// Nyquist frequency of the take).
pub const GCV_CUTOFFS_HZ: [f32; 14] = [
    0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0,
];

/// Low-passes `track` at the cutoff of [`GCV_CUTOFFS_HZ`] with the lowest
/// generalised cross-validation score
/// `GCV(c) = |x - H_c x|^2 / (1 - tr(H_c)/n)^2`: the residual of the
/// smoother, inflated by how many degrees of freedom it keeps. Its minimum
/// estimates the cutoff with the lowest error against the unknown clean
/// signal when the noise is white (Craven and Wahba 1979), without knowing
/// the noise level: a clean channel gets a high cutoff, a noisy one a low one.
fn butterworth_gcv(track: &mut [f32], order: usize, fps: f32) {
    let frames = track.len();
    let mut best: Option<(f64, Vec<f32>)> = None;
    for cutoff in GCV_CUTOFFS_HZ.into_iter().filter(|&c| c < 0.5 * fps) {
        let mut smoothed = track.to_vec();
        butterworth(&mut smoothed, order, cutoff, fps);
        let residual: f64 = track
            .iter()
            .zip(&smoothed)
            .map(|(&x, &y)| ((x - y) as f64).powi(2))
            .sum();
        let score = gcv_score(residual, gcv_trace_fraction(order, cutoff, fps, frames));
        if best.as_ref().is_none_or(|(b, _)| score < *b) {
            best = Some((score, smoothed));
        }
    }
    if let Some((_, smoothed)) = best {
        track.copy_from_slice(&smoothed);
    }
}

/// The generalised cross-validation score of a smoother from the sum of
/// squared residuals `|x - H x|^2` and the share of degrees of freedom it
/// keeps, `tr(H) / n` ([`gcv_trace_fraction`]): lower is better.
pub fn gcv_score(residual_sum_of_squares: f64, kept_fraction: f64) -> f64 {
    residual_sum_of_squares / (1.0 - kept_fraction).powi(2)
}

/// The share of a take's `frames` degrees of freedom that a zero-phase
/// Butterworth low-pass of `order` and `cutoff_hz` keeps: `tr(H) / n` of the
/// smoother `y = H x`, the term generalised cross-validation divides by.
///
/// Forward-backward filtering squares the filter's gain, so the smoother's
/// frequency response is `G(w) = 1 / (1 + (tan(w/2) / tan(wc/2))^(2 order))`
/// (the digital Butterworth by the bilinear transform with pre-warping, as
/// SciPy's `butter` designs it), and `tr(H) / n` is the mean of `G` over the
/// take's `n` DFT frequencies (exact for a circular filter; the edge padding
/// changes it little).
pub fn gcv_trace_fraction(order: usize, cutoff_hz: f32, fps: f32, frames: usize) -> f64 {
    if frames == 0 {
        return 0.0;
    }
    let n = frames as f64;
    let tan_cut = (std::f64::consts::PI * cutoff_hz as f64 / fps as f64).tan();
    let sum: f64 = (0..frames)
        .map(|k| {
            // Frequencies above Nyquist mirror those below.
            let k = k.min(frames - k) as f64;
            let ratio = (std::f64::consts::PI * k / n).tan() / tan_cut;
            1.0 / (1.0 + ratio.powi(2 * order as i32))
        })
        .sum();
    sum / n
}

fn butterworth(track: &mut [f32], order: usize, cutoff_hz: f32, fps: f32) {
    let filter = butter_dyn::<f64>(
        order,
        vec![cutoff_hz as f64],
        Some(FilterBandType::Lowpass),
        Some(false),
        Some(FilterOutputType::Sos),
        Some(fps as f64),
    );
    let DigitalFilter::Sos(sos) = filter else {
        unreachable!("asked for second-order sections")
    };
    // sosfiltfilt pads both ends by 3 * (2 * sections + 1) frames by odd
    // reflection and needs a longer signal; shorter takes are left as they are.
    let pad = 3 * (2 * sos.sos.len() + 1);
    if track.len() <= pad {
        return;
    }
    let out = sosfiltfilt_dyn(track.iter().map(|&v| v as f64), &sos.sos);
    for (t, v) in track.iter_mut().zip(out) {
        *t = v as f32;
    }
}

fn savitzky_golay(track: &mut [f32], window: usize, polyorder: usize) {
    if track.len() < 2 {
        return;
    }
    let coeffs: Vec<f64> = savgol_coeffs_dyn::<f64>(window, polyorder, None, None)
        .into_iter()
        .collect();
    let half = (window / 2) as isize;
    let n = track.len() as isize;
    let input: Vec<f64> = track.iter().map(|&v| v as f64).collect();
    for i in 0..n {
        // Smoothing coefficients are symmetric, so convolution and
        // correlation agree; edges take the nearest frame.
        let mut acc = 0.0;
        for (k, c) in coeffs.iter().enumerate() {
            let idx = (i + k as isize - half).clamp(0, n - 1);
            acc += c * input[idx as usize];
        }
        track[i as usize] = acc as f32;
    }
}

fn median(track: &mut [f32], window: usize) {
    let half = window / 2;
    let n = track.len();
    if n == 0 || half == 0 {
        return;
    }
    let input = track.to_vec();
    let mut buf = Vec::with_capacity(window);
    for (i, out) in track.iter_mut().enumerate() {
        buf.clear();
        for k in 0..window {
            // Nearest-frame padding at the edges.
            let idx = (i + k).saturating_sub(half).min(n - 1);
            buf.push(input[idx]);
        }
        buf.sort_by(f32::total_cmp);
        *out = buf[half];
    }
}

/// Smoothing factor of an exponential low-pass with cutoff `fc` at `fps`
/// (Casiez et al. 2012, eq. for alpha: `1 / (1 + tau / Te)`, `tau = 1 / (2 pi fc)`).
fn smoothing_factor(fc: f32, fps: f32) -> f32 {
    let tau = 1.0 / (2.0 * std::f32::consts::PI * fc);
    1.0 / (1.0 + tau * fps)
}

fn one_euro(track: &mut [f32], min_cutoff: f32, beta: f32, d_cutoff: f32, fps: f32) {
    if track.is_empty() {
        return;
    }
    let mut x_hat = track[0];
    let mut dx_hat = 0.0;
    let a_d = smoothing_factor(d_cutoff, fps);
    for v in track.iter_mut().skip(1) {
        let dx = (*v - x_hat) * fps;
        dx_hat += a_d * (dx - dx_hat);
        let cutoff = min_cutoff + beta * dx_hat.abs();
        x_hat += smoothing_factor(cutoff, fps) * (*v - x_hat);
        *v = x_hat;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noisy_sine(n: usize) -> (Vec<f32>, Vec<f32>) {
        let clean: Vec<f32> = (0..n).map(|i| (i as f32 / 30.0 * 2.0).sin()).collect();
        // Deterministic high-frequency "noise": alternating sign.
        let noisy = clean
            .iter()
            .enumerate()
            .map(|(i, v)| v + if i % 2 == 0 { 0.1 } else { -0.1 })
            .collect();
        (clean, noisy)
    }

    fn rms(a: &[f32], b: &[f32]) -> f32 {
        (a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f32>() / a.len() as f32).sqrt()
    }

    #[test]
    fn every_filter_removes_high_frequency_noise() {
        let (clean, noisy) = noisy_sine(300);
        let before = rms(&clean, &noisy);
        for filter in [
            Filter::Butterworth {
                order: 2,
                cutoff_hz: 3.0,
            },
            Filter::SavitzkyGolay {
                window: 9,
                polyorder: 2,
            },
            Filter::Median { window: 5 },
            Filter::ButterworthGcv { order: 2 },
            Filter::OneEuro {
                min_cutoff_hz: 4.0,
                beta: 0.0,
                d_cutoff_hz: 1.0,
            },
        ] {
            filter.validate(30.0).unwrap();
            let mut track = noisy.clone();
            filter.apply_track(&mut track, 30.0);
            let after = rms(&clean, &track);
            // One Euro is causal: it lags, so it removes less.
            let bound = if filter.family() == "one-euro" {
                0.75
            } else {
                0.5
            };
            assert!(
                after < bound * before,
                "{}: {before} -> {after}",
                filter.label()
            );
        }
    }

    #[test]
    fn zero_phase_filters_keep_a_line_in_place() {
        // A straight line has no delay under a zero-phase or polynomial filter.
        let line: Vec<f32> = (0..200).map(|i| 0.01 * i as f32).collect();
        for filter in [
            Filter::Butterworth {
                order: 2,
                cutoff_hz: 3.0,
            },
            Filter::SavitzkyGolay {
                window: 11,
                polyorder: 2,
            },
            Filter::Median { window: 5 },
            Filter::ButterworthGcv { order: 2 },
        ] {
            let mut track = line.clone();
            filter.apply_track(&mut track, 30.0);
            for i in 20..180 {
                assert!(
                    (track[i] - line[i]).abs() < 1e-3,
                    "{} at {i}",
                    filter.label()
                );
            }
        }
    }

    #[test]
    fn median_removes_a_short_spike() {
        let mut track = vec![1.0f32; 50];
        for v in &mut track[20..23] {
            *v = 9.0;
        }
        Filter::Median { window: 9 }.apply_track(&mut track, 30.0);
        assert!(track.iter().all(|&v| v == 1.0));
    }

    #[test]
    fn filters_parse_from_text() {
        assert_eq!(
            "butterworth:2:6".parse::<Filter>().unwrap(),
            Filter::Butterworth {
                order: 2,
                cutoff_hz: 6.0
            }
        );
        assert_eq!(
            "median:9".parse::<Filter>().unwrap(),
            Filter::Median { window: 9 }
        );
        assert_eq!(
            "butterworth-gcv:4".parse::<Filter>().unwrap(),
            Filter::ButterworthGcv { order: 4 }
        );
        assert!("butterworth-gcv:2:3".parse::<Filter>().is_err());
        assert!("median".parse::<Filter>().is_err());
        assert!("kalman:1".parse::<Filter>().is_err());
        assert!("one-euro:1:x:1".parse::<Filter>().is_err());
    }

    #[test]
    fn bad_settings_are_errors() {
        assert!(Filter::Butterworth {
            order: 2,
            cutoff_hz: 20.0
        }
        .validate(30.0)
        .is_err());
        assert!(Filter::SavitzkyGolay {
            window: 4,
            polyorder: 2
        }
        .validate(30.0)
        .is_err());
        assert!(Filter::Median { window: 4 }.validate(30.0).is_err());
        assert!(Filter::ButterworthGcv { order: 0 }.validate(30.0).is_err());
        assert!(Filter::ButterworthGcv { order: 2 }.validate(1.0).is_err());
    }

    #[test]
    fn filtering_a_motion_keeps_layout_and_root_translation() {
        let motion = crate::test_support::synthetic_motion(90, 5);
        let out = filter_motion(
            &motion,
            &Filter::Butterworth {
                order: 2,
                cutoff_hz: 6.0,
            },
        )
        .unwrap();
        assert_eq!(out.skeleton(), motion.skeleton());
        assert_eq!(out.frame_count(), motion.frame_count());
        for f in 0..90 {
            assert_eq!(out.root_translation(f), motion.root_translation(f));
        }
    }

    /// Filtering joint by joint gives the bits of filtering the features of
    /// the whole take at once (encode, filter every channel, decode), on the
    /// bundled walk with noise.
    #[test]
    fn a_joint_at_a_time_gives_the_bits_of_the_whole_features() {
        use rand::SeedableRng;
        let walk = mocap_core::io::read_motion(&mocap_testdata::sample_walk()).unwrap();
        let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(2);
        let noisy = crate::noise::add_random_noise_sigma(
            &walk,
            4.0,
            &crate::noise::RandomNoise::default(),
            &mut rng,
        );
        for spec in [
            "butterworth:2:6",
            "butterworth-gcv:2",
            "median:5",
            "one-euro:1:0.5:1",
        ] {
            let filter: Filter = spec.parse().unwrap();
            let fps = noisy.fps() as f32;
            let layout = FeatureLayout::new(noisy.skeleton(), Representation::Rot6d).unwrap();
            let mut features = layout.encode(&noisy);
            filter_features(&mut features, layout.channels(), &filter, fps);
            let mut expected = noisy.clone();
            layout.decode_into(&features, &mut expected);
            let got = filter_motion(&noisy, &filter).unwrap();
            let same = got
                .values()
                .iter()
                .zip(expected.values())
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "{spec}: other values");
        }
    }

    /// A 0.7 Hz sine (30 fps) with white gaussian noise of `sigma`.
    fn sine_with_white_noise(frames: usize, sigma: f32, seed: u64) -> (Vec<f32>, Vec<f32>) {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(seed);
        let normal = Normal::new(0.0f32, sigma.max(1e-12)).unwrap();
        let clean: Vec<f32> = (0..frames)
            .map(|i| (2.0 * std::f32::consts::PI * 0.7 * i as f32 / 30.0).sin())
            .collect();
        let noisy = clean
            .iter()
            .map(|v| {
                v + if sigma > 0.0 {
                    normal.sample(&mut rng)
                } else {
                    0.0
                }
            })
            .collect();
        (clean, noisy)
    }

    #[test]
    fn gcv_smooths_noisy_tracks_hard_and_leaves_clean_ones_alone() {
        let gcv = Filter::ButterworthGcv { order: 2 };
        // No noise: the track comes back almost as it was (a fixed 2 Hz
        // cutoff would not be far off here either, but a noisy-take setting
        // like 1 Hz would be).
        let (clean, _) = sine_with_white_noise(300, 0.0, 1);
        let mut track = clean.clone();
        gcv.apply_track(&mut track, 30.0);
        assert!(rms(&clean, &track) < 0.01, "{}", rms(&clean, &track));
        // With noise, GCV's error is near the best fixed cutoff's for that
        // noise level, at two noise levels whose best cutoffs differ.
        let mut best_cutoffs = Vec::new();
        for sigma in [0.02, 0.5] {
            let (clean, noisy) = sine_with_white_noise(300, sigma, 2);
            let mut track = noisy.clone();
            gcv.apply_track(&mut track, 30.0);
            let chosen = rms(&clean, &track);
            let (best_cutoff, best) = GCV_CUTOFFS_HZ
                .iter()
                .map(|&c| {
                    let mut t = noisy.clone();
                    butterworth(&mut t, 2, c, 30.0);
                    (c, rms(&clean, &t))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            best_cutoffs.push(best_cutoff);
            assert!(
                chosen < 1.3 * best,
                "sigma {sigma}: GCV {chosen}, best fixed {best}"
            );
            assert!(chosen < 0.6 * rms(&clean, &noisy), "sigma {sigma}");
        }
        assert!(best_cutoffs[0] > best_cutoffs[1], "{best_cutoffs:?}");
    }

    #[test]
    fn gcv_trace_fraction_matches_the_smoothers_impulse_responses() {
        // tr(H) / n measured by filtering unit impulses, against the
        // frequency-response formula.
        let frames = 240;
        for cutoff in [1.0, 3.0, 8.0] {
            let mut trace = 0.0;
            for i in 0..frames {
                let mut impulse = vec![0.0f32; frames];
                impulse[i] = 1.0;
                butterworth(&mut impulse, 2, cutoff, 30.0);
                trace += impulse[i] as f64;
            }
            let measured = trace / frames as f64;
            let formula = gcv_trace_fraction(2, cutoff, 30.0, frames);
            assert!(
                (measured - formula).abs() < 0.1 * formula,
                "{cutoff} Hz: impulses {measured}, formula {formula}"
            );
        }
        assert!(gcv_trace_fraction(2, 1.0, 30.0, 240) < gcv_trace_fraction(2, 3.0, 30.0, 240));
    }
}
