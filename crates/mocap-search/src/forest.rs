//! Decision trees and random forests over interval features.
//!
//! A tree node holds one *test*: "is feature `d` of the clip below the
//! threshold `s`?" In this crate feature `d` stands for one interval mean
//! (value `i` averaged over interval `r`, see [`crate::features`]); the trees
//! themselves only see a dense row of numbers per clip.
//!
//! Growing a node follows the report:
//!
//! - draw candidate features at random (a *random* tree) or take every
//!   feature (the *deterministic* tree: the best test at every node);
//! - for each candidate, choose the threshold with the largest information
//!   gain (eq. 6-7):
//!
//!   ```text
//!   H(S)    = - sum_c p_c log2 p_c                       (6)
//!   G(S, s) = H(S) - |L|/|S| H(L) - |R|/|S| H(R)         (7)
//!   ```
//!
//!   where `L` and `R` are the samples below and above the threshold;
//! - split on the best (feature, threshold) and recurse;
//! - stop when the node's entropy falls below a set value (or the node is
//!   too deep or too small); the leaf stores the class histogram of the
//!   training samples that reached it.
//!
//! A forest averages the leaf histograms of its trees.

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How one tree is grown.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TreeConfig {
    /// Number of candidate features drawn at random at each node. `None`
    /// tries every feature at every node (the deterministic tree).
    pub candidates_per_node: Option<usize>,
    /// A node whose class entropy (bits) is at or below this becomes a leaf.
    pub min_entropy: f32,
    /// A node at this depth becomes a leaf (the root has depth 0).
    pub max_depth: usize,
    /// A node with fewer training samples becomes a leaf.
    pub min_samples_split: usize,
}

impl Default for TreeConfig {
    fn default() -> Self {
        TreeConfig {
            candidates_per_node: Some(64),
            min_entropy: 0.0,
            max_depth: 32,
            min_samples_split: 2,
        }
    }
}

/// How a forest is grown.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ForestConfig {
    /// Number of trees (the report uses 100).
    pub trees: usize,
    pub tree: TreeConfig,
    /// Train each tree on a bootstrap sample (drawn with replacement) of the
    /// training clips, as in Breiman's random forests. Without it every tree
    /// sees every clip and only the random tests make the trees differ.
    pub bootstrap: bool,
    /// Seed of the random numbers: the same seed and data give the same forest.
    pub seed: u64,
}

impl Default for ForestConfig {
    fn default() -> Self {
        ForestConfig {
            trees: 100,
            tree: TreeConfig::default(),
            bootstrap: true,
            seed: 1,
        }
    }
}

/// Labelled training rows: `rows[k * dim .. (k + 1) * dim]` is sample `k`,
/// `labels[k]` its class (below `class_count`).
#[derive(Debug, Clone, Copy)]
pub struct Samples<'a> {
    pub rows: &'a [f32],
    pub dim: usize,
    pub labels: &'a [u32],
    pub class_count: usize,
}

impl<'a> Samples<'a> {
    /// Checks that the shapes agree.
    pub fn new(
        rows: &'a [f32],
        dim: usize,
        labels: &'a [u32],
        class_count: usize,
    ) -> Result<Samples<'a>, String> {
        if dim == 0 || rows.len() != dim * labels.len() {
            return Err(format!(
                "{} samples of {dim} features need {} values, got {}",
                labels.len(),
                dim * labels.len(),
                rows.len()
            ));
        }
        if let Some(&bad) = labels.iter().find(|&&l| l as usize >= class_count) {
            return Err(format!(
                "label {bad} is not below the class count {class_count}"
            ));
        }
        if labels.is_empty() {
            return Err("no training samples".into());
        }
        Ok(Samples {
            rows,
            dim,
            labels,
            class_count,
        })
    }

    pub fn len(&self) -> usize {
        self.labels.len()
    }

    pub fn is_empty(&self) -> bool {
        self.labels.is_empty()
    }

    fn value(&self, sample: u32, feature: u32) -> f32 {
        self.rows[sample as usize * self.dim + feature as usize]
    }
}

/// One node of a tree, stored in a flat list (the root is node 0).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Node {
    /// Samples whose `feature` is below `threshold` go to `left`, the others
    /// to `right`.
    Split {
        feature: u32,
        threshold: f32,
        left: u32,
        right: u32,
    },
    /// Class histogram of the training samples that reached this leaf,
    /// normalised to sum 1.
    Leaf { histogram: Vec<f32> },
}

