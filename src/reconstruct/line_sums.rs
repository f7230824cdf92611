//! A preconditioner for the conjugate gradients of a consistent mass matrix on a square 2D
//! lattice of DOFs (first axis fastest): M's couplings summed onto the grid lines of each axis
//! and solved line by line. For a Kronecker product M = rho A (x) B (constant density, a
//! tensor-product basis) the line sums are M_0 = rho A (x) L_B and M_1 = rho L_A (x) B, with L
//! the row sums, so M_0^-1 L M_1^-1 = M_1^-1 L M_0^-1 = M^-1. The preconditioner is the mean of
//! the two orders, which is symmetric. Where the density varies slowly it stays close to M^-1,
//! and the iterations drop from the lumped preconditioner's tens to a few (docs/NOTES.md).

use super::banded::{BandMatrix, NotPositiveDefinite};
use super::diagonals::SymmetricDiagonals;

#[derive(Clone, Debug, Default)]
pub struct LineSums {
    per_axis: usize,
    /// The line sums along axis 0 in DOF order and along axis 1 in transposed order (second
    /// axis fastest), each a band matrix whose blocks are the lines; identity rows at the DOFs
    /// not solved for. Factorised.
    along: [BandMatrix; 2],
    /// Row sums of M over the DOFs solved for, zero elsewhere.
    lumped: Vec<f64>,
    /// Per DOF its lattice coordinates, and whether it is solved for.
    coords: Vec<[usize; 2]>,
    solved: Vec<bool>,
    scratch: [Vec<f64>; 3],
}

impl LineSums {
    /// The line sums of `matrix` restricted to the DOFs where `solved` holds, factorised;
    /// `Ok(false)` without them where no DOF couples beyond its neighbours along an axis (the
    /// hat's values): there the lumped preconditioner is within a factor of 9 of M in 2D (the
    /// 1D symbols (4 + 2 cos t) / 6, one per axis), and a solve needs fewer instructions with
    /// it than with the line sums (docs/NOTES.md). The quadratic B-spline's lumped mass is
    /// within 56 of M ((66 + 52 cos t + 2 cos 2t) / 120), and its lines pay.
    pub fn prepare(
        &mut self,
        matrix: &SymmetricDiagonals,
        per_axis: usize,
        solved: impl Fn(usize) -> bool,
    ) -> Result<bool, NotPositiveDefinite> {
        let n = matrix.order();
        debug_assert_eq!(n, per_axis * per_axis);
        let p = per_axis;
        // Diagonals only at a lattice step (d = 0, 1, p - 1, p, p + 1) couple neighbours, or
        // the two ends of a row, which no stencil on a grid without wrap-around reaches: the
        // hat's pattern, told without a pass over the entries.
        let neighbours = [0, 1, p.saturating_sub(1), p, p + 1];
        if matrix.distances().iter().all(|d| neighbours.contains(d)) {
            return Ok(false);
        }
        if self.per_axis != p || self.coords.len() != n {
            self.per_axis = p;
            self.coords = (0..n).map(|i| [i % p, i / p]).collect();
        }
        self.solved.clear();
        self.solved.extend((0..n).map(&solved));
        let (coords, solved) = (&self.coords, &self.solved);
        // A stored diagonal also holds the zeros between DOFs of distant lines.
        let coupled = |i: usize, j: usize, value: f64| value != 0.0 && solved[i] && solved[j];
        let mut band = [0; 2];
        matrix.for_each_lower(|i, j, value| {
            if coupled(i, j, value) {
                for (b, (ci, cj)) in band.iter_mut().zip(coords[i].iter().zip(&coords[j])) {
                    *b = (*b).max(ci.abs_diff(*cj));
                }
            }
        });
        if band.iter().all(|&b| b <= 1) {
            return Ok(false);
        }
        for (line, &b) in self.along.iter_mut().zip(&band) {
            line.reset(n, b);
        }
        self.lumped.clear();
        self.lumped.resize(n, 0.0);
        let [along_0, along_1] = &mut self.along;
        let lumped = &mut self.lumped;
        matrix.for_each_lower(|i, j, value| {
            if !coupled(i, j, value) {
                return;
            }
            let ([ix, iy], [jx, jy]) = (coords[i], coords[j]);
            // Row i's coupling to j lands on i's line at j's position along it, and row j's
            // on j's line at i's position; in transposed numbering for axis 1.
            add_directed(along_0, i, jx + p * iy, value);
            add_directed(along_1, iy + p * ix, jy + p * ix, value);
            lumped[i] += value;
            if i != j {
                add_directed(along_0, j, ix + p * jy, value);
                add_directed(along_1, jy + p * jx, iy + p * jx, value);
                lumped[j] += value;
            }
        });
        for i in (0..n).filter(|&i| !solved[i]) {
            let [ix, iy] = coords[i];
            along_0.add(i, i, 1.0);
            along_1.add(iy + p * ix, iy + p * ix, 1.0);
        }
        along_0.factor()?;
        along_1.factor()?;
        for v in &mut self.scratch {
            v.clear();
            v.resize(n, 0.0);
        }
        Ok(true)
    }

