//! The explicit predictor-corrector of Molinos et al. sec 4 (Newmark, gamma = 1/2) as the
//! authors' code runs it (NL-PartSol, GraMS tree `Code/src`: `Formulations/U_PCE.c`,
//! `MPM/Update_Eulerian.c` `compute_VelocityPredictor` and `compute_VelocityCorrector`,
//! `MPM/Update_Lagrangian.c` `update_Particles_PCE`). Every step maps the predictor from the
//! particles, with N and grad N at the start-of-step positions x_p:
//!   1. m_i = sum_p N_ip m_p,  v~_i = sum_p m_p N_ip (v_p + dt/2 a_p) / m_i, fixed components 0
//!   2. the stress of every particle from grad v~ (algorithm steps 4-5)
//!   3. f_i = f_int + f_ext with the new stress, fixed components 0
//!   4. the corrector v_i = v~_i + dt/2 f_i / m_i
//!   5. a_p = sum_i N_ip f_i / m_i, v_p += dt a_p, x_p += dt sum_i N_ip (v_i + dt/2 f_i / m_i)
//!
//! with a_p = 0 before the first step. The particle velocity is whole-step (the one the code
//! steps and writes). The scheme is first order in time and damps every mode: for one
//! oscillator of frequency w its amplification factor z obeys |z|^2 = 1 - (w dt)^2 / 2
//! (docs/NOTES.md, "the predictor-corrector").

use nalgebra::SVector;

use super::musl::move_particles;
use super::solve_grid;
use crate::divergence::Divergence;
use crate::grid::{FixedDof, GridState};
use crate::particles::Particles;
use crate::reconstruct::map_velocity;
use crate::shape::Stencils;

/// The particle accelerations the predictor needs, and the scratch arrays of one step; sized
/// by the first step, so a run of another integrator allocates nothing.
#[derive(Default)]
pub struct PredictorCorrector<const D: usize> {
    /// a_p of the last step; zero before the first.
    acceleration: Vec<SVector<f64, D>>,
    /// v_p + dt/2 a_p: what the predictor maps.
    predicted: Vec<SVector<f64, D>>,
    /// v_i + dt/2 a_i: the nodal velocity the particles move with.
    drift: Vec<SVector<f64, D>>,
}

impl<const D: usize> PredictorCorrector<D> {
    /// Step 1 before the boundary conditions: the nodal mass and the predictor v~_i in
    /// `grid.velocity` (empty nodes at rest); `grid.force` is cleared.
    pub fn predict(
        &mut self,
        stencils: &Stencils<D>,
        particles: &Particles<D>,
        dt: f64,
        grid: &mut GridState<D>,
    ) {
        self.acceleration.resize(particles.len(), SVector::zeros());
        self.predicted.resize(particles.len(), SVector::zeros());
        for ((u, v), a) in self
            .predicted
            .iter_mut()
            .zip(&particles.v)
            .zip(&self.acceleration)
        {
            *u = v + a * (0.5 * dt);
        }
        map_velocity(stencils, &particles.mass, &self.predicted, grid);
    }

    /// The particle velocities the last `predict` mapped, v_p + dt/2 a_p.
    pub fn predicted(&self) -> &[SVector<f64, D>] {
        &self.predicted
    }

    /// Step 4, once `grid.force` holds f_i from the stress of step 2: a_i in `grid.force`,
    /// the corrected v_i in `grid.velocity_new`, both zero at fixed components and empty
    /// nodes; returns v_i + dt/2 a_i, the velocity the particles (and particle domains) move
    /// with.
    pub fn correct(
        &mut self,
        grid: &mut GridState<D>,
        fixed: &[FixedDof],
        dt: f64,
    ) -> &[SVector<f64, D>] {
        solve_grid(grid, fixed, 0.5 * dt);
        self.drift.resize(grid.mass.len(), SVector::zeros());
        for ((d, v), a) in self
            .drift
            .iter_mut()
            .zip(&grid.velocity_new)
            .zip(&grid.force)
        {
            *d = v + a * (0.5 * dt);
        }
        &self.drift
    }

