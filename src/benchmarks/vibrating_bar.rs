//! Wobbes et al. (2018), sec 5: a linear-elastic bar on [0, H] with fixed ends, set vibrating
//! by v(X, 0) = v0 sin(pi X / H), with rho v_t = sigma_x and sigma_t = E v_x. For small
//! strain the exact solution is eq 15, u = v0 H / (pi c) sin(pi c t / H) sin(pi X / H) with
//! c = sqrt(E / rho0); for large strain there is none (`exact: none`) and runs are compared
//! with a reference run instead (the `ulfem` method, `reference`).

use std::f64::consts::PI;

use nalgebra::{SMatrix, SVector};

use super::limits::{check_lattice, given_time_step};
use super::{boxed, BenchmarkKind, Build};
use super::{BenchmarkInfo, ExactState, FixedFaces, ParamDefault, ParamKind, ParamSpec};
use super::{ParamError, Params, Problem, TimeStep};
use crate::grid::Domain;
use crate::material::{LinearElasticRate, Material};
use crate::params::{get_f64, get_str, get_usize};

/// Values of the `exact` parameter.
const EXACT_CHOICES: &[&str] = &["small_strain", "none"];

const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        key: "H",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(1.0),
        unit: "m",
        doc: "length of the bar, which is also the grid",
    },
    ParamSpec {
        key: "rho0",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(2.0e3),
        unit: "kg/m^D",
        doc: "initial density",
    },
    ParamSpec {
        key: "E",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(7.0e6),
        unit: "Pa",
        doc: "Young's modulus (Table 1; Table 2 uses 4e4)",
    },
    ParamSpec {
        key: "v0",
        kind: ParamKind::Real,
        default: ParamDefault::Float(0.28),
        unit: "m/s",
        doc: "largest initial velocity (Table 1; Table 2 uses 0.8)",
    },
    ParamSpec {
        key: "dt",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(1.0e-7),
        unit: "s",
        doc: "time step; kept when t_end/dt is a whole number (to 1e-9), else shortened so t_end is hit",
    },
    ParamSpec {
        key: "t_end",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(1.9e-6),
        unit: "s",
        doc: "final time (Table 1: 1.9e-6; the large-strain case: 0.1)",
    },
    ParamSpec {
        key: "exact",
        kind: ParamKind::Choice(EXACT_CHOICES),
        default: ParamDefault::Text("small_strain"),
        unit: "1",
        doc: "small_strain: errors against eq 15; none: no exact solution (errors NaN)",
    },
    ParamSpec {
        key: "ppc",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(12),
        unit: "1",
        doc: "material points per cell (ignored by ulfem, which has one point per element)",
    },
    ParamSpec {
        key: "cells",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Required,
        unit: "1",
        doc: "grid cells (elements for ulfem)",
    },
];

pub const INFO: BenchmarkInfo = BenchmarkInfo {
    name: "vibrating_bar",
    kind: BenchmarkKind::Simulation,
    build: Build::Line(|params| boxed(vibrating_bar(params))),
    source: "Wobbes et al. 2018, sec 5, eq 15, Tables 1-2",
    description: "linear-elastic bar on [0,H], fixed ends, sine initial velocity",
    params: PARAMS,
    check: check_params,
    time_step: Some(time_step),
};

/// The size of the run, explicit stability with the undeformed wave speed, and an exact
/// solution that keeps the density finite.
fn check_params(params: &Params) -> Result<(), ParamError> {
    check_lattice(params, 1, "particles")?;
    let bar = VibratingBar::new(params)?;
    let h = bar.length / bar.cells as f64;
    let c = bar.wave_speed();
    let dt = get_f64(params, "dt")?;
    let courant = dt * c / h;
    if courant > 1.0 {
        return Err(ParamError::new(
            "dt",
            format!(
                "dt = {dt} gives the Courant number dt c / h = {courant:.4} > 1, with \
                 c = sqrt(E/rho0) = {c:.4} m/s and h = H/cells = {h}; the explicit scheme is \
                 unstable. Use dt <= {:.4e}",
                h / c
            ),
        ));
    }
    let strain = bar.v0.abs() / c;
    if bar.small_strain && strain >= 1.0 {
        return Err(ParamError::new(
            "v0",
            format!(
                "|v0| / c = {strain:.4} >= 1 makes the exact strain of eq 15 reach -1 (zero \
                 length); use |v0| < c = {c:.4} m/s, or exact: none"
            ),
        ));
    }
    Ok(())
}

/// The bar with its parameters resolved.
pub struct VibratingBar {
    length: f64,
    rho0: f64,
    young: f64,
    v0: f64,
    cells: usize,
    ppc: usize,
    dt: f64,
    steps: usize,
    /// Whether `exact` gives eq 15.
    small_strain: bool,
}

impl VibratingBar {
    fn new(params: &Params) -> Result<Self, ParamError> {
        let TimeStep { dt, steps } = time_step(params)?;
        Ok(VibratingBar {
            length: get_f64(params, "H")?,
            rho0: get_f64(params, "rho0")?,
            young: get_f64(params, "E")?,
            v0: get_f64(params, "v0")?,
            cells: get_usize(params, "cells")?,
            ppc: get_usize(params, "ppc")?,
            dt,
            steps,
            small_strain: get_str(params, "exact")? == EXACT_CHOICES[0],
        })
    }

    fn wave_speed(&self) -> f64 {
        (self.young / self.rho0).sqrt()
    }
}

/// The given dt, fitted to t_end.
fn time_step(params: &Params) -> Result<TimeStep, ParamError> {
    given_time_step(params, PARAMS)
}

