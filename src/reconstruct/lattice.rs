//! Where reconstructed fields are evaluated: grid nodes, cell centres, Gauss points. Each is
//! a tensor-product lattice of points at fixed offsets inside the cells of the grid.

use nalgebra::SVector;

use crate::gauss::gauss_legendre;
use crate::grid::{index_to_f64, lattice_strides, Dofs, Grid};

/// How far below s - radius, in cells, `near_on_axis` takes a cell's last point to be out
/// of reach for certain: far above the rounding of (c + offset) - s, a few ulps of c, on
/// any lattice of under 2^32 cells.
const EDGE: f64 = 1e-6;

/// Points `lower + (c + offsets[j]) h` per axis (cell c, offset j), numbered with the
/// offset fastest, then the cell, then the axes with the first fastest.
#[derive(Clone, Debug)]
pub struct Lattice<const D: usize> {
    lower: SVector<f64, D>,
    h: f64,
    /// Offsets inside a cell in units of h, ascending in [0, 1).
    offsets: Vec<f64>,
    /// Points per axis.
    per_axis: usize,
    /// Cells per axis that hold points, `per_axis / offsets.len()`: for the nodes one more
    /// than the grid's, the upper face's node counting as a cell of its own. Kept so that
    /// `near_on_axis`, called per particle and axis, bounds its cells without a division.
    cells: usize,
    strides: [usize; D],
}

impl<const D: usize> Lattice<D> {
    fn new(grid: &Grid<D>, offsets: Vec<f64>, per_axis: usize) -> Self {
        let strides = lattice_strides(&[per_axis; D]);
        Lattice {
            lower: grid.lower,
            h: grid.h,
            cells: per_axis / offsets.len(),
            offsets,
            per_axis,
            strides,
        }
    }

    /// The grid nodes, numbered as the grid numbers them (a grid of `Dofs::Nodes`).
    pub fn nodes(grid: &Grid<D>) -> Self {
        debug_assert_eq!(grid.dofs(), Dofs::Nodes);
        Self::new(grid, vec![0.0], grid.cells + 1)
    }

    /// One point per cell at its centre (Gong's one-point quadrature, eq 5.9).
    pub fn cell_centres(grid: &Grid<D>) -> Self {
        Self::new(grid, vec![0.5], grid.cells)
    }

    /// `n`-point Gauss-Legendre points per axis and cell (n = 1, 2 or 3).
    pub fn gauss(grid: &Grid<D>, n: usize) -> Self {
        let offsets = gauss_legendre(n).0.iter().map(|&s| 0.5 + 0.5 * s).collect();
        Self::new(grid, offsets, grid.cells * n)
    }

    pub fn len(&self) -> usize {
        self.per_axis.pow(D as u32)
    }

    pub fn is_empty(&self) -> bool {
        self.per_axis == 0
    }

    pub fn h(&self) -> f64 {
        self.h
    }

    /// Coordinate along one axis of lattice index `i` on that axis.
    #[inline]
    fn axis_coordinate(&self, axis: usize, i: usize) -> f64 {
        let k = self.offsets.len();
        self.lower[axis] + ((i / k) as f64 + self.offsets[i % k]) * self.h
    }

    pub fn point(&self, index: usize) -> SVector<f64, D> {
        SVector::from_fn(|axis, _| {
            self.axis_coordinate(axis, (index / self.strides[axis]) % self.per_axis)
        })
    }

