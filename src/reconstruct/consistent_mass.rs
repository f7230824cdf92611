//! The particle sums of the original MPM solved with the consistent mass matrix of the same
//! quadrature, M_ij = sum_p M_p N_ip N_jp: v = M^-1 p (Wobbes et al. eq 8 with the full
//! matrix) and a = M^-1 f, for the mapping, the grid solve and MUSL's remap alike. The L2
//! projection it makes reproduces every field the basis spans, also in the first and last
//! knot spans of the open B-spline, where the lumped average does not reproduce a linear
//! field (docs/NOTES.md, BSMPM at the boundary).

use nalgebra::SVector;

use super::mass_matrix::{MassMatrix, MassSolver};
use super::shepard::{momentum_sums, particle_sums};
use crate::divergence::Divergence;
use crate::grid::{FixedDof, GridState};
use crate::particles::Particles;
use crate::shape::Stencils;

pub struct ConsistentMassTransfer<const D: usize> {
    solver: MassSolver<D>,
}

impl<const D: usize> ConsistentMassTransfer<D> {
    /// A transfer on a lattice of `dofs_per_axis` DOFs per axis.
    pub fn new(dofs_per_axis: usize, fixed: &[FixedDof]) -> Self {
        ConsistentMassTransfer {
            solver: MassSolver::new(MassMatrix::Consistent, dofs_per_axis, fixed),
        }
    }

    /// Lumped mass, momentum and force as the original MPM sums them, the consistent matrix
    /// from the same stencils (particles in order), and the velocity solved from it.
    pub fn map_to_grid(
        &mut self,
        stencils: &Stencils<D>,
        particles: &Particles<D>,
        body_force: &[SVector<f64, D>],
        grid: &mut GridState<D>,
    ) -> Result<(), Divergence> {
        particle_sums(stencils, particles, body_force, grid);
        self.solver.reset(stencils.bandwidth());
        self.solver
            .add_points(stencils.for_values(), 0..particles.len(), |p| {
                particles.mass[p]
            });
        self.solver.prepare(&grid.mass, grid.empty_mass)?;
        self.solver
            .solve_momenta(&grid.mass, grid.empty_mass, &mut grid.velocity)
    }

    /// MUSL's v_i^L: the momenta of the updated particle velocities solved with this step's
    /// matrix.
    pub fn remap_velocity(
        &mut self,
        stencils: &Stencils<D>,
        particles: &Particles<D>,
        grid: &GridState<D>,
        out: &mut [SVector<f64, D>],
    ) -> Result<(), Divergence> {
        momentum_sums(stencils, particles, out);
        self.solver.solve_momenta(&grid.mass, grid.empty_mass, out)
    }

    /// a = M^-1 f, v_new = v + kick a; fixed components and empty DOFs held at zero.
    /// Afterwards `force` holds a.
    pub fn solve_grid(&mut self, grid: &mut GridState<D>, kick: f64) -> Result<(), Divergence> {
        self.solver.solve_grid(grid, kick)
    }

