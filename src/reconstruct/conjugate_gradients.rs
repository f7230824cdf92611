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

/// One right-hand side's work vectors, kept between solves.
#[derive(Clone, Debug, Default)]
struct Column {
    x: Vec<f64>,
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
}

/// Work vectors of the right-hand sides solved together, kept between solves.
#[derive(Clone, Debug, Default)]
pub struct ConjugateGradients {
    columns: Vec<Column>,
}

impl ConjugateGradients {
    /// Solves M x_c = b_c for C right-hand sides on the DOFs where the preconditioner
    /// `precondition(c, r, z)` (z = P_c^-1 r, symmetric and positive definite there) is
    /// nonzero, x_c zero elsewhere; each `b[c]` is overwritten with x_c. Returns each column's
    /// iterations. The columns run in lock step, each taking the steps and sums of a solve on
    /// its own in the same order, so its x_c is the same to the bit; their dot products run in
    /// one pass, where the chains of dependent additions overlap instead of following one
    /// another.
    pub fn solve_columns<const C: usize>(
        &mut self,
        matrix: &SymmetricDiagonals,
        mut precondition: impl FnMut(usize, &[f64], &mut [f64]),
        mut b: [&mut [f64]; C],
    ) -> [Result<usize, Breakdown>; C] {
        let n = matrix.order();
        self.columns.resize_with(C, Column::default);
        let columns = &mut self.columns[..C];
        for (c, (column, b)) in columns.iter_mut().zip(&b).enumerate() {
            for v in [
                &mut column.x,
                &mut column.r,
                &mut column.z,
                &mut column.p,
                &mut column.q,
            ] {
                v.clear();
                v.resize(n, 0.0);
            }
            // Entries off the DOFs never enter: z and so p, x are zero there.
            column.r.copy_from_slice(&b[..n]);
            precondition(c, &column.r, &mut column.z);
            column.p.copy_from_slice(&column.z);
        }
        let mut rz = dots::<C>(columns, |c| (&c.r, &c.z));
        // A column's outcome, once it has one; the others are still iterating.
        let mut outcome: [Option<Result<usize, Breakdown>>; C] = [None; C];
        let mut target = [0.0; C];
        for c in 0..C {
            if rz[c].is_finite() {
                target[c] = rz[c] * RELATIVE_RESIDUAL * RELATIVE_RESIDUAL;
            } else {
                outcome[c] = Some(Err(Breakdown::NotConverged(rz[c])));
            }
        }
        let mut iterations = [0; C];
        loop {
            // The columns that take this iteration.
            let mut stepping = [false; C];
            for c in 0..C {
                if outcome[c].is_some() {
                    continue;
                }
                if rz[c] <= target[c] {
                    outcome[c] = Some(Ok(iterations[c]));
                } else if iterations[c] == MAX_ITERATIONS {
                    let residual = (rz[c] / target[c]).sqrt() * RELATIVE_RESIDUAL;
                    outcome[c] = Some(Err(Breakdown::NotConverged(residual)));
                } else {
                    iterations[c] += 1;
                    matrix.multiply(&columns[c].p, &mut columns[c].q);
                    stepping[c] = true;
                }
            }
            if !stepping.contains(&true) {
                break;
            }
            // The finished columns' products come along unused: their chains overlap the
            // others' and cost about nothing.
            let pq = dots::<C>(columns, |c| (&c.p, &c.q));
            for c in 0..C {
                if !stepping[c] {
                    continue;
                }
                if pq[c].is_nan() || pq[c] <= 0.0 {
                    outcome[c] = Some(Err(Breakdown::NotPositiveDefinite(pq[c])));
                    stepping[c] = false;
                    continue;
                }
                let alpha = rz[c] / pq[c];
                let column = &mut columns[c];
                // Zipped rather than indexed: no bounds checks, so the updates vectorise.
                let updates = column.x.iter_mut().zip(&mut column.r);
                for ((x, r), (&p, &q)) in updates.zip(column.p.iter().zip(&column.q)) {
                    *x += alpha * p;
                    *r -= alpha * q;
                }
                precondition(c, &column.r, &mut column.z);
            }
            let rz_new = dots::<C>(columns, |c| (&c.r, &c.z));
            for c in 0..C {
                if !stepping[c] {
                    continue;
                }
                if !rz_new[c].is_finite() {
                    outcome[c] = Some(Err(Breakdown::NotConverged(rz_new[c])));
                    continue;
                }
                let beta = rz_new[c] / rz[c];
                let column = &mut columns[c];
                for (p, &z) in column.p.iter_mut().zip(&column.z) {
                    *p = z + beta * *p;
                }
                rz[c] = rz_new[c];
            }
        }
        std::array::from_fn(|c| {
            let result = outcome[c].expect("every column ends with an outcome");
            if result.is_ok() {
                b[c][..n].copy_from_slice(&columns[c].x);
            }
            result
        })
    }
}

/// The lumped preconditioner: z = M_L^-1 r with `inverse_lumped` zero off the DOFs.
pub fn precondition_lumped(inverse_lumped: &[f64], r: &[f64], z: &mut [f64]) {
    for ((z, &r), &w) in z.iter_mut().zip(r).zip(inverse_lumped) {
        *z = r * w;
    }
}

