//! Material points as a structure of arrays.

use nalgebra::{SMatrix, SVector};

use crate::benchmarks::Problem;
use crate::shape::Grid;

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
        let mut x0 = Vec::with_capacity(count);
        for index in 0..count {
            let mut rest = index;
            let x = SVector::<f64, D>::from_fn(|k, _| {
                let m = rest % per_axis[k];
                rest /= per_axis[k];
                lo[k] + (m as f64 + 0.5) * spacing
            });
            x0.push(x);
        }
        let v = x0.iter().map(|x| problem.initial_velocity(x)).collect();
        Particles {
            x: x0.clone(),
            v,
            f: vec![SMatrix::identity(); count],
            j: vec![1.0; count],
            stress: vec![SMatrix::zeros(); count],
            mass: vec![problem.rho0() * volume; count],
            volume0: vec![volume; count],
            x0,
        }
    }

    pub fn len(&self) -> usize {
        self.x.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Current volume V_p = J_p V_p^0.
    #[inline]
    pub fn volume(&self, p: usize) -> f64 {
        self.j[p] * self.volume0[p]
    }
}
