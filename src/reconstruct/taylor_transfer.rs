//! The Taylor least-squares transfer of Wobbes et al. sec 3. Per active element (a grid cell,
//! or a knot span for B-splines, holding particles): the stress is reconstructed by plain
//! least squares and integrated by Gauss quadrature into the internal forces; density and
//! momentum density are reconstructed with the element's mass and momentum prescribed (eq 5),
//! and integrated into the momentum vector p (eq 9) and the mass matrix M (eq 10), consistent
//! or lumped. The nodal velocity solves M v = p (eq 11) and the acceleration M a = f, with the
//! fixed velocity components removed from both systems.

use std::fmt;

use nalgebra::{SMatrix, SVector};

use super::mass_matrix::{MassMatrix, MassSolver};
use super::taylor::{Conservation, TaylorCell, TaylorFit, MAX_TAYLOR_TERMS};
use super::FitStats;
use crate::divergence::Divergence;
use crate::gauss::gauss_legendre_rule;
use crate::grid::{lattice_coords, FixedDof, Grid, GridState};
use crate::particles::Particles;
use crate::shape::{Shape, Stencils};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TaylorRecipe {
    /// Degree of the Taylor polynomials: 2 is Wobbes' quadratic TLS (n_b = 3 in 1D).
    pub degree: usize,
    /// Gauss-Legendre points per element and axis. Two integrate a quadratic density exactly,
    /// which is what conservation needs (n_b <= 2 N_g / N_e).
    pub gauss_points: usize,
    pub mass: MassMatrix,
}

pub struct TaylorTransfer<const D: usize> {
    recipe: TaylorRecipe,
    grid: Grid<D>,
    /// Basis values and gradients at the Gauss points, element by element: point q of
    /// element e is entry e * per_element + q.
    basis: Stencils<D>,
    gauss_x: Vec<SVector<f64, D>>,
    /// Weight of local Gauss point q, the same in every element.
    gauss_w: Vec<f64>,
    per_element: usize,
    /// Scratch: rho times the quadrature weight at each Gauss point of one element.
    point_scales: Vec<f64>,
    /// Sub-diagonals of the mass matrix in DOF numbering.
    bandwidth: usize,
    /// Particles sorted by element (a counting sort, stable in particle order).
    element_of: Vec<u32>,
    element_start: Vec<u32>,
    /// Scratch of the counting sort: the next free slot per element.
    next: Vec<u32>,
    order: Vec<u32>,
    /// Positions and densities of the sorted particles at the mapping, kept for the remap.
    points: Vec<SVector<f64, D>>,
    density: Vec<f64>,
    /// Scratch: the momentum densities and stresses of one element's particles.
    vectors: Vec<SVector<f64, D>>,
    tensors: Vec<SMatrix<f64, D, D>>,
    /// Per element, the fit with the element's mass and momentum prescribed, factorised at the
    /// mapping and reused by the remap, which fits the same points.
    prescribed: Vec<TaylorFit<D>>,
    fitted: TaylorFit<D>,
    /// The mass matrix of eq 10 (or its row sums) and its solve (eq 11).
    mass_solver: MassSolver<D>,
}