    /// Step 5: a_p = sum_i N_ip a_i, v_p += dt a_p, x_p += dt sum_i N_ip (v_i + dt/2 a_i);
    /// a_p is kept for the next predictor.
    pub fn move_particles(
        &mut self,
        stencils: &Stencils<D>,
        particles: &mut Particles<D>,
        grid: &GridState<D>,
        dt: f64,
    ) -> Result<(), Divergence> {
        let acceleration = Some(self.acceleration.as_mut_slice());
        move_particles(stencils, particles, grid, &self.drift, dt, acceleration)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmarks::{gong_mms, thesis_params, Problem};
    use crate::grid::Grid;
    use crate::reconstruct::nodal_forces;
    use crate::shape::{LinearHat, Shape};
    use nalgebra::SMatrix;

    /// One particle on a grid of one cell [0, 1] at x, with its stencil.
    fn one_particle(x: f64) -> (Particles<1>, Stencils<1>) {
        let problem = gong_mms::<1>(&thesis_params(0.0, 1, 1)).unwrap();
        let grid = Grid::<1>::new(&problem.domain());
        assert_eq!((grid.lower[0], grid.h), (0.0, 1.0));
        let mut particles = problem.seed_particles(&grid);
        assert_eq!(particles.len(), 1);
        particles.x[0] = SVector::repeat(x);
        let mut stencils = Stencils::new(Shape::<1>::nodes_per_point(&LinearHat), 1);
        stencils.update(&LinearHat, &grid, &particles.x).unwrap();
        (particles, stencils)
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-14
    }

    /// One particle of mass 2 at x = 0.25 of a unit cell (N = 0.75, 0.25), with v_p = 1,
    /// a_p = 4, dt = 0.1 and a nodal force f = (1, -3) standing in for step 3. By hand:
    /// m = (1.5, 0.5); v~ = 1 + 0.05 * 4 = 1.2 at both nodes (the particle is their only
    /// mass); a = (2/3, -6); v = v~ + 0.05 a = (1.2 + 1/30, 0.9); the drift v + 0.05 a is
    /// (1.2 + 1/15, 0.6); a_p = 0.75 * 2/3 - 0.25 * 6 = -1, v_p = 1 - 0.1 = 0.9, and
    /// x_p = 0.25 + 0.1 (0.75 (1.2 + 1/15) + 0.25 * 0.6) = 0.25 + 0.1 * 1.1.
    #[test]
    fn one_particle_two_nodes_by_hand() {
        let (mut particles, stencils) = one_particle(0.25);
        particles.mass[0] = 2.0;
        particles.v[0] = SVector::repeat(1.0);
        let mut pc = PredictorCorrector::<1> {
            acceleration: vec![SVector::repeat(4.0)],
            ..Default::default()
        };
        let mut grid = GridState::<1>::new(2, 2.0);
        let dt = 0.1;
        pc.predict(&stencils, &particles, dt, &mut grid);
        assert!(close(grid.mass[0], 1.5) && close(grid.mass[1], 0.5));
        assert!(grid.velocity.iter().all(|v| close(v[0], 1.2)));
        grid.force = vec![SVector::repeat(1.0), SVector::repeat(-3.0)];
        let drift = pc.correct(&mut grid, &[], dt).to_vec();
        assert!(close(grid.force[0][0], 2.0 / 3.0) && close(grid.force[1][0], -6.0));
        assert!(close(grid.velocity_new[0][0], 1.2 + 1.0 / 30.0));
        assert!(close(grid.velocity_new[1][0], 0.9));
        assert!(close(drift[0][0], 1.2 + 1.0 / 15.0) && close(drift[1][0], 0.6));
        pc.move_particles(&stencils, &mut particles, &grid, dt)
            .unwrap();
        assert!(close(pc.acceleration[0][0], -1.0));
        assert!(close(particles.v[0][0], 0.9));
        assert!(close(particles.x[0][0], 0.25 + 0.1 * 1.1));
    }

    /// A fixed component has no acceleration and is at rest after the corrector, whatever
    /// the predictor gave it.
    #[test]
    fn the_corrector_holds_fixed_components() {
        let (mut particles, stencils) = one_particle(0.5);
        particles.v[0] = SVector::repeat(3.0);
        let mut pc = PredictorCorrector::<1>::default();
        let mut grid = GridState::<1>::new(2, particles.mass[0]);
        pc.predict(&stencils, &particles, 0.1, &mut grid);
        assert!(grid.velocity.iter().all(|v| close(v[0], 3.0)));
        grid.force = vec![SVector::repeat(5.0), SVector::repeat(5.0)];
        let drift = pc.correct(&mut grid, &[(0, 0)], 0.1).to_vec();
        assert_eq!((grid.force[0][0], grid.velocity_new[0][0]), (0.0, 0.0));
        assert_eq!(drift[0][0], 0.0);
        assert!(grid.force[1][0] > 0.0);
    }

    /// The uGIMP free end in miniature: a node whose weight, and so whose mass, goes to zero
    /// while the particle's stress pulls on it through a gradient that does not, so that
    /// f_i / m_i grows without bound. Mapped from the particle every step, the node starts
    /// each step at the particle's velocity, and what it passes back (N a, N (v + dt/2 a))
    /// stays bounded: nothing accumulates at the node however small its mass.
    #[test]
    fn a_node_of_vanishing_mass_does_not_run_away() {
        for eps in [1e-3, 1e-6, 1e-9] {
            let (mut particles, stencils) = one_particle(1.0 - eps);
            particles.v[0] = SVector::repeat(1.0);
            particles.stress[0] = SMatrix::repeat(1.0e6);
            let mut pc = PredictorCorrector::<1>::default();
            let mut grid = GridState::<1>::new(2, particles.mass[0]);
            let dt = 1e-7;
            for step in 0..50 {
                pc.predict(&stencils, &particles, dt, &mut grid);
                for v in &grid.velocity {
                    assert!(
                        (v[0] - 1.0).abs() < 1e-9,
                        "eps {eps}, step {step}: a node starts at {}",
                        v[0]
                    );
                }
                nodal_forces(&stencils, &particles, &[SVector::zeros()], &mut grid.force);
                pc.correct(&mut grid, &[], dt);
                // The largest acceleration is at the light node, yet the particle's, the sum
                // of N_i a_i, is zero: one free particle under its own stress keeps its
                // momentum.
                assert!(grid.force[0][0].abs() > 100.0 * grid.force[1][0].abs());
                pc.move_particles(&stencils, &mut particles, &grid, dt)
                    .unwrap();
                assert!((particles.v[0][0] - 1.0).abs() < 1e-9);
            }
        }
    }

    /// One particle at the middle of a unit cell whose left node is fixed is one oscillator:
    /// with K = E / h and B = V / (h m), the stress follows s += dt K v~ and the particle
    /// acceleration is a_p = -B s, so steps 1-5 give v~_(k+1) - v~_k = dt (3/2 a_k - 1/2
    /// a_(k-1)) and, with q = (w dt)^2 = dt^2 K B,
    ///   s_(k+1) - (2 - 3q/2) s_k + (1 - q/2) s_(k-1) = 0,
    /// whose roots have |z|^2 = 1 - q/2: the scheme loses (w dt)^2 / 4 of the amplitude of
    /// every mode per step (first order in dt over a fixed time). The leapfrog's recurrence,
    /// s_(k+1) - (2 - q) s_k + s_(k-1) = 0, keeps it.
    #[test]
    fn one_oscillator_follows_the_damped_recurrence() {
        use crate::integrate::deform_particles;
        use crate::material::{LinearElasticRate, Material};
        let (mut particles, stencils) = one_particle(0.5);
        let young = 1.0e7;
        let material = Material::LinearElasticRate(LinearElasticRate::without_poisson(young));
        // A velocity small enough that J stays 1 to 1e-11, so that V, and so B, are constant.
        particles.v[0] = SVector::repeat(1.0e-6);
        let (mass, volume, h) = (particles.mass[0], particles.volume0[0], 1.0);
        let dt = 1.0e-3;
        let q = dt * dt * (young / h) * (volume / (h * mass));
        assert!((q - 0.01).abs() < 1e-12, "q = {q}");
        let fixed = [(0u32, 0u8)];
        let mut pc = PredictorCorrector::<1>::default();
        let mut grid = GridState::<1>::new(2, mass);
        let mut stress = vec![0.0];
        for _ in 0..400 {
            pc.predict(&stencils, &particles, dt, &mut grid);
            crate::integrate::apply_fixed(&mut grid.velocity, &fixed);
            deform_particles(&stencils, &mut particles, &grid.velocity, dt, &material).unwrap();
            nodal_forces(&stencils, &particles, &[SVector::zeros()], &mut grid.force);
            pc.correct(&mut grid, &fixed, dt);
            pc.move_particles(&stencils, &mut particles, &grid, dt)
                .unwrap();
            stress.push(particles.stress[0][(0, 0)]);
        }
        let largest = stress.iter().fold(0.0f64, |m, s| m.max(s.abs()));
        for k in 1..stress.len() - 1 {
            let residual =
                stress[k + 1] - (2.0 - 1.5 * q) * stress[k] + (1.0 - 0.5 * q) * stress[k - 1];
            assert!(
                residual.abs() < 1e-9 * largest,
                "step {k}: residual {residual:e} of {largest:e}"
            );
        }
        // The envelope between the largest value of the first period (about 63 steps) and
        // that of the last falls as |z|^(steps between them).
        let peak = |range: std::ops::Range<usize>| {
            range
                .map(|k| (k, stress[k].abs()))
                .fold(
                    (0, 0.0),
                    |best, (k, a)| if a > best.1 { (k, a) } else { best },
                )
        };
        let (first, a0) = peak(1..64);
        let (last, a1) = peak(stress.len() - 63..stress.len());
        let expected = (1.0 - 0.5 * q).powf(0.5 * (last - first) as f64);
        let ratio = a1 / a0;
        assert!(expected < 0.45, "a real decay: {expected}");
        assert!(
            (ratio / expected - 1.0).abs() < 0.01,
            "amplitude ratio {ratio}, expected {expected}"
        );
    }
}
