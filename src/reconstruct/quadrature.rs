//! Transfers that reconstruct fields instead of lumping particle data (IMPM, Gong sec 5.3;
//! IMLS-MPM, Tran eqs 24-31): the nodal velocity is a least-squares fit of the particle
//! velocities evaluated at the nodes (or the original MPM's mass-weighted average, to isolate
//! the field fits); density, stress and body force are fitted and evaluated at quadrature
//! points, where the nodal masses and forces are integrated.

use std::fmt;

use nalgebra::{SMatrix, SVector};

use super::least_squares::Components;
use super::shepard::{map_velocity, remap_velocity};
use super::{FitStats, Lattice, Recipe, Reconstructor, SingularMoments, VelocityFit};
use crate::catalog::{names_of, Catalog, Entry, Parts};
use crate::grid::{Grid, GridState};
use crate::particles::Particles;
use crate::shape::{LinearHat, Shape, Stencils};

/// The parts of a quadrature transfer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadratureRecipe {
    /// How the nodal velocity is made: a fit of the particle velocities evaluated at the
    /// nodes (Gong eq 5.6, Tran eq 31), or the original MPM's average.
    pub velocity: NodalVelocity,
    /// Fit of density, stress and body force, evaluated at the quadrature points (Gong eqs
    /// 5.7-5.8, Tran eqs 24-26).
    pub fields: Recipe,
    /// Gauss-Legendre points per cell and axis: 1 is Gong's cell-centre rule (eq 5.9).
    pub gauss_points: usize,
    /// How the body-force term rho b is fitted at the quadrature points.
    pub body_force: BodyForceFit,
}

/// The nodal velocity of a quadrature transfer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NodalVelocity {
    /// A least-squares fit of the particle velocities evaluated at the nodes.
    Fit(Recipe),
    /// v_i = sum_p M_p v_p N_ip / sum_p M_p N_ip with the run's basis at the particles, the
    /// original MPM's mapping (Gong sec 4.3.1); the nodal mass that divides it is the Shepard
    /// one, not the mass integrated from the fitted density.
    Shepard,
}

impl fmt::Display for NodalVelocity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NodalVelocity::Fit(recipe) => write!(f, "{recipe}"),
            NodalVelocity::Shepard => f.write_str("shepard"),
        }
    }
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

const BODY_FORCE_FIT_ENTRIES: &[Entry<BodyForceFit>] = &[
    Entry {
        name: "separate",
        value: BodyForceFit::Separate,
        description: "rho and b fitted apart and multiplied",
    },
    Entry {
        name: "product",
        value: BodyForceFit::Product,
        description: "one fit of rho_p b_p",
    },
];

/// The body-force fits by name: the `body_force_fit` parameter's choices.
pub const BODY_FORCE_FITS: Parts<BodyForceFit> = Catalog {
    kind: "body_force_fit",
    entries: BODY_FORCE_FIT_ENTRIES,
};

pub const BODY_FORCE_FIT_NAMES: [&str; BODY_FORCE_FIT_ENTRIES.len()] =
    names_of(BODY_FORCE_FIT_ENTRIES);

impl BodyForceFit {
    pub fn name(self) -> &'static str {
        BODY_FORCE_FITS
            .name_of(&self)
            .expect("every body-force fit is registered")
    }
}

/// The nodal velocity of a quadrature transfer as it is computed.
enum VelocityMap<const D: usize> {
    Fit(Box<VelocityFit<D>>),
    /// With the Shepard masses sum_p M_p N_ip of the last mapping, which MUSL's remap
    /// divides by.
    Shepard(Vec<f64>),
}

