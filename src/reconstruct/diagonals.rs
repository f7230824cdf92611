//! Symmetric sparse matrices stored by diagonals. A consistent mass matrix couples two DOFs
//! only when one point's stencil holds both, so on a tensor-product grid its nonzeros lie
//! on a few diagonals i - j = d (0, 1, n - 1, n, n + 1 for the bilinear hat on rows of n
//! nodes) spread over a band as wide as a grid row: storing the diagonals that occur keeps
//! the memory and a product at the stencil's size instead of the band's.

/// A symmetric matrix of order `n`: the lower triangle's diagonals d = i - j that received
/// an entry, each stored whole.
#[derive(Clone, Debug, Default)]
pub struct SymmetricDiagonals {
    n: usize,
    /// Per distance d <= the widest one given to `reset`, the index of its stored diagonal.
    slot: Vec<u32>,
    /// Distance d of each stored diagonal.
    distances: Vec<usize>,
    /// Stored diagonal s holds A[i][i - d] at `values[s * n + i]` (zero for i < d).
    values: Vec<f64>,
}

const UNUSED: u32 = u32::MAX;

impl SymmetricDiagonals {
    /// Makes this the zero matrix of order `n` whose entries are at most `bandwidth` off the
    /// diagonal, reusing the storage.
    pub fn reset(&mut self, n: usize, bandwidth: usize) {
        self.n = n;
        self.slot.clear();
        self.slot.resize(bandwidth + 1, UNUSED);
        self.distances.clear();
        self.values.clear();
    }

    pub fn order(&self) -> usize {
        self.n
    }

    /// The largest distance of a stored diagonal from the main one.
    pub fn bandwidth(&self) -> usize {
        self.distances.iter().copied().max().unwrap_or(0)
    }

    /// The distances d = i - j of the stored diagonals, in the order they were first given.
    pub fn distances(&self) -> &[usize] {
        &self.distances
    }

    /// Stored entries per row: the main diagonal and each off-diagonal on both sides.
    pub fn entries_per_row(&self) -> usize {
        self.distances
            .iter()
            .map(|&d| if d == 0 { 1 } else { 2 })
            .sum()
    }

    /// Adds `value` to entry (i, j) and, by symmetry, (j, i); `i` and `j` in either order.
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, value: f64) {
        let (row, d) = if i >= j { (i, i - j) } else { (j, j - i) };
        let mut s = self.slot[d];
        if s == UNUSED {
            s = self.distances.len() as u32;
            self.slot[d] = s;
            self.distances.push(d);
            self.values.resize(self.values.len() + self.n, 0.0);
        }
        self.values[s as usize * self.n + row] += value;
    }

    /// Where entry (i, j) is stored (`i` and `j` in either order), for `stored_value` and
    /// `store`; None off the stored diagonals.
    #[inline]
    pub fn position(&self, i: usize, j: usize) -> Option<usize> {
        let (row, d) = if i >= j { (i, i - j) } else { (j, j - i) };
        match self.slot.get(d) {
            Some(&s) if s != UNUSED => Some(s as usize * self.n + row),
            _ => None,
        }
    }

    /// The entry at a `position`.
    #[inline]
    pub fn stored_value(&self, position: usize) -> f64 {
        self.values[position]
    }

    /// Sets the entry at a `position` (and its symmetric twin) to `value`.
    #[inline]
    pub fn store(&mut self, position: usize, value: f64) {
        self.values[position] = value;
    }

    /// Entry (i, j), `i` and `j` in either order; zero off the stored diagonals.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.position(i, j).map_or(0.0, |at| self.values[at])
    }

    /// The stored diagonals of the lower triangle in the order of `distances`: each distance d
    /// with its values, A[i][i - d] at index i (zero for i < d).
    pub fn diagonals(&self) -> impl Iterator<Item = (usize, &[f64])> {
        let n = self.n.max(1);
        self.distances
            .iter()
            .copied()
            .zip(self.values.chunks_exact(n))
    }

    /// y = A x.
    pub fn multiply(&self, x: &[f64], y: &mut [f64]) {
        let n = self.n;
        y[..n].fill(0.0);
        for (s, &d) in self.distances.iter().enumerate() {
            let diagonal = &self.values[s * n..(s + 1) * n];
            if d == 0 {
                for ((y, &a), &x) in y[..n].iter_mut().zip(diagonal).zip(&x[..n]) {
                    *y += a * x;
                }
                continue;
            }
            // The lower triangle's terms, then the upper's: each y_i still receives its two
            // terms of this diagonal in that order, and neither loop reads what it writes, so
            // both vectorise (one loop with both chained y_i to y_{i-d}).
            for ((y, &a), &x) in y[d..n].iter_mut().zip(&diagonal[d..]).zip(&x[..n - d]) {
                *y += a * x;
            }
            for ((y, &a), &x) in y[..n - d].iter_mut().zip(&diagonal[d..]).zip(&x[d..n]) {
                *y += a * x;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    #[test]
    fn products_and_entries_match_a_dense_matrix() {
        let n = 23;
        let mut rng = crate::rng::Lcg::new(3);
        let mut sparse = SymmetricDiagonals::default();
        sparse.reset(n, 9);
        let mut dense = DMatrix::<f64>::zeros(n, n);
        for _ in 0..200 {
            let i = (rng.unit() * n as f64) as usize % n;
            let d = [0, 1, 5, 6, 9][(rng.unit() * 5.0) as usize % 5];
            let Some(j) = i.checked_sub(d) else { continue };
            let v = rng.unit() - 0.5;
            // Either order of the indices adds to the same symmetric pair.
            if rng.unit() < 0.5 {
                sparse.add(i, j, v);
            } else {
                sparse.add(j, i, v);
            }
            dense[(i, j)] += v;
            if i != j {
                dense[(j, i)] += v;
            }
        }
        for i in 0..n {
            for j in 0..n {
                assert_eq!(sparse.get(i, j), dense[(i, j)], "({i}, {j})");
            }
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).cos()).collect();
        let mut y = vec![f64::NAN; n];
        sparse.multiply(&x, &mut y);
        let expected = &dense * DVector::from_vec(x);
        for i in 0..n {
            assert!((y[i] - expected[i]).abs() < 1e-14, "row {i}");
        }
        assert_eq!(sparse.bandwidth(), 9);
        assert!(sparse.entries_per_row() <= 9);
    }
}
