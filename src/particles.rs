//! Material points as a structure of arrays.

use nalgebra::{SMatrix, SVector};

use crate::benchmarks::Problem;
use crate::shape::{lattice_coords, Grid};

/// State carried by the material points. Velocities are the leapfrog half-step values
/// v^{s-1/2} between steps (v^0 before the first).
pub struct Particles<const D: usize> {
    /// Reference (initial) positions X_p.
    pub x0: Vec<SVector<f64, D>>,
    pub x: Vec<SVector<f64, D>>,
    pub v: Vec<SVector<f64, D>>,
    pub f: Vec<SMatrix<f64, D, D>>,
    /// det F, kept beside F because density, volume and stress all need it.
    pub j: Vec<f64>,
    /// Cauchy stress.
    pub stress: Vec<SMatrix<f64, D, D>>,
    pub mass: Vec<f64>,
    pub volume0: Vec<f64>,
    /// Current volume: J V^0, or the area of the tracked domain for CPDI2.
    pub volume: Vec<f64>,
    /// Where the points were seeded.
    pub lattice: SeedLattice<D>,
}

/// The regular sub-grid the particles were seeded on: particle p sits at the centre of
/// sub-cell `m` (first axis fastest), whose corners are lower + (m + {0,1}) spacing.
#[derive(Clone, Copy, Debug)]
pub struct SeedLattice<const D: usize> {
    pub lower: SVector<f64, D>,
    pub spacing: f64,
    pub per_axis: [usize; D],
}

impl<const D: usize> SeedLattice<D> {
    /// Sub-cell coordinates of particle `p`.
    pub fn cell_of(&self, p: usize) -> [usize; D] {
        lattice_coords(p, &self.per_axis)
    }
}

impl<const D: usize> Particles<D> {
    /// `ppc^D` points per grid cell of the problem's body, at the centres of a regular
    /// sub-grid (Gong sec 4.6: x_e + (j - 1/2) h / ppc), numbered with the first axis fastest.
    pub fn seed(problem: &dyn Problem<D>, grid: &Grid<D>) -> Self {
        let (lo, hi) = problem.body();
        let ppc = problem.ppc();
        let spacing = grid.h / ppc as f64;
        let per_axis: [usize; D] =
            std::array::from_fn(|k| ((hi[k] - lo[k]) / grid.h).round() as usize * ppc);
        let count: usize = per_axis.iter().product();
        let volume = spacing.powi(D as i32);
        let lattice = SeedLattice {
            lower: lo,
            spacing,
            per_axis,
        };
        let x0: Vec<SVector<f64, D>> = (0..count)
            .map(|p| {
                let m = lattice.cell_of(p);
                SVector::from_fn(|k, _| lo[k] + (m[k] as f64 + 0.5) * spacing)
            })
            .collect();
        let v = x0.iter().map(|x| problem.initial_velocity(x)).collect();
        Particles {
            x: x0.clone(),
            v,
            f: vec![SMatrix::identity(); count],
            j: vec![1.0; count],
            stress: vec![SMatrix::zeros(); count],
            mass: vec![problem.rho0() * volume; count],
            volume0: vec![volume; count],
            volume: vec![volume; count],
            lattice,
            x0,
        }
    }

    pub fn len(&self) -> usize {
        self.x.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    #[inline]
    pub fn volume(&self, p: usize) -> f64 {
        self.volume[p]
    }
}