impl<const D: usize> TaylorTransfer<D> {
    /// `shape` is the run's basis, evaluated once at the Gauss points (the grid is reset
    /// every step); `fixed` the velocity components held at zero.
    pub fn new<S: Shape<D> + ?Sized>(
        recipe: TaylorRecipe,
        grid: &Grid<D>,
        shape: &S,
        fixed: &[FixedDof],
    ) -> Self {
        let (abscissae, weights) = gauss_legendre_rule(recipe.gauss_points);
        let n = recipe.gauss_points;
        let per_element = n.pow(D as u32);
        let elements = grid.cells.pow(D as u32);
        let mut gauss_x = Vec::with_capacity(elements * per_element);
        for e in 0..elements {
            let cell = lattice_coords(e, &[grid.cells; D]);
            for q in 0..per_element {
                let local = lattice_coords(q, &[n; D]);
                gauss_x.push(SVector::from_fn(|k, _| {
                    grid.lower[k] + (cell[k] as f64 + 0.5 + 0.5 * abscissae[local[k]]) * grid.h
                }));
            }
        }
        let gauss_w = (0..per_element)
            .map(|q| {
                let local = lattice_coords(q, &[n; D]);
                (0..D).map(|k| 0.5 * weights[local[k]] * grid.h).product()
            })
            .collect();
        let mut basis = Stencils::new(shape.nodes_per_point(), gauss_x.len());
        basis
            .update(shape, grid, &gauss_x)
            .expect("Gauss points lie inside their elements");
        let bandwidth = basis.bandwidth();
        TaylorTransfer {
            recipe,
            grid: grid.clone(),
            basis,
            gauss_x,
            gauss_w,
            per_element,
            point_scales: vec![0.0; per_element],
            bandwidth,
            element_of: Vec::new(),
            element_start: vec![0; elements + 1],
            next: Vec::new(),
            order: Vec::new(),
            points: Vec::new(),
            density: Vec::new(),
            vectors: Vec::new(),
            tensors: Vec::new(),
            prescribed: (0..elements).map(|_| TaylorFit::default()).collect(),
            fitted: TaylorFit::default(),
            mass_solver: MassSolver::new(recipe.mass, grid.nodes_per_dim(), fixed),
        }
    }

    /// Re-evaluates the basis at the Gauss points, for a basis that changes with the material
    /// (the dual-domain gradient).
    pub fn refresh_basis<S: Shape<D> + ?Sized>(&mut self, shape: &S) {
        self.basis
            .update(shape, &self.grid, &self.gauss_x)
            .expect("Gauss points lie inside their elements");
    }

    /// Nodal mass, velocity and force from the particles; `stencils` are the particles' own
    /// basis values, used for the body force, which is lumped as in the original MPM
    /// (sum_p M_p b_p N_ip keeps the total external force exact).
    pub fn map_to_grid(
        &mut self,
        stencils: &Stencils<D>,
        particles: &Particles<D>,
        body_force: &[SVector<f64, D>],
        grid: &mut GridState<D>,
    ) -> Result<FitStats, Divergence> {
        grid.clear();
        self.sort_by_element(particles)?;
        let consistent = self.mass_solver.is_consistent();
        if consistent {
            self.mass_solver.reset(self.bandwidth);
        }
        let degree = self.recipe.degree;
        let mut stats = FitStats::default();
        for e in 0..self.elements() {
            let Some((start, end)) = self.particles_of(e) else {
                continue;
            };
            let cell = self.cell(e);
            let prescribed = self.prescribed[e].factor(
                &cell,
                degree,
                Conservation::Fixed,
                &self.points[start..end],
            );
            let fitted = self.fitted.factor(
                &cell,
                degree,
                Conservation::Fitted,
                &self.points[start..end],
            );
            stats.fits += 2;
            stats.rank_deficient += usize::from(prescribed < degree) + usize::from(fitted < degree);
            let mass: f64 = self.order[start..end]
                .iter()
                .map(|&p| particles.mass[p as usize])
                .sum();
            let rho = self.prescribed[e].solve(&self.density[start..end], mass / cell.volume());
            let rho_v = self.momentum_density(e, &cell, &particles.v, &particles.mass);
            let sigma = self.stress(start, end, &particles.stress);
            for q in 0..self.per_element {
                let g = e * self.per_element + q;
                let w = self.gauss_w[q];
                let psi = cell.basis(prescribed, &self.gauss_x[g]);
                let rho_g = dot(&rho, &psi) * w;
                let rho_v_g = combine(&rho_v, &psi) * w;
                let sigma_g = combine(&sigma, &cell.basis(fitted, &self.gauss_x[g])) * w;
                for (i, n_i, grad) in self.basis.of(g) {
                    grid.mass[i] += rho_g * n_i;
                    grid.velocity[i] += rho_v_g * n_i;
                    grid.force[i] -= sigma_g * grad;
                }
                if consistent {
                    self.point_scales[q] = rho_g;
                }
            }
            if consistent {
                let first = e * self.per_element;
                let scales = &self.point_scales;
                self.mass_solver.add_points(
                    self.basis.for_values(),
                    first..first + self.per_element,
                    |g| scales[g - first],
                );
            }
        }
        for p in 0..particles.len() {
            let mb = body_force[p] * particles.mass[p];
            for (i, w, _) in stencils.for_values().of(p) {
                grid.force[i] += mb * w;
            }
        }
        if consistent {
            self.mass_solver.prepare(&grid.mass, grid.empty_mass)?;
        }
        self.mass_solver
            .solve_momenta(&grid.mass, grid.empty_mass, &mut grid.velocity)?;
        Ok(stats)
    }

