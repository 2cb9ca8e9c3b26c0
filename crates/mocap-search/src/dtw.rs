//! Dynamic time warping, for the nearest-neighbour baseline.
//!
//! The baseline compares two clips frame by frame on the same per-frame
//! features as the forest, letting the time axis stretch: the classic DTW
//! recurrence
//!
//! ```text
//! D(a, b) = c(a, b) + min(D(a-1, b), D(a, b-1), D(a-1, b-1))
//! ```
//!
//! with `c` the Euclidean distance between frame `a` of one clip and frame
//! `b` of the other, and the distance `D(n, m) / (n + m)` so that longer
//! clips are not penalised.

use crate::intervals::FeatureSequence;

/// DTW distance between two feature sequences of the same dimension,
/// normalised by the sum of their lengths. Infinite when either is empty.
pub(crate) fn dtw_distance(a: &FeatureSequence, b: &FeatureSequence) -> f32 {
    assert_eq!(a.dim, b.dim, "DTW needs sequences of the same features");
    let (n, m) = (a.frame_count(), b.frame_count());
    if n == 0 || m == 0 {
        return f32::INFINITY;
    }
    // Two rows of the cost matrix are enough.
    let mut previous = vec![f32::INFINITY; m + 1];
    let mut current = vec![f32::INFINITY; m + 1];
    previous[0] = 0.0;
    for i in 1..=n {
        current[0] = f32::INFINITY;
        let fa = a.frame(i - 1);
        for j in 1..=m {
            let cost = euclidean(fa, b.frame(j - 1));
            let best = previous[j].min(current[j - 1]).min(previous[j - 1]);
            current[j] = cost + best;
        }
        std::mem::swap(&mut previous, &mut current);
    }
    previous[m] / (n + m) as f32
}

/// One match of [`subsequence_dtw`]: frames `[start, end)` of the long
/// sequence and the normalised cost of the alignment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SubsequenceMatch {
    pub start: usize,
    pub end: usize,
    pub cost: f32,
}

/// Subsequence DTW: where in `long` the whole of `query` aligns best,
/// with free start and end in `long` (Müller, "Information Retrieval for
/// Music and Motion", 2007, ch. 4.4). The steps are (1,1), (2,1) and (1,2),
/// so the match lasts between half and twice the query's duration and
/// cannot collapse onto a few frames:
///
/// ```text
/// D(i, j) = min(D(i-1, j-1) + c(i, j),
///               D(i-2, j-1) + c(i-1, j) + c(i, j),
///               D(i-1, j-2) + c(i, j-1) + c(i, j))
/// ```
///
/// with `D(0, j) = c(0, j)` for every `j` (a match may start anywhere),
/// and each end `j` scored by `D(n-1, j)` divided by the number of cells on
/// its path. Returns up to `top` matches, best first, each overlapping an
/// earlier one by at most `max_overlap` (intersection over union).
pub(crate) fn subsequence_dtw(
    query: &FeatureSequence,
    long: &FeatureSequence,
    top: usize,
    max_overlap: f32,
) -> Vec<SubsequenceMatch> {
    assert_eq!(
        query.dim, long.dim,
        "DTW needs sequences of the same features"
    );
    let (n, m) = (query.frame_count(), long.frame_count());
    if n == 0 || m == 0 || top == 0 {
        return Vec::new();
    }
    /// One cell: accumulated cost, cells on the path, where it started.
    #[derive(Clone, Copy)]
    struct Cell {
        cost: f32,
        cells: u32,
        start: usize,
    }
    const NONE: Cell = Cell {
        cost: f32::INFINITY,
        cells: 0,
        start: 0,
    };
    let c = |i: usize, j: usize| euclidean(query.frame(i), long.frame(j));
    // Rows i-2, i-1 and i of the cost matrix.
    let mut two_back = vec![NONE; m];
    let mut one_back = vec![NONE; m];
    let mut row = vec![NONE; m];
    for i in 0..n {
        for j in 0..m {
            let here = c(i, j);
            row[j] = if i == 0 {
                Cell {
                    cost: here,
                    cells: 1,
                    start: j,
                }
            } else {
                let mut best = NONE;
                let mut consider = |from: Cell, extra: f32, extra_cells: u32| {
                    let cost = from.cost + extra + here;
                    if cost < best.cost {
                        best = Cell {
                            cost,
                            cells: from.cells + extra_cells + 1,
                            start: from.start,
                        };
                    }
                };
                if j >= 1 {
                    consider(one_back[j - 1], 0.0, 0);
                    if i >= 2 {
                        consider(two_back[j - 1], c(i - 1, j), 1);
                    }
                }
                if j >= 2 {
                    consider(one_back[j - 2], c(i, j - 1), 1);
                }
                best
            };
        }
        std::mem::swap(&mut two_back, &mut one_back);
        std::mem::swap(&mut one_back, &mut row);
    }
    // `one_back` now holds the last query row.
    let mut ends: Vec<SubsequenceMatch> = one_back
        .iter()
        .enumerate()
        .filter(|(_, cell)| cell.cost.is_finite())
        .map(|(j, cell)| SubsequenceMatch {
            start: cell.start,
            end: j + 1,
            cost: cell.cost / cell.cells as f32,
        })
        .collect();
    ends.sort_by(|a, b| a.cost.total_cmp(&b.cost).then(a.end.cmp(&b.end)));
    let mut kept: Vec<SubsequenceMatch> = Vec::new();
    for e in ends {
        if kept.len() >= top {
            break;
        }
        let overlaps = kept.iter().any(|k| {
            let inter = e.end.min(k.end).saturating_sub(e.start.max(k.start));
            let union = e.end.max(k.end) - e.start.min(k.start);
            inter as f32 > max_overlap * union as f32
        });
        if !overlaps {
            kept.push(e);
        }
    }
    kept
}

