//! The quadratic B-spline basis of BSMPM (Steffen, Kirby & Berzins 2008; Tielen et al. 2017),
//! as Wobbes et al. (2018) use it: an open (clamped) knot vector on the uniform grid.

use nalgebra::SVector;

use super::block::next_block_entry;
use super::Shape;
use crate::grid::{Dofs, Grid};

/// B-splines per axis that are nonzero at a point.
const PER_AXIS: usize = 3;

/// Quadratic B-splines on the knots 0, 0, 0, h, 2h, ..., L, L, L of every axis (a tensor
/// product in 2D): cells + 2 functions per axis (`Dofs::QuadraticSpline`), 3^D nonzero at a
/// point. The repeated end knots make the basis interpolate at the ends: at x = 0 only the
/// first function is nonzero and equals one, at x = L only the last.
#[derive(Clone, Copy, Debug, Default)]
pub struct QuadraticBSpline;

/// The three B-splines nonzero in cell `c` of `cells`, B_c, B_{c+1}, B_{c+2}, at the local
/// coordinate `xi` in [0, 1]: values and derivatives per unit of the cell coordinate.
///
/// With the knots t_j = clamp(j - 2, 0, cells) (in cells), B_i lives on [t_i, t_{i+3}] and
/// the cell is [t_{c+2}, t_{c+3}]. The Cox-de Boor recursion from the hats 1 - xi and xi of
/// the cell gives B_c = a (1 - xi)^2 and B_{c+2} = b xi^2 with a = 1/(t_{c+3} - t_{c+1}) and
/// b = 1/(t_{c+4} - t_{c+2}); a = b = 1/2 inside, 1 in the cells whose outer knot is
/// repeated. B_{c+1} = (1 - xi)(1 - a (1 - xi)) + xi (1 - b xi) makes the three sum to one.
#[inline]
fn axis_basis(c: usize, cells: usize, xi: f64) -> ([f64; PER_AXIS], [f64; PER_AXIS]) {
    let a = 1.0 / (c + 1 - c.saturating_sub(1)) as f64;
    let b = 1.0 / ((c + 2).min(cells) - c) as f64;
    let eta = 1.0 - xi;
    let value = [
        a * eta * eta,
        eta * (1.0 - a * eta) + xi * (1.0 - b * xi),
        b * xi * xi,
    ];
    let slope = [-2.0 * a * eta, 2.0 * a * eta - 2.0 * b * xi, 2.0 * b * xi];
    (value, slope)
}

impl<const D: usize> Shape<D> for QuadraticBSpline {
    fn nodes_per_point(&self) -> usize {
        PER_AXIS.pow(D as u32)
    }

