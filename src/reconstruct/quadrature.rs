//! Transfers that reconstruct fields instead of lumping particle data (IMPM, Gong sec 5.3;
//! IMLS-MPM, Tran eqs 24-31): the nodal velocity is a least-squares fit of the particle
//! velocities evaluated at the nodes; density, stress and body force are fitted and
//! evaluated at quadrature points, where the nodal masses and forces are integrated.

use std::fmt;

use nalgebra::{SMatrix, SVector};

use super::{FitStats, GridState, Lattice, Recipe, Reconstructor, SingularMoments};
use crate::particles::Particles;
use crate::shape::{Grid, LinearHat, Shape, Stencils};

/// The parts of a quadrature transfer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadratureRecipe {
    /// Fit of the particle velocities, evaluated at the nodes (Gong eq 5.6, Tran eq 31).
    pub velocity: Recipe,
    /// Fit of density, stress and body force, evaluated at the quadrature points (Gong eqs
    /// 5.7-5.8, Tran eqs 24-26).
    pub fields: Recipe,
    /// Gauss-Legendre points per cell and axis: 1 is Gong's cell-centre rule (eq 5.9).
    pub gauss_points: usize,
    /// How the body-force term rho b is fitted at the quadrature points.
    pub body_force: BodyForceFit,
}

/// The fit behind the body-force term sum_g N_ig (rho b)_g omega_g.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyForceFit {
    /// rho and b fitted apart and multiplied at the point (Gong eq 5.10; Tran eq 29 with the
    /// density it needs).
    Separate,
    /// One fit of the particles' rho_p b_p (Tran et al.'s CPLS code,
    /// `Interpolate_Particle_To_Grid_MLS`).
    Product,
}