pub struct QuadratureTransfer<const D: usize> {
    velocity: VelocityMap<D>,
    fields: Reconstructor<D>,
    /// N_i and grad N_i of the grid's hat at the quadrature points (whatever basis the
    /// particles use): fixed, because the grid is reset each step.
    basis: Stencils<D>,
    /// Quadrature weights omega_g.
    weights: Vec<f64>,
    /// The fitted fields at the particles, then at the quadrature points.
    particle_fields: Vec<Fields<D>>,
    fields_at_points: Vec<Fields<D>>,
    body_force: BodyForceFit,
}

/// The fields one quadrature transfer fits: density, stress, and b or rho b (the body-force
/// fit). One fit applied to all of them at once is, field by field, the same arithmetic as a
/// fit applied to each, with one pass over the entries.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Fields<const D: usize> {
    density: f64,
    stress: SMatrix<f64, D, D>,
    body: SVector<f64, D>,
}

/// Density, the stress's lower triangle column by column, the body force, and last the
/// stress above the diagonal (2D), which in a symmetric stress copies the one below.
impl<const D: usize> Components for Fields<D> {
    const COUNT: usize = 1 + D * D + D;
    const LAST_MAY_COPY: Option<usize> = if D == 2 { Some(2) } else { None };

    #[inline(always)]
    fn component(&self, c: usize) -> f64 {
        const { assert!(D <= 2, "the quadrature transfers run in 1D and 2D") };
        let lower = D * (D + 1) / 2;
        match c {
            0 => self.density,
            c if c <= lower => self.stress[[(0, 0), (1, 0), (1, 1)][c - 1]],
            c if c <= lower + D => self.body[c - 1 - lower],
            _ => self.stress[(0, 1)],
        }
    }

    #[inline(always)]
    fn from_components(component: impl Fn(usize) -> f64) -> Self {
        let lower = D * (D + 1) / 2;
        Fields {
            density: component(0),
            stress: SMatrix::from_fn(|i, j| {
                if i >= j {
                    component(1 + i + j)
                } else {
                    component(Self::COUNT - 1)
                }
            }),
            body: SVector::from_fn(|k, _| component(1 + lower + k)),
        }
    }
}

impl<const D: usize> QuadratureTransfer<D> {
    /// `remaps`: whether the run rebuilds the nodal velocity after the particles move.
    pub fn new(recipe: &QuadratureRecipe, grid: &Grid<D>, remaps: bool) -> Self {
        let points = Lattice::gauss(grid, recipe.gauss_points);
        let n = points.len();
        let positions: Vec<SVector<f64, D>> = (0..n).map(|g| points.point(g)).collect();
        let weights = (0..n).map(|g| points.quadrature_weight(g)).collect();
        let mut basis = Stencils::new(Shape::<D>::nodes_per_point(&LinearHat), n);
        basis
            .update(&LinearHat, grid, &positions)
            .expect("quadrature points lie inside their cells");
        QuadratureTransfer {
            velocity: match recipe.velocity {
                NodalVelocity::Fit(fit) => {
                    VelocityMap::Fit(Box::new(VelocityFit::new(fit, grid, remaps)))
                }
                NodalVelocity::Shepard => VelocityMap::Shepard(Vec::new()),
            },
            fields: Reconstructor::new(recipe.fields, points),
            basis,
            weights,
            particle_fields: Vec::new(),
            fields_at_points: vec![Fields::from_components(|_| 0.0); n],
            body_force: recipe.body_force,
        }
    }