    /// z = (M_0^-1 L M_1^-1 + M_1^-1 L M_0^-1) r / 2, zero off the DOFs solved for.
    pub fn apply(&mut self, r: &[f64], z: &mut [f64]) {
        let [first, second, transposed] = &mut self.scratch;
        let p = self.per_axis;
        // M_1^-1 L M_0^-1 r into `first`.
        first.copy_from_slice(r);
        self.along[0].solve_blocks(first, p);
        scale(first, &self.lumped);
        transpose(p, first, transposed);
        self.along[1].solve_blocks(transposed, p);
        transpose(p, transposed, first);
        // M_0^-1 L M_1^-1 r into `second`.
        transpose(p, r, transposed);
        self.along[1].solve_blocks(transposed, p);
        transpose(p, transposed, second);
        scale(second, &self.lumped);
        self.along[0].solve_blocks(second, p);
        for ((z, a), b) in z.iter_mut().zip(first.iter()).zip(second.iter()) {
            *z = 0.5 * (a + b);
        }
    }
}

/// Adds the entry (i, j) of a matrix that is not symmetric to the symmetric `band` as its
/// symmetric part: half to (i, j) and half to (j, i).
fn add_directed(band: &mut BandMatrix, i: usize, j: usize, value: f64) {
    band.add(i, j, if i == j { value } else { 0.5 * value });
}

fn scale(x: &mut [f64], by: &[f64]) {
    for (x, &s) in x.iter_mut().zip(by) {
        *x *= s;
    }
}

/// `to` = `from` with the two axes of the p x p lattice swapped.
fn transpose(p: usize, from: &[f64], to: &mut [f64]) {
    for (row, chunk) in from.chunks_exact(p).enumerate() {
        for (column, &value) in chunk.iter().enumerate() {
            to[row + p * column] = value;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The product with itself of a 1D mass matrix of the quadratic B-spline's interior
    /// stencil (1, 26, 66, 26, 1) / 120 on `p` DOFs, symmetrically scaled by a density per
    /// DOF.
    fn kronecker(p: usize, density: impl Fn(usize) -> f64) -> SymmetricDiagonals {
        let one_d = |a: usize, b: usize| -> f64 {
            match a.abs_diff(b) {
                0 => 66.0 / 120.0,
                1 => 26.0 / 120.0,
                2 => 1.0 / 120.0,
                _ => 0.0,
            }
        };
        let mut matrix = SymmetricDiagonals::default();
        matrix.reset(p * p, 2 * p + 2);
        for i in 0..p * p {
            for j in 0..=i {
                let (ix, iy, jx, jy) = (i % p, i / p, j % p, j / p);
                let value = one_d(ix, jx) * one_d(iy, jy);
                if value != 0.0 {
                    matrix.add(i, j, value * (density(i) * density(j)).sqrt());
                }
            }
        }
        matrix
    }

    /// With constant density and every DOF solved for, the preconditioner inverts the
    /// Kronecker product exactly.
    #[test]
    fn inverts_a_kronecker_product() {
        let p = 7;
        let matrix = kronecker(p, |_| 2.5);
        let mut lines = LineSums::default();
        assert!(lines.prepare(&matrix, p, |_| true).unwrap());
        let mut rng = crate::rng::Lcg::new(11);
        let x: Vec<f64> = (0..p * p).map(|_| rng.unit() - 0.5).collect();
        let mut b = vec![0.0; p * p];
        matrix.multiply(&x, &mut b);
        let mut z = vec![0.0; p * p];
        lines.apply(&b, &mut z);
        for (z, x) in z.iter().zip(&x) {
            assert!((z - x).abs() < 1e-12, "{z} against {x}");
        }
    }

    /// The preconditioner is symmetric and positive definite on a varying density with some
    /// DOFs left out, and zero on those.
    #[test]
    fn is_symmetric_positive_and_zero_off_the_dofs() {
        let p = 6;
        let matrix = kronecker(p, |i| 1.0 + 0.3 * (i as f64).sin());
        let solved = |i: usize| !i.is_multiple_of(p);
        let mut lines = LineSums::default();
        assert!(lines.prepare(&matrix, p, solved).unwrap());
        let n = p * p;
        let column = |lines: &mut LineSums, j: usize| {
            let mut e = vec![0.0; n];
            e[j] = 1.0;
            let mut z = vec![0.0; n];
            lines.apply(&e, &mut z);
            z
        };
        let columns: Vec<Vec<f64>> = (0..n).map(|j| column(&mut lines, j)).collect();
        for i in 0..n {
            for j in 0..n {
                assert!((columns[j][i] - columns[i][j]).abs() < 1e-12);
                if !solved(i) {
                    assert_eq!(columns[j][i], 0.0);
                }
            }
        }
        let dense = nalgebra::DMatrix::from_fn(n, n, |i, j| columns[j][i]);
        let eigenvalues = dense.symmetric_eigenvalues();
        let kept = (0..n).filter(|&i| solved(i)).count();
        assert_eq!(eigenvalues.iter().filter(|&&l| l > 1e-12).count(), kept);
        assert!(eigenvalues.iter().all(|&l| l > -1e-12));
    }

    /// A matrix whose DOFs couple only to their neighbours along each axis (the hat's) gets
    /// no line sums.
    #[test]
    fn leaves_the_hat_to_the_lumped_preconditioner() {
        let p = 5;
        let mut matrix = SymmetricDiagonals::default();
        matrix.reset(p * p, p + 1);
        for i in 0..p * p {
            matrix.add(i, i, 4.0);
            for j in [i.checked_sub(1), i.checked_sub(p), i.checked_sub(p + 1)]
                .into_iter()
                .flatten()
                .filter(|&j| (i % p).abs_diff(j % p) <= 1)
            {
                matrix.add(i, j, 1.0);
            }
        }
        assert!(!LineSums::default().prepare(&matrix, p, |_| true).unwrap());
    }
}
