//! B-spline bases of any degree on the open (clamped) knot vector of the uniform grid: the
//! quadratic one of BSMPM (Steffen, Kirby & Berzins 2008; Tielen et al. 2017), as Wobbes et al.
//! (2018) use it, and the cubic one.

use nalgebra::SVector;

use super::block::next_block_entry;
use super::Shape;
use crate::grid::{Dofs, Grid};

/// The degrees the registry offers. A new degree is a variant here and its `Order` below.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplineDegree {
    Quadratic,
    Cubic,
}

impl SplineDegree {
    pub fn degree(self) -> usize {
        match self {
            SplineDegree::Quadratic => 2,
            SplineDegree::Cubic => 3,
        }
    }

    /// The word that names the degree in a basis's description ("quadratic-bspline").
    pub fn word(self) -> &'static str {
        match self {
            SplineDegree::Quadratic => "quadratic",
            SplineDegree::Cubic => "cubic",
        }
    }

    pub fn dofs(self) -> Dofs {
        Dofs::BSpline {
            degree: self.degree(),
        }
    }

    /// The basis of this degree, monomorphised for its order.
    pub fn shape<const D: usize>(self) -> &'static dyn Shape<D> {
        match self {
            SplineDegree::Quadratic => &BSpline::<3>,
            SplineDegree::Cubic => &BSpline::<4>,
        }
    }
}

/// B-splines of order `ORDER` (degree `ORDER - 1`) on the knots 0, ..., 0, h, 2h, ..., L, ..., L
/// of every axis, each end knot repeated `ORDER` times (a tensor product in 2D): cells + degree
/// functions per axis (`Dofs::BSpline`), ORDER^D nonzero at a point. The repeated end knots
/// make the basis interpolate at the ends: at x = 0 only the first function is nonzero and
/// equals one, at x = L only the last. (The order, not the degree, is the parameter because it
/// sizes the arrays.)
#[derive(Clone, Copy, Debug, Default)]
pub struct BSpline<const ORDER: usize>;

/// The knot t_j of the open knot vector of `degree` on `cells` cells, in cells:
/// t_j = clamp(j - degree, 0, cells), so that cell c is [t_{c+degree}, t_{c+degree+1}].
fn knot(j: usize, degree: usize, cells: usize) -> usize {
    j.saturating_sub(degree).min(cells)
}

/// Where the support of a function reaching cell c ends, in whole cells: from its left knot to
/// the cell's left end, from the cell's right end to its right knot, and its length.
#[derive(Clone, Copy)]
struct Reach {
    left: usize,
    right: usize,
    span: usize,
}

/// The B-splines nonzero in cell `c` of `cells`, B_c, ..., B_{c+degree}, at the local coordinate
/// `xi` in [0, 1]: values and derivatives per unit of the cell coordinate.
#[inline]
fn axis_basis<const ORDER: usize>(c: usize, cells: usize, xi: f64) -> ([f64; ORDER], [f64; ORDER]) {
    let degree = ORDER - 1;
    if c + 1 >= degree && c + degree <= cells {
        // No repeated knot within reach: every span and distance is a constant of the step,
        // which the unrolled recursion folds.
        raise::<ORDER>(xi, |j, k| Reach {
            left: j - 1 - k,
            right: k,
            span: j,
        })
    } else {
        raise::<ORDER>(xi, |j, k| reach_on_knots(c, cells, degree, j, k))
    }
}

/// The support of the k-th function raised at step j in cell `c`, B^{j-1}_i on [t_i, t_{i+j}],
/// from the knots.
fn reach_on_knots(c: usize, cells: usize, degree: usize, j: usize, k: usize) -> Reach {
    let i = c + degree + 1 + k - j;
    let (left, right) = (knot(i, degree, cells), knot(i + j, degree, cells));
    Reach {
        left: c - left,
        right: right - (c + 1),
        span: right - left,
    }
}