/// A decision tree.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tree {
    nodes: Vec<Node>,
    /// Parent of every node (`u32::MAX` for the root), to walk up from a leaf.
    parents: Vec<u32>,
    /// Depth of every node (root 0).
    depths: Vec<u16>,
}

impl Tree {
    /// Grows a tree on `samples` restricted to the sample indices `subset`
    /// (which may repeat a sample, as a bootstrap sample does).
    pub fn train(
        samples: &Samples,
        subset: &[u32],
        config: &TreeConfig,
        rng: &mut Xoshiro256PlusPlus,
    ) -> Tree {
        let mut grower = Grower {
            samples,
            config,
            tree: Tree {
                nodes: Vec::new(),
                parents: Vec::new(),
                depths: Vec::new(),
            },
            xlogx: xlogx_table(subset.len()),
        };
        let mut subset = subset.to_vec();
        grower.grow(&mut subset, 0, u32::MAX, rng);
        grower.tree
    }

    /// The deterministic tree of the report: every feature is tried at every
    /// node and every training sample is used once.
    pub fn train_deterministic(samples: &Samples, config: &TreeConfig) -> Tree {
        let config = TreeConfig {
            candidates_per_node: None,
            ..config.clone()
        };
        let all: Vec<u32> = (0..samples.len() as u32).collect();
        // The generator is never drawn from when every feature is a candidate.
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(0);
        Tree::train(samples, &all, &config, &mut rng)
    }

    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub fn leaf_count(&self) -> usize {
        self.nodes
            .iter()
            .filter(|n| matches!(n, Node::Leaf { .. }))
            .count()
    }

    /// Depth of the deepest leaf.
    pub fn depth(&self) -> usize {
        self.depths.iter().copied().max().unwrap_or(0) as usize
    }

    /// Depth of node `node` (the root has depth 0).
    pub fn node_depth(&self, node: u32) -> usize {
        self.depths[node as usize] as usize
    }

    /// Parent of `node`, `None` for the root.
    pub fn parent(&self, node: u32) -> Option<u32> {
        let p = self.parents[node as usize];
        (p != u32::MAX).then_some(p)
    }

    /// Index of the leaf that `row` reaches.
    pub fn leaf(&self, row: &[f32]) -> u32 {
        let mut at = 0u32;
        loop {
            match &self.nodes[at as usize] {
                Node::Split {
                    feature,
                    threshold,
                    left,
                    right,
                } => {
                    at = if row[*feature as usize] < *threshold {
                        *left
                    } else {
                        *right
                    }
                }
                Node::Leaf { .. } => return at,
            }
        }
    }

    /// The class histogram stored in leaf `node`. Panics if `node` is not a
    /// leaf (leaf indices come from [`Tree::leaf`]).
    pub fn leaf_histogram(&self, node: u32) -> &[f32] {
        match &self.nodes[node as usize] {
            Node::Leaf { histogram } => histogram,
            Node::Split { .. } => panic!("node {node} is not a leaf"),
        }
    }

    /// The class histogram of the leaf that `row` reaches.
    pub fn histogram(&self, row: &[f32]) -> &[f32] {
        self.leaf_histogram(self.leaf(row))
    }

    /// Whether every reference between nodes points inside the tree and
    /// every leaf histogram has `class_count` entries (checked after loading
    /// a file, so that a bad file gives an error instead of a panic later).
    pub fn is_consistent(&self, class_count: usize, dim: usize) -> bool {
        let n = self.nodes.len() as u32;
        n > 0
            && self.parents.len() == self.nodes.len()
            && self.depths.len() == self.nodes.len()
            && self.nodes.iter().enumerate().all(|(k, node)| match node {
                Node::Split {
                    feature,
                    left,
                    right,
                    ..
                } => {
                    // Children are always stored after their parent, which
                    // also rules out cycles.
                    (*feature as usize) < dim
                        && *left < n
                        && *right < n
                        && *left as usize > k
                        && *right as usize > k
                }
                Node::Leaf { histogram } => histogram.len() == class_count,
            })
    }
}

/// `xlogx[c] = c log2 c`, so that the entropy of counts `c_k` summing to `n`
/// is `(n log2 n - sum_k c_k log2 c_k) / n` (eq. 6 multiplied through by n),
/// which lets the threshold sweep update it in constant time per sample.
fn xlogx_table(n: usize) -> Vec<f64> {
    (0..=n)
        .map(|c| {
            if c == 0 {
                0.0
            } else {
                c as f64 * (c as f64).log2()
            }
        })
        .collect()
}