impl BodyForceFit {
    /// The names the `body_force_fit` parameter takes, in the order of `ALL`.
    pub const NAMES: &'static [&'static str] = &["separate", "product"];
    const ALL: [BodyForceFit; 2] = [BodyForceFit::Separate, BodyForceFit::Product];

    pub fn name(self) -> &'static str {
        match self {
            BodyForceFit::Separate => Self::NAMES[0],
            BodyForceFit::Product => Self::NAMES[1],
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

pub struct QuadratureTransfer<const D: usize> {
    velocity: Reconstructor<D>,
    fields: Reconstructor<D>,
    /// N_i and grad N_i of the grid's hat at the quadrature points (whatever basis the
    /// particles use): fixed, because the grid is reset each step.
    basis: Stencils<D>,
    /// Quadrature weights omega_g.
    weights: Vec<f64>,
    particle_density: Vec<f64>,
    /// rho_p b_p, for the product fit.
    particle_body: Vec<SVector<f64, D>>,
    body_force: BodyForceFit,
    density: Vec<f64>,
    stress: Vec<SMatrix<f64, D, D>>,
    body: Vec<SVector<f64, D>>,
}

impl<const D: usize> QuadratureTransfer<D> {
    pub fn new(recipe: &QuadratureRecipe, grid: &Grid<D>) -> Self {
        let points = Lattice::gauss(grid, recipe.gauss_points);
        let n = points.len();
        let positions: Vec<SVector<f64, D>> = (0..n).map(|g| points.point(g)).collect();
        let weights = (0..n).map(|g| points.quadrature_weight(g)).collect();
        let mut basis = Stencils::new(Shape::<D>::nodes_per_point(&LinearHat), n);
        basis
            .update(&LinearHat, grid, &positions)
            .expect("quadrature points lie inside their cells");
        QuadratureTransfer {
            velocity: Reconstructor::new(recipe.velocity, Lattice::nodes(grid)),
            fields: Reconstructor::new(recipe.fields, points),
            basis,
            weights,
            particle_density: Vec::new(),
            particle_body: Vec::new(),
            body_force: recipe.body_force,
            density: vec![0.0; n],
            stress: vec![SMatrix::zeros(); n],
            body: vec![SVector::zeros(); n],
        }
    }

    /// Nodal velocity by the velocity fit; m_i = sum_g N_ig rho_g omega_g and
    /// f_i = sum_g (N_ig (rho b)_g - sigma_g grad N_ig) omega_g (Gong eqs 5.9-5.14 with the
    /// cell volume, Tran eqs 28-30 with rho_g in the body-force term), (rho b)_g = rho_g b_g
    /// or the fit of rho_p b_p. Sums run in a fixed order. Returns the fit counters of this
    /// step.
    pub fn map_to_grid(
        &mut self,
        particles: &Particles<D>,
        body_force: &[SVector<f64, D>],
        grid: &mut GridState<D>,
    ) -> Result<FitStats, SingularMoments> {
        grid.clear();
        let mut stats = self.velocity.fit(&particles.x)?;
        self.velocity.apply(&particles.v, &mut grid.velocity);
        stats += self.fields.fit(&particles.x)?;
        self.particle_density.clear();
        self.particle_density
            .extend((0..particles.len()).map(|p| particles.mass[p] / particles.volume(p)));
        self.fields.apply(&self.particle_density, &mut self.density);
        self.fields.apply(&particles.stress, &mut self.stress);
        match self.body_force {
            BodyForceFit::Separate => self.fields.apply(body_force, &mut self.body),
            BodyForceFit::Product => {
                self.particle_body.clear();
                self.particle_body.extend(
                    body_force
                        .iter()
                        .zip(&self.particle_density)
                        .map(|(b, rho)| b * *rho),
                );
                self.fields.apply(&self.particle_body, &mut self.body);
            }
        }
        for g in 0..self.weights.len() {
            let rho_omega = self.density[g] * self.weights[g];
            let body = match self.body_force {
                BodyForceFit::Separate => self.body[g] * rho_omega,
                BodyForceFit::Product => self.body[g] * self.weights[g],
            };
            let stress = self.stress[g] * self.weights[g];
            for (i, n, grad) in self.basis.of(g) {
                grid.mass[i] += n * rho_omega;
                grid.force[i] += body * n - stress * grad;
            }
        }
        Ok(stats)
    }

    /// The velocity fit of this step applied to other particle velocities (Tran eq 36).
    pub fn remap_velocity(&self, v: &[SVector<f64, D>], out: &mut [SVector<f64, D>]) {
        self.velocity.apply(v, out);
    }
}

impl fmt::Display for QuadratureRecipe {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "velocity {}, fields {}, {} Gauss point(s) per cell and axis, body force {}",
            self.velocity,
            self.fields,
            self.gauss_points,
            self.body_force.name()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmarks::{gong_mms, thesis_params, Problem};
    use crate::methods;

    fn recipes() -> Vec<QuadratureRecipe> {
        methods::presets()
            .iter()
            .filter_map(|p| match p.method.transfer {
                crate::methods::TransferKind::Quadrature(r) => Some(r),
                _ => None,
            })
            .collect()
    }

    /// Uniform density on a covered domain: the fits reproduce constants, so the grid mass
    /// is the particle mass and the body force its resultant, to round-off. Internal forces
    /// cancel for any stress because sum_i grad N_i = 0 at every quadrature point.
    fn check_balance<const D: usize>() {
        let prob = gong_mms::<D>(&thesis_params(0.1, 6, 3)).unwrap();
        let grid = Grid::new(&prob.domain());
        let mut particles = Particles::seed(&prob, &grid);
        let mut rng = crate::rng::Lcg::new(99);
        for p in 0..particles.len() {
            particles.stress[p] = SMatrix::from_fn(|_, _| 1e3 * (rng.unit() - 0.5));
            particles.v[p] = SVector::from_fn(|_, _| rng.unit());
        }
        let b = SVector::<f64, D>::from_fn(|k, _| 1.0 - 3.0 * k as f64);
        let body = vec![b; particles.len()];
        let total: f64 = particles.mass.iter().sum();
        for recipe in recipes() {
            let mut transfer = QuadratureTransfer::new(&recipe, &grid);
            let mut nodes = GridState::new(grid.num_nodes(), particles.mass[0]);
            let stats = transfer.map_to_grid(&particles, &body, &mut nodes).unwrap();
            assert_eq!(stats.rank_deficient, 0);
            let mass: f64 = nodes.mass.iter().sum();
            assert!(
                (mass - total).abs() < 1e-12 * total,
                "{recipe}: {mass} vs {total}"
            );
            let force: SVector<f64, D> = nodes.force.iter().sum();
            assert!(
                (force - b * total).norm() < 1e-9 * total,
                "{recipe}: {force}"
            );
        }
    }

    #[test]
    fn uniform_density_conserves_mass_and_balances_forces_1d() {
        check_balance::<1>();
    }

    #[test]
    fn uniform_density_conserves_mass_and_balances_forces_2d() {
        check_balance::<2>();
    }

    /// One Gauss point per cell and axis is the cell centre, with the cell's volume as weight
    /// (the CPLS code's `LOCC`, `le(1)*le(2)`).
    #[test]
    fn one_gauss_point_is_the_cell_centre() {
        let prob = gong_mms::<2>(&thesis_params(0.1, 4, 2)).unwrap();
        let grid = Grid::new(&prob.domain());
        let points = Lattice::gauss(&grid, 1);
        assert_eq!(points.len(), 16);
        for g in 0..points.len() {
            let x = points.point(g);
            let (cell, _) = grid.locate(&x).unwrap();
            let centre = grid.lower + SVector::from_fn(|k, _| (cell[k] as f64 + 0.5) * grid.h);
            assert!(
                (x - centre).norm() < 1e-15,
                "point {g}: {x} against {centre}"
            );
            assert!((points.quadrature_weight(g) - grid.h * grid.h).abs() < 1e-15);
        }
    }

    /// A linear rho b from a linear density and a body force that is not linear,
    /// rho = 2 + x and b = (1 + x) / (2 + x): the product fit reproduces rho b = 1 + x at the
    /// quadrature points, so the nodal body force is sum_g N_ig (1 + x_g) omega_g to
    /// round-off; fitting rho and b apart misses it by the error of the fit of b.
    #[test]
    fn the_product_fit_reproduces_a_linear_rho_b() {
        let prob = gong_mms::<1>(&thesis_params(0.1, 8, 3)).unwrap();
        let grid = Grid::new(&prob.domain());
        let mut particles = Particles::seed(&prob, &grid);
        let mut body = Vec::new();
        for p in 0..particles.len() {
            let x = particles.x[p][0];
            particles.mass[p] = (2.0 + x) * particles.volume(p);
            body.push(SVector::repeat((1.0 + x) / (2.0 + x)));
        }
        let mut expected = vec![0.0; grid.num_nodes()];
        let points = Lattice::gauss(&grid, 1);
        let positions: Vec<SVector<f64, 1>> = (0..points.len()).map(|g| points.point(g)).collect();
        let mut hat = Stencils::new(Shape::<1>::nodes_per_point(&LinearHat), positions.len());
        hat.update(&LinearHat, &grid, &positions).unwrap();
        for (g, x) in positions.iter().enumerate() {
            for (i, n, _) in hat.of(g) {
                expected[i] += n * (1.0 + x[0]) * points.quadrature_weight(g);
            }
        }
        let recipe = |body_force| QuadratureRecipe {
            gauss_points: 1,
            body_force,
            ..recipes().into_iter().find(|r| r.gauss_points == 2).unwrap()
        };
        let force = |body_force| {
            let mut transfer = QuadratureTransfer::new(&recipe(body_force), &grid);
            let mut nodes = GridState::new(grid.num_nodes(), particles.mass[0]);
            transfer.map_to_grid(&particles, &body, &mut nodes).unwrap();
            nodes.force.iter().map(|f| f[0]).collect::<Vec<f64>>()
        };
        let largest = |f: &[f64]| {
            f.iter()
                .zip(&expected)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        };
        let product = largest(&force(BodyForceFit::Product));
        let separate = largest(&force(BodyForceFit::Separate));
        assert!(product < 1e-14, "product fit off by {product:e}");
        assert!(
            separate > 1e3 * product.max(1e-17),
            "separate fit off by {separate:e}"
        );
    }
}