    /// MUSL's v_i^L: the momentum density of the particle velocities `v` reconstructed with
    /// the fits of this step's mapping (same elements and positions), integrated (eq 9) and
    /// solved with its mass matrix (eq 11).
    pub fn remap_velocity(
        &mut self,
        particles: &Particles<D>,
        grid: &GridState<D>,
        out: &mut [SVector<f64, D>],
    ) -> Result<(), Divergence> {
        out.fill(SVector::zeros());
        for e in 0..self.elements() {
            if self.particles_of(e).is_none() {
                continue;
            }
            let cell = self.cell(e);
            let degree = self.prescribed[e].degree();
            let rho_v = self.momentum_density(e, &cell, &particles.v, &particles.mass);
            for q in 0..self.per_element {
                let g = e * self.per_element + q;
                let rho_v_g =
                    combine(&rho_v, &cell.basis(degree, &self.gauss_x[g])) * self.gauss_w[q];
                for (i, n_i, _) in self.basis.of(g) {
                    out[i] += rho_v_g * n_i;
                }
            }
        }
        self.mass_solver
            .solve_momenta(&grid.mass, grid.empty_mass, out)
    }

    /// The grid solve with this transfer's mass matrix (`MassSolver::solve_grid`).
    pub fn solve_grid(&mut self, grid: &mut GridState<D>, kick: f64) -> Result<(), Divergence> {
        self.mass_solver.solve_grid(grid, kick)
    }

    /// Total of p_i (eq 9) at the last mapping or remap: the momentum the DOFs received,
    /// before the solve and the boundary conditions.
    pub fn momentum_total(&self) -> SVector<f64, D> {
        self.mass_solver.received_momentum()
    }

    fn elements(&self) -> usize {
        self.element_start.len() - 1
    }

    /// Taylor coefficients of rho v on element `e` with the element momentum prescribed
    /// (eq 5); the element's prescribed fit must be factorised.
    fn momentum_density(
        &mut self,
        e: usize,
        cell: &TaylorCell<D>,
        v: &[SVector<f64, D>],
        mass: &[f64],
    ) -> [SVector<f64, D>; MAX_TAYLOR_TERMS] {
        let (start, end) = self.range(e);
        self.vectors.clear();
        let mut momentum = SVector::zeros();
        for (&p, &rho) in self.order[start..end].iter().zip(&self.density[start..end]) {
            let p = p as usize;
            self.vectors.push(v[p] * rho);
            momentum += v[p] * mass[p];
        }
        self.prescribed[e].solve(&self.vectors, momentum / cell.volume())
    }

    /// Taylor coefficients of the stress by plain least squares; `fitted` must be factorised.
    /// Each component sigma_rs, r <= s, is fitted once and stands for sigma_sr as well.
    fn stress(
        &mut self,
        start: usize,
        end: usize,
        stress: &[SMatrix<f64, D, D>],
    ) -> [SMatrix<f64, D, D>; MAX_TAYLOR_TERMS] {
        self.tensors.clear();
        self.tensors.extend(self.order[start..end].iter().map(|&p| {
            let sigma = &stress[p as usize];
            SMatrix::from_fn(|r, s| sigma[(r.min(s), r.max(s))])
        }));
        self.fitted.solve(&self.tensors, SMatrix::zeros())
    }

    /// Element `e`'s box.
    fn cell(&self, e: usize) -> TaylorCell<D> {
        let c = lattice_coords(e, &[self.grid.cells; D]);
        let lower = SVector::from_fn(|k, _| self.grid.lower[k] + c[k] as f64 * self.grid.h);
        TaylorCell::new(lower, lower.add_scalar(self.grid.h))
    }