/// Entropy in bits of a class histogram given as counts (eq. 6).
pub fn entropy(counts: &[u32]) -> f64 {
    let n: u32 = counts.iter().sum();
    if n == 0 {
        return 0.0;
    }
    let n = n as f64;
    counts
        .iter()
        .filter(|&&c| c > 0)
        .map(|&c| {
            let p = c as f64 / n;
            -p * p.log2()
        })
        .sum()
}

struct Grower<'a, 'b> {
    samples: &'a Samples<'b>,
    config: &'a TreeConfig,
    tree: Tree,
    xlogx: Vec<f64>,
}

/// The best test found for a node.
struct BestSplit {
    gain: f64,
    feature: u32,
    threshold: f32,
}

impl Grower<'_, '_> {
    fn push(&mut self, node: Node, parent: u32, depth: usize) -> u32 {
        self.tree.nodes.push(node);
        self.tree.parents.push(parent);
        self.tree.depths.push(depth as u16);
        (self.tree.nodes.len() - 1) as u32
    }

    fn counts(&self, subset: &[u32]) -> Vec<u32> {
        let mut counts = vec![0u32; self.samples.class_count];
        for &s in subset {
            counts[self.samples.labels[s as usize] as usize] += 1;
        }
        counts
    }

    fn leaf(&mut self, counts: &[u32], parent: u32, depth: usize) -> u32 {
        let n: u32 = counts.iter().sum();
        let histogram = counts.iter().map(|&c| c as f32 / n as f32).collect();
        self.push(Node::Leaf { histogram }, parent, depth)
    }

    /// Grows the subtree for `subset` and returns its root's index.
    fn grow(
        &mut self,
        subset: &mut [u32],
        depth: usize,
        parent: u32,
        rng: &mut Xoshiro256PlusPlus,
    ) -> u32 {
        let counts = self.counts(subset);
        let node_entropy = entropy(&counts);
        if node_entropy <= self.config.min_entropy as f64
            || depth >= self.config.max_depth
            || subset.len() < self.config.min_samples_split.max(2)
        {
            return self.leaf(&counts, parent, depth);
        }
        let Some(best) = self.best_split(subset, &counts, rng) else {
            // No candidate separates the samples (all drawn features are
            // constant here): nothing more to learn at this node.
            return self.leaf(&counts, parent, depth);
        };
        // Reserve this node's slot, then grow the children after it.
        let here = self.push(
            Node::Split {
                feature: best.feature,
                threshold: best.threshold,
                left: 0,
                right: 0,
            },
            parent,
            depth,
        );
        let split_at = partition(subset, |&s| {
            self.samples.value(s, best.feature) < best.threshold
        });
        let (left_set, right_set) = subset.split_at_mut(split_at);
        let left = self.grow(left_set, depth + 1, here, rng);
        let right = self.grow(right_set, depth + 1, here, rng);
        if let Node::Split {
            left: l, right: r, ..
        } = &mut self.tree.nodes[here as usize]
        {
            *l = left;
            *r = right;
        }
        here
    }