/// Builds the bar from validated parameters.
pub fn vibrating_bar(params: &Params) -> Result<VibratingBar, ParamError> {
    check_params(params)?;
    VibratingBar::new(params)
}

impl Problem<1> for VibratingBar {
    fn domain(&self) -> Domain<1> {
        Domain {
            lower: SVector::zeros(),
            upper: SVector::repeat(self.length),
            cells: self.cells,
        }
    }

    fn body(&self) -> (SVector<f64, 1>, SVector<f64, 1>) {
        (SVector::zeros(), SVector::repeat(self.length))
    }

    fn ppc(&self) -> usize {
        self.ppc
    }

    fn rho0(&self) -> f64 {
        self.rho0
    }

    /// nu = 0, so lambda = 0, 2 mu = E and sigma_t = E v_x.
    fn material(&self) -> Material {
        Material::LinearElasticRate(LinearElasticRate::without_poisson(self.young))
    }

    fn dt(&self) -> f64 {
        self.dt
    }

    fn steps(&self) -> usize {
        self.steps
    }

    fn fixed_faces(&self) -> FixedFaces<1> {
        [[true, true]]
    }

    fn initial_velocity(&self, x0: &SVector<f64, 1>) -> SVector<f64, 1> {
        x0.map(|x| self.v0 * (PI * x / self.length).sin())
    }

    fn body_force(&mut self, _t: f64, out: &mut [SVector<f64, 1>]) {
        out.fill(SVector::zeros());
    }

    fn attach_particles(&mut self, _x0: &[SVector<f64, 1>]) {}

    /// Eq 15 and its derivatives: v = u_t, sigma = E u_X, density rho0 / (1 + u_X).
    fn exact(&self, x0: &SVector<f64, 1>, t: f64) -> Option<ExactState<1>> {
        if !self.small_strain {
            return None;
        }
        let c = self.wave_speed();
        let k = PI / self.length;
        let (st, ct) = (k * c * t).sin_cos();
        let (sx, cx) = (k * x0[0]).sin_cos();
        let u = self.v0 / (k * c) * st * sx;
        let strain = self.v0 / c * st * cx;
        Some(ExactState {
            displacement: SVector::repeat(u),
            velocity: SVector::repeat(self.v0 * ct * sx),
            stress: SMatrix::repeat(self.young * strain),
            density: self.rho0 / (1.0 + strain),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmarks::{default_params, CATALOG};
    use crate::params::ParamValue;

    fn params(overrides: &[(&str, ParamValue)]) -> Params {
        let mut p = default_params(PARAMS);
        p.insert("cells".into(), ParamValue::Int(10));
        for (key, value) in overrides {
            p.insert(key.to_string(), value.clone());
        }
        p
    }

    #[test]
    fn is_in_the_catalogue_with_table_1_defaults() {
        assert!(CATALOG.entries.iter().any(|b| b.name == "vibrating_bar"));
        let bar = vibrating_bar(&params(&[])).unwrap();
        assert_eq!(bar.steps(), 19);
        assert!((bar.dt() - 1e-7).abs() < 1e-22);
        assert_eq!(bar.material().p_wave_modulus(), 7e6);
    }

    /// rho0 v_t = sigma_X and sigma_t = E v_X, checked by central differences of eq 15.
    #[test]
    fn exact_solution_satisfies_the_equations() {
        let bar = vibrating_bar(&params(&[])).unwrap();
        let (t, dx, dt) = (3.1e-3, 1e-6, 1e-7);
        for x in [0.13, 0.5, 0.87] {
            let at = |x: f64, t: f64| bar.exact(&SVector::repeat(x), t).unwrap();
            let s = at(x, t);
            let v_t = (at(x, t + dt).velocity[0] - at(x, t - dt).velocity[0]) / (2.0 * dt);
            let sigma_x =
                (at(x + dx, t).stress[(0, 0)] - at(x - dx, t).stress[(0, 0)]) / (2.0 * dx);
            assert!((bar.rho0 * v_t - sigma_x).abs() < 1e-6 * sigma_x.abs().max(1.0));
            let sigma_t =
                (at(x, t + dt).stress[(0, 0)] - at(x, t - dt).stress[(0, 0)]) / (2.0 * dt);
            let v_x = (at(x + dx, t).velocity[0] - at(x - dx, t).velocity[0]) / (2.0 * dx);
            assert!((sigma_t - bar.young * v_x).abs() < 1e-6 * sigma_t.abs().max(1.0));
            let u_t = (at(x, t + dt).displacement[0] - at(x, t - dt).displacement[0]) / (2.0 * dt);
            assert!((u_t - s.velocity[0]).abs() < 1e-8);
        }
        let v0 = bar.initial_velocity(&SVector::repeat(0.5))[0];
        assert_eq!(
            v0,
            bar.exact(&SVector::repeat(0.5), 0.0).unwrap().velocity[0]
        );
    }

    #[test]
    fn large_strain_has_no_exact_solution() {
        let p = params(&[("exact", ParamValue::Str("none".into()))]);
        assert!(vibrating_bar(&p)
            .unwrap()
            .exact(&SVector::repeat(0.3), 0.0)
            .is_none());
    }

    #[test]
    fn rejects_unstable_dt_and_inverting_amplitude() {
        let p = params(&[("dt", ParamValue::Float(2e-3))]);
        assert_eq!(check_params(&p).unwrap_err().key, "dt");
        let p = params(&[("v0", ParamValue::Float(-60.0))]);
        assert_eq!(check_params(&p).unwrap_err().key, "v0");
        let p = params(&[
            ("v0", ParamValue::Float(-60.0)),
            ("exact", ParamValue::Str("none".into())),
        ]);
        assert!(check_params(&p).is_ok());
    }
}
