//! Preconditioned conjugate gradients for a consistent mass matrix restricted to a set of
//! DOFs, with the lumped mass (here) or the line sums (`line_sums.rs`) as the preconditioner.
//! For a basis that is nonnegative and a partition of unity the lumped matrix bounds the
//! consistent one from above, x^T M x <= x^T M_L x (Cauchy-Schwarz on sum_i N_i x_i), and
//! stays within a small factor of it from below on a mesh the material covers, so the
//! iteration count does not grow with the mesh, while a direct band factorisation costs a
//! grid row squared per DOF.

use super::diagonals::SymmetricDiagonals;

/// The solve stops when the preconditioned residual r^T P^-1 r has fallen by this factor
/// squared: about the accuracy of a direct factorisation of these well-conditioned
/// matrices, so that the change from one is round-off (docs/NOTES.md).
pub const RELATIVE_RESIDUAL: f64 = 1e-14;

/// More iterations than a matrix within the bounds above needs by an order of magnitude.
pub const MAX_ITERATIONS: usize = 1000;

/// Why a solve stopped without a solution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Breakdown {
    /// p^T M p was not positive: the matrix is not positive definite on the DOFs.
    NotPositiveDefinite(f64),
    /// The residual had not fallen by `RELATIVE_RESIDUAL` after `MAX_ITERATIONS`.
    NotConverged(f64),
}

/// Work vectors, kept between solves.
#[derive(Clone, Debug, Default)]
pub struct ConjugateGradients {
    x: Vec<f64>,
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
}

impl ConjugateGradients {
    /// Solves M x = b on the DOFs where the preconditioner `precondition(r, z)` (z = P^-1 r,
    /// symmetric and positive definite there) is nonzero, x zero elsewhere; `b` is
    /// overwritten with x. Returns the iterations taken.
    pub fn solve(
        &mut self,
        matrix: &SymmetricDiagonals,
        mut precondition: impl FnMut(&[f64], &mut [f64]),
        b: &mut [f64],
    ) -> Result<usize, Breakdown> {
        let n = matrix.order();
        for v in [
            &mut self.x,
            &mut self.r,
            &mut self.z,
            &mut self.p,
            &mut self.q,
        ] {
            v.clear();
            v.resize(n, 0.0);
        }
        // Entries off the DOFs never enter: z and so p, x are zero there.
        self.r.copy_from_slice(&b[..n]);
        precondition(&self.r, &mut self.z);
        self.p.copy_from_slice(&self.z);
        let mut rz = dot(&self.r, &self.z);
        if !rz.is_finite() {
            return Err(Breakdown::NotConverged(rz));
        }
        let target = rz * RELATIVE_RESIDUAL * RELATIVE_RESIDUAL;
        let mut iterations = 0;
        while rz > target {
            if iterations == MAX_ITERATIONS {
                return Err(Breakdown::NotConverged(
                    (rz / target).sqrt() * RELATIVE_RESIDUAL,
                ));
            }
            iterations += 1;
            matrix.multiply(&self.p, &mut self.q);
            let pq = dot(&self.p, &self.q);
            if pq.is_nan() || pq <= 0.0 {
                return Err(Breakdown::NotPositiveDefinite(pq));
            }
            let alpha = rz / pq;
            // Zipped rather than indexed: no bounds checks, so the updates vectorise.
            let updates = self.x.iter_mut().zip(&mut self.r).zip(&self.p).zip(&self.q);
            for (((x, r), &p), &q) in updates {
                *x += alpha * p;
                *r -= alpha * q;
            }
            precondition(&self.r, &mut self.z);
            let rz_new = dot(&self.r, &self.z);
            if !rz_new.is_finite() {
                return Err(Breakdown::NotConverged(rz_new));
            }
            let beta = rz_new / rz;
            for (p, &z) in self.p.iter_mut().zip(&self.z) {
                *p = z + beta * *p;
            }
            rz = rz_new;
        }
        b[..n].copy_from_slice(&self.x);
        Ok(iterations)
    }
}