    #[inline]
    fn eval(
        &self,
        grid: &Grid<D>,
        x: &SVector<f64, D>,
        node: &mut [u32],
        weight: &mut [f64],
        grad: &mut [SVector<f64, D>],
    ) -> bool {
        debug_assert_eq!(grid.dofs(), Dofs::QuadraticSpline);
        let Some((cell, xi)) = grid.locate(x) else {
            return false;
        };
        let mut value = [[0.0; PER_AXIS]; D];
        let mut slope = [[0.0; PER_AXIS]; D];
        for k in 0..D {
            (value[k], slope[k]) = axis_basis(cell[k], grid.cells, xi[k]);
        }
        // B_c is DOF c along each axis: the cell's index is that of its first B-spline.
        let base = grid.node_index(cell);
        let inv_h = grid.inv_h();
        let along: [[usize; PER_AXIS]; D] =
            std::array::from_fn(|k| std::array::from_fn(|l| l * grid.stride(k)));
        // A constant count, slices cut to it and the local coordinates counted up, so that
        // the entries unroll without bounds checks.
        let count = PER_AXIS.pow(D as u32);
        let (node, weight, grad) = (&mut node[..count], &mut weight[..count], &mut grad[..count]);
        let mut locals = [0; D];
        for e in 0..count {
            let mut index = base;
            let mut w = 1.0;
            let mut g = SVector::<f64, D>::repeat(inv_h);
            for k in 0..D {
                let local = locals[k];
                index += along[k][local];
                w *= value[k][local];
                for l in 0..D {
                    g[l] *= if l == k {
                        slope[k][local]
                    } else {
                        value[k][local]
                    };
                }
            }
            node[e] = index as u32;
            weight[e] = w;
            grad[e] = g;
            next_block_entry(&mut locals, PER_AXIS);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::SMatrix;

    use super::*;
    use crate::grid::{lattice_coords, Domain};
    use crate::shape::stencils::assert_gradient_matches_differences;
    use crate::shape::Stencils;

    fn grid<const D: usize>(cells: usize) -> Grid<D> {
        Grid::with_dofs(
            &Domain {
                lower: SVector::repeat(-0.5),
                upper: SVector::repeat(1.5),
                cells,
            },
            Dofs::QuadraticSpline,
        )
    }

    /// Random points, the corners and faces of the domain exactly, and points in the first
    /// and last cells.
    fn points<const D: usize>(g: &Grid<D>) -> Vec<SVector<f64, D>> {
        let length = g.cells as f64 * g.h;
        let mut rng = crate::rng::Lcg::new(0x2545f4914f6cdd1d);
        let mut xs: Vec<SVector<f64, D>> = (0..400)
            .map(|_| g.lower + SVector::from_fn(|_, _| length * rng.unit()))
            .collect();
        let edges = [
            0.0,
            0.3 * g.h,
            0.5 * g.h,
            g.h,
            length - g.h,
            length - 0.2 * g.h,
            length,
        ];
        let n = [edges.len(); D];
        for m in 0..edges.len().pow(D as u32) {
            let ijk = lattice_coords(m, &n);
            xs.push(g.lower + SVector::from_fn(|k, _| edges[ijk[k]]));
        }
        xs
    }

    /// Partition of unity, non-negativity, sum_i grad B_i = 0, reproduction of x with the
    /// Greville abscissae, sum_i xi_i (x) grad B_i = I, and interpolation at the ends.
    fn check_consistency<const D: usize>(cells: usize) {
        let g = grid::<D>(cells);
        let xs = points(&g);
        let per_point = Shape::<D>::nodes_per_point(&QuadraticBSpline);
        let mut st = Stencils::new(per_point, xs.len());
        st.update(&QuadraticBSpline, &g, &xs).unwrap();
        for (p, x) in xs.iter().enumerate() {
            let sum_w: f64 = st.of(p).map(|(_, w, _)| w).sum();
            let sum_g: SVector<f64, D> = st.of(p).map(|(_, _, gr)| *gr).sum();
            let sum_wx: SVector<f64, D> = st.of(p).map(|(i, w, _)| g.node_position(i) * w).sum();
            let sum_gx: SMatrix<f64, D, D> = st
                .of(p)
                .map(|(i, _, gr)| g.node_position(i) * gr.transpose())
                .sum();
            assert!((sum_w - 1.0).abs() < 1e-14, "{x:?}: sum B = {sum_w}");
            assert!(st.of(p).all(|(_, w, _)| w >= 0.0), "{x:?}: negative B");
            assert!(sum_g.norm() < 1e-12, "{x:?}: sum grad B = {sum_g:?}");
            assert!((sum_wx - x).norm() < 1e-14, "{x:?}: sum xi B = {sum_wx:?}");
            assert!((sum_gx - SMatrix::<f64, D, D>::identity()).norm() < 1e-12);
            // On a face x_k = 0 or L only the first or last function along k is nonzero.
            for k in 0..D {
                let s = (x[k] - g.lower[k]) / g.h;
                let end = if s == 0.0 {
                    Some(0)
                } else if s == cells as f64 {
                    Some(cells + 1)
                } else {
                    None
                };
                if let Some(end) = end {
                    for (i, w, _) in st.of(p) {
                        assert!(w == 0.0 || g.node_coords(i)[k] == end, "{x:?}: DOF {i}");
                    }
                }
            }
        }
    }

    #[test]
    fn bspline_consistency_1d() {
        for cells in [1, 2, 3, 7] {
            check_consistency::<1>(cells);
        }
    }

    #[test]
    fn bspline_consistency_2d() {
        for cells in [1, 2, 5] {
            check_consistency::<2>(cells);
        }
    }

    /// The DOFs and their Greville abscissae: 0, h/2, 3h/2, ..., L - h/2, L.
    #[test]
    fn dofs_sit_at_the_greville_abscissae() {
        let g = grid::<1>(4);
        assert_eq!(g.num_nodes(), 6);
        let xs: Vec<f64> = (0..6)
            .map(|i| (g.dof_coordinate(0, i) + 0.5) / g.h)
            .collect();
        assert_eq!(xs, vec![0.0, 0.5, 1.5, 2.5, 3.5, 4.0]);
        assert_eq!(grid::<2>(4).num_nodes(), 36);
    }

    /// The interior functions are the uniform quadratic B-spline, the end ones its clamped
    /// variants: the closed forms at a few points of a 4-cell grid (in units of h).
    #[test]
    fn values_match_the_closed_forms() {
        let (v, _) = axis_basis(0, 4, 0.5);
        assert_eq!(v, [0.25, 0.625, 0.125]);
        let (v, _) = axis_basis(1, 4, 0.5);
        assert_eq!(v, [0.125, 0.75, 0.125]);
        let (v, _) = axis_basis(3, 4, 1.0);
        assert_eq!(v, [0.0, 0.0, 1.0]);
        let (v, _) = axis_basis(0, 1, 0.5);
        assert_eq!(v, [0.25, 0.5, 0.25]);
    }

    /// Gradients agree with central differences of the values, in every cell (1D and 2D).
    fn check_gradient<const D: usize>() {
        let g = grid::<D>(4);
        let mut rng = crate::rng::Lcg::new(77);
        for c in 0..g.cells {
            // A point inside cell c along every axis, away from the faces.
            let x = g.lower + SVector::from_fn(|_, _| (c as f64 + 0.1 + 0.8 * rng.unit()) * g.h);
            assert_gradient_matches_differences(&QuadraticBSpline, &g, &x, 1e-7);
        }
    }

    #[test]
    fn bspline_gradient_matches_finite_differences_1d() {
        check_gradient::<1>();
    }

    #[test]
    fn bspline_gradient_matches_finite_differences_2d() {
        check_gradient::<2>();
    }
}