/// Euclidean distance between two vectors of the same length.
pub(crate) fn euclidean(a: &[f32], b: &[f32]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f32>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seq(values: &[f32]) -> FeatureSequence {
        FeatureSequence {
            dim: 1,
            values: values.to_vec(),
        }
    }

    #[test]
    fn dtw_absorbs_a_change_of_speed() {
        let slow = seq(&[0.0, 0.0, 1.0, 1.0, 2.0, 2.0]);
        let fast = seq(&[0.0, 1.0, 2.0]);
        assert_eq!(dtw_distance(&slow, &fast), 0.0);
        // Without warping the frames would not line up.
        let other = seq(&[2.0, 1.0, 0.0]);
        assert!(dtw_distance(&slow, &other) > 0.0);
    }

    #[test]
    fn subsequence_dtw_finds_the_query_inside_a_long_sequence() {
        // The query (0, 1, 2) played at half speed from frame 4.
        let long = seq(&[5.0, 5.0, 5.0, 5.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 5.0, 5.0]);
        let query = seq(&[0.0, 1.0, 2.0]);
        let found = subsequence_dtw(&query, &long, 3, 0.0);
        // Frames 4-9, or 5-8 (one 0 and one 2 fewer), align at no cost.
        let best = found[0];
        assert_eq!(best.cost, 0.0);
        assert!(
            (4..=5).contains(&best.start) && (9..=10).contains(&best.end),
            "{best:?}"
        );
        // Later matches do not overlap the first.
        assert!(found[1..]
            .iter()
            .all(|m| m.end <= best.start || m.start >= best.end));
    }

    #[test]
    fn dtw_of_known_pair() {
        // Best path: (0,0) (1,1) (2,1): costs 1 + 0 + 1 = 2, over 3 + 2.
        let a = seq(&[1.0, 2.0, 3.0]);
        let b = seq(&[0.0, 2.0]);
        assert!((dtw_distance(&a, &b) - 2.0 / 5.0).abs() < 1e-6);
        assert_eq!(dtw_distance(&a, &seq(&[])), f32::INFINITY);
    }
}