/// The lumped preconditioner: z = M_L^-1 r with `inverse_lumped` zero off the DOFs.
pub fn precondition_lumped(inverse_lumped: &[f64], r: &[f64], z: &mut [f64]) {
    for ((z, &r), &w) in z.iter_mut().zip(r).zip(inverse_lumped) {
        *z = r * w;
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// The consistent mass matrix of the 1D hat on `n` nodes of unit spacing with one unit
    /// mass per cell at its centre, and its row sums.
    fn hat_mass(n: usize) -> (SymmetricDiagonals, Vec<f64>) {
        let mut matrix = SymmetricDiagonals::default();
        matrix.reset(n, 1);
        let mut lumped = vec![0.0; n];
        for cell in 0..n - 1 {
            let (a, b) = (cell, cell + 1);
            for (i, j, value) in [(a, a, 0.25), (b, b, 0.25), (b, a, 0.25)] {
                matrix.add(i, j, value);
            }
            lumped[a] += 0.5;
            lumped[b] += 0.5;
        }
        (matrix, lumped)
    }

    fn dense(matrix: &SymmetricDiagonals) -> DMatrix<f64> {
        let n = matrix.order();
        DMatrix::from_fn(n, n, |i, j| matrix.get(i, j))
    }

    /// The solution on the kept DOFs is that of the restricted dense system, to the
    /// tolerance; the others stay zero.
    #[test]
    fn solves_the_system_restricted_to_its_dofs() {
        let n = 40;
        let (mut matrix, lumped) = hat_mass(n);
        // A positive diagonal shift: one mass per cell at its centre alone is singular.
        for i in 0..n {
            matrix.add(i, i, 0.1);
        }
        let kept: Vec<bool> = (0..n).map(|i| i != 0 && i != 17).collect();
        let inverse: Vec<f64> = (0..n)
            .map(|i| if kept[i] { 1.0 / lumped[i] } else { 0.0 })
            .collect();
        let b: Vec<f64> = (0..n).map(|i| (0.3 * i as f64).sin() + 0.5).collect();
        let mut x = b.clone();
        let iterations = ConjugateGradients::default()
            .solve(&matrix, |r, z| precondition_lumped(&inverse, r, z), &mut x)
            .unwrap();
        assert!(iterations < 40, "{iterations} iterations");
        let index: Vec<usize> = (0..n).filter(|&i| kept[i]).collect();
        let full = dense(&matrix);
        let restricted =
            DMatrix::from_fn(index.len(), index.len(), |a, c| full[(index[a], index[c])]);
        let rhs = DVector::from_iterator(index.len(), index.iter().map(|&i| b[i]));
        let exact = restricted.cholesky().unwrap().solve(&rhs);
        for (a, &i) in index.iter().enumerate() {
            assert!((x[i] - exact[a]).abs() < 1e-12 * exact.amax(), "DOF {i}");
        }
        assert_eq!((x[0], x[17]), (0.0, 0.0));
    }

    #[test]
    fn a_zero_right_hand_side_takes_no_iteration() {
        let (matrix, lumped) = hat_mass(5);
        let inverse: Vec<f64> = lumped.iter().map(|m| 1.0 / m).collect();
        let mut x = vec![0.0; 5];
        let iterations = ConjugateGradients::default().solve(
            &matrix,
            |r, z| precondition_lumped(&inverse, r, z),
            &mut x,
        );
        assert_eq!(iterations, Ok(0));
    }

    #[test]
    fn indefinite_and_non_finite_systems_are_reported() {
        let mut matrix = SymmetricDiagonals::default();
        matrix.reset(2, 1);
        matrix.add(0, 0, 1.0);
        matrix.add(1, 1, -1.0);
        let mut x = vec![0.0, 1.0];
        let result = ConjugateGradients::default().solve(
            &matrix,
            |r, z| precondition_lumped(&[1.0, 1.0], r, z),
            &mut x,
        );
        assert!(
            matches!(result, Err(Breakdown::NotPositiveDefinite(_))),
            "{result:?}"
        );
        let mut x = vec![f64::NAN, 1.0];
        let result = ConjugateGradients::default().solve(
            &matrix,
            |r, z| precondition_lumped(&[1.0, 1.0], r, z),
            &mut x,
        );
        assert!(
            matches!(result, Err(Breakdown::NotConverged(_))),
            "{result:?}"
        );
    }
}
