//! Symmetric positive definite band matrices: the consistent mass matrix of a transfer, whose
//! bandwidth is fixed by the basis support, factorised by Cholesky in band storage.

/// Blocks that `BandMatrix::solve_blocks` substitutes side by side.
const LANES: usize = 4;

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

    /// Adds `value` to entry (i, i - offset) and, by symmetry, (i - offset, i), for an offset
    /// of either sign within the band.
    #[inline]
    pub fn add_offset(&mut self, i: usize, offset: isize, value: f64) {
        let row = if offset < 0 {
            i + offset.unsigned_abs()
        } else {
            i
        };
        let k = row * (self.bandwidth + 1) + self.bandwidth - offset.unsigned_abs();
        self.band[k] += value;
    }

    /// Overwrites the matrix with its Cholesky factor L (A = L L^T), in place. Right-looking:
    /// once column k of L is known it is subtracted from the trailing block, so every entry
    /// receives its terms L_ik L_jk in ascending k, as the dot products of the textbook
    /// left-looking form subtract them (the same bits), but the updates of one row are
    /// independent and contiguous instead of one dependent chain.
    pub fn factor(&mut self) -> Result<(), NotPositiveDefinite> {
        let b = self.bandwidth;
        let mut column = vec![0.0; b];
        for k in 0..self.n {
            let kk = self.at(k, k);
            let pivot = self.band[kk];
            // Written so that a NaN pivot fails too.
            if pivot.is_nan() || pivot <= 0.0 {
                return Err(NotPositiveDefinite { row: k, pivot });
            }
            let l_kk = pivot.sqrt();
            self.band[kk] = l_kk;
            let last = (k + b).min(self.n - 1);
            for i in k + 1..=last {
                let at = self.at(i, k);
                self.band[at] /= l_kk;
                column[i - k - 1] = self.band[at];
            }
            for i in k + 1..=last {
                let l_ik = column[i - k - 1];
                let row = self.at(i, k + 1)..=self.at(i, i);
                for (a, &l_jk) in self.band[row].iter_mut().zip(&column[..i - k]) {
                    *a -= l_ik * l_jk;
                }
            }
        }
        Ok(())
    }

    /// Solves A x = rhs in place with the factor of `factor`. The forward substitution runs
    /// by columns (each x_k subtracted from the rows below once known, in ascending k as the
    /// row-wise sums take them), so that rows overlap instead of waiting on each other.
    pub fn solve(&self, rhs: &mut [f64]) {
        let b = self.bandwidth;
        for k in 0..self.n {
            let x_k = rhs[k] / self.get(k, k);
            rhs[k] = x_k;
            for i in k + 1..(k + b + 1).min(self.n) {
                rhs[i] -= self.get(i, k) * x_k;
            }
        }
        for i in (0..self.n).rev() {
            let mut sum = rhs[i];
            for k in i + 1..(i + b + 1).min(self.n) {
                sum -= self.get(k, i) * rhs[k];
            }
            rhs[i] = sum / self.get(i, i);
        }
    }

    /// `solve` for a matrix whose entries outside diagonal blocks of `block` rows are zero
    /// (`n` a multiple of `block`), as the line sums' are: each block gets `solve`'s arithmetic,
    /// the zero terms between blocks left out. `LANES` blocks are substituted side by side:
    /// each substitution is a chain of dependent divisions, and one chain alone leaves the
    /// processor waiting on it. Bandwidths above 3 (no line sum of the bases here) take `solve`.
    pub fn solve_blocks(&self, rhs: &mut [f64], block: usize) {
        match self.bandwidth {
            0 => self.solve_blocks_with::<0>(rhs, block),
            1 => self.solve_blocks_with::<1>(rhs, block),
            2 => self.solve_blocks_with::<2>(rhs, block),
            3 => self.solve_blocks_with::<3>(rhs, block),
            _ => self.solve(rhs),
        }
    }

    /// `solve_blocks` with the bandwidth `B` a constant, so that the loops over the band
    /// unroll.
    fn solve_blocks_with<const B: usize>(&self, rhs: &mut [f64], block: usize) {
        debug_assert_eq!(self.bandwidth, B);
        debug_assert!(block > 0 && self.n.is_multiple_of(block));
        // An empty matrix has no blocks, whatever `block` says.
        let blocks = self.n.checked_div(block).unwrap_or(0);
        // L_(j+t)j = band[j (B + 1) + B + t B], as `at` places it; t = 0 is the diagonal.
        let entry = |j: usize, t: usize| self.band[j * (B + 1) + B + t * B];
        // Rows more than B from a block's end reach B entries ahead, a constant, so their
        // loops over the band unroll without tests.
        let interior = block.saturating_sub(B);
        for group in (0..blocks).step_by(LANES) {
            let lanes = (group + LANES).min(blocks) - group;
            let forward = |rhs: &mut [f64], k: usize, reach: usize| {
                for lane in 0..lanes {
                    let row = (group + lane) * block + k;
                    let x_k = rhs[row] / entry(row, 0);
                    rhs[row] = x_k;
                    for t in 1..=reach {
                        rhs[row + t] -= entry(row, t) * x_k;
                    }
                }
            };
            for k in 0..interior {
                forward(rhs, k, B);
            }
            for k in interior..block {
                forward(rhs, k, block - 1 - k);
            }
            let back = |rhs: &mut [f64], k: usize, reach: usize| {
                for lane in 0..lanes {
                    let i = (group + lane) * block + k;
                    let mut sum = rhs[i];
                    for t in 1..=reach {
                        sum -= entry(i, t) * rhs[i + t];
                    }
                    rhs[i] = sum / entry(i, 0);
                }
            };
            for k in (interior..block).rev() {
                back(rhs, k, block - 1 - k);
            }
            for k in (0..interior).rev() {
                back(rhs, k, B);
            }
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

    /// On a block-diagonal band matrix (blocks of 9 rows, 1 to 2 LANES of them and a
    /// remainder; blocks as short as the band or shorter, with no interior rows) the block
    /// solve gives `solve`'s numbers to the last bit.
    #[test]
    fn block_solve_matches_the_solve() {
        let cases = [
            (1, 2, 9),
            (3, 1, 9),
            (4, 2, 9),
            (9, 2, 9),
            (11, 3, 9),
            (5, 0, 9),
            (6, 4, 9),
        ];
        let short = [(5, 2, 2), (6, 3, 3), (7, 3, 1), (5, 1, 2)];
        for (blocks, b, block) in cases.into_iter().chain(short) {
            let n = block * blocks;
            let (sampled, _) = sample(n, b);
            let mut band = BandMatrix::default();
            band.reset(n, b);
            for i in 0..n {
                for j in i.saturating_sub(b)..=i {
                    if i / block == j / block {
                        band.add(i, j, sampled.get(i, j));
                    }
                }
            }
            band.factor().unwrap();
            let rhs: Vec<f64> = (0..n).map(|i| (i as f64).cos() - 0.3).collect();
            let (mut by_rows, mut by_blocks) = (rhs.clone(), rhs);
            band.solve(&mut by_rows);
            band.solve_blocks(&mut by_blocks, block);
            let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(&by_rows),
                bits(&by_blocks),
                "{blocks} blocks of {block}, band {b}"
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
