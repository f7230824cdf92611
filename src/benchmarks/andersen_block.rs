//! Molinos et al., sec 6.2 (after Andersen 2009): an H x H linear-elastic block on a rigid base,
//! loaded by gravity ramped up by eq 41 over T and then held, so that the block settles
//! towards its quasi-static state. The base y = 0 and the side x = 0 hold the normal velocity
//! (rollers: with nu = 0 the block does not expand sideways, so a base that also held the
//! tangential velocity would change nothing); the top and the side x = H are free, with
//! `extra_cells` empty cells of grid beyond them. There is no exact solution; the probes are
//! drawn against the small-strain static solution under the current g(t):
//!   sigma_yy(Y) = -rho0 g(t) (H - Y),   u_y(Y) = -(rho0 g(t) / E) (H Y - Y^2 / 2),
//! whose top displacement at full g is -rho0 g H^2 / (2E) (-0.5886 m with the defaults) and
//! whose base stress is -rho0 g H (-0.589 MPa; docs/NOTES.md on the 5.2 MPa the paper prints).

use std::f64::consts::PI;

use nalgebra::{SMatrix, SVector, Vector2};

use super::limits::{check_lattice, courant_time_step};
use super::{boxed, placement, BenchmarkKind, Build, PLACEMENTS, PLACEMENT_KEY};
use super::{courant_number, ParamError, Params, Probe, ProbeQuantity, Problem, TimeStep};
use super::{BenchmarkInfo, ExactState, FixedFaces, ParamDefault, ParamKind, ParamSpec};
use crate::grid::Domain;
use crate::material::{LinearElasticRate, Material};
use crate::params::{get_f64, get_usize};
use crate::particles::Placement;

const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        key: "H",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(10.0),
        unit: "m",
        doc: "side of the square block",
    },
    ParamSpec {
        key: "cells",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(5),
        unit: "1",
        doc: "grid cells across the block per axis (h = H / cells; 5 gives the paper's 2 m)",
    },
    ParamSpec {
        key: "extra_cells",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(1),
        unit: "1",
        doc: "grid cells beyond the top and the free side",
    },
    ParamSpec {
        key: "ppc",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(2),
        unit: "1",
        doc: "material points per cell and axis",
    },
    ParamSpec {
        key: PLACEMENT_KEY,
        kind: ParamKind::Choice(PLACEMENTS),
        // The paper's choice for the hat and LME; uGIMP's domains need the centres.
        default: ParamDefault::Text("gauss"),
        unit: "1",
        doc: "gauss: the Gauss points of each cell; centres: the sub-cell centres \
              (required by the particle-domain methods)",
    },
    ParamSpec {
        key: "rho0",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(6000.0),
        unit: "kg/m^D",
        doc: "initial density",
    },
    ParamSpec {
        key: "E",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(5e6),
        unit: "Pa",
        doc: "Young's modulus (nu = 0)",
    },
    ParamSpec {
        key: "g",
        kind: ParamKind::Real,
        default: ParamDefault::Float(9.81),
        unit: "m/s^2",
        doc: "gravity at full load, pointing in -y",
    },
    ParamSpec {
        key: "T",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(20.0),
        unit: "s",
        doc: "loading period of eq 41: gravity ramps up until T/2, then holds",
    },
    ParamSpec {
        key: "cfl",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(0.1),
        unit: "1",
        doc: "Courant number: dt = cfl h / c, shortened so that t_end is hit",
    },
    ParamSpec {
        key: "t_end",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(20.0),
        unit: "s",
        doc: "final time (the paper: T)",
    },
];

pub const INFO: BenchmarkInfo = BenchmarkInfo {
    name: "andersen_block",
    kind: BenchmarkKind::Simulation,
    build: Build::Plane(|params| boxed(andersen_block(params))),
    source: "Molinos et al., sec 6.2, eq 41 (Andersen 2009)",
    description: "elastic block on a rigid base under gravity ramped up by eq 41; probes \
                  top_displacement, bottom_stress",
    params: PARAMS,
    check: check_params,
    time_step: Some(time_step),
};

/// The size of the run, the explicit scheme's Courant bound, and a static strain below 1.
fn check_params(params: &Params) -> Result<(), ParamError> {
    check_lattice(params, 2, "particles")?;
    courant_number(params)?;
    let block = AndersenBlock::new(params)?;
    let strain = block.rho0 * block.gravity.abs() * block.height / block.young;
    if strain >= 1.0 {
        return Err(ParamError::new(
            "g",
            format!(
                "the static strain at the base, rho0 g H / E = {strain:.4}, reaches 1 (zero \
                 length); lower g or H, or raise E"
            ),
        ));
    }
    Ok(())
}

/// The block with its parameters resolved.
pub struct AndersenBlock {
    height: f64,
    cells: usize,
    extra_cells: usize,
    ppc: usize,
    placement: Placement,
    rho0: f64,
    young: f64,
    gravity: f64,
    period: f64,
    dt: f64,
    steps: usize,
}