    /// Nodal velocity by the velocity fit, or the Shepard average with the particles' basis
    /// `stencils`; m_i = sum_g N_ig rho_g omega_g and
    /// f_i = sum_g (N_ig (rho b)_g - sigma_g grad N_ig) omega_g (Gong eqs 5.9-5.14 with the
    /// cell volume, Tran eqs 28-30 with rho_g in the body-force term), (rho b)_g = rho_g b_g
    /// or the fit of rho_p b_p. Sums run in a fixed order. Returns the fit counters of this
    /// step.
    pub fn map_to_grid(
        &mut self,
        stencils: &Stencils<D>,
        particles: &Particles<D>,
        body_force: &[SVector<f64, D>],
        grid: &mut GridState<D>,
    ) -> Result<FitStats, SingularMoments> {
        let mut stats = FitStats::default();
        match &mut self.velocity {
            VelocityMap::Fit(fit) => {
                grid.clear();
                stats += fit.map(&particles.x, &particles.v, &mut grid.velocity)?;
            }
            VelocityMap::Shepard(mass) => {
                map_velocity(stencils, &particles.mass, &particles.v, grid);
                mass.clone_from(&grid.mass);
                grid.mass.fill(0.0);
            }
        }
        stats += self.fields.fit(&particles.x)?;
        self.particle_fields.clear();
        self.particle_fields.extend((0..particles.len()).map(|p| {
            let density = particles.mass[p] / particles.volume(p);
            Fields {
                density,
                stress: particles.stress[p],
                body: match self.body_force {
                    BodyForceFit::Separate => body_force[p],
                    BodyForceFit::Product => body_force[p] * density,
                },
            }
        }));
        self.fields
            .apply(&self.particle_fields, &mut self.fields_at_points);
        for (g, at_point) in self.fields_at_points.iter().enumerate() {
            let rho_omega = at_point.density * self.weights[g];
            let body = match self.body_force {
                BodyForceFit::Separate => at_point.body * rho_omega,
                BodyForceFit::Product => at_point.body * self.weights[g],
            };
            let stress = at_point.stress * self.weights[g];
            for (i, n, grad) in self.basis.of(g) {
                grid.mass[i] += n * rho_omega;
                grid.force[i] += body * n - stress * grad;
            }
        }
        Ok(stats)
    }