    /// The (feature, threshold) of largest information gain (eq. 7) among
    /// the candidate features, or `None` if no candidate has a positive gain.
    fn best_split(
        &self,
        subset: &[u32],
        counts: &[u32],
        rng: &mut Xoshiro256PlusPlus,
    ) -> Option<BestSplit> {
        let dim = self.samples.dim;
        let candidates: Vec<u32> = match self.config.candidates_per_node {
            Some(k) if k < dim => rand::seq::index::sample(rng, dim, k)
                .into_iter()
                .map(|f| f as u32)
                .collect(),
            _ => (0..dim as u32).collect(),
        };
        let n = subset.len();
        let xlogx = &self.xlogx;
        // n * H(S): eq. 6 multiplied by the sample count.
        let parent_sum: f64 = counts.iter().map(|&c| xlogx[c as usize]).sum();
        let parent_nh = xlogx[n] - parent_sum;
        let mut best: Option<BestSplit> = None;
        let mut pairs: Vec<(f32, u32)> = Vec::with_capacity(n);
        let mut left = vec![0u32; counts.len()];
        for &feature in &candidates {
            pairs.clear();
            pairs.extend(subset.iter().map(|&s| {
                (
                    self.samples.value(s, feature),
                    self.samples.labels[s as usize],
                )
            }));
            pairs.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
            if pairs[0].0 == pairs[n - 1].0 {
                continue;
            }
            left.iter_mut().for_each(|c| *c = 0);
            // Running sums of c log2 c over the classes left and right of
            // the threshold.
            let mut left_sum = 0.0f64;
            let mut right_sum = parent_sum;
            for k in 0..n - 1 {
                let class = pairs[k].1 as usize;
                let l = left[class] as usize;
                let r = (counts[class] - left[class]) as usize;
                left_sum += xlogx[l + 1] - xlogx[l];
                right_sum += xlogx[r - 1] - xlogx[r];
                left[class] += 1;
                if pairs[k].0 == pairs[k + 1].0 {
                    continue; // no threshold between equal values
                }
                let (nl, nr) = (k + 1, n - k - 1);
                let children_nh = (xlogx[nl] - left_sum) + (xlogx[nr] - right_sum);
                let gain = (parent_nh - children_nh) / n as f64;
                if best.as_ref().is_none_or(|b| gain > b.gain + 1e-12) {
                    // Halfway between the two values; computed in f64 so
                    // that it lies strictly above the lower value.
                    let mid = ((pairs[k].0 as f64 + pairs[k + 1].0 as f64) / 2.0) as f32;
                    let threshold = if mid > pairs[k].0 {
                        mid
                    } else {
                        pairs[k + 1].0
                    };
                    best = Some(BestSplit {
                        gain,
                        feature,
                        threshold,
                    });
                }
            }
        }
        best.filter(|b| b.gain > 1e-9)
    }
}

/// Moves the items for which `below` holds to the front; returns their count.
fn partition<T, F: FnMut(&T) -> bool>(items: &mut [T], mut below: F) -> usize {
    let mut next = 0;
    for k in 0..items.len() {
        if below(&items[k]) {
            items.swap(next, k);
            next += 1;
        }
    }
    next
}

/// A random forest: trees whose leaf histograms are averaged.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Forest {
    trees: Vec<Tree>,
    class_count: usize,
    dim: usize,
    /// For every training sample, the trees whose bootstrap sample did not
    /// contain it (its *out-of-bag* trees), as indices into `trees`.
    #[serde(skip)]
    out_of_bag: Vec<Vec<u32>>,
}

impl Forest {
    /// Grows `config.trees` random trees on `samples`, in parallel. Tree `t`
    /// uses the random numbers seeded by `config.seed` and `t`, so the result
    /// does not depend on the number of threads. `on_tree` is called after
    /// each tree (for a progress bar).
    pub fn train(samples: &Samples, config: &ForestConfig, on_tree: &(dyn Fn() + Sync)) -> Forest {
        let n = samples.len();
        let grown: Vec<(Tree, Vec<u32>)> = (0..config.trees)
            .into_par_iter()
            .map(|t| {
                let mut rng = Xoshiro256PlusPlus::seed_from_u64(
                    config.seed ^ (t as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15),
                );
                let subset: Vec<u32> = if config.bootstrap {
                    (0..n).map(|_| rng.random_range(0..n as u32)).collect()
                } else {
                    (0..n as u32).collect()
                };
                let tree = Tree::train(samples, &subset, &config.tree, &mut rng);
                on_tree();
                (tree, subset)
            })
            .collect();
        let mut out_of_bag = vec![Vec::new(); n];
        let mut trees = Vec::with_capacity(grown.len());
        for (t, (tree, subset)) in grown.into_iter().enumerate() {
            let mut in_bag = vec![false; n];
            for &s in &subset {
                in_bag[s as usize] = true;
            }
            for (s, used) in in_bag.into_iter().enumerate() {
                if !used {
                    out_of_bag[s].push(t as u32);
                }
            }
            trees.push(tree);
        }
        Forest {
            trees,
            class_count: samples.class_count,
            dim: samples.dim,
            out_of_bag,
        }
    }

    /// A forest of given trees (e.g. a single tree, to use the same code).
    pub fn from_trees(trees: Vec<Tree>, class_count: usize, dim: usize) -> Forest {
        Forest {
            trees,
            class_count,
            dim,
            out_of_bag: Vec::new(),
        }
    }

    pub fn trees(&self) -> &[Tree] {
        &self.trees
    }