/// The Cox-de Boor recursion B_i^j = lambda_{i,j} B_i^{j-1} + (1 - lambda_{i+1,j}) B_{i+1}^{j-1},
/// lambda_{i,j} = (x - t_i) / (t_{i+j} - t_i), from the cell's hats 1 - xi and xi, with
/// `reach(j, k)` the support of the k-th function raised at step j.
///
/// Each B^{j-1} is split into the parts rho = 1 - lambda and lambda it hands to its two
/// successors, so the values sum to one at every degree. The first half of the functions take
/// rho from the distance to their right knot, the rest lambda from their left knot: for the
/// quadratic B-spline this is B_c = a (1 - xi)^2, B_{c+1} = (1 - xi)(1 - a (1 - xi)) +
/// xi (1 - b xi) and B_{c+2} = b xi^2, a and b the inverse spans of B_c's and B_{c+2}'s parents.
/// The derivative is dB_i^p = p (B_i^{p-1} / (t_{i+p} - t_i) - B_{i+1}^{p-1} / (t_{i+p+1} - t_{i+1})).
#[inline(always)]
fn raise<const ORDER: usize>(
    xi: f64,
    reach: impl Fn(usize, usize) -> Reach,
) -> ([f64; ORDER], [f64; ORDER]) {
    let degree = ORDER - 1;
    let eta = 1.0 - xi;
    // The degree-1 functions of the cell, raised one degree at a time in place: before step j,
    // value[..j] are B^{j-1}_{c+degree-j+1}, ..., B^{j-1}_{c+degree}.
    let mut value = [0.0; ORDER];
    value[0] = eta;
    value[1] = xi;
    // The last step's B^{degree-1} / span, for the derivative.
    let mut scaled = [0.0; ORDER];
    for j in 2..=degree {
        let mut carried = 0.0;
        for k in 0..j {
            let Reach { left, right, span } = reach(j, k);
            let inv_span = 1.0 / span as f64;
            let parent = value[k];
            // The part measured from the nearer end exactly, the other its complement.
            let (rho, lambda) = if 2 * k < j {
                let rho = inv_span * (eta + right as f64);
                (rho, 1.0 - rho)
            } else {
                let lambda = inv_span * (xi + left as f64);
                (1.0 - lambda, lambda)
            };
            let part = rho * parent;
            value[k] = if k == 0 { part } else { carried + part };
            carried = lambda * parent;
            if j == degree {
                scaled[k] = parent * inv_span;
            }
        }
        value[j] = carried;
    }
    let p = degree as f64;
    let slope = std::array::from_fn(|k| match k {
        0 => -scaled[0] * p,
        _ if k == degree => scaled[k - 1] * p,
        _ => p * (scaled[k - 1] - scaled[k]),
    });
    (value, slope)
}

