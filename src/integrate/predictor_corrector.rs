//! The explicit predictor-corrector of Molinos et al. sec 4 (Newmark with gamma = 1/2,
//! beta = 0): the grid carries its nodal velocity from step to step instead of mapping it from
//! the particles, and the particle velocities are a post-process.
//!
//! With a^s = f^s / m^s at the particles' positions x^s, the algorithm box reads
//!   corrector  v_i^s       = v~_i^s + dt/2 a_i^s            (step 7 of the previous step)
//!   predictor  v~_i^{s+1}  = v_i^s + dt/2 a_i^s             (step 1)
//!   move       x_p^{s+1}   = x_p^s + dt sum_i N_ip v~_i^{s+1} (eq 28, step 8)
//!   strain     from grad v~^{s+1}                              (step 4)
//! so the predictor is v~^{s+1} = v~^s + dt a^s: the leapfrog update with the nodal velocity
//! v~^s carried over from the last step in place of the velocity mapped from the particles.
//! The particle velocities take the same two half kicks, which is the leapfrog's particle
//! update (`leapfrog::update_particles`, output by `leapfrog::synchronized_velocity`).
//!
//! A node that had no mass at the last step carries nothing; it starts from the velocity the
//! transfer mapped from the particles, as every node does at s = 0 (docs/NOTES.md).

use nalgebra::SVector;

use crate::reconstruct::GridState;

/// The predictor v~^{s+1} of the last step at every node, and which nodes had mass then.
pub struct CarriedVelocity<const D: usize> {
    predicted: Vec<SVector<f64, D>>,
    carried: Vec<bool>,
}

impl<const D: usize> CarriedVelocity<D> {
    /// Nothing carried: the first step starts from the mapped velocities.
    pub fn new(nodes: usize) -> Self {
        CarriedVelocity {
            predicted: vec![SVector::zeros(); nodes],
            carried: vec![false; nodes],
        }
    }

    /// Before the grid solve: the start-of-step nodal velocity becomes the carried predictor
    /// where there is one, so that the solve's v + kick a is the next predictor.
    pub fn substitute(&self, grid: &mut GridState<D>) {
        for (i, v) in grid.velocity.iter_mut().enumerate() {
            if self.carried[i] {
                *v = self.predicted[i];
            }
        }
    }

    /// After the grid solve (empty nodes and fixed components at rest): keeps the predictor
    /// for the next step.
    pub fn keep(&mut self, grid: &GridState<D>) {
        self.predicted.copy_from_slice(&grid.velocity_new);
        for (carried, &m) in self.carried.iter_mut().zip(&grid.mass) {
            *carried = m > grid.empty_mass;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::solve_grid;

    /// One node with a fixed force: after the first half kick the predictor advances by whole
    /// kicks of dt a, i.e. v~^{s+1} = v^0 + (s + 1/2) dt a, whatever the particles carry.
    #[test]
    fn predictor_advances_by_whole_kicks_from_the_carried_velocity() {
        let (dt, a, v0) = (0.1, 2.0, 1.0);
        let mut grid = GridState::<1>::new(1, 1.0);
        let mut carried = CarriedVelocity::new(1);
        for s in 0..4 {
            grid.mass[0] = 1.0;
            grid.force[0] = SVector::repeat(a);
            // What the transfer maps from the particles: ignored once a velocity is carried.
            grid.velocity[0] = SVector::repeat(if s == 0 { v0 } else { -7.0 });
            carried.substitute(&mut grid);
            let kick = if s == 0 { 0.5 * dt } else { dt };
            solve_grid(&mut grid, &[], kick);
            carried.keep(&grid);
            let expected = v0 + (s as f64 + 0.5) * dt * a;
            assert!((grid.velocity_new[0][0] - expected).abs() < 1e-14);
        }
    }

    /// A node that was empty carries nothing and starts from the mapped velocity.
    #[test]
    fn a_node_without_mass_starts_from_the_mapped_velocity() {
        let mut grid = GridState::<1>::new(2, 1.0);
        let mut carried = CarriedVelocity::new(2);
        grid.mass = vec![1.0, 0.0];
        grid.velocity = vec![SVector::repeat(3.0), SVector::repeat(0.0)];
        solve_grid(&mut grid, &[], 0.0);
        carried.keep(&grid);
        grid.mass = vec![1.0, 1.0];
        grid.velocity = vec![SVector::repeat(-1.0), SVector::repeat(5.0)];
        grid.force = vec![SVector::zeros(); 2];
        carried.substitute(&mut grid);
        assert_eq!(grid.velocity[0][0], 3.0);
        assert_eq!(grid.velocity[1][0], 5.0);
    }
}