    /// Along `axis`, the lattice indices strictly within `radius` (in units of h) of `x`, in
    /// index order: `found(i, d)` for each, index i, offset d = (x_i - x)/h.
    /// Returns how many; at most `max_per_axis(radius)`. The callback lets a caller tabulate
    /// what it needs of each point as it is found, without a list in between.
    #[inline(always)]
    pub fn near_on_axis(
        &self,
        axis: usize,
        x: f64,
        radius: f64,
        mut found: impl FnMut(usize, f64),
    ) -> usize {
        let k = self.offsets.len();
        let s = (x - self.lower[axis]) / self.h;
        // Cell c's points lie at c + offset, none past c + (its largest offset): a cell
        // whose last point lies below s - radius by more than rounding (`EDGE`) holds none
        // within the radius, and the first cell that may is one past the last such. On
        // the nonnegative, truncation is floor() without a libm call; through i64, which
        // converts in one instruction where usize does not. Below the lattice's first
        // cell, that cell.
        let below = s - radius - self.last_offset() - EDGE;
        let first_cell = if below < 0.0 {
            0
        } else {
            below as i64 as usize + 1
        };
        let last_cell = ((s + radius) as i64).max(0) as usize;
        // Cells, then offsets within a cell: lattice index order without a division. The
        // offsets d grow with the index (rounding is monotone), so the points within the
        // radius are one run, and the first point at or past it ends the search. Every cell
        // holds k points, so none lies in the cells past the lattice's last.
        let cells = first_cell..(last_cell + 1).min(self.cells);
        let mut n = 0;
        // Takes point i at offset d if it is within the radius; false once past it.
        let mut take = |i: usize, d: f64| {
            if d >= radius {
                return false;
            }
            if d > -radius {
                found(i, d);
                n += 1;
            }
            true
        };
        if let [offset] = self.offsets[..] {
            // One point per cell (the nodes, the cell centres: every velocity fit and IMPM's
            // fields), the cell its index: the loop over the offsets below cost `impm` 5 % of
            // its instructions.
            for cell in cells {
                if !take(cell, (index_to_f64(cell) + offset) - s) {
                    break;
                }
            }
        } else {
            'cells: for cell in cells {
                for (j, &offset) in self.offsets.iter().enumerate() {
                    if !take(cell * k + j, (index_to_f64(cell) + offset) - s) {
                        break 'cells;
                    }
                }
            }
        }
        n
    }

    fn last_offset(&self) -> f64 {
        self.offsets[self.offsets.len() - 1]
    }

    /// An upper bound on `near_on_axis`'s count: an open interval of length 2 radius
    /// meets at most ceil(2 radius) + 1 cells.
    pub fn max_per_axis(&self, radius: f64) -> usize {
        ((2.0 * radius).ceil() as usize + 1) * self.offsets.len()
    }

    pub fn stride(&self, axis: usize) -> usize {
        self.strides[axis]
    }

    /// Quadrature weight of each point: the cell volume shared by the points of a cell with
    /// the Gauss weights (for one offset, the whole cell).
    pub fn quadrature_weight(&self, index: usize) -> f64 {
        let weights = gauss_legendre(self.offsets.len()).1;
        (0..D)
            .map(|axis| {
                let i = (index / self.strides[axis]) % self.per_axis;
                0.5 * weights[i % self.offsets.len()] * self.h
            })
            .product()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::Domain;

    fn grid<const D: usize>(cells: usize) -> Grid<D> {
        Grid::new(&Domain {
            lower: SVector::repeat(-1.0),
            upper: SVector::repeat(1.0),
            cells,
        })
    }

    #[test]
    fn nodes_match_the_grid_numbering() {
        let g = grid::<2>(4);
        let nodes = Lattice::nodes(&g);
        assert_eq!(nodes.len(), g.num_nodes());
        for i in 0..g.num_nodes() {
            let ijk = g.node_coords(i);
            let x = SVector::<f64, 2>::from_fn(|k, _| -1.0 + ijk[k] as f64 * g.h);
            assert!((nodes.point(i) - x).norm() < 1e-15);
        }
    }

    /// Gauss points integrate cubics exactly over the domain, cell centres linears.
    #[test]
    fn quadrature_weights_integrate_polynomials() {
        let g = grid::<2>(3);
        let cubic = |x: f64, y: f64| x * x * x + x * y * y + 1.0;
        let linear = |x: f64, y: f64| 2.0 * x - y + 1.0;
        type Integrand<'a> = &'a dyn Fn(f64, f64) -> f64;
        let cases: [(Lattice<2>, Integrand); 2] = [
            (Lattice::gauss(&g, 2), &cubic),
            (Lattice::cell_centres(&g), &linear),
        ];
        for (lattice, f) in cases {
            let sum: f64 = (0..lattice.len())
                .map(|i| {
                    let p = lattice.point(i);
                    lattice.quadrature_weight(i) * f(p[0], p[1])
                })
                .sum();
            assert!((sum - 4.0).abs() < 1e-13, "integral {sum}");
        }
    }

    /// `near_on_axis`'s points on the first axis, checking their count and its bound.
    fn near(lattice: &Lattice<1>, x: f64, radius: f64) -> Vec<(usize, f64)> {
        let mut out = Vec::new();
        let n = lattice.near_on_axis(0, x, radius, |i, d| out.push((i, d)));
        assert_eq!(n, out.len());
        assert!(n <= lattice.max_per_axis(radius));
        out
    }

    /// `near_on_axis` finds exactly the points within the radius, for points anywhere.
    #[test]
    fn near_on_axis_is_exhaustive() {
        let g = grid::<1>(5);
        for lattice in [
            Lattice::nodes(&g),
            Lattice::cell_centres(&g),
            Lattice::gauss(&g, 2),
        ] {
            for radius in [1.0, 1.5, 2.0, 3.0] {
                for &x in &[-1.0, -0.93, -0.2, 0.0, 0.41, 0.99, 1.0] {
                    let out = near(&lattice, x, radius);
                    let found: Vec<usize> = out.iter().map(|e| e.0).collect();
                    // Points at exactly the radius have zero weight: either answer is right.
                    for i in 0..lattice.len() {
                        let d = ((lattice.point(i)[0] - x) / g.h).abs();
                        if d < radius - 1e-9 {
                            assert!(found.contains(&i), "x = {x}, radius {radius}: missed {i}");
                        } else if d > radius + 1e-9 {
                            assert!(!found.contains(&i), "x = {x}, radius {radius}: {i}");
                        }
                    }
                    for &(i, d) in &out {
                        assert!((d - (lattice.point(i)[0] - x) / g.h).abs() < 1e-12);
                    }
                }
            }
        }
    }

    /// The pruned search returns what testing every lattice point returns, to the bit:
    /// the same points, in index order, with the same offsets.
    #[test]
    fn near_on_axis_matches_testing_every_point() {
        let g = grid::<1>(8);
        let mut rng = crate::rng::Lcg::new(7);
        for lattice in [
            Lattice::nodes(&g),
            Lattice::cell_centres(&g),
            Lattice::gauss(&g, 2),
            Lattice::gauss(&g, 3),
        ] {
            let k = lattice.offsets.len();
            for radius in [0.5, 1.0, 1.5, 2.0, 3.0] {
                for trial in 0..2000 {
                    // Random points, and points on the lattice and the cell faces.
                    let x = match trial % 3 {
                        0 => -1.1 + 2.2 * rng.unit(),
                        1 => lattice.point(trial % lattice.len())[0],
                        _ => -1.0 + (trial % 9) as f64 * g.h,
                    };
                    let s = (x - lattice.lower[0]) / lattice.h;
                    let every: Vec<(usize, f64)> = (0..lattice.len())
                        .map(|i| (i, ((i / k) as f64 + lattice.offsets[i % k]) - s))
                        .filter(|&(_, d)| d.abs() < radius)
                        .collect();
                    let found = near(&lattice, x, radius);
                    assert_eq!(found.len(), every.len(), "x = {x}, radius {radius}");
                    for (a, b) in found.iter().zip(&every) {
                        assert_eq!((a.0, a.1.to_bits()), (b.0, b.1.to_bits()), "x = {x}");
                    }
                }
            }
        }
    }
}