impl AndersenBlock {
    fn new(params: &Params) -> Result<Self, ParamError> {
        let TimeStep { dt, steps } = time_step(params)?;
        let placement = placement(params, Placement::Gauss)?;
        Ok(AndersenBlock {
            height: get_f64(params, "H")?,
            cells: get_usize(params, "cells")?,
            extra_cells: get_usize(params, "extra_cells")?,
            ppc: get_usize(params, "ppc")?,
            placement,
            rho0: get_f64(params, "rho0")?,
            young: get_f64(params, "E")?,
            gravity: get_f64(params, "g")?,
            period: get_f64(params, "T")?,
            dt,
            steps,
        })
    }

    /// Eq 41: 0.5 g (sin(2 pi t / T - pi / 2) + 1) until T/2, then g; the ramp starts at 0 with
    /// zero slope and meets g with zero slope.
    fn gravity_at(&self, t: f64) -> f64 {
        if t <= 0.5 * self.period {
            0.5 * self.gravity * ((2.0 * PI * t / self.period - 0.5 * PI).sin() + 1.0)
        } else {
            self.gravity
        }
    }
}

/// dt = cfl h / c over the block's cells, with c = sqrt(E/rho0).
fn time_step(params: &Params) -> Result<TimeStep, ParamError> {
    courant_time_step(params, PARAMS, get_f64(params, "H")?)
}

/// Builds the block from validated parameters.
pub fn andersen_block(params: &Params) -> Result<AndersenBlock, ParamError> {
    check_params(params)?;
    AndersenBlock::new(params)
}

impl Problem<2> for AndersenBlock {
    fn domain(&self) -> Domain<2> {
        Domain::padded(self.height, self.cells, self.extra_cells)
    }

    fn body(&self) -> (SVector<f64, 2>, SVector<f64, 2>) {
        (SVector::zeros(), SVector::repeat(self.height))
    }

    fn ppc(&self) -> usize {
        self.ppc
    }

    fn rho0(&self) -> f64 {
        self.rho0
    }

    /// nu = 0, so lambda = 0 and 2 mu = E.
    fn material(&self) -> Material {
        Material::LinearElasticRate(LinearElasticRate::without_poisson(self.young))
    }

    fn dt(&self) -> f64 {
        self.dt
    }

    fn steps(&self) -> usize {
        self.steps
    }

    /// x = 0 and y = 0 hold the normal velocity; the upper faces lie beyond the free surfaces.
    fn fixed_faces(&self) -> FixedFaces<2> {
        [[true, false], [true, false]]
    }

    fn initial_velocity(&self, _x0: &SVector<f64, 2>) -> SVector<f64, 2> {
        SVector::zeros()
    }

    fn body_force(&mut self, t: f64, out: &mut [SVector<f64, 2>]) {
        out.fill(Vector2::new(0.0, -self.gravity_at(t)));
    }

    fn attach_particles(&mut self, _x0: &[SVector<f64, 2>]) {}

    fn exact(&self, _x0: &SVector<f64, 2>, _t: f64) -> Option<ExactState<2>> {
        None
    }

    fn placement(&self) -> Placement {
        self.placement
    }

    /// The vertical displacement near the middle of the top and the vertical stress near the
    /// middle of the base (Molinos Figs 10-11). With an odd number of cells, x = H/2 is a cell
    /// centre with a particle either side at ppc = 2; the tie picks the lower x.
    fn probes(&self) -> Vec<Probe<2>> {
        vec![
            Probe {
                name: "top_displacement",
                at: Vector2::new(0.5 * self.height, self.height),
                quantity: ProbeQuantity::Displacement(1),
            },
            Probe {
                name: "bottom_stress",
                at: Vector2::new(0.5 * self.height, 0.0),
                quantity: ProbeQuantity::Stress(1, 1),
            },
        ]
    }

