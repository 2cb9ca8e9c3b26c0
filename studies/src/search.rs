//! Setup shared by the search studies (`studies/examples/search_*.rs`).

use rand::rngs::Xoshiro256PlusPlus;
use rand::seq::SliceRandom;
use rand::SeedableRng;

/// Training and test clips of one fold, as indices into the clip list.
#[derive(Debug, Clone)]
pub struct Fold {
    pub train: Vec<usize>,
    pub test: Vec<usize>,
}

/// The fold deal of `mocap search eval` (stratified `k`-fold by take), so
/// that a study's own classifiers are tested on the evaluation's folds: the
/// clips of every class, shuffled, are dealt to `k` folds, each class's
/// deal starting where the previous class's ended. `labels[i]` is clip
/// `i`'s class, below `classes`; folds with no test or no training clip are
/// left out.
pub fn stratified_folds(
    labels: &[u32],
    classes: usize,
    k: usize,
    seed: u64,
) -> Result<Vec<Fold>, String> {
    if k < 2 {
        return Err(format!("cross-validation needs at least 2 folds, got {k}"));
    }
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut fold_of = vec![0usize; labels.len()];
    let mut next = 0usize;
    for class in 0..classes as u32 {
        let mut members: Vec<usize> = (0..labels.len()).filter(|&i| labels[i] == class).collect();
        members.shuffle(&mut rng);
        for m in members {
            fold_of[m] = next % k;
            next += 1;
        }
    }
    Ok((0..k)
        .map(|f| Fold {
            train: (0..labels.len()).filter(|&i| fold_of[i] != f).collect(),
            test: (0..labels.len()).filter(|&i| fold_of[i] == f).collect(),
        })
        .filter(|f| !f.test.is_empty() && !f.train.is_empty())
        .collect())
}
