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
    /// Per DOF whether it is solved for.
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
        self.per_axis = p;
        self.solved.clear();
        self.solved.extend((0..n).map(&solved));
        let solved = &self.solved;
        // A stored diagonal also holds the zeros between DOFs of distant lines.
        let coupled = |i: usize, value: f64, d: usize| value != 0.0 && solved[i] && solved[i - d];
        let mut band = [0; 2];
        for (d, diagonal) in matrix.diagonals() {
            if (d..n).any(|i| coupled(i, diagonal[i], d)) {
                let step = LatticeStep::of(d, p);
                band[0] = band[0].max(step.along_0.unsigned_abs());
                band[1] = band[1].max(step.along_1);
            }
        }
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
        for (d, diagonal) in matrix.diagonals() {
            let step = LatticeStep::of(d, p);
            let (dx, dy) = (step.along_0, step.along_1 as isize);
            // The diagonal's pairs (i, j = i - d), each with its transposed numbers.
            let half = |offset: isize, value: f64| if offset == 0 { value } else { 0.5 * value };
            let pairs = (d..n).map(|i| (i, i - d)).zip(transposed_pairs(d, p, step));
            for ((i, j), (ti, tj)) in pairs {
                let value = diagonal[i];
                if !coupled(i, value, d) {
                    continue;
                }
                debug_assert_eq!(LatticeStep::between(i, j, p), step);
                // Row i's coupling to j lands on i's line at j's position along it, and row
                // j's on j's line at i's position; in transposed numbering for axis 1.
                along_0.add_offset(i, dx, half(dx, value));
                along_1.add_offset(ti, dy, half(dy, value));
                lumped[i] += value;
                if d != 0 {
                    along_0.add_offset(j, -dx, half(dx, value));
                    along_1.add_offset(tj, -dy, half(dy, value));
                    lumped[j] += value;
                }
            }
        }
        for i in (0..n).filter(|&i| !solved[i]) {
            let t = transposed(i, p);
            along_0.add(i, i, 1.0);
            along_1.add(t, t, 1.0);
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

/// The lattice step from DOF j to DOF i = j + d of a stored diagonal d: `along_0` on the first
/// axis (of either sign) and `along_1` on the second. A stencil is a box of a few nodes per axis
/// that never wraps from one end of a grid row to the next, so every coupled pair of a
/// diagonal is the same step, the one with |along_0| under half a row.
#[derive(Clone, Copy, Debug, PartialEq)]
struct LatticeStep {
    along_0: isize,
    along_1: usize,
}

impl LatticeStep {
    fn of(d: usize, p: usize) -> Self {
        let along_1 = (d + p / 2) / p;
        LatticeStep {
            along_0: d as isize - (p * along_1) as isize,
            along_1,
        }
    }

    fn between(i: usize, j: usize, p: usize) -> Self {
        LatticeStep {
            along_0: (i % p) as isize - (j % p) as isize,
            along_1: i / p - j / p,
        }
    }
}

/// DOF i's number with the axes swapped (second axis fastest).
fn transposed(i: usize, p: usize) -> usize {
    i / p + p * (i % p)
}

/// For i = d, d + 1, ... the transposed numbers of i and of j = i - d, counted along: t_i
/// steps by p within a row of the lattice and starts the next row at its index; t_j is t_i
/// less the transposed step, valid where (i, j) is the diagonal's lattice step.
fn transposed_pairs(d: usize, p: usize, step: LatticeStep) -> impl Iterator<Item = (usize, usize)> {
    let back = step.along_1 as isize + p as isize * step.along_0;
    let (mut x, mut t) = (d % p, transposed(d, p));
    std::iter::from_fn(move || {
        let pair = (t, t.wrapping_add_signed(-back));
        x += 1;
        t += p;
        if x == p {
            x = 0;
            t = t + 1 - p * p;
        }
        Some(pair)
    })
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

    /// The transposed numbers counted along a diagonal are those of i and i - d wherever the
    /// pair is the diagonal's lattice step.
    #[test]
    fn counts_the_transposed_numbers_along_a_diagonal() {
        let p = 7;
        for d in 0..3 * p {
            let step = LatticeStep::of(d, p);
            for (i, (ti, tj)) in (d..p * p).zip(transposed_pairs(d, p, step)) {
                assert_eq!(ti, transposed(i, p));
                if LatticeStep::between(i, i - d, p) == step {
                    assert_eq!(tj, transposed(i - d, p), "d {d}, i {i}");
                }
            }
        }
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