    /// The range of element `e`'s particles in the sorted order, if it has any.
    fn particles_of(&self, e: usize) -> Option<(usize, usize)> {
        let (start, end) = self.range(e);
        (start < end).then_some((start, end))
    }

    fn range(&self, e: usize) -> (usize, usize) {
        (
            self.element_start[e] as usize,
            self.element_start[e + 1] as usize,
        )
    }

    /// Buckets the particles by element, stable in particle order, and keeps their positions
    /// and densities m_p / V_p for the remap.
    fn sort_by_element(&mut self, particles: &Particles<D>) -> Result<(), Divergence> {
        let n = particles.len();
        self.element_of.clear();
        self.element_start.fill(0);
        for p in 0..n {
            let (cell, _) = self
                .grid
                .locate(&particles.x[p])
                .ok_or(Divergence::LeftGrid { particle: p })?;
            let e = self.grid.cell_index(cell);
            self.element_of.push(e as u32);
            self.element_start[e + 1] += 1;
        }
        for e in 1..self.element_start.len() {
            self.element_start[e] += self.element_start[e - 1];
        }
        self.order.resize(n, 0);
        self.next.clear();
        self.next.extend_from_slice(&self.element_start);
        for p in 0..n {
            let e = self.element_of[p] as usize;
            self.order[self.next[e] as usize] = p as u32;
            self.next[e] += 1;
        }
        self.points.clear();
        self.density.clear();
        for &p in &self.order {
            let p = p as usize;
            self.points.push(particles.x[p]);
            self.density.push(particles.mass[p] / particles.volume(p));
        }
        Ok(())
    }
}

/// sum_t c_t psi_t for coefficients of any linear type.
#[inline]
fn combine<T>(coefficients: &[T; MAX_TAYLOR_TERMS], psi: &[f64; MAX_TAYLOR_TERMS]) -> T
where
    T: Copy + std::ops::Mul<f64, Output = T> + std::iter::Sum<T>,
{
    coefficients.iter().zip(psi).map(|(&c, &p)| c * p).sum()
}

