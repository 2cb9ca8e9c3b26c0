//! Time normalisation and interval means.
//!
//! Every clip is resampled to `N` frames (the report uses 10), so that a
//! slow and a fast performance of the same motion line up. A test of the
//! forest compares the mean of one feature value `i` over an interval of
//! those frames `r = [t0, t1)` with a threshold. The means come from running
//! sums over the frames,
//!
//! ```text
//! g_0 = 0,   g_t = g_(t-1) + p_t,   mean_i[t0, t1) = (g_t1 - g_t0) / (t1 - t0)
//! ```
//!
//! so each costs two look-ups whatever the interval's length.

use serde::{Deserialize, Serialize};

/// A per-frame sequence of feature vectors: `values[frame * dim + i]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FeatureSequence {
    pub dim: usize,
    pub values: Vec<f32>,
}

impl FeatureSequence {
    pub fn frame_count(&self) -> usize {
        self.values.len().checked_div(self.dim).unwrap_or(0)
    }

    pub fn frame(&self, frame: usize) -> &[f32] {
        &self.values[frame * self.dim..(frame + 1) * self.dim]
    }

    /// Running sums of the frames, for means over any frame range.
    pub fn running_sums(&self) -> RunningSums {
        RunningSums::new(&self.values, self.dim)
    }

    /// Resamples to `n` frames: frame `k` of the result is the mean of the
    /// source over the `k`-th of `n` equal parts of the clip's duration.
    /// Averaging over each part rather than picking one frame keeps noise and
    /// single-frame glitches out of the resampled clip.
    pub fn resample(&self, n: usize) -> FeatureSequence {
        self.running_sums()
            .resample_range(0.0, self.frame_count() as f64, n)
    }
}

/// Running sums `g_t` of a feature sequence (f64, so that long takes keep
/// their precision), `g_0 = 0`.
#[derive(Debug, Clone)]
pub struct RunningSums {
    dim: usize,
    sums: Vec<f64>,
}

impl RunningSums {
    /// Running sums of `values` laid out frame after frame, `dim` per frame.
    pub fn new(values: &[f32], dim: usize) -> RunningSums {
        let frames = values.len().checked_div(dim).unwrap_or(0);
        let mut sums = vec![0.0f64; (frames + 1) * dim];
        for t in 0..frames {
            for i in 0..dim {
                sums[(t + 1) * dim + i] = sums[t * dim + i] + values[t * dim + i] as f64;
            }
        }
        RunningSums { dim, sums }
    }

    pub fn frame_count(&self) -> usize {
        self.sums.len() / self.dim.max(1) - 1
    }

    /// `g` at a fractional frame position `x` in `[0, frame_count]`: the sum
    /// of the first `floor(x)` frames plus the fraction of the next one.
    fn sum_at(&self, x: f64, i: usize) -> f64 {
        let frames = self.frame_count();
        let x = x.clamp(0.0, frames as f64);
        let whole = (x.floor() as usize).min(frames);
        let base = self.sums[whole * self.dim + i];
        if whole == frames {
            return base;
        }
        let next = self.sums[(whole + 1) * self.dim + i];
        base + (x - whole as f64) * (next - base)
    }

    /// Mean of value `i` over frames `[t0, t1)` in constant time; fractional
    /// bounds weigh the partial frames. Returns the value at `t0` when the
    /// range is empty, and 0 for a sequence without frames.
    pub fn mean(&self, i: usize, t0: f64, t1: f64) -> f32 {
        let frames = self.frame_count();
        if frames == 0 {
            return 0.0;
        }
        if t1 - t0 < 1e-9 {
            let f = (t0.floor() as usize).min(frames.saturating_sub(1));
            return (self.sums[(f + 1) * self.dim + i] - self.sums[f * self.dim + i]) as f32;
        }
        ((self.sum_at(t1, i) - self.sum_at(t0, i)) / (t1 - t0)) as f32
    }

    /// Resamples frames `[start, end)` (fractional) to `n` frames, each the
    /// mean over one `n`-th of the range. This is how a window of a long
    /// take is brought to the clip length without touching its frames again.
    pub fn resample_range(&self, start: f64, end: f64, n: usize) -> FeatureSequence {
        let mut values = Vec::with_capacity(n * self.dim);
        let step = (end - start) / n as f64;
        for k in 0..n {
            let (t0, t1) = (start + k as f64 * step, start + (k + 1) as f64 * step);
            for i in 0..self.dim {
                values.push(self.mean(i, t0, t1));
            }
        }
        FeatureSequence {
            dim: self.dim,
            values,
        }
    }
}