    /// The small-strain static solution under g(t), in the reference configuration.
    fn probe_reference(&self, x0: &SVector<f64, 2>, t: f64) -> Option<ExactState<2>> {
        let (y, height) = (x0[1], self.height);
        let load = self.rho0 * self.gravity_at(t);
        let strain = -load * (height - y) / self.young;
        Some(ExactState {
            displacement: Vector2::new(0.0, -load / self.young * (height * y - 0.5 * y * y)),
            velocity: SVector::zeros(),
            stress: SMatrix::from_diagonal(&Vector2::new(0.0, self.young * strain)),
            density: self.rho0 / (1.0 + strain),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell(b: &AndersenBlock) -> f64 {
        b.height / b.cells as f64
    }
    use crate::benchmarks::{default_params, CATALOG};
    use crate::grid::Grid;
    use crate::params::ParamValue;

    fn block(overrides: &[(&str, ParamValue)]) -> AndersenBlock {
        let mut p = default_params(PARAMS);
        for (key, value) in overrides {
            p.insert(key.to_string(), value.clone());
        }
        andersen_block(&p).unwrap()
    }

    #[test]
    fn is_in_the_catalogue_with_the_papers_grid() {
        assert!(CATALOG.entries.iter().any(|b| b.name == "andersen_block"));
        let b = block(&[]);
        assert_eq!(cell(&b), 2.0);
        let domain = b.domain();
        assert_eq!(domain.cells, 6);
        assert_eq!(domain.upper, Vector2::repeat(12.0));
        // c = sqrt(5e6 / 6000) = 28.87 m/s, dt <= 0.1 h / c = 6.93e-3 s: 2887 steps to 20 s.
        assert_eq!(b.steps(), 2887);
        assert!(b.dt() <= 0.1 * 2.0 / (5e6f64 / 6000.0).sqrt());
    }

    #[test]
    fn eq_41_starts_at_zero_and_joins_g_smoothly() {
        let b = block(&[]);
        let (g, half) = (b.gravity, 0.5 * b.period);
        assert!(b.gravity_at(0.0).abs() < 1e-15);
        let eps = 1e-6;
        let slope = |t: f64| (b.gravity_at(t + eps) - b.gravity_at(t - eps)) / (2.0 * eps);
        assert!(slope(eps).abs() < 1e-6);
        assert!((b.gravity_at(half) - g).abs() < 1e-12);
        assert!((b.gravity_at(half - eps) - g).abs() < 1e-9);
        assert_eq!(b.gravity_at(half + eps), g);
        assert!(slope(half).abs() < 1e-6, "{}", slope(half));
        // Halfway up the ramp the load is half of g, rising fastest: pi g / T.
        assert!((b.gravity_at(0.25 * b.period) - 0.5 * g).abs() < 1e-12);
        assert!((slope(0.25 * b.period) - PI * g / b.period).abs() < 1e-6);
    }

    #[test]
    fn static_solution_balances_gravity() {
        let b = block(&[]);
        let t = 0.5 * b.period;
        let at = |y: f64| b.probe_reference(&Vector2::new(3.0, y), t).unwrap();
        let dy = 1e-4;
        for y in [0.5, 3.0, 7.5, 9.9] {
            let dsigma = (at(y + dy).stress[(1, 1)] - at(y - dy).stress[(1, 1)]) / (2.0 * dy);
            assert!((dsigma - b.rho0 * b.gravity).abs() < 1e-6 * b.rho0 * b.gravity);
            let strain = (at(y + dy).displacement[1] - at(y - dy).displacement[1]) / (2.0 * dy);
            assert!((b.young * strain - at(y).stress[(1, 1)]).abs() < 1e-3);
        }
        assert_eq!(at(b.height).stress[(1, 1)], 0.0);
        assert_eq!(at(0.0).displacement[1], 0.0);
        let top = at(b.height).displacement[1];
        assert!((top + 0.5886).abs() < 1e-4, "{top}");
        assert!((at(0.0).stress[(1, 1)] + 588_600.0).abs() < 1e-6);
    }

    /// Gauss points at x_e + h (1 -+ 1/sqrt 3) / 2, sub-cell centres at x_e + h/4 and x_e + 3h/4;
    /// both with 4 points of volume h^2 / 4 per cell, 100 in all, filling the block.
    #[test]
    fn placements_give_the_expected_points_and_volumes() {
        for (placement, offsets) in [
            ("gauss", [1.0 - 1.0 / 3f64.sqrt(), 1.0 + 1.0 / 3f64.sqrt()]),
            ("centres", [0.5, 1.5]),
        ] {
            let b = block(&[("placement", ParamValue::Str(placement.into()))]);
            let grid = Grid::new(&b.domain());
            let particles = b.seed_particles(&grid);
            assert_eq!(particles.len(), 100);
            let h = cell(&b);
            for (p, x) in particles.x0.iter().enumerate() {
                for k in 0..2 {
                    let cell = (x[k] / h).floor();
                    let local = x[k] - cell * h;
                    let near = offsets.iter().any(|o| (local - 0.5 * h * o).abs() < 1e-12);
                    assert!(near, "{placement}: particle {p} at {x:?}");
                }
                assert!((particles.volume0[p] - 0.25 * h * h).abs() < 1e-12);
                assert_eq!(particles.mass[p], b.rho0 * particles.volume0[p]);
            }
            let area: f64 = particles.volume0.iter().sum();
            assert!((area - 100.0).abs() < 1e-10, "{area}");
        }
    }

    /// x = H/2 falls between two particles of the middle column: the lower x is taken, at
    /// x_e + h (1 - 1/sqrt 3) / 2 = 4.42 m, in the top row (9.58 m) and the bottom row (0.42 m).
    #[test]
    fn probes_take_the_middle_column() {
        let b = block(&[]);
        let grid = Grid::new(&b.domain());
        let particles = b.seed_particles(&grid);
        let low = 1.0 - 1.0 / 3f64.sqrt();
        let probes = b.probes();
        let top = particles.x0[probes[0].nearest(&particles.x0).unwrap()];
        assert!(
            (top - Vector2::new(4.0 + low, 10.0 - low)).norm() < 1e-12,
            "{top:?}"
        );
        let bottom = particles.x0[probes[1].nearest(&particles.x0).unwrap()];
        assert!(
            (bottom - Vector2::new(4.0 + low, low)).norm() < 1e-12,
            "{bottom:?}"
        );
    }
}
