use nalgebra::{SMatrix, SVector};

use crate::grid::GridState;
use crate::parallel;
use crate::particles::Particles;
use crate::shape::Stencils;

/// The original MPM mapping (Gong sec 4.4 step 1): lumped mass m_i = sum_p M_p N_ip,
/// velocity v_i = sum_p M_p v_p N_ip / m_i (Shepard interpolation with weight M_p N_ip; left
/// zero at empty nodes),
/// and force f_i = -sum_p V_p sigma_p grad N_ip + sum_p M_p b_p N_ip by one-point
/// quadrature at the particles (V_p sigma_p = M_p sigma_p / rho_p, Gong's M_p sigma^s_p).
/// Particles are visited in order at every node, so the sums are the same on every run and
/// for any thread count.
pub fn particles_to_grid<const D: usize>(
    stencils: &Stencils<D>,
    particles: &Particles<D>,
    body_force: &[SVector<f64, D>],
    grid: &mut GridState<D>,
) {
    particle_sums(stencils, particles, body_force, grid);
    momentum_to_velocity(&mut grid.velocity, &grid.mass, grid.empty_mass);
}

/// The sums of `particles_to_grid` with the momentum p_i = sum_p M_p v_p N_ip left in
/// `grid.velocity`, for transfers that solve for the velocity with a mass matrix.
pub fn particle_sums<const D: usize>(
    stencils: &Stencils<D>,
    particles: &Particles<D>,
    body_force: &[SVector<f64, D>],
    grid: &mut GridState<D>,
) {
    mass_force_sums::<D, true>(stencils, particles, body_force, grid);
}

/// The masses and forces of `particles_to_grid`, `grid.velocity` cleared: for transfers that
/// make the nodal velocity another way (a fit of the particle velocities), which would
/// discard the momenta.
pub fn mass_and_forces<const D: usize>(
    stencils: &Stencils<D>,
    particles: &Particles<D>,
    body_force: &[SVector<f64, D>],
    grid: &mut GridState<D>,
) {
    mass_force_sums::<D, false>(stencils, particles, body_force, grid);
}

/// Nodal masses and forces, and with `MOMENTUM` the momenta into `grid.velocity`; each sum's
/// terms and order the same either way.
fn mass_force_sums<const D: usize, const MOMENTUM: bool>(
    stencils: &Stencils<D>,
    particles: &Particles<D>,
    body_force: &[SVector<f64, D>],
    grid: &mut GridState<D>,
) {
    if stencils.has_value_entries() || stencils.dual_domain().is_some() {
        // Mass (and momentum) over the entries with values, the forces over all of them (or
        // in factored form).
        lumped_sums::<D, MOMENTUM>(stencils, &particles.mass, &particles.v, grid);
        nodal_forces(stencils, particles, body_force, &mut grid.force);
        return;
    }
    grid.clear();
    let len = parallel::block_len(grid.mass.len());
    let blocks = grid
        .mass
        .chunks_mut(len)
        .zip(grid.velocity.chunks_mut(len))
        .zip(grid.force.chunks_mut(len));
    let point = |p: usize| {
        let m = particles.mass[p];
        let vs = particles.stress[p] * particles.volume(p);
        (m, particles.v[p] * m, vs, body_force[p] * m)
    };
    stencils.scatter(
        particles.len(),
        len,
        blocks,
        point,
        |((mass, velocity), force), i, (m, mv, vs, mb), w, g| {
            mass[i] += m * w;
            if MOMENTUM {
                velocity[i] += mv * w;
            }
            force[i] += mb * w - vs * g;
        },
    );
}

/// The Shepard mapping of mass and of one velocity per particle, with no forces: m_i as in
/// `particles_to_grid`, v_i = sum_p M_p u_p N_ip / m_i, `grid.force` cleared (the
/// predictor of `integrate::predictor_corrector` maps u_p = v_p + dt/2 a_p this way).
pub fn map_velocity<const D: usize>(
    stencils: &Stencils<D>,
    mass: &[f64],
    velocity: &[SVector<f64, D>],
    grid: &mut GridState<D>,
) {
    lumped_sums::<D, true>(stencils, mass, velocity, grid);
    momentum_to_velocity(&mut grid.velocity, &grid.mass, grid.empty_mass);
}

/// m_i = sum_p M_p N_ip and, with `MOMENTUM`, the momenta sum_p M_p u_p N_ip into
/// `grid.velocity`, the rest of `grid` cleared.
fn lumped_sums<const D: usize, const MOMENTUM: bool>(
    stencils: &Stencils<D>,
    mass: &[f64],
    velocity: &[SVector<f64, D>],
    grid: &mut GridState<D>,
) {
    grid.clear();
    let len = parallel::block_len(grid.mass.len());
    let blocks = grid.mass.chunks_mut(len).zip(grid.velocity.chunks_mut(len));
    let point = |p: usize| (mass[p], velocity[p] * mass[p]);
    stencils.for_values().scatter(
        mass.len(),
        len,
        blocks,
        point,
        |(nodal_mass, momentum), i, (m, mu), w, _| {
            nodal_mass[i] += m * w;
            if MOMENTUM {
                momentum[i] += mu * w;
            }
        },
    );
}