    pub fn class_count(&self) -> usize {
        self.class_count
    }

    /// Number of features a row must have.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Class probabilities of `row`: the mean of the leaf histograms it
    /// reaches in every tree.
    pub fn predict(&self, row: &[f32]) -> Vec<f32> {
        let mut histogram = vec![0.0f32; self.class_count];
        for tree in &self.trees {
            for (h, &p) in histogram.iter_mut().zip(tree.histogram(row)) {
                *h += p;
            }
        }
        let n = self.trees.len().max(1) as f32;
        histogram.iter_mut().for_each(|h| *h /= n);
        histogram
    }

    /// Like [`Forest::predict`] for training sample `sample` of the forest's
    /// training set, but averaged only over the trees that did not see it
    /// (out-of-bag), which estimates how the forest treats unseen clips.
    /// Falls back to all trees when every tree saw the sample or the forest
    /// was loaded from a file (the bookkeeping is not stored).
    pub fn predict_out_of_bag(&self, row: &[f32], sample: usize) -> Vec<f32> {
        match self.out_of_bag.get(sample) {
            Some(trees) if !trees.is_empty() => {
                let mut histogram = vec![0.0f32; self.class_count];
                for &t in trees {
                    for (h, &p) in histogram
                        .iter_mut()
                        .zip(self.trees[t as usize].histogram(row))
                    {
                        *h += p;
                    }
                }
                let n = trees.len() as f32;
                histogram.iter_mut().for_each(|h| *h /= n);
                histogram
            }
            _ => self.predict(row),
        }
    }

    /// The leaf reached in every tree.
    pub fn leaves(&self, row: &[f32]) -> Vec<u32> {
        self.trees.iter().map(|t| t.leaf(row)).collect()
    }

    /// Forest proximity of two clips from the leaves they reach: for each
    /// tree, the depth of the deepest node on both root-to-leaf paths divided
    /// by the depth of the deeper leaf (1 when both reach the same leaf),
    /// averaged over the trees. It grades how long two clips travel
    /// together, which still separates clips that end in different leaves,
    /// e.g. clips of a class the forest was never trained on.
    pub fn path_proximity(&self, a: &[u32], b: &[u32]) -> f32 {
        let mut sum = 0.0f32;
        for ((tree, &la), &lb) in self.trees.iter().zip(a).zip(b) {
            let (mut x, mut y) = (la, lb);
            let deeper = tree.node_depth(x).max(tree.node_depth(y)).max(1);
            // Walk the deeper node up until both meet.
            while x != y {
                if tree.node_depth(x) >= tree.node_depth(y) {
                    x = tree.parent(x).unwrap_or(0);
                } else {
                    y = tree.parent(y).unwrap_or(0);
                }
            }
            sum += tree.node_depth(x) as f32 / deeper as f32;
        }
        sum / self.trees.len().max(1) as f32
    }

    /// Whether the trees fit the forest's class count and feature count.
    pub fn is_consistent(&self) -> bool {
        !self.trees.is_empty()
            && self
                .trees
                .iter()
                .all(|t| t.is_consistent(self.class_count, self.dim))
    }
}

