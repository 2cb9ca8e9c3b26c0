//! Searching inside long, unsegmented takes: the time ranges of a recording
//! where a motion like the query happens.
//!
//! Windows of several lengths around the query's duration slide over the
//! take. The take's per-frame features are computed once and turned into
//! running sums, so each window is resampled to the index's `N` frames in
//! constant time per frame ([`RunningSums::resample_range`]) and compared
//! with the query like a library clip. The best windows are kept, skipping
//! any that overlaps an already kept one too much (non-maximum suppression).
//!
//! The other method, [`TakeMethod::SubsequenceDtw`], aligns the whole query
//! with every part of the take by subsequence dynamic time warping on the
//! standardised features ([`crate::dtw::subsequence_dtw`]); its matches may
//! be of any length, so they follow the motion's real duration in the take.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::clips::load_features;
use crate::dtw::subsequence_dtw;
use crate::error::{Result, SearchError};
use crate::forest::argmax;
use crate::index::{Index, Ranking};
use crate::intervals::FeatureSequence;

/// How the take is searched.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TakeMethod {
    /// Sliding windows compared with the query by `ranking`.
    Windows,
    /// Subsequence DTW on the standardised features, at `dtw_fps`.
    SubsequenceDtw,
}

impl std::str::FromStr for TakeMethod {
    type Err = SearchError;
    fn from_str(s: &str) -> Result<TakeMethod> {
        match s {
            "windows" => Ok(TakeMethod::Windows),
            "dtw" => Ok(TakeMethod::SubsequenceDtw),
            other => Err(SearchError::Invalid(format!(
                "unknown take search method `{other}`; expected windows or dtw"
            ))),
        }
    }
}

/// How a take is searched. The default, windows compared by their forest
/// histograms, found the clips of the query's class best in the long-take
/// experiment of `bench/results/search.md` (subsequence DTW and feature
/// distance localise less well on Bandai takes).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TakeSearchConfig {
    pub method: TakeMethod,
    /// Frame rate both sequences are brought to for subsequence DTW.
    pub dtw_fps: f64,
    /// Window durations as multiples of the query's duration (the same
    /// motion is often performed faster or slower).
    pub scales: Vec<f32>,
    /// Step between window starts, as a fraction of the query's duration.
    pub hop: f32,
    pub ranking: Ranking,
    /// Number of time ranges to return.
    pub top: usize,
    /// A window is dropped when its overlap (intersection over union) with a
    /// better one already returned is above this.
    pub max_overlap: f32,
}

impl Default for TakeSearchConfig {
    fn default() -> Self {
        TakeSearchConfig {
            method: TakeMethod::Windows,
            dtw_fps: 10.0,
            scales: vec![0.5, 0.7, 1.0, 1.4, 2.0],
            hop: 0.1,
            ranking: Ranking::Histogram,
            top: 10,
            max_overlap: 0.3,
        }
    }
}

/// A time range of the take that resembles the query.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TakeMatch {
    /// First frame of the range.
    pub start_frame: usize,
    /// One past the last frame.
    pub end_frame: usize,
    pub start_seconds: f64,
    pub end_seconds: f64,
    pub distance: f32,
    /// The class the forest gives the window.
    pub predicted: String,
}

/// Intersection over union of two frame ranges.
pub(crate) fn overlap(a: (usize, usize), b: (usize, usize)) -> f32 {
    let inter = a.1.min(b.1).saturating_sub(a.0.max(b.0));
    let union = a.1.max(b.1) - a.0.min(b.0);
    if union == 0 {
        0.0
    } else {
        inter as f32 / union as f32
    }
}

/// `mocap search find`: reads the query clip and the long take (BVH, or AMC
/// next to its ASF) and finds the time ranges of the take most like the
/// query ([`search_take`]).
pub fn find_in_take(
    index: &Index,
    query: &Path,
    take: &Path,
    config: &TakeSearchConfig,
) -> Result<TakeReport> {
    let (query_features, query_fps) = load_features(query)?;
    let (take_features, take_fps) = load_features(take)?;
    let matches = search_take(
        index,
        &query_features,
        query_fps,
        &take_features,
        take_fps,
        config,
    )?;
    Ok(TakeReport {
        query: query.display().to_string(),
        take: take.display().to_string(),
        take_seconds: take_features.frame_count() as f64 / take_fps,
        matches,
    })
}

