//! Material points as a structure of arrays.

use nalgebra::{SMatrix, SVector};

use crate::fallible::filled;
use crate::gauss::gauss_legendre_rule;
use crate::grid::{lattice_coords, Grid};
use crate::parallel;

/// State carried by the material points. Velocities are what the integrator steps: the
/// leapfrog's half-step values v^{s-1/2} between steps (v^0 before the first), the whole-step
/// values of the others.
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

/// Where the points sit inside each grid cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// The centres of a regular sub-grid of `ppc` sub-cells per axis, each with the sub-cell's
    /// volume (Gong sec 4.6). The particle-domain methods read these sub-cells as domains.
    SubCellCentres,
    /// The `ppc`-point Gauss-Legendre abscissae of the cell per axis, each with its Gauss
    /// weight's share of the cell (Molinos et al. sec 6.2: the points of a quadratic finite
    /// element for ppc = 2, x_e + h (1 -+ 1/sqrt 3) / 2, equal volumes).
    Gauss,
}

/// What seeding needs of a problem: the box of its body, how many points per cell and axis
/// and where in the cell, and the initial density.
#[derive(Clone, Copy, Debug)]
pub struct Body<const D: usize> {
    pub lower: SVector<f64, D>,
    pub upper: SVector<f64, D>,
    pub ppc: usize,
    pub placement: Placement,
    pub rho0: f64,
}

impl<const D: usize> Particles<D> {
    /// `ppc^D` points per grid cell of the body, where its placement puts them, numbered with
    /// the first axis fastest, moving at `initial_velocity`.
    pub fn seed(
        body: &Body<D>,
        grid: &Grid<D>,
        initial_velocity: impl Fn(&SVector<f64, D>) -> SVector<f64, D>,
    ) -> Self {
        let (lo, hi, ppc) = (body.lower, body.upper, body.ppc);
        let spacing = grid.h / ppc as f64;
        let per_axis: [usize; D] =
            std::array::from_fn(|k| ((hi[k] - lo[k]) / grid.h).round() as usize * ppc);
        let count: usize = per_axis.iter().product();
        // The largest table first: if the memory is refused, before the others are built.
        let stress = filled(count, SMatrix::zeros(), "the particles' stresses");
        let lattice = SeedLattice {
            lower: lo,
            spacing,
            per_axis,
        };
        let (x0, volume): (Vec<SVector<f64, D>>, Vec<f64>) = match body.placement {
            Placement::SubCellCentres => {
                let volume = spacing.powi(D as i32);
                (0..count)
                    .map(|p| {
                        let m = lattice.cell_of(p);
                        let x = SVector::from_fn(|k, _| lo[k] + (m[k] as f64 + 0.5) * spacing);
                        (x, volume)
                    })
                    .unzip()
            }
            Placement::Gauss => {
                let (nodes, weights) = gauss_legendre_rule(ppc);
                let half = 0.5 * grid.h;
                (0..count)
                    .map(|p| {
                        // Sub-cell m of the lattice is Gauss point m % ppc of cell m / ppc.
                        let m = lattice.cell_of(p);
                        let x = SVector::from_fn(|k, _| {
                            let cell = lo[k] + (m[k] / ppc) as f64 * grid.h;
                            cell + half * (1.0 + nodes[m[k] % ppc])
                        });
                        let volume: f64 = m.iter().map(|&mk| half * weights[mk % ppc]).product();
                        (x, volume)
                    })
                    .unzip()
            }
        };
        let v = x0.iter().map(initial_velocity).collect();
        Particles {
            x: x0.clone(),
            v,
            f: filled(
                count,
                SMatrix::identity(),
                "the particles' deformation gradients",
            ),
            j: filled(count, 1.0, "the particles' Jacobians"),
            stress,
            mass: volume.iter().map(|v| body.rho0 * v).collect(),
            volume0: volume.clone(),
            volume,
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

    /// The particles in consecutive chunks of `parallel::CHUNK`, one task each of a loop that
    /// updates them.
    pub fn chunks_mut(&mut self) -> impl Iterator<Item = ParticleChunk<'_, D>> {
        let n = parallel::CHUNK;
        self.x
            .chunks_mut(n)
            .zip(self.v.chunks_mut(n))
            .zip(self.f.chunks_mut(n))
            .zip(self.j.chunks_mut(n))
            .zip(self.stress.chunks_mut(n))
            .zip(self.volume.chunks_mut(n))
            .zip(self.volume0.chunks(n))
            .enumerate()
            .map(
                move |(c, ((((((x, v), f), j), stress), volume), volume0))| ParticleChunk {
                    start: c * n,
                    x,
                    v,
                    f,
                    j,
                    stress,
                    volume,
                    volume0,
                },
            )
    }
}

/// Particles `start..start + x.len()` with the state a step updates writable, indexed from 0.
pub struct ParticleChunk<'a, const D: usize> {
    pub start: usize,
    pub x: &'a mut [SVector<f64, D>],
    pub v: &'a mut [SVector<f64, D>],
    pub f: &'a mut [SMatrix<f64, D, D>],
    pub j: &'a mut [f64],
    pub stress: &'a mut [SMatrix<f64, D, D>],
    pub volume: &'a mut [f64],
    pub volume0: &'a [f64],
}