impl<const ORDER: usize, const D: usize> Shape<D> for BSpline<ORDER> {
    fn nodes_per_point(&self) -> usize {
        ORDER.pow(D as u32)
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
        debug_assert_eq!(grid.dofs(), Dofs::BSpline { degree: ORDER - 1 });
        let Some((cell, xi)) = grid.locate(x) else {
            return false;
        };
        let mut value = [[0.0; ORDER]; D];
        let mut slope = [[0.0; ORDER]; D];
        for k in 0..D {
            (value[k], slope[k]) = axis_basis::<ORDER>(cell[k], grid.cells, xi[k]);
        }
        // B_c is DOF c along each axis: the cell's index is that of its first B-spline.
        let base = grid.node_index(cell);
        let inv_h = grid.inv_h();
        let along: [[usize; ORDER]; D] =
            std::array::from_fn(|k| std::array::from_fn(|l| l * grid.stride(k)));
        // A constant count, slices cut to it and the local coordinates counted up, so that
        // the entries unroll without bounds checks.
        let count = ORDER.pow(D as u32);
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
            next_block_entry(&mut locals, ORDER);
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

    const DEGREES: [SplineDegree; 2] = [SplineDegree::Quadratic, SplineDegree::Cubic];

    fn grid<const D: usize>(cells: usize, degree: SplineDegree) -> Grid<D> {
        Grid::with_dofs(
            &Domain {
                lower: SVector::repeat(-0.5),
                upper: SVector::repeat(1.5),
                cells,
            },
            degree.dofs(),
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
    fn check_consistency<const D: usize>(cells: usize, degree: SplineDegree) {
        let g = grid::<D>(cells, degree);
        let shape = degree.shape::<D>();
        let xs = points(&g);
        let mut st = Stencils::new(shape.nodes_per_point(), xs.len());
        st.update(shape, &g, &xs).unwrap();
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
                    Some(cells + degree.degree() - 1)
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
        for degree in DEGREES {
            for cells in [1, 2, 3, 4, 5, 7] {
                check_consistency::<1>(cells, degree);
            }
        }
    }

    #[test]
    fn bspline_consistency_2d() {
        for degree in DEGREES {
            for cells in [1, 2, 5, 6] {
                check_consistency::<2>(cells, degree);
            }
        }
    }

    /// The DOFs and their Greville abscissae, the means of each function's interior knots.
    #[test]
    fn dofs_sit_at_the_greville_abscissae() {
        let greville = |degree: SplineDegree| {
            let g = grid::<1>(4, degree);
            let xs: Vec<f64> = (0..g.num_nodes())
                .map(|i| (g.dof_coordinate(0, i) + 0.5) / g.h)
                .collect();
            xs
        };
        assert_eq!(
            greville(SplineDegree::Quadratic),
            [0.0, 0.5, 1.5, 2.5, 3.5, 4.0]
        );
        let cubic = greville(SplineDegree::Cubic);
        let expected = [0.0, 1.0 / 3.0, 1.0, 2.0, 3.0, 11.0 / 3.0, 4.0];
        assert_eq!(cubic.len(), expected.len());
        for (x, e) in cubic.iter().zip(expected) {
            assert!((x - e).abs() < 1e-14, "{cubic:?}");
        }
        assert_eq!(grid::<2>(4, SplineDegree::Quadratic).num_nodes(), 36);
        assert_eq!(grid::<2>(4, SplineDegree::Cubic).num_nodes(), 49);
    }

    /// The interior functions are the uniform B-splines, the end ones their clamped variants:
    /// the closed forms at a few points (in units of h).
    #[test]
    fn values_match_the_closed_forms() {
        let quadratic = |c, cells, xi| axis_basis::<3>(c, cells, xi).0;
        assert_eq!(quadratic(0, 4, 0.5), [0.25, 0.625, 0.125]);
        assert_eq!(quadratic(1, 4, 0.5), [0.125, 0.75, 0.125]);
        assert_eq!(quadratic(3, 4, 1.0), [0.0, 0.0, 1.0]);
        assert_eq!(quadratic(0, 1, 0.5), [0.25, 0.5, 0.25]);
        let cubic = |c, cells, xi: f64, expected: [f64; 4]| {
            let (v, _) = axis_basis::<4>(c, cells, xi);
            for (v, e) in v.iter().zip(expected) {
                assert!(
                    (v - e).abs() < 1e-15,
                    "cell {c} of {cells} at {xi}: {v} against {e}"
                );
            }
        };
        // The uniform cubic: (1 - xi)^3 / 6, (3 xi^3 - 6 xi^2 + 4) / 6, ..., xi^3 / 6.
        cubic(
            2,
            6,
            0.5,
            [1.0 / 48.0, 23.0 / 48.0, 23.0 / 48.0, 1.0 / 48.0],
        );
        cubic(3, 6, 0.0, [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0, 0.0]);
        // The first cell on the clamped knots 0, 0, 0, 0, 1, 2, ...: B_0 = (1 - x)^3,
        // B_1 = 3x - 9x^2/2 + 7x^3/4, B_2 = 3x^2/2 - 11x^3/12, B_3 = x^3/6.
        let x: f64 = 0.3;
        let first = [
            (1.0 - x).powi(3),
            3.0 * x - 4.5 * x * x + 1.75 * x.powi(3),
            1.5 * x * x - 11.0 / 12.0 * x.powi(3),
            x.powi(3) / 6.0,
        ];
        cubic(0, 6, x, first);
        // The last cell mirrors the first.
        let mut last = first;
        last.reverse();
        cubic(5, 6, 1.0 - x, last);
        // One cell: the Bernstein polynomials.
        cubic(0, 1, 0.5, [0.125, 0.375, 0.375, 0.125]);
    }

    /// The Cox-de Boor recursion as the textbooks write it, B_i^0 the indicator of
    /// [t_i, t_{i+1}) and 0/0 = 0, on the open knot vector in cell units.
    fn textbook(i: usize, degree: usize, p: usize, cells: usize, x: f64) -> f64 {
        let t = |j: usize| knot(j, degree, cells) as f64;
        if p == 0 {
            let last = t(i + 1) == cells as f64 && x == cells as f64;
            return f64::from(t(i) <= x && (x < t(i + 1) || last) && t(i) < t(i + 1));
        }
        let ratio = |num: f64, den: f64| if den == 0.0 { 0.0 } else { num / den };
        ratio(x - t(i), t(i + p) - t(i)) * textbook(i, degree, p - 1, cells, x)
            + ratio(t(i + p + 1) - x, t(i + p + 1) - t(i + 1))
                * textbook(i + 1, degree, p - 1, cells, x)
    }

    /// Every function in every cell, values and (by differences of the textbook values)
    /// derivatives, for both degrees on grids from one cell to eight.
    #[test]
    fn values_match_the_textbook_recursion_in_every_cell() {
        fn check<const ORDER: usize>() {
            let degree = ORDER - 1;
            for cells in 1..=8 {
                for c in 0..cells {
                    for xi in [0.0, 0.1, 0.37, 0.5, 0.83, 0.999] {
                        let x = c as f64 + xi;
                        let (value, slope) = axis_basis::<ORDER>(c, cells, xi);
                        for k in 0..ORDER {
                            let want = textbook(c + k, degree, degree, cells, x);
                            assert!(
                                (value[k] - want).abs() < 1e-14,
                                "degree {degree}, cell {c} of {cells}, xi {xi}: B_{} = {} against {want}",
                                c + k,
                                value[k]
                            );
                            if xi == 0.0 || xi > 0.99 {
                                continue;
                            }
                            let e = 1e-6;
                            let fd = (textbook(c + k, degree, degree, cells, x + e)
                                - textbook(c + k, degree, degree, cells, x - e))
                                / (2.0 * e);
                            assert!(
                                (slope[k] - fd).abs() < 1e-6,
                                "degree {degree}, cell {c} of {cells}, xi {xi}: B_{}' = {} against {fd}",
                                c + k,
                                slope[k]
                            );
                        }
                    }
                }
            }
        }
        check::<3>();
        check::<4>();
    }

    /// Away from the repeated knots the recursion runs on constant spans; the general knots
    /// give the same bits there.
    #[test]
    fn interior_cells_match_the_general_knots() {
        fn general<const ORDER: usize>(c: usize, cells: usize, xi: f64) -> [[f64; ORDER]; 2] {
            let (v, s) = raise::<ORDER>(xi, |j, k| reach_on_knots(c, cells, ORDER - 1, j, k));
            [v, s]
        }
        let mut rng = crate::rng::Lcg::new(5);
        for _ in 0..200 {
            let xi = rng.unit();
            for c in 1..7 {
                let (v, s) = axis_basis::<3>(c, 8, xi);
                assert_eq!([v, s], general::<3>(c, 8, xi));
            }
            for c in 2..6 {
                let (v, s) = axis_basis::<4>(c, 8, xi);
                assert_eq!([v, s], general::<4>(c, 8, xi));
            }
        }
    }

    /// Gradients agree with central differences of the values, in every cell (1D and 2D).
    fn check_gradient<const D: usize>(degree: SplineDegree) {
        let g = grid::<D>(6, degree);
        let mut rng = crate::rng::Lcg::new(77);
        for c in 0..g.cells {
            // A point inside cell c along every axis, away from the faces.
            let x = g.lower + SVector::from_fn(|_, _| (c as f64 + 0.1 + 0.8 * rng.unit()) * g.h);
            assert_gradient_matches_differences(degree.shape::<D>(), &g, &x, 1e-7);
        }
    }

    #[test]
    fn bspline_gradient_matches_finite_differences_1d() {
        for degree in DEGREES {
            check_gradient::<1>(degree);
        }
    }

    #[test]
    fn bspline_gradient_matches_finite_differences_2d() {
        for degree in DEGREES {
            check_gradient::<2>(degree);
        }
    }
}
