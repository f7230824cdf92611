//! The uniform background grid: the box it covers, the numbering of its basis's DOFs, and the
//! nodal state assembled on them each step.

mod domain;
mod state;

use nalgebra::SVector;

pub use domain::Domain;
pub use state::{FixedDof, GridState};

/// Where the degrees of freedom of the grid's basis sit along each axis. The grid's "nodes"
/// are these DOFs: nodal masses, velocities and forces live on them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dofs {
    /// One per grid node, cells + 1 per axis: the hat and the shapes built on it.
    Nodes,
    /// The B-spline of `degree` on the open knot vector (each end knot repeated degree + 1
    /// times): cells + degree per axis, at the Greville abscissae (for the quadratic one
    /// 0, h/2, 3h/2, ..., L - h/2, L).
    BSpline { degree: usize },
}

impl Dofs {
    /// The degree of the DOF lattice: cells + degree DOFs per axis (1 for the nodes, which
    /// are the Greville abscissae of the hat).
    pub fn degree(self) -> usize {
        match self {
            Dofs::Nodes => 1,
            Dofs::BSpline { degree } => degree,
        }
    }
}

/// A uniform background grid: `cells` cells of size `h` per direction, and the DOFs of its
/// basis ("nodes") numbered with the first axis fastest.
#[derive(Clone, Debug)]
pub struct Grid<const D: usize> {
    pub lower: SVector<f64, D>,
    pub h: f64,
    pub cells: usize,
    dofs: Dofs,
    inv_h: f64,
    per_axis: usize,
    strides: [usize; D],
    num_nodes: usize,
}

impl<const D: usize> Grid<D> {
    /// A grid with one DOF per node over `domain`; the domain must be a cube (the same h in
    /// every direction).
    pub fn new(domain: &Domain<D>) -> Self {
        Self::with_dofs(domain, Dofs::Nodes)
    }

    /// A grid over `domain` whose basis has the DOFs `dofs`.
    pub fn with_dofs(domain: &Domain<D>, dofs: Dofs) -> Self {
        let h = (domain.upper[0] - domain.lower[0]) / domain.cells as f64;
        let n = domain.cells + dofs.degree();
        let strides = lattice_strides(&[n; D]);
        Grid {
            lower: domain.lower,
            h,
            cells: domain.cells,
            dofs,
            inv_h: 1.0 / h,
            per_axis: n,
            strides,
            num_nodes: n.pow(D as u32),
        }
    }

    pub fn dofs(&self) -> Dofs {
        self.dofs
    }

    /// The number of DOFs (nodes) of the grid's basis.
    pub fn num_nodes(&self) -> usize {
        self.num_nodes
    }

    /// DOFs (nodes) per axis: cells + 1 for the hat, cells + degree for a B-spline.
    pub fn nodes_per_dim(&self) -> usize {
        self.per_axis
    }

    /// Position of DOF `i` along one axis: the grid node, or the Greville abscissa of the
    /// B-spline (the mean of its interior knots), where it carries the value of a linear
    /// function that the basis reproduces.
    pub fn dof_coordinate(&self, axis: usize, i: usize) -> f64 {
        let in_cells = match self.dofs {
            Dofs::Nodes => i as f64,
            // The mean of the knots t_{i+1}, ..., t_{i+degree}, t_j = clamp(j - degree, 0, cells).
            Dofs::BSpline { degree } => {
                let knots: usize = (i + 1..=i + degree)
                    .map(|j| j.saturating_sub(degree).min(self.cells))
                    .sum();
                knots as f64 / degree as f64
            }
        };
        self.lower[axis] + in_cells * self.h
    }

    /// Flat index of the node with integer coordinates `ijk`.
    #[inline]
    pub fn node_index(&self, ijk: [usize; D]) -> usize {
        (0..D).map(|k| ijk[k] * self.strides[k]).sum()
    }

    /// Integer coordinates of a flat node index.
    pub fn node_coords(&self, index: usize) -> [usize; D] {
        let n = self.nodes_per_dim();
        std::array::from_fn(|k| (index / self.strides[k]) % n)
    }

    /// Position of the node (DOF) with flat index `index`.
    pub fn node_position(&self, index: usize) -> SVector<f64, D> {
        let ijk = self.node_coords(index);
        SVector::from_fn(|k, _| self.dof_coordinate(k, ijk[k]))
    }

    /// The cell containing `x` and the local coordinates in [0, 1] within it, or `None`
    /// when `x` lies outside the grid (or is not finite). A point on an interior cell face
    /// belongs to the upper cell; a point on the upper boundary to the last cell.
    #[inline]
    pub fn locate(&self, x: &SVector<f64, D>) -> Option<([usize; D], SVector<f64, D>)> {
        let mut cell = [0usize; D];
        let mut xi = SVector::<f64, D>::zeros();
        for k in 0..D {
            let s = (x[k] - self.lower[k]) * self.inv_h;
            // Written so that NaN fails the test.
            if !(s >= 0.0 && s <= self.cells as f64) {
                return None;
            }
            // Through i64, which converts to and from f64 in one instruction each where usize
            // does not; s is in [0, cells] here, so the values are the same.
            let c = (s as i64).min(self.cells as i64 - 1);
            cell[k] = c as usize;
            xi[k] = s - c as f64;
        }
        Some((cell, xi))
    }

    /// Flat index of the cell with integer coordinates `cell` (first axis fastest).
    #[inline]
    pub fn cell_index(&self, cell: [usize; D]) -> usize {
        cell.iter()
            .rev()
            .fold(0, |index, &c| index * self.cells + c)
    }

    #[inline]
    pub fn inv_h(&self) -> f64 {
        self.inv_h
    }

    pub fn stride(&self, axis: usize) -> usize {
        self.strides[axis]
    }
}

/// Node or cell number `i` as f64, through i64: its conversion is one instruction where
/// usize's takes several, and the value is the same (numbers on a grid are far below 2^53).
#[inline(always)]
pub fn index_to_f64(i: usize) -> f64 {
    i as i64 as f64
}

/// Flat-index strides of a `D`-dimensional lattice with `per_axis[k]` points along axis k,
/// the first axis fastest.
pub fn lattice_strides<const D: usize>(per_axis: &[usize; D]) -> [usize; D] {
    let mut strides = [1; D];
    for k in 1..D {
        strides[k] = strides[k - 1] * per_axis[k - 1];
    }
    strides
}

/// Integer coordinates of entry `index` of the same lattice.
pub fn lattice_coords<const D: usize>(index: usize, per_axis: &[usize; D]) -> [usize; D] {
    let mut rest = index;
    std::array::from_fn(|k| {
        let m = rest % per_axis[k];
        rest /= per_axis[k];
        m
    })
}