    /// The velocity fit of this step applied to the particle velocities now (Tran eq 36), or
    /// their Shepard average with this step's weights and Shepard masses.
    pub fn remap_velocity(
        &mut self,
        stencils: &Stencils<D>,
        particles: &Particles<D>,
        empty_mass: f64,
        out: &mut [SVector<f64, D>],
    ) {
        match &mut self.velocity {
            VelocityMap::Fit(fit) => fit.remap(&particles.v, out),
            VelocityMap::Shepard(mass) => {
                remap_velocity(stencils, particles, mass, empty_mass, out)
            }
        }
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
    use crate::reconstruct::particles_to_grid;

    fn recipes() -> Vec<QuadratureRecipe> {
        methods::PRESETS
            .entries
            .iter()
            .filter_map(|p| match p.method.transfer {
                crate::reconstruct::TransferKind::Quadrature(r) => Some(r),
                _ => None,
            })
            .collect()
    }

    fn hat_stencils<const D: usize>(grid: &Grid<D>, x: &[SVector<f64, D>]) -> Stencils<D> {
        let mut stencils = Stencils::new(Shape::<D>::nodes_per_point(&LinearHat), x.len());
        stencils.update(&LinearHat, grid, x).unwrap();
        stencils
    }

    /// Uniform density on a covered domain: the fits reproduce constants, so the grid mass
    /// is the particle mass and the body force its resultant, to round-off. Internal forces
    /// cancel for any stress because sum_i grad N_i = 0 at every quadrature point.
    fn check_balance<const D: usize>() {
        let prob = gong_mms::<D>(&thesis_params(0.1, 6, 3)).unwrap();
        let grid = Grid::new(&prob.domain());
        let mut particles = prob.seed_particles(&grid);
        let mut rng = crate::rng::Lcg::new(99);
        for p in 0..particles.len() {
            particles.stress[p] = SMatrix::from_fn(|_, _| 1e3 * (rng.unit() - 0.5));
            particles.v[p] = SVector::from_fn(|_, _| rng.unit());
        }
        let b = SVector::<f64, D>::from_fn(|k, _| 1.0 - 3.0 * k as f64);
        let body = vec![b; particles.len()];
        let total: f64 = particles.mass.iter().sum();
        let stencils = hat_stencils(&grid, &particles.x);
        for recipe in recipes() {
            let mut transfer = QuadratureTransfer::new(&recipe, &grid, false);
            let mut nodes = GridState::new(grid.num_nodes(), particles.mass[0]);
            let stats = transfer
                .map_to_grid(&stencils, &particles, &body, &mut nodes)
                .unwrap();
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

    fn preset_recipe(name: &str) -> QuadratureRecipe {
        match methods::PRESETS.find(name).unwrap().method.transfer {
            crate::reconstruct::TransferKind::Quadrature(r) => r,
            other => panic!("{name} maps with {other}"),
        }
    }

    /// The field half of IMPM alone (`impm_fields_only`) on scattered particles with varying
    /// density: the nodal velocity is the original MPM's mass-weighted average and the nodal
    /// masses and forces are IMPM's, to round-off; MUSL's remap divides by the Shepard masses,
    /// which differ from the fitted ones.
    fn check_shepard_velocity<const D: usize>() {
        let prob = gong_mms::<D>(&thesis_params(0.1, 6, 3)).unwrap();
        let grid = Grid::new(&prob.domain());
        let mut particles = prob.seed_particles(&grid);
        let mut rng = crate::rng::Lcg::new(31);
        for p in 0..particles.len() {
            particles.x[p] += SVector::<f64, D>::from_fn(|_, _| 0.02 * (rng.unit() - 0.5));
            particles.x[p] = particles.x[p].map(|c| c.clamp(0.0, 1.0));
            particles.v[p] = SVector::from_fn(|_, _| rng.unit() - 0.5);
            particles.stress[p] = SMatrix::from_fn(|_, _| 1e3 * (rng.unit() - 0.5));
            particles.volume[p] *= 1.0 + 0.2 * (rng.unit() - 0.5);
        }
        let body = vec![SVector::<f64, D>::from_fn(|k, _| 2.0 - k as f64); particles.len()];
        let stencils = hat_stencils(&grid, &particles.x);
        let map = |nodes: &mut GridState<D>, recipe: Option<QuadratureRecipe>| {
            let mut transfer = recipe.map(|r| QuadratureTransfer::new(&r, &grid, true));
            match &mut transfer {
                Some(t) => {
                    t.map_to_grid(&stencils, &particles, &body, nodes).unwrap();
                }
                None => particles_to_grid(&stencils, &particles, &body, nodes),
            }
            transfer
        };
        let fresh = || GridState::new(grid.num_nodes(), particles.mass[0]);
        let (mut mpm, mut impm, mut fields) = (fresh(), fresh(), fresh());
        map(&mut mpm, None);
        map(&mut impm, Some(preset_recipe("impm")));
        let mut transfer = map(&mut fields, Some(preset_recipe("impm_fields_only"))).unwrap();
        let largest = |a: &[SVector<f64, D>], b: &[SVector<f64, D>]| {
            a.iter()
                .zip(b)
                .map(|(x, y)| (x - y).norm())
                .fold(0.0, f64::max)
        };
        assert!(largest(&fields.velocity, &mpm.velocity) < 1e-15);
        assert!(largest(&fields.force, &impm.force) < 1e-15);
        assert_eq!(fields.mass, impm.mass);
        assert!(largest(&fields.velocity, &impm.velocity) > 1e-3);
        let mut remapped = vec![SVector::zeros(); grid.num_nodes()];
        transfer.remap_velocity(&stencils, &particles, fields.empty_mass, &mut remapped);
        assert!(largest(&remapped, &mpm.velocity) < 1e-15);
        let mass_gap = fields
            .mass
            .iter()
            .zip(&mpm.mass)
            .map(|(a, b)| (a - b).abs() / b)
            .fold(0.0, f64::max);
        assert!(
            mass_gap > 1e-3,
            "fitted and Shepard masses agree to {mass_gap:e}"
        );
    }

    #[test]
    fn the_shepard_velocity_is_mpms_and_the_fields_are_impms_1d() {
        check_shepard_velocity::<1>();
    }

    #[test]
    fn the_shepard_velocity_is_mpms_and_the_fields_are_impms_2d() {
        check_shepard_velocity::<2>();
    }

    /// The O(h^2) constants C of IMPM's reconstructions on the undistorted seed lattice of
    /// `mms1d_gong` (docs/NOTES.md, the isolation of IMPM's parts): at a point x_e in the
    /// middle of the bar, u^h(x_e) = u(x_e) (1 - C (pi h)^2) for a mode u = sin(pi x) sampled at
    /// the particles, sampled as the linear interpolant of its nodal values (what the leapfrog's
    /// particle update leaves), or constant per cell (the particle stresses of a small
    /// deformation), against the closed forms of the weights' lattice moments. Nodal velocity:
    /// the Shepard average (`mpm`) and the cubic MLS (`impm`); fields at the cell centre: the
    /// quadratic MLS; nodal body force sum_p M_p b_p N_ip (`mpm`) and IMPM's cell-centre rule,
    /// over rho0 h.
    #[test]
    fn lattice_constants_of_the_impm_reconstructions() {
        let impm = preset_recipe("impm");
        let NodalVelocity::Fit(velocity_fit) = impm.velocity else {
            panic!("impm fits its velocity");
        };
        let cells = 64;
        for ppc in [2, 4] {
            let prob = gong_mms::<1>(&thesis_params(1e-4, cells as i64, ppc as i64)).unwrap();
            let grid = Grid::new(&prob.domain());
            let particles = prob.seed_particles(&grid);
            let h = grid.h;
            let mode = |x: f64| (std::f64::consts::PI * x).sin();
            let x: Vec<f64> = particles.x.iter().map(|x| x[0]).collect();
            let node = cells / 2;
            let centre = cells / 2;
            let x_node = node as f64 * h;
            let x_centre = (centre as f64 + 0.5) * h;
            let sampled: Vec<f64> = x.iter().map(|&x| mode(x)).collect();
            let interpolated: Vec<f64> = x
                .iter()
                .map(|&x| {
                    let left = (x / h).floor();
                    let xi = x / h - left;
                    (1.0 - xi) * mode(left * h) + xi * mode((left + 1.0) * h)
                })
                .collect();
            let per_cell: Vec<f64> = x
                .iter()
                .map(|&x| mode(((x / h).floor() + 0.5) * h))
                .collect();
            let stencils = hat_stencils(&grid, &particles.x);
            let constant =
                |value: f64, exact: f64| (1.0 - value / exact) / (std::f64::consts::PI * h).powi(2);
            let shepard = |u: &[f64]| {
                let v: Vec<SVector<f64, 1>> = u.iter().map(|&u| SVector::repeat(u)).collect();
                let mut nodes = GridState::new(grid.num_nodes(), particles.mass[0]);
                map_velocity(&stencils, &particles.mass, &v, &mut nodes);
                constant(nodes.velocity[node][0], mode(x_node))
            };
            let fit = |recipe: Recipe, lattice: Lattice<1>, u: &[f64], e: usize, exact: f64| {
                let mut fit = Reconstructor::new(recipe, lattice);
                fit.fit(&particles.x).unwrap();
                let mut out = vec![0.0; fit.lattice().len()];
                fit.apply(u, &mut out);
                constant(out[e], exact)
            };
            let nodes = || Lattice::nodes(&grid);
            let centres = || Lattice::cell_centres(&grid);
            let body = |recipe: Option<QuadratureRecipe>| {
                let b: Vec<SVector<f64, 1>> = sampled.iter().map(|&b| SVector::repeat(b)).collect();
                let mut nodes = GridState::new(grid.num_nodes(), particles.mass[0]);
                match recipe {
                    Some(r) => {
                        QuadratureTransfer::new(&r, &grid, false)
                            .map_to_grid(&stencils, &particles, &b, &mut nodes)
                            .unwrap();
                    }
                    None => particles_to_grid(&stencils, &particles, &b, &mut nodes),
                }
                constant(nodes.force[node][0] / (prob.rho0() * h), mode(x_node))
            };
            // The closed forms: half the lattice moment sum_p w_p r_p^2 / sum_p w_p (r in
            // cells) of the weight about the point (1/3 for the cubic and 1/4 for the
            // quadratic spline, which these lattices sample exactly; 3/16 and 11/64 for the
            // hat); the linear interpolant adds half the mean of xi (1 - xi) over the seed
            // offsets xi; data constant per cell take the moment of the cell-centre distances;
            // the cell-centre rule adds (1 - cos(pi h / 2)) / (pi h)^2 = 1/8 to the body force.
            let (shepard_moment, interpolant) = match ppc {
                2 => (3.0 / 32.0, 3.0 / 32.0),
                _ => (11.0 / 128.0, 11.0 / 128.0),
            };
            let per_cell_fit = match ppc {
                2 => 5.0 / 32.0,
                _ => 21.0 / 128.0,
            };
            let checks = [
                ("Shepard nodal velocity", shepard(&sampled), shepard_moment),
                (
                    "MLS nodal velocity",
                    fit(velocity_fit, nodes(), &sampled, node, mode(x_node)),
                    1.0 / 6.0,
                ),
                (
                    "Shepard of the interpolant",
                    shepard(&interpolated),
                    shepard_moment + interpolant,
                ),
                (
                    "MLS of the interpolant",
                    fit(velocity_fit, nodes(), &interpolated, node, mode(x_node)),
                    1.0 / 6.0 + interpolant,
                ),
                (
                    "field fit at the cell centre",
                    fit(impm.fields, centres(), &sampled, centre, mode(x_centre)),
                    0.125,
                ),
                (
                    "field fit of per-cell data",
                    fit(impm.fields, centres(), &per_cell, centre, mode(x_centre)),
                    per_cell_fit,
                ),
                ("MPM body force", body(None), shepard_moment),
                ("IMPM body force", body(Some(impm)), 0.125 + 0.125),
            ];
            for (what, measured, expected) in checks {
                assert!(
                    (measured - expected).abs() < 2e-3 * expected,
                    "ppc {ppc}, {what}: {measured} against {expected}"
                );
            }
        }
    }

    /// The fields' components are density, the stress's lower triangle column by column, the
    /// body force and the stress above the diagonal, and they make the same fields again.
    #[test]
    fn fields_are_their_components() {
        let fields = Fields::<2> {
            density: 1.0,
            stress: SMatrix::<f64, 2, 2>::new(2.0, 4.0, 3.0, 5.0),
            body: SVector::<f64, 2>::new(6.0, 7.0),
        };
        let components: Vec<f64> = (0..Fields::<2>::COUNT)
            .map(|c| fields.component(c))
            .collect();
        assert_eq!(components, [1.0, 2.0, 3.0, 5.0, 6.0, 7.0, 4.0]);
        assert_eq!(Fields::<2>::from_components(|c| components[c]), fields);
        let one = Fields::<1>::from_components(|c| c as f64 + 1.0);
        assert_eq!((one.density, one.stress[0], one.body[0]), (1.0, 2.0, 3.0));
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
        let mut particles = prob.seed_particles(&grid);
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
        let stencils = hat_stencils(&grid, &particles.x);
        let force = |body_force| {
            let mut transfer = QuadratureTransfer::new(&recipe(body_force), &grid, false);
            let mut nodes = GridState::new(grid.num_nodes(), particles.mass[0]);
            transfer
                .map_to_grid(&stencils, &particles, &body, &mut nodes)
                .unwrap();
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