#[inline]
fn dot(a: &[f64; MAX_TAYLOR_TERMS], b: &[f64; MAX_TAYLOR_TERMS]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

impl fmt::Display for TaylorRecipe {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mass = match self.mass {
            MassMatrix::Consistent => "consistent",
            MassMatrix::Lumped => "lumped",
        };
        write!(
            f,
            "degree {}, {} Gauss point(s) per element and axis, {mass} mass",
            self.degree, self.gauss_points
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmarks::{gong_mms, thesis_params, Problem};
    use crate::shape::{LinearHat, SplineDegree};

    fn recipe(mass: MassMatrix) -> TaylorRecipe {
        TaylorRecipe {
            degree: 2,
            gauss_points: 2,
            mass,
        }
    }

    /// Particles of Gong's manufactured problem with a velocity `velocity(x)` and random
    /// stress; when `scatter`, moved off their seeds and given random volumes:
    /// (grid, particles, stencils).
    fn particles<const D: usize>(
        scatter: bool,
        velocity: impl Fn(&SVector<f64, D>) -> SVector<f64, D>,
    ) -> (Grid<D>, Particles<D>, Stencils<D>) {
        let prob = gong_mms::<D>(&thesis_params(0.1, 6, 3)).unwrap();
        let grid = Grid::new(&prob.domain());
        let mut particles = prob.seed_particles(&grid);
        let mut rng = crate::rng::Lcg::new(5);
        let spacing = particles.lattice.spacing;
        for p in 0..particles.len() {
            if scatter {
                particles.x[p] += SVector::from_fn(|_, _| 0.6 * spacing * (rng.unit() - 0.5));
                particles.volume[p] *= 0.8 + 0.4 * rng.unit();
            }
            particles.v[p] = velocity(&particles.x[p]);
            particles.stress[p] = SMatrix::from_fn(|_, _| 1e3 * (rng.unit() - 0.5));
        }
        let mut stencils = Stencils::new(1 << D, particles.len());
        stencils.update(&LinearHat, &grid, &particles.x).unwrap();
        (grid, particles, stencils)
    }

    /// The domain a grid was built on.
    fn domain<const D: usize>(grid: &Grid<D>) -> crate::grid::Domain<D> {
        crate::grid::Domain {
            lower: grid.lower,
            upper: grid.lower.add_scalar(grid.h * grid.cells as f64),
            cells: grid.cells,
        }
    }

    /// Wobbes sec 4: for the hat and the B-spline and with both mass matrices, the DOFs receive the particles' mass and
    /// momentum to round-off, and the internal forces cancel.
    fn check_conservation<const D: usize>() {
        let (grid, particles, stencils) = particles::<D>(true, |x| {
            SVector::from_fn(|k, _| (3.0 * x[k]).sin() + 0.5 * k as f64)
        });
        let body = vec![SVector::<f64, D>::zeros(); particles.len()];
        let mass: f64 = particles.mass.iter().sum();
        let momentum: SVector<f64, D> = (0..particles.len())
            .map(|p| particles.v[p] * particles.mass[p])
            .sum();
        let scale: f64 = (0..particles.len())
            .map(|p| particles.v[p].norm() * particles.mass[p])
            .sum();
        let spline_grid = Grid::with_dofs(&domain(&grid), SplineDegree::Quadratic.dofs());
        let bases: [(&Grid<D>, &dyn Shape<D>); 2] = [
            (&grid, &LinearHat),
            (&spline_grid, SplineDegree::Quadratic.shape()),
        ];
        for ((grid, shape), kind) in bases
            .into_iter()
            .flat_map(|b| [(b, MassMatrix::Consistent), (b, MassMatrix::Lumped)])
        {
            let mut tls = TaylorTransfer::new(recipe(kind), grid, shape, &[]);
            let mut nodes = GridState::new(grid.num_nodes(), particles.mass[0]);
            let stats = tls
                .map_to_grid(&stencils, &particles, &body, &mut nodes)
                .unwrap();
            assert_eq!(stats.rank_deficient, 0);
            let grid_mass: f64 = nodes.mass.iter().sum();
            assert!(
                (grid_mass - mass).abs() < 1e-14 * mass,
                "{kind:?}: mass {grid_mass} vs {mass}"
            );
            let error = (tls.momentum_total() - momentum).norm();
            assert!(error < 1e-14 * scale, "{kind:?}: momentum error {error:e}");
            let force: SVector<f64, D> = nodes.force.iter().sum();
            assert!(
                force.norm() < 1e-9,
                "{kind:?}: internal forces sum to {force}"
            );
        }
    }

    #[test]
    fn conserves_mass_and_momentum_1d() {
        check_conservation::<1>();
    }

    #[test]
    fn conserves_mass_and_momentum_2d() {
        check_conservation::<2>();
    }

    /// A linear velocity is in the span of the hat functions: the consistent mass matrix
    /// projects it exactly when the density is uniform and the particles integrate linear
    /// functions exactly per element (seeded at sub-cell centres), so that the prescribed
    /// element momentum is the exact one.
    fn check_linear_velocity<const D: usize>() {
        let v =
            |x: &SVector<f64, D>| SVector::from_fn(|k, _| 0.3 + 2.0 * x[k] - 0.7 * x[(k + 1) % D]);
        let (grid, particles, stencils) = particles::<D>(false, v);
        let body = vec![SVector::<f64, D>::zeros(); particles.len()];
        let mut tls = TaylorTransfer::new(recipe(MassMatrix::Consistent), &grid, &LinearHat, &[]);
        let mut nodes = GridState::new(grid.num_nodes(), particles.mass[0]);
        tls.map_to_grid(&stencils, &particles, &body, &mut nodes)
            .unwrap();
        for i in 0..grid.num_nodes() {
            let error = (nodes.velocity[i] - v(&grid.node_position(i))).norm();
            assert!(error < 1e-10, "node {i}: velocity error {error:e}");
        }
    }

    #[test]
    fn consistent_mass_reproduces_linear_velocity_1d() {
        check_linear_velocity::<1>();
    }

    #[test]
    fn consistent_mass_reproduces_linear_velocity_2d() {
        check_linear_velocity::<2>();
    }
}
