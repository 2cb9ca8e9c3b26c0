//! Classification and ranking scores: precision, recall and F-measure per
//! class (the report's Fig. 4), mean average precision and precision at k.

use serde::{Deserialize, Serialize};

/// Counts of (true class, predicted class) pairs.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ConfusionMatrix {
    classes: usize,
    /// `counts[truth * classes + predicted]`.
    counts: Vec<u32>,
}

/// Precision, recall and F-measure of one class.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ClassScores {
    pub precision: f64,
    pub recall: f64,
    /// Harmonic mean of precision and recall (F1).
    pub f_measure: f64,
    /// Test clips of this class.
    pub support: u32,
}

impl ConfusionMatrix {
    pub fn new(classes: usize) -> ConfusionMatrix {
        ConfusionMatrix {
            classes,
            counts: vec![0; classes * classes],
        }
    }

    pub fn add(&mut self, truth: usize, predicted: usize) {
        self.counts[truth * self.classes + predicted] += 1;
    }

    /// Adds every count of `other` (pooling cross-validation folds).
    pub fn merge(&mut self, other: &ConfusionMatrix) {
        for (a, b) in self.counts.iter_mut().zip(&other.counts) {
            *a += b;
        }
    }

    pub fn count(&self, truth: usize, predicted: usize) -> u32 {
        self.counts[truth * self.classes + predicted]
    }

    pub fn classes(&self) -> usize {
        self.classes
    }

    pub fn total(&self) -> u32 {
        self.counts.iter().sum()
    }

    /// Fraction of clips classified right.
    pub fn accuracy(&self) -> f64 {
        let right: u32 = (0..self.classes).map(|c| self.count(c, c)).sum();
        ratio(right, self.total())
    }

    /// Scores of class `c`. A class never predicted has precision 0, a class
    /// absent from the test set recall 0 (and is left out of the averages).
    pub fn class_scores(&self, c: usize) -> ClassScores {
        let tp = self.count(c, c);
        let predicted: u32 = (0..self.classes).map(|t| self.count(t, c)).sum();
        let support: u32 = (0..self.classes).map(|p| self.count(c, p)).sum();
        let precision = ratio(tp, predicted);
        let recall = ratio(tp, support);
        let f_measure = if precision + recall > 0.0 {
            2.0 * precision * recall / (precision + recall)
        } else {
            0.0
        };
        ClassScores {
            precision,
            recall,
            f_measure,
            support,
        }
    }

    /// Unweighted mean of the per-class scores over the classes present in
    /// the test set (macro average).
    pub fn macro_average(&self) -> ClassScores {
        self.macro_average_over(1)
    }

    /// Macro average over the classes with at least `min_support` test
    /// clips (at least one). A class with two clips in 5-fold
    /// cross-validation is learnt from a single example and its F is 0 or 1
    /// per clip, so reports give this average beside the one over all
    /// classes, never instead of it.
    pub fn macro_average_over(&self, min_support: u32) -> ClassScores {
        let present: Vec<ClassScores> = (0..self.classes)
            .map(|c| self.class_scores(c))
            .filter(|s| s.support >= min_support.max(1))
            .collect();
        let n = present.len().max(1) as f64;
        // Folded from +0.0: an empty float sum is -0.0, printed "-0.000".
        let mean =
            |score: fn(&ClassScores) -> f64| present.iter().map(score).fold(0.0, |a, b| a + b) / n;
        ClassScores {
            precision: mean(|s| s.precision),
            recall: mean(|s| s.recall),
            f_measure: mean(|s| s.f_measure),
            support: present.iter().map(|s| s.support).sum(),
        }
    }
}

fn ratio(a: u32, b: u32) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
    }
}

/// Average precision of one ranked list given whether each item is
/// relevant: the mean, over the relevant items, of the precision of the list
/// cut just after that item. `total_relevant` counts every relevant item in
/// the library (a relevant item missing from the list counts as precision 0).
pub(crate) fn average_precision(relevant: &[bool], total_relevant: usize) -> f64 {
    if total_relevant == 0 {
        return 0.0;
    }
    let mut hits = 0usize;
    let mut sum = 0.0;
    for (k, &r) in relevant.iter().enumerate() {
        if r {
            hits += 1;
            sum += hits as f64 / (k + 1) as f64;
        }
    }
    sum / total_relevant as f64
}

/// Fraction of the first `k` items that are relevant (a list shorter than
/// `k` counts the missing places as not relevant).
pub(crate) fn precision_at(relevant: &[bool], k: usize) -> f64 {
    if k == 0 {
        return 0.0;
    }
    relevant.iter().take(k).filter(|&&r| r).count() as f64 / k as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scores_from_a_hand_made_confusion_matrix() {
        // Class 0: 3 right, 1 called class 1. Class 1: 2 right.
        let mut m = ConfusionMatrix::new(3);
        for _ in 0..3 {
            m.add(0, 0);
        }
        m.add(0, 1);
        m.add(1, 1);
        m.add(1, 1);
        let s0 = m.class_scores(0);
        assert_eq!((s0.precision, s0.recall, s0.support), (1.0, 0.75, 4));
        assert!((s0.f_measure - 2.0 * 0.75 / 1.75).abs() < 1e-12);
        let s1 = m.class_scores(1);
        assert!((s1.precision - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(s1.recall, 1.0);
        // Class 2 has no test clips: not averaged.
        let avg = m.macro_average();
        assert!((avg.recall - 0.875).abs() < 1e-12);
        assert!((m.accuracy() - 5.0 / 6.0).abs() < 1e-12);
    }

    #[test]
    fn ranking_scores() {
        let ranked = [true, false, true, false, false];
        // (1/1 + 2/3) / 2
        assert!((average_precision(&ranked, 2) - (1.0 + 2.0 / 3.0) / 2.0).abs() < 1e-12);
        // A third relevant item never retrieved lowers AP.
        assert!((average_precision(&ranked, 3) - (1.0 + 2.0 / 3.0) / 3.0).abs() < 1e-12);
        assert_eq!(precision_at(&ranked, 2), 0.5);
        assert_eq!(precision_at(&ranked, 10), 0.2);
    }
}