/// a_c . b_c for each column's pair of vectors `pair(column)`, in one pass. Each sum starts
/// from the value `Iterator::sum` starts from and adds its products in index order, as
/// `a.iter().zip(b).map(|(x, y)| x * y).sum()` does, to the bit.
fn dots<const C: usize>(
    columns: &[Column],
    pair: impl Fn(&Column) -> (&[f64], &[f64]),
) -> [f64; C] {
    let pairs: [(&[f64], &[f64]); C] = std::array::from_fn(|c| {
        let (a, b) = pair(&columns[c]);
        (a, &b[..a.len()])
    });
    let mut sums = [std::iter::empty::<f64>().sum::<f64>(); C];
    let n = pairs.first().map_or(0, |(a, _)| a.len());
    for i in 0..n {
        for (sum, (a, b)) in sums.iter_mut().zip(&pairs) {
            *sum += a[i] * b[i];
        }
    }
    sums
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    impl ConjugateGradients {
        /// One right-hand side.
        fn solve(
            &mut self,
            matrix: &SymmetricDiagonals,
            mut precondition: impl FnMut(&[f64], &mut [f64]),
            b: &mut [f64],
        ) -> Result<usize, Breakdown> {
            let [result] = self.solve_columns(matrix, |_, r, z| precondition(r, z), [b]);
            result
        }
    }

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

    /// Columns solved together give each column's x and iteration count to the bit, whatever
    /// the others do: here one converges in fewer iterations than the other, and one breaks
    /// down.
    #[test]
    fn columns_solved_together_match_each_solved_alone() {
        let n = 30;
        let (mut matrix, lumped) = hat_mass(n);
        for i in 0..n {
            matrix.add(i, i, 0.05 * (1.0 + (i % 3) as f64));
        }
        let inverse: Vec<f64> = lumped.iter().map(|m| 1.0 / m).collect();
        // The second column's preconditioner is the lumped one on every other DOF only.
        let sparse: Vec<f64> = (0..n)
            .map(|i| if i % 2 == 0 { inverse[i] } else { 0.0 })
            .collect();
        let precondition = |c: usize, r: &[f64], z: &mut [f64]| {
            precondition_lumped(if c == 0 { &inverse } else { &sparse }, r, z)
        };
        let b0: Vec<f64> = (0..n).map(|i| (0.7 * i as f64).cos()).collect();
        let b1: Vec<f64> = (0..n).map(|i| 0.3 * (i % 5) as f64).collect();
        let alone: Vec<(Vec<f64>, Result<usize, Breakdown>)> = [&b0, &b1]
            .iter()
            .enumerate()
            .map(|(c, b)| {
                let mut x = b.to_vec();
                let result = ConjugateGradients::default().solve(
                    &matrix,
                    |r, z| precondition(c, r, z),
                    &mut x,
                );
                (x, result)
            })
            .collect();
        assert_ne!(
            alone[0].1, alone[1].1,
            "the columns should differ in iterations"
        );
        let (mut x0, mut x1) = (b0.clone(), b1.clone());
        let together = ConjugateGradients::default().solve_columns(
            &matrix,
            precondition,
            [&mut x0[..], &mut x1[..]],
        );
        for (c, x) in [x0, x1].iter().enumerate() {
            assert_eq!(together[c], alone[c].1, "column {c}");
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(x), bits(&alone[c].0), "column {c}");
        }
        // A column that breaks down leaves the other's solution as it is alone.
        let mut indefinite = SymmetricDiagonals::default();
        indefinite.reset(2, 1);
        indefinite.add(0, 0, 1.0);
        indefinite.add(1, 1, -1.0);
        let (mut y0, mut y1) = (vec![1.0, 0.0], vec![0.0, 1.0]);
        let ones = [1.0, 1.0];
        let [first, second] = ConjugateGradients::default().solve_columns(
            &indefinite,
            |_, r, z| precondition_lumped(&ones, r, z),
            [&mut y0[..], &mut y1[..]],
        );
        assert_eq!(first, Ok(1));
        assert_eq!(y0, [1.0, 0.0]);
        assert!(
            matches!(second, Err(Breakdown::NotPositiveDefinite(_))),
            "{second:?}"
        );
    }

    /// `dots` sums as `Iterator::sum` does, from its starting value: a sum of negative zeros
    /// keeps the sign it gets there.
    #[test]
    fn dots_match_the_iterator_sum_to_the_bit() {
        let column = |a: Vec<f64>, b: Vec<f64>| Column {
            x: a,
            r: b,
            ..Column::default()
        };
        let columns = [
            column(vec![-0.0, -0.0], vec![1.0, 2.0]),
            column(vec![0.1, 0.2, 0.3], vec![3.0, -1.0, 7.0]),
        ];
        let sums = dots::<1>(&columns[..1], |c| (&c.x, &c.r));
        let expected: f64 = [-0.0f64, -0.0].iter().map(|x| x * 1.0).sum();
        assert_eq!(sums[0].to_bits(), expected.to_bits());
        let sums = dots::<1>(&columns[1..], |c| (&c.x, &c.r));
        let expected: f64 = columns[1]
            .x
            .iter()
            .zip(&columns[1].r)
            .map(|(x, y)| x * y)
            .sum();
        assert_eq!(sums[0].to_bits(), expected.to_bits());
    }
}
