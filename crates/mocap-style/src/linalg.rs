//! Whitening and colouring of latent vectors (mean and covariance
//! statistics, and the inverse square root and square root of a covariance
//! through its symmetric eigen-decomposition).

use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// Eigenvalues below this fraction of the largest are raised to it before
/// inverting: latent channels that a clip never uses (ReLU units at zero)
/// have no variance, and whitening must not divide by zero.
const RELATIVE_FLOOR: f64 = 1e-4;

/// Mean and covariance of a set of vectors, with the matrices that whiten
/// (`C^-1/2`) and colour (`C^1/2`) with them.
#[derive(Debug, Clone)]
pub struct Statistics {
    pub mean: DVector<f64>,
    /// `C^-1/2`: whitened vectors have identity covariance.
    pub whiten: DMatrix<f64>,
    /// `C^1/2`: coloured vectors have the covariance `C`.
    pub colour: DMatrix<f64>,
    /// Per-channel standard deviations (for the AdaIN-like baseline).
    pub std: DVector<f64>,
}

impl Statistics {
    /// Statistics of `rows` vectors of `dim` numbers laid one after another.
    /// Needs at least one vector.
    pub fn of_rows<'a>(chunks: impl IntoIterator<Item = &'a [f32]>, dim: usize) -> Statistics {
        let rows: Vec<&[f32]> = chunks
            .into_iter()
            .flat_map(|c| c.chunks_exact(dim))
            .collect();
        let n = rows.len().max(1) as f64;
        let mut mean = DVector::<f64>::zeros(dim);
        for r in &rows {
            for (c, &x) in r.iter().enumerate() {
                mean[c] += x as f64;
            }
        }
        mean /= n;
        let mut cov = DMatrix::<f64>::zeros(dim, dim);
        let mut d = DVector::<f64>::zeros(dim);
        for r in &rows {
            for (c, &x) in r.iter().enumerate() {
                d[c] = x as f64 - mean[c];
            }
            cov.syger(1.0, &d, &d, 1.0);
        }
        cov /= n;
        // syger fills the lower triangle only.
        cov.fill_upper_triangle_with_lower_triangle();
        let std = DVector::from_iterator(dim, (0..dim).map(|c| cov[(c, c)].max(0.0).sqrt()));
        let eig = SymmetricEigen::new(cov);
        let largest = eig.eigenvalues.iter().copied().fold(0.0f64, f64::max);
        let floor = (largest * RELATIVE_FLOOR).max(1e-12);
        let values: Vec<f64> = eig.eigenvalues.iter().map(|&v| v.max(floor)).collect();
        let q = &eig.eigenvectors;
        let with = |f: &dyn Fn(f64) -> f64| {
            let diag =
                DMatrix::from_diagonal(&DVector::from_iterator(dim, values.iter().map(|&v| f(v))));
            q * diag * q.transpose()
        };
        Statistics {
            mean,
            whiten: with(&|v| 1.0 / v.sqrt()),
            colour: with(&|v| v.sqrt()),
            std,
        }
    }

    /// Whitens one vector: `C^-1/2 (x - mean)`.
    pub fn whiten(&self, x: &[f32], out: &mut [f32]) {
        apply(&self.whiten, x, Some(&self.mean), None, out);
    }

    /// Colours one whitened vector: `C^1/2 x + mean`.
    pub fn colour(&self, x: &[f32], out: &mut [f32]) {
        apply(&self.colour, x, None, Some(&self.mean), out);
    }
}

/// `out = m (x - sub) + add`.
fn apply(
    m: &DMatrix<f64>,
    x: &[f32],
    sub: Option<&DVector<f64>>,
    add: Option<&DVector<f64>>,
    out: &mut [f32],
) {
    let dim = x.len();
    for (r, o) in out.iter_mut().enumerate().take(dim) {
        let mut s = add.map_or(0.0, |a| a[r]);
        for (c, &v) in x.iter().enumerate() {
            let v = v as f64 - sub.map_or(0.0, |m| m[c]);
            s += m[(r, c)] * v;
        }
        *o = s as f32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whitened_vectors_have_identity_covariance_and_colouring_inverts() {
        // Correlated 3-D data.
        let mut data = Vec::new();
        for i in 0..500 {
            let a = ((i * 37 % 101) as f32 / 50.0) - 1.0;
            let b = ((i * 53 % 97) as f32 / 48.0) - 1.0;
            let c = ((i * 71 % 89) as f32 / 44.0) - 1.0;
            data.extend([a + 2.0, 0.5 * a + b, 3.0 * b - a + c + 1.0]);
        }
        let s = Statistics::of_rows([data.as_slice()], 3);
        let mut white = vec![0.0; data.len()];
        for (x, w) in data.chunks(3).zip(white.chunks_mut(3)) {
            s.whiten(x, w);
        }
        let w = Statistics::of_rows([white.as_slice()], 3);
        for r in 0..3 {
            assert!(w.mean[r].abs() < 1e-5);
            for c in 0..3 {
                let expected = if r == c { 1.0 } else { 0.0 };
                // C^1/2 of whitened data is the identity.
                let cov = w.colour[(r, c)];
                assert!((cov - expected).abs() < 1e-3, "({r},{c}) = {cov}");
            }
        }
        let mut back = [0.0f32; 3];
        s.colour(&white[..3], &mut back);
        for c in 0..3 {
            assert!((back[c] - data[c]).abs() < 1e-3);
        }
    }
}
