//! Symmetric positive definite band matrices: the consistent mass matrix of a transfer, whose
//! bandwidth is fixed by the basis support, factorised by Cholesky in band storage.

/// A symmetric matrix of order `n` with `bandwidth` sub-diagonals, the lower band stored row by
/// row (`bandwidth + 1` entries per row, the diagonal last).
#[derive(Clone, Debug, Default)]
pub struct BandMatrix {
    n: usize,
    bandwidth: usize,
    band: Vec<f64>,
}

/// The factorisation met a pivot that is not positive: the matrix is not positive definite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NotPositiveDefinite {
    /// Row of the failing pivot.
    pub row: usize,
    pub pivot: f64,
}

impl BandMatrix {
    /// Makes this the zero matrix of order `n`, reusing the storage.
    pub fn reset(&mut self, n: usize, bandwidth: usize) {
        self.n = n;
        self.bandwidth = bandwidth;
        self.band.clear();
        self.band.resize(n * (bandwidth + 1), 0.0);
    }

    #[inline]
    fn at(&self, i: usize, j: usize) -> usize {
        debug_assert!(j <= i && i - j <= self.bandwidth);
        i * (self.bandwidth + 1) + self.bandwidth + j - i
    }

    /// Entry (i, j) of the lower triangle (j <= i, within the band).
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.band[self.at(i, j)]
    }

    /// Adds `value` to entry (i, j) and, by symmetry, (j, i); `i` and `j` in either order.
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, value: f64) {
        let (row, col) = if i >= j { (i, j) } else { (j, i) };
        let k = self.at(row, col);
        self.band[k] += value;
    }

    /// Overwrites the matrix with its Cholesky factor L (A = L L^T), in place.
    pub fn factor(&mut self) -> Result<(), NotPositiveDefinite> {
        let b = self.bandwidth;
        for i in 0..self.n {
            let first = i.saturating_sub(b);
            for j in first..=i {
                let mut sum = self.get(i, j);
                // Rows i and j (j <= i) both hold entries k >= i - b = first.
                for k in first..j {
                    sum -= self.get(i, k) * self.get(j, k);
                }
                let entry = if j == i {
                    // Written so that a NaN pivot fails too.
                    if sum.is_nan() || sum <= 0.0 {
                        return Err(NotPositiveDefinite { row: i, pivot: sum });
                    }
                    sum.sqrt()
                } else {
                    sum / self.get(j, j)
                };
                let at = self.at(i, j);
                self.band[at] = entry;
            }
        }
        Ok(())
    }

    /// Solves A x = rhs in place with the factor of `factor`.
    pub fn solve(&self, rhs: &mut [f64]) {
        let b = self.bandwidth;
        for i in 0..self.n {
            let mut sum = rhs[i];
            for k in i.saturating_sub(b)..i {
                sum -= self.get(i, k) * rhs[k];
            }
            rhs[i] = sum / self.get(i, i);
        }
        for i in (0..self.n).rev() {
            let mut sum = rhs[i];
            for k in i + 1..(i + b + 1).min(self.n) {
                sum -= self.get(k, i) * rhs[k];
            }
            rhs[i] = sum / self.get(i, i);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// A random SPD band matrix: diagonally dominant with symmetric off-diagonals.
    fn sample(n: usize, b: usize) -> (BandMatrix, DMatrix<f64>) {
        let mut rng = crate::rng::Lcg::new(7);
        let mut band = BandMatrix::default();
        band.reset(n, b);
        let mut dense = DMatrix::zeros(n, n);
        for i in 0..n {
            for j in i.saturating_sub(b)..i {
                let v = rng.unit() - 0.5;
                band.add(i, j, v);
                dense[(i, j)] += v;
                dense[(j, i)] += v;
            }
            let d = 1.0 + 2.0 * b as f64 + rng.unit();
            band.add(i, i, d);
            dense[(i, i)] += d;
        }
        (band, dense)
    }

    #[test]
    fn solves_like_a_dense_factorisation() {
        for (n, b) in [(1, 0), (7, 1), (12, 2), (30, 7)] {
            let (mut band, dense) = sample(n, b);
            let rhs: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
            let mut x = rhs.clone();
            band.factor().unwrap();
            band.solve(&mut x);
            let residual =
                &dense * nalgebra::DVector::from_vec(x) - nalgebra::DVector::from_vec(rhs);
            assert!(
                residual.norm() < 1e-12,
                "n {n} b {b}: residual {}",
                residual.norm()
            );
        }
    }

    #[test]
    fn indefinite_matrices_are_reported() {
        let mut band = BandMatrix::default();
        band.reset(2, 1);
        band.add(0, 0, 1.0);
        band.add(1, 0, 2.0);
        band.add(1, 1, 1.0);
        assert_eq!(band.factor().unwrap_err().row, 1);
    }
}