/// Index of the largest value (the first one on ties).
pub fn argmax(values: &[f32]) -> usize {
    let mut best = 0;
    for (k, &v) in values.iter().enumerate() {
        if v > values[best] {
            best = k;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entropy_of_known_histograms() {
        assert_eq!(entropy(&[4, 0]), 0.0);
        assert!((entropy(&[2, 2]) - 1.0).abs() < 1e-12);
        assert!((entropy(&[1, 1, 1, 1]) - 2.0).abs() < 1e-12);
        // 3/4 and 1/4: 0.811278 bits.
        assert!((entropy(&[3, 1]) - 0.811_278_124_459_132_6).abs() < 1e-12);
    }

    /// Two features: the first is noise, the second separates the classes
    /// at 0.5. The deterministic tree must split on the second one, at a
    /// threshold between the classes, with gain 1 bit.
    #[test]
    fn deterministic_tree_finds_the_informative_feature() {
        let rows = vec![
            0.9, 0.1, //
            0.1, 0.2, //
            0.5, 0.3, //
            0.3, 0.7, //
            0.8, 0.8, //
            0.2, 0.9,
        ];
        let labels = vec![0, 0, 0, 1, 1, 1];
        let samples = Samples::new(&rows, 2, &labels, 2).unwrap();
        let tree = Tree::train_deterministic(&samples, &TreeConfig::default());
        match &tree.nodes()[0] {
            Node::Split {
                feature, threshold, ..
            } => {
                assert_eq!(*feature, 1);
                assert!(*threshold > 0.3 && *threshold < 0.7, "{threshold}");
            }
            other => panic!("root should split, got {other:?}"),
        }
        assert_eq!(tree.leaf_count(), 2);
        assert_eq!(tree.histogram(&[0.0, 0.0]), &[1.0, 0.0]);
        assert_eq!(tree.histogram(&[0.0, 1.0]), &[0.0, 1.0]);
    }

    /// The sweep's constant-time gain must equal eq. 7 computed directly.
    #[test]
    fn sweep_gain_matches_direct_formula() {
        let rows: Vec<f32> = vec![0.1, 0.4, 0.35, 0.8, 0.6, 0.2, 0.9];
        let labels = vec![0, 1, 0, 2, 1, 0, 2];
        let samples = Samples::new(&rows, 1, &labels, 3).unwrap();
        let subset: Vec<u32> = (0..7).collect();
        let config = TreeConfig {
            candidates_per_node: None,
            ..TreeConfig::default()
        };
        let grower = Grower {
            samples: &samples,
            config: &config,
            tree: Tree {
                nodes: vec![],
                parents: vec![],
                depths: vec![],
            },
            xlogx: xlogx_table(7),
        };
        let counts = grower.counts(&subset);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(0);
        let best = grower.best_split(&subset, &counts, &mut rng).unwrap();
        // Direct: try every threshold between sorted values.
        let mut sorted = rows.clone();
        sorted.sort_by(f32::total_cmp);
        let mut best_direct = 0.0f64;
        for w in sorted.windows(2) {
            let s = (w[0] + w[1]) / 2.0;
            let mut l = [0u32; 3];
            let mut r = [0u32; 3];
            for (v, &c) in rows.iter().zip(&labels) {
                if *v < s {
                    l[c as usize] += 1
                } else {
                    r[c as usize] += 1
                }
            }
            let (nl, nr) = (l.iter().sum::<u32>() as f64, r.iter().sum::<u32>() as f64);
            let g = entropy(&counts) - nl / 7.0 * entropy(&l) - nr / 7.0 * entropy(&r);
            best_direct = best_direct.max(g);
        }
        assert!(
            (best.gain - best_direct).abs() < 1e-9,
            "{} vs {best_direct}",
            best.gain
        );
    }

    #[test]
    fn forest_is_reproducible_and_separates_clusters() {
        // Class k lies around k on feature 3 of 6; the rest is noise.
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let mut rows = Vec::new();
        let mut labels = Vec::new();
        for s in 0..90u32 {
            let class = s % 3;
            for f in 0..6 {
                let noise: f32 = rng.random_range(-0.3..0.3);
                rows.push(if f == 3 {
                    class as f32 + noise
                } else {
                    noise * 3.0
                });
            }
            labels.push(class);
        }
        let samples = Samples::new(&rows, 6, &labels, 3).unwrap();
        let config = ForestConfig {
            trees: 10,
            tree: TreeConfig {
                candidates_per_node: Some(2),
                ..TreeConfig::default()
            },
            ..ForestConfig::default()
        };
        let a = Forest::train(&samples, &config, &|| {});
        let b = Forest::train(&samples, &config, &|| {});
        assert_eq!(a, b, "same seed, same forest");
        assert!(a.is_consistent());
        for class in 0..3 {
            let row = [0.0, 0.0, 0.0, class as f32, 0.0, 0.0];
            let p = a.predict(&row);
            assert!((p.iter().sum::<f32>() - 1.0).abs() < 1e-5);
            assert_eq!(argmax(&p), class);
        }
        let leaves = a.leaves(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(a.path_proximity(&leaves, &leaves), 1.0);
        let other = a.leaves(&[0.0, 0.0, 0.0, 2.0, 0.0, 0.0]);
        assert!(a.path_proximity(&leaves, &other) < 1.0);
    }

    #[test]
    fn bad_shapes_are_errors() {
        assert!(Samples::new(&[1.0, 2.0, 3.0], 2, &[0, 1], 2).is_err());
        assert!(Samples::new(&[1.0, 2.0], 1, &[0, 2], 2).is_err());
        assert!(Samples::new(&[], 1, &[], 2).is_err());
    }
}