    /// Total of p_i at the last mapping or remap, before the solve.
    pub fn momentum_total(&self) -> SVector<f64, D> {
        self.solver.received_momentum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::{Dofs, Domain, Grid};
    use crate::particles::SeedLattice;
    use crate::reconstruct::remap_velocity;
    use crate::shape::{Shape, SplineDegree};
    use nalgebra::SMatrix;

    /// The open quadratic B-spline on [0, cells] (h = 1) with three particles of unit mass per
    /// knot span at xi = 1/6, 1/2, 5/6, moving with v = x.
    fn boundary_spans(cells: usize) -> (Grid<1>, Particles<1>, Stencils<1>) {
        seeded(cells as f64, cells, 3)
    }

    /// The open quadratic B-spline on [0, length] with `ppc` particles of unit mass per knot
    /// span at the centres of equal sub-cells, moving with v = x.
    fn seeded(length: f64, cells: usize, ppc: usize) -> (Grid<1>, Particles<1>, Stencils<1>) {
        let grid = Grid::with_dofs(
            &Domain {
                lower: SVector::repeat(0.0),
                upper: SVector::repeat(length),
                cells,
            },
            SplineDegree::Quadratic.dofs(),
        );
        let n = ppc * cells;
        let spacing = length / n as f64;
        let x: Vec<SVector<f64, 1>> = (0..n)
            .map(|k| SVector::repeat((k as f64 + 0.5) * spacing))
            .collect();
        let particles = Particles {
            x0: x.clone(),
            v: x.clone(),
            x,
            f: vec![SMatrix::identity(); n],
            j: vec![1.0; n],
            stress: vec![SMatrix::zeros(); n],
            mass: vec![1.0; n],
            volume0: vec![spacing; n],
            volume: vec![spacing; n],
            lattice: SeedLattice {
                lower: SVector::zeros(),
                spacing,
                per_axis: [n],
            },
        };
        let mut stencils = Stencils::new(SplineDegree::Quadratic.shape::<1>().nodes_per_point(), n);
        stencils
            .update(SplineDegree::Quadratic.shape(), &grid, &particles.x)
            .unwrap();
        (grid, particles, stencils)
    }

    /// The lumped average sum_p M_p B_ip v_p / m_i and the consistent projection of v = x.
    fn projections(cells: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let (grid, particles, stencils) = boundary_spans(cells);
        let body = vec![SVector::zeros(); particles.len()];
        let mut lumped = GridState::new(grid.num_nodes(), 1.0);
        crate::reconstruct::particles_to_grid(&stencils, &particles, &body, &mut lumped);
        let mut consistent = GridState::new(grid.num_nodes(), 1.0);
        let mut transfer = ConsistentMassTransfer::new(grid.nodes_per_dim(), &[]);
        transfer
            .map_to_grid(&stencils, &particles, &body, &mut consistent)
            .unwrap();
        let mut remapped = vec![SVector::zeros(); grid.num_nodes()];
        transfer
            .remap_velocity(&stencils, &particles, &consistent, &mut remapped)
            .unwrap();
        for (a, b) in remapped.iter().zip(&consistent.velocity) {
            assert_eq!(a, b, "the remap of unchanged velocities is the mapping");
        }
        let mut lumped_remap = vec![SVector::zeros(); grid.num_nodes()];
        remap_velocity(
            &stencils,
            &particles,
            &lumped.mass,
            lumped.empty_mass,
            &mut lumped_remap,
        );
        assert_eq!(lumped_remap, lumped.velocity);
        (
            lumped.mass.clone(),
            lumped.velocity.iter().map(|v| v[0]).collect(),
            consistent.velocity.iter().map(|v| v[0]).collect(),
        )
    }

    fn assert_close(got: &[f64], want: &[f64], what: &str) {
        for (i, (g, w)) in got.iter().zip(want).enumerate() {
            assert!((g - w).abs() < 1e-14, "{what}, DOF {i}: {g} against {w}");
        }
    }

    /// One knot span: the Bernstein polynomials (1 - xi)^2, 2 xi (1 - xi), xi^2. Lumped masses
    /// 35/36, 38/36, 35/36; the lumped average of v = x puts 57/210 at the end DOF, whose
    /// Greville abscissa is 0; the consistent projection returns the Greville abscissae 0,
    /// 1/2, 1, so sum_i c_i B_i = x.
    #[test]
    fn one_knot_span_against_hand_values() {
        let (mass, lumped, consistent) = projections(1);
        assert_close(&mass, &[35.0 / 36.0, 38.0 / 36.0, 35.0 / 36.0], "mass");
        assert_close(&lumped, &[57.0 / 210.0, 0.5, 153.0 / 210.0], "lumped");
        assert_close(&consistent, &[0.0, 0.5, 1.0], "consistent");
    }

    /// Two knot spans: B_1 = 2 xi - 3 xi^2 / 2 on [0, 1] and (1 - xi)^2 / 2 on [1, 2] is not
    /// symmetric about its Greville abscissa 1/2. Its lumped mass is 146/72 and the lumped
    /// average of v = x there is 108/146 (the particle-quadrature centroid of B_1; 3/4 exactly
    /// integrated), so the lumped field's slope at x = 0 is 2 v_1 = 216/146, not 1: the O(1)
    /// strain-rate error of BSMPM's first knot span. The consistent projection is exact.
    #[test]
    fn two_knot_spans_against_hand_values() {
        let (mass, lumped, consistent) = projections(2);
        assert!((mass[1] - 146.0 / 72.0).abs() < 1e-14, "m_1 = {}", mass[1]);
        assert!(
            (lumped[1] - 108.0 / 146.0).abs() < 1e-14,
            "v_1 = {}",
            lumped[1]
        );
        assert_close(
            &lumped[1..3],
            &[108.0 / 146.0, 2.0 - 108.0 / 146.0],
            "lumped",
        );
        assert_close(&consistent, &[0.0, 0.5, 1.5, 2.0], "consistent");
        // The slope at x = 0 with the end DOF held at rest, as the bar's fixed end is.
        let (grid, _, _) = boundary_spans(2);
        let mut at_end = Stencils::new(3, 1);
        at_end
            .update(SplineDegree::Quadratic.shape(), &grid, &[SVector::zeros()])
            .unwrap();
        let slope = |v: &[f64]| -> f64 {
            at_end
                .of(0)
                .filter(|&(i, _, _)| i != 0)
                .map(|(i, _, g)| v[i] * g[0])
                .sum()
        };
        assert!((slope(&consistent) - 1.0).abs() < 1e-13);
        assert!(
            (slope(&lumped) - 216.0 / 146.0).abs() < 1e-13,
            "slope {}",
            slope(&lumped)
        );
    }

    /// Scattered particles with random masses and v = 2 - 3x: the projection is exact at
    /// every DOF (linear reproduction), the DOFs receive the particles' momentum,
    /// sum_i m_i v_i = 1^T M v = 1^T p, and the accelerations of internal forces carry no net
    /// momentum, sum_i m_i a_i = sum_i f_i = 0, to round-off.
    #[test]
    fn reproduces_linear_fields_and_conserves_momentum() {
        let (grid, mut particles, mut stencils) = boundary_spans(5);
        let mut rng = crate::rng::Lcg::new(11);
        for p in 0..particles.len() {
            particles.x[p][0] += 0.3 * (rng.unit() - 0.5);
            particles.mass[p] = 0.5 + rng.unit();
            particles.v[p][0] = 2.0 - 3.0 * particles.x[p][0];
            particles.stress[p][(0, 0)] = 1e3 * (rng.unit() - 0.5);
        }
        stencils
            .update(SplineDegree::Quadratic.shape(), &grid, &particles.x)
            .unwrap();
        let body = vec![SVector::zeros(); particles.len()];
        let mut nodes = GridState::new(grid.num_nodes(), 1.0);
        let mut transfer = ConsistentMassTransfer::new(grid.nodes_per_dim(), &[]);
        transfer
            .map_to_grid(&stencils, &particles, &body, &mut nodes)
            .unwrap();
        for i in 0..grid.num_nodes() {
            let want = 2.0 - 3.0 * grid.node_position(i)[0];
            assert!((nodes.velocity[i][0] - want).abs() < 1e-12, "DOF {i}");
        }
        let momentum: f64 = (0..particles.len())
            .map(|p| particles.mass[p] * particles.v[p][0])
            .sum();
        let received: f64 = (0..grid.num_nodes())
            .map(|i| nodes.mass[i] * nodes.velocity[i][0])
            .sum();
        assert!((received - momentum).abs() < 1e-13 * momentum.abs());
        assert!((transfer.momentum_total()[0] - momentum).abs() < 1e-13 * momentum.abs());
        transfer.solve_grid(&mut nodes, 1e-3).unwrap();
        let net: f64 = (0..grid.num_nodes())
            .map(|i| nodes.mass[i] * nodes.force[i][0])
            .sum();
        assert!(net.abs() < 1e-9, "net force {net}");
    }

    /// The derivative of the L2 projection of v = sin(pi x) onto the open quadratic B-spline
    /// (12 particles per span, ends held at zero, as the vibrating bar is seeded): its RMS
    /// error at the particles against pi cos(pi x) falls at second order, the values of an
    /// independent dense computation. BSMPM's stress with a consistent projection is
    /// E t (projected v)' for the small-strain bar, so it cannot converge at third order.
    #[test]
    fn projected_gradient_of_a_sine_converges_at_second_order() {
        let expected = [
            (5, 0.033_683_887_662_972_76),
            (10, 0.008_126_062_962_578_626),
            (20, 0.002_013_269_743_838_646_7),
            (40, 0.000_502_179_894_582_471_5),
        ];
        let mut previous: Option<f64> = None;
        for (cells, want) in expected {
            let (grid, mut particles, stencils) = seeded(1.0, cells, 12);
            let n = particles.len();
            for p in 0..n {
                particles.v[p][0] = (std::f64::consts::PI * particles.x[p][0]).sin();
            }
            let last = (grid.num_nodes() - 1) as u32;
            let mut nodes = GridState::new(grid.num_nodes(), 1.0 / n as f64);
            let mut transfer =
                ConsistentMassTransfer::new(grid.nodes_per_dim(), &[(0, 0), (last, 0)]);
            let body = vec![SVector::zeros(); n];
            transfer
                .map_to_grid(&stencils, &particles, &body, &mut nodes)
                .unwrap();
            let squares: f64 = (0..n)
                .map(|p| {
                    let slope: f64 = stencils
                        .of(p)
                        .map(|(i, _, g)| nodes.velocity[i][0] * g[0])
                        .sum();
                    let exact =
                        std::f64::consts::PI * (std::f64::consts::PI * particles.x[p][0]).cos();
                    (slope - exact).powi(2)
                })
                .sum();
            let rms = (squares / n as f64).sqrt();
            assert!(
                (rms - want).abs() < 1e-9 * want,
                "{cells} cells: {rms} against {want}"
            );
            if let Some(coarse) = previous {
                let rate = (coarse / rms).log2();
                assert!((rate - 2.0).abs() < 0.1, "{cells} cells: rate {rate}");
            }
            previous = Some(rms);
        }
    }

    /// On a 2D grid of 32 cells the band is a grid row wide and the solve iterates: the
    /// projection of v = (1 + 2x - y, 3 - x + 4y) from jittered particles of random mass is
    /// still exact at every DOF that carries mass, with the lumped preconditioner (the hat)
    /// and with the line sums (the quadratic B-spline).
    fn check_iterative_solve_2d<S: Shape<2> + ?Sized>(shape: &S, dofs: Dofs, with_lines: bool) {
        use crate::benchmarks::Problem;
        let prob = crate::benchmarks::gong_mms::<2>(&crate::benchmarks::thesis_params(1e-4, 32, 2))
            .unwrap();
        let grid = Grid::with_dofs(&prob.domain(), dofs);
        let mut particles = prob.seed_particles(&grid);
        let mut rng = crate::rng::Lcg::new(5);
        let field = |x: &SVector<f64, 2>| {
            SVector::<f64, 2>::from([1.0 + 2.0 * x[0] - x[1], 3.0 - x[0] + 4.0 * x[1]])
        };
        for p in 0..particles.len() {
            particles.x[p] += SVector::<f64, 2>::from_fn(|_, _| 0.004 * (rng.unit() - 0.5));
            particles.x[p] = particles.x[p].map(|c| c.clamp(0.0, 1.0));
            particles.mass[p] *= 0.5 + rng.unit();
            particles.v[p] = field(&particles.x[p]);
        }
        let mut stencils = Stencils::new(shape.nodes_per_point(), particles.len());
        stencils.update(shape, &grid, &particles.x).unwrap();
        let mut transfer = ConsistentMassTransfer::new(grid.nodes_per_dim(), &[]);
        let mut nodes = GridState::new(grid.num_nodes(), particles.mass[0]);
        let body = vec![SVector::zeros(); particles.len()];
        transfer
            .map_to_grid(&stencils, &particles, &body, &mut nodes)
            .unwrap();
        assert!(
            !transfer.solver.is_direct(),
            "the 2D band should be iterated"
        );
        assert_eq!(transfer.solver.uses_line_sums(), with_lines);
        let mut checked = 0;
        for i in 0..grid.num_nodes() {
            let want = field(&grid.node_position(i));
            for k in 0..2 {
                let got = nodes.velocity[i][k];
                if nodes.mass[i] > nodes.empty_mass {
                    assert!(
                        (got - want[k]).abs() < 1e-10 * want.amax(),
                        "DOF {i}, {k}: {got}"
                    );
                    checked += 1;
                }
            }
        }
        let per_axis = grid.nodes_per_dim();
        assert!(checked > 2 * per_axis * per_axis - 10);
    }

    #[test]
    fn the_iterative_solve_reproduces_linear_fields_in_2d() {
        check_iterative_solve_2d(&crate::shape::LinearHat, Dofs::Nodes, false);
        check_iterative_solve_2d(
            SplineDegree::Quadratic.shape(),
            SplineDegree::Quadratic.dofs(),
            true,
        );
    }
}