/// The set of intervals `[t0, t1)` of an `N`-frame clip the tests may use,
/// and the numbering of interval features: feature `d = r * values + i` is
/// the mean of value `i` over interval `r`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct IntervalLayout {
    /// Number of resampled frames `N`.
    pub frames: usize,
    /// Number of per-frame values.
    pub values: usize,
    /// All intervals `0 <= t0 < t1 <= N`, shortest first.
    pub intervals: Vec<(u16, u16)>,
}

impl IntervalLayout {
    /// Every interval of an `frames`-frame clip: `N (N + 1) / 2` of them.
    pub fn all(frames: usize, values: usize) -> IntervalLayout {
        let mut intervals = Vec::new();
        for len in 1..=frames {
            for t0 in 0..=frames - len {
                intervals.push((t0 as u16, (t0 + len) as u16));
            }
        }
        IntervalLayout {
            frames,
            values,
            intervals,
        }
    }

    /// Number of interval features: values times intervals.
    pub fn dim(&self) -> usize {
        self.values * self.intervals.len()
    }

    /// Value index `i` and interval `(t0, t1)` of interval feature `d`.
    pub fn describe(&self, d: usize) -> (usize, (u16, u16)) {
        (d % self.values, self.intervals[d / self.values])
    }

    /// All interval means of a clip already resampled to `frames` frames.
    pub fn interval_means(&self, clip: &FeatureSequence) -> Vec<f32> {
        debug_assert_eq!(clip.frame_count(), self.frames);
        debug_assert_eq!(clip.dim, self.values);
        let sums = clip.running_sums();
        let mut row = Vec::with_capacity(self.dim());
        for &(t0, t1) in &self.intervals {
            for i in 0..self.values {
                row.push(sums.mean(i, t0 as f64, t1 as f64));
            }
        }
        row
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sequence(frames: &[[f32; 2]]) -> FeatureSequence {
        FeatureSequence {
            dim: 2,
            values: frames.iter().flatten().copied().collect(),
        }
    }

    #[test]
    fn interval_means_match_direct_averages() {
        let seq = sequence(&[[1.0, 10.0], [2.0, 20.0], [4.0, 40.0], [8.0, 80.0]]);
        let sums = seq.running_sums();
        assert_eq!(sums.frame_count(), 4);
        for t0 in 0..4 {
            for t1 in t0 + 1..=4 {
                for i in 0..2 {
                    let direct: f32 =
                        (t0..t1).map(|t| seq.frame(t)[i]).sum::<f32>() / (t1 - t0) as f32;
                    let fast = sums.mean(i, t0 as f64, t1 as f64);
                    assert!((direct - fast).abs() < 1e-6, "[{t0},{t1}) {i}");
                }
            }
        }
        // Half of frame 1 and all of frame 2: (0.5 * 2 + 4) / 1.5.
        assert!((sums.mean(0, 1.5, 3.0) - 5.0 / 1.5).abs() < 1e-6);
    }

    #[test]
    fn resampling_averages_equal_parts() {
        let seq = sequence(&[[1.0, 0.0], [3.0, 0.0], [5.0, 0.0], [7.0, 0.0]]);
        let two = seq.resample(2);
        assert_eq!(two.values, vec![2.0, 0.0, 6.0, 0.0]);
        // Upsampling a 2-frame clip to 4 frames repeats each frame twice.
        let four = two.resample(4);
        assert_eq!(four.values, vec![2.0, 0.0, 2.0, 0.0, 6.0, 0.0, 6.0, 0.0]);
        // 3 parts of 4 frames: [0, 4/3), [4/3, 8/3), [8/3, 4).
        let three = seq.resample(3);
        let expect = [
            (1.0 + 3.0 / 3.0) / (4.0 / 3.0),
            4.0,
            (5.0 / 3.0 + 7.0) / (4.0 / 3.0),
        ];
        for (k, e) in expect.iter().enumerate() {
            assert!((three.frame(k)[0] - e).abs() < 1e-5, "{k}");
        }
    }

    #[test]
    fn layout_counts_and_describes_intervals() {
        let layout = IntervalLayout::all(10, 56);
        assert_eq!(layout.intervals.len(), 55);
        assert_eq!(layout.dim(), 55 * 56);
        assert_eq!(layout.describe(0), (0, (0, 1)));
        assert_eq!(layout.describe(56 * 10 + 3), (3, (0, 2)));
        assert_eq!(*layout.intervals.last().unwrap(), (0, 10));
        let seq = sequence(&[[1.0, 2.0], [3.0, 4.0]]);
        let layout = IntervalLayout::all(2, 2);
        // Intervals [0,1), [1,2), [0,2).
        assert_eq!(
            layout.interval_means(&seq),
            vec![1.0, 2.0, 3.0, 4.0, 2.0, 3.0]
        );
    }
}