/// The forces of `particles_to_grid` alone, into `force`: f_i = sum_p (M_p b_p N_ip -
/// V_p sigma_p grad N_ip), for integrators that update the stress after the mapping. For the
/// dual-domain basis the internal force is taken in factored form: T_j = sum_p N_jp V_p
/// sigma_p over the hat's entries, then f_i -= sum_j T_j A_ij
/// (`DualDomain::subtract_divergence`).
pub fn nodal_forces<const D: usize>(
    stencils: &Stencils<D>,
    particles: &Particles<D>,
    body_force: &[SVector<f64, D>],
    force: &mut [SVector<f64, D>],
) {
    force.fill(SVector::zeros());
    let len = parallel::block_len(force.len());
    let point = |p: usize| {
        let vs = particles.stress[p] * particles.volume(p);
        (vs, body_force[p] * particles.mass[p])
    };
    if let Some(dual) = stencils.dual_domain() {
        let mut stress = vec![SMatrix::<f64, D, D>::zeros(); force.len()];
        stencils.scatter(
            particles.len(),
            len,
            force.chunks_mut(len).zip(stress.chunks_mut(len)),
            point,
            |(force, stress), i, (vs, mb), w, _| {
                force[i] += mb * w;
                stress[i] += vs * w;
            },
        );
        dual.subtract_divergence(&stress, force);
        return;
    }
    stencils.scatter(
        particles.len(),
        len,
        force.chunks_mut(len),
        point,
        |force, i, (vs, mb), w, g| force[i] += mb * w - vs * g,
    );
}

/// MUSL's v_i^L for the Shepard mapping: sum_p M_p v_p N_ip / m_i with this step's weights
/// and Shepard masses m_i = sum_p M_p N_ip (nodes at or below `empty_mass` left at rest).
pub fn remap_velocity<const D: usize>(
    stencils: &Stencils<D>,
    particles: &Particles<D>,
    mass: &[f64],
    empty_mass: f64,
    out: &mut [SVector<f64, D>],
) {
    momentum_sums(stencils, particles, out);
    momentum_to_velocity(out, mass, empty_mass);
}

/// p_i = sum_p M_p v_p N_ip into `out`.
pub fn momentum_sums<const D: usize>(
    stencils: &Stencils<D>,
    particles: &Particles<D>,
    out: &mut [SVector<f64, D>],
) {
    out.fill(SVector::zeros());
    let len = parallel::block_len(out.len());
    stencils.for_values().scatter(
        particles.len(),
        len,
        out.chunks_mut(len),
        |p| particles.v[p] * particles.mass[p],
        |out, i, mv, w, _| out[i] += mv * w,
    );
}

/// Divides nodal momenta by the nodal masses; empty nodes are left at rest.
fn momentum_to_velocity<const D: usize>(
    velocity: &mut [SVector<f64, D>],
    mass: &[f64],
    empty_mass: f64,
) {
    for (v, &m) in velocity.iter_mut().zip(mass) {
        *v = if m > empty_mass {
            *v / m
        } else {
            SVector::zeros()
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmarks::{gong_mms, thesis_params, Problem, SineMms};
    use crate::grid::Grid;
    use crate::shape::{LinearHat, Shape};

    fn problem<const D: usize>() -> SineMms<D> {
        gong_mms(&thesis_params(0.1, 6, 3)).unwrap()
    }

    /// The transfer conserves mass and momentum and its internal forces sum to zero, to
    /// round-off, for scattered particles with arbitrary stress.
    fn check_conservation<const D: usize>() {
        let prob = problem::<D>();
        let grid = Grid::new(&prob.domain());
        let mut particles = prob.seed_particles(&grid);
        let mut rng = crate::rng::Lcg::new(12345);
        let mut rand = || rng.unit() - 0.5;
        for p in 0..particles.len() {
            particles.x[p] += SVector::<f64, D>::from_fn(|_, _| 0.05 * rand());
            particles.x[p] = particles.x[p].map(|c| c.clamp(0.0, 1.0));
            particles.v[p] = SVector::from_fn(|_, _| rand());
            particles.stress[p] = SMatrix::from_fn(|_, _| 1e3 * rand());
            particles.j[p] = 1.0 + 0.2 * rand();
        }
        let body = vec![SVector::<f64, D>::from_fn(|k, _| k as f64 - 9.81); particles.len()];
        let mut st = Stencils::new(Shape::<D>::nodes_per_point(&LinearHat), particles.len());
        st.update(&LinearHat, &grid, &particles.x).unwrap();
        let mut nodes = GridState::new(grid.num_nodes(), particles.mass[0]);
        particles_to_grid(&st, &particles, &body, &mut nodes);

        let total_mass: f64 = particles.mass.iter().sum();
        let momentum: SVector<f64, D> = (0..particles.len())
            .map(|p| particles.v[p] * particles.mass[p])
            .sum();
        let external: SVector<f64, D> = (0..particles.len())
            .map(|p| body[p] * particles.mass[p])
            .sum();
        let grid_mass: f64 = nodes.mass.iter().sum();
        let grid_momentum: SVector<f64, D> = (0..grid.num_nodes())
            .map(|i| nodes.velocity[i] * nodes.mass[i])
            .sum();
        let grid_force: SVector<f64, D> = nodes.force.iter().sum();
        assert!((grid_mass - total_mass).abs() < 1e-13 * total_mass);
        assert!((grid_momentum - momentum).norm() < 1e-12 * (1.0 + momentum.norm()));
        // Internal forces cancel: only the body force is left.
        assert!((grid_force - external).norm() < 1e-9 * (1.0 + external.norm()));
    }

    #[test]
    fn conserves_mass_momentum_and_force_balance_1d() {
        check_conservation::<1>();
    }

    #[test]
    fn conserves_mass_momentum_and_force_balance_2d() {
        check_conservation::<2>();
    }
}