/// The time ranges of `take` (per-frame features at `take_fps`) most like
/// `query` (per-frame features at `query_fps`), best first.
pub fn search_take(
    index: &Index,
    query: &FeatureSequence,
    query_fps: f64,
    take: &FeatureSequence,
    take_fps: f64,
    config: &TakeSearchConfig,
) -> Result<Vec<TakeMatch>> {
    if query.frame_count() == 0 || take.frame_count() == 0 {
        return Err(SearchError::Invalid(
            "the query and the take need at least one frame".into(),
        ));
    }
    if config.scales.is_empty()
        || config.scales.iter().any(|s| !s.is_finite() || *s <= 0.0)
        || !config.hop.is_finite()
        || config.hop <= 0.0
    {
        return Err(SearchError::Invalid(
            "window scales and hop must be positive".into(),
        ));
    }
    if config.method == TakeMethod::SubsequenceDtw {
        return Ok(search_take_dtw(
            index, query, query_fps, take, take_fps, config,
        ));
    }
    let target = index.describe(query);
    let sums = take.running_sums();
    let frames = take.frame_count();
    // The query's duration in take frames.
    let query_len = query.frame_count() as f64 / query_fps * take_fps;
    let hop = (query_len * config.hop as f64).max(1.0);
    let mut windows: Vec<(usize, usize, f32, usize)> = Vec::new();
    for &scale in &config.scales {
        let len = (query_len * scale as f64).round().max(1.0);
        if len > frames as f64 {
            continue;
        }
        let mut start = 0.0;
        while start + len <= frames as f64 + 1e-9 {
            let resampled = sums.resample_range(start, start + len, index.config.frames);
            let window = index.describe_resampled(resampled);
            let distance = index.pair_distance(&target, &window, config.ranking);
            let (s, e) = (start.round() as usize, (start + len).round() as usize);
            windows.push((s, e.min(frames), distance, argmax(&window.histogram)));
            start += hop;
        }
    }
    if windows.is_empty() {
        // The take is shorter than every window: compare it whole.
        let window = index.describe(take);
        let distance = index.pair_distance(&target, &window, config.ranking);
        windows.push((0, frames, distance, argmax(&window.histogram)));
    }
    windows.sort_by(|a, b| a.2.total_cmp(&b.2).then(a.0.cmp(&b.0)));
    let mut kept: Vec<TakeMatch> = Vec::new();
    for (s, e, distance, class) in windows {
        if kept.len() >= config.top {
            break;
        }
        if kept
            .iter()
            .any(|k| overlap((s, e), (k.start_frame, k.end_frame)) > config.max_overlap)
        {
            continue;
        }
        kept.push(TakeMatch {
            start_frame: s,
            end_frame: e,
            start_seconds: s as f64 / take_fps,
            end_seconds: e as f64 / take_fps,
            distance,
            predicted: index.classes[class].clone(),
        });
    }
    Ok(kept)
}

/// Brings a feature sequence to `fps` (means over equal parts) and
/// standardises it with the index's statistics.
fn standardised_at(
    index: &Index,
    features: &FeatureSequence,
    from_fps: f64,
    fps: f64,
) -> FeatureSequence {
    let frames = ((features.frame_count() as f64 * fps / from_fps).round() as usize).max(1);
    let mut resampled = features.resample(frames);
    for (k, v) in resampled.values.iter_mut().enumerate() {
        let i = k % resampled.dim;
        *v = (*v - index.value_mean[i]) / index.value_scale[i];
    }
    resampled
}

fn search_take_dtw(
    index: &Index,
    query: &FeatureSequence,
    query_fps: f64,
    take: &FeatureSequence,
    take_fps: f64,
    config: &TakeSearchConfig,
) -> Vec<TakeMatch> {
    let fps = if config.dtw_fps > 0.0 {
        config.dtw_fps
    } else {
        take_fps
    };
    let q = standardised_at(index, query, query_fps, fps);
    let t = standardised_at(index, take, take_fps, fps);
    // Take frames per DTW frame.
    let ratio = take.frame_count() as f64 / t.frame_count() as f64;
    let sums = take.running_sums();
    subsequence_dtw(&q, &t, config.top, config.max_overlap)
        .into_iter()
        .map(|m| {
            let start_frame = (m.start as f64 * ratio).round() as usize;
            let end_frame = ((m.end as f64 * ratio).round() as usize).min(take.frame_count());
            let window = index.describe_resampled(sums.resample_range(
                start_frame as f64,
                end_frame.max(start_frame + 1) as f64,
                index.config.frames,
            ));
            TakeMatch {
                start_frame,
                end_frame,
                start_seconds: start_frame as f64 / take_fps,
                end_seconds: end_frame as f64 / take_fps,
                distance: m.cost,
                predicted: index.classes[argmax(&window.histogram)].clone(),
            }
        })
        .collect()
}

/// The answer to a search in a take, for printing or JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TakeReport {
    pub query: String,
    pub take: String,
    pub take_seconds: f64,
    pub matches: Vec<TakeMatch>,
}

impl TakeReport {
    /// Plain text for a terminal.
    pub fn to_text(&self) -> String {
        let mut s = format!(
            "{} in {} ({:.1} s):\n",
            self.query, self.take, self.take_seconds
        );
        for (k, m) in self.matches.iter().enumerate() {
            s += &format!(
                "{:>4}  {:>8.2} s - {:>8.2} s  (frames {}-{})  distance {:.4}  looks like {}\n",
                k + 1,
                m.start_seconds,
                m.end_seconds,
                m.start_frame,
                m.end_frame,
                m.distance,
                m.predicted
            );
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlap_of_ranges() {
        assert_eq!(overlap((0, 10), (0, 10)), 1.0);
        assert_eq!(overlap((0, 10), (10, 20)), 0.0);
        assert!((overlap((0, 10), (5, 15)) - 5.0 / 15.0).abs() < 1e-6);
    }
}
