//! Tran, Berzins & Solowski (2019), eqs 41-48: a neo-Hookean bar on [0, L] with both ends
//! fixed and u = A sin(2 pi X / L) sin(c pi t / L), c = sqrt(E/rho0), driven by the body
//! force of eq 47 with its prefactor corrected to pi^2 u / L^2 (docs/NOTES.md).

use std::f64::consts::PI;

use super::limits::{check_lattice, given_time_step};
use super::sine_mms::{SineMms, SineMmsSpec, SineWave, CELLS, PPC, RHO0};
use super::{boxed, BenchmarkKind, Build};
use super::{BenchmarkInfo, ParamDefault, ParamError, ParamKind, ParamSpec, Params, TimeStep};
use crate::material::{young_from_lame, NeoHookean};
use crate::params::{get_f64, get_usize};
use crate::particles::Placement;

const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        key: "A",
        kind: ParamKind::Real,
        default: ParamDefault::Float(0.1),
        unit: "m",
        doc: "displacement amplitude; the largest strain is 2 pi A / L",
    },
    ParamSpec {
        key: "mu",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(3.85e6),
        unit: "Pa",
        doc: "shear modulus",
    },
    ParamSpec {
        key: "lambda",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(5.77e6),
        unit: "Pa",
        doc: "Lame's first constant",
    },
    RHO0,
    ParamSpec {
        key: "L",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(1.0),
        unit: "m",
        doc: "length of the bar, which is also the grid",
    },
    ParamSpec {
        key: "dt",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(1.0e-5),
        unit: "s",
        doc: "time step; kept when t_end/dt is a whole number (to 1e-9), else shortened so t_end is hit",
    },
    ParamSpec {
        key: "t_end",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(0.02),
        unit: "s",
        doc: "final time (one period 2L/c = 0.019991 s for the default material)",
    },
    PPC,
    CELLS,
];

pub const INFO: BenchmarkInfo = BenchmarkInfo {
    name: "mms1d_tran",
    kind: BenchmarkKind::Simulation,
    build: Build::Line(|params| boxed(tran_mms(params))),
    source: "Tran, Berzins & Solowski 2019, eqs 41-48",
    description: "neo-Hookean bar on [0,L], fixed ends, manufactured solution",
    params: PARAMS,
    check: check_params,
    time_step: Some(time_step),
};

/// The size of the run, and admissibility checks that involve several parameters.
fn check_params(params: &Params) -> Result<(), ParamError> {
    check_lattice(params, 1, "particles")?;
    let a = get_f64(params, "A")?;
    let length = get_f64(params, "L")?;
    let strain = 2.0 * PI * a.abs() / length;
    if strain >= 1.0 {
        return Err(ParamError::new(
            "A",
            format!(
                "|2 pi A / L| = {strain:.4} >= 1 makes the exact deformation gradient \
                 1 + (2 pi A / L) cos(2 pi X / L) sin(c pi t / L) reach zero; use \
                 |A| < L / (2 pi) = {:.6}",
                length / (2.0 * PI)
            ),
        ));
    }
    let material = material(params)?;
    let rho0 = get_f64(params, "rho0")?;
    let dt = get_f64(params, "dt")?;
    let h = length / get_usize(params, "cells")? as f64;
    // Explicit stability (Gong eq 7.32) with the P-wave speed of the linearised model.
    let c_p = (material.p_wave_modulus() / rho0).sqrt();
    let courant = dt * c_p / h;
    if courant > 1.0 {
        return Err(ParamError::new(
            "dt",
            format!(
                "dt = {dt} gives the Courant number dt c_p / h = {courant:.4} > 1, with \
                 c_p = sqrt((lambda + 2 mu)/rho0) = {c_p:.4} m/s and h = L/cells = {h}; the \
                 explicit scheme is unstable. Use dt <= {:.4e}",
                h / c_p
            ),
        ));
    }
    time_step(params).map(drop)
}

/// The given dt, fitted to t_end.
fn time_step(params: &Params) -> Result<TimeStep, ParamError> {
    given_time_step(params, PARAMS)
}

fn material(params: &Params) -> Result<NeoHookean, ParamError> {
    Ok(NeoHookean {
        lambda: get_f64(params, "lambda")?,
        mu: get_f64(params, "mu")?,
    })
}

/// Tran's problem: k = 2 pi / L and omega = c pi / L, i.e. the phase speed is c / 2.
pub fn tran_mms(params: &Params) -> Result<SineMms<1>, ParamError> {
    check_params(params)?;
    let material = material(params)?;
    let rho0 = get_f64(params, "rho0")?;
    let length = get_f64(params, "L")?;
    let c = (young_from_lame(material.lambda, material.mu) / rho0).sqrt();
    Ok(SineMms::new(&SineMmsSpec {
        wave: SineWave {
            amplitude: get_f64(params, "A")?,
            wavenumber: 2.0 * PI / length,
            speed: 0.5 * c,
        },
        length,
        rho0,
        material,
        cells: get_usize(params, "cells")?,
        ppc: get_usize(params, "ppc")?,
        placement: Placement::SubCellCentres,
        step: time_step(params)?,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmarks::sine_mms::tests::{check_body_force, probe_points};
    use crate::benchmarks::{default_params, Problem, CATALOG};
    use crate::params::ParamValue;
    use nalgebra::SVector;

    /// The catalogue defaults with the given overrides.
    fn params(overrides: &[(&str, ParamValue)]) -> Params {
        let mut p = default_params(PARAMS);
        p.insert("ppc".into(), ParamValue::Int(3));
        p.insert("cells".into(), ParamValue::Int(16));
        for (key, value) in overrides {
            p.insert(key.to_string(), value.clone());
        }
        p
    }

    #[test]
    fn is_in_the_catalogue() {
        assert!(CATALOG.entries.iter().any(|b| b.name == "mms1d_tran"));
    }

    #[test]
    fn body_force_matches_finite_differences() {
        check_body_force(tran_mms(&params(&[])).unwrap(), 0.0037);
        let longer = [("L", ParamValue::Float(2.5)), ("A", ParamValue::Float(0.2))];
        check_body_force(tran_mms(&params(&longer)).unwrap(), 0.011);
    }

    /// Eq 47 with the prefactor pi^2 u / L^2:
    /// b = (pi^2 u / L^2) [4 mu/rho0 - c^2 + 4 (lambda (1 - ln F) + mu) / (rho0 F^2)].
    #[test]
    fn body_force_is_corrected_eq_47() {
        let length = 2.5;
        let p = params(&[
            ("L", ParamValue::Float(length)),
            ("A", ParamValue::Float(0.2)),
        ]);
        let mut m = tran_mms(&p).unwrap();
        let NeoHookean { lambda, mu } = material(&p).unwrap();
        let rho0 = m.rho0();
        let c2 = young_from_lame(lambda, mu) / rho0;
        let points = probe_points::<1>(length);
        m.attach_particles(&points);
        let t = 0.011;
        let mut b = vec![SVector::zeros(); points.len()];
        m.body_force(t, &mut b);
        for (x0, b) in points.iter().zip(&b) {
            let exact = m.exact(x0, t).unwrap();
            let (u, f) = (exact.displacement[0], rho0 / exact.density);
            let eq47 = PI * PI * u / (length * length)
                * (4.0 * mu / rho0 - c2 + 4.0 * (lambda * (1.0 - f.ln()) + mu) / (rho0 * f * f));
            assert!(
                (b[0] - eq47).abs() < 1e-9 * eq47.abs().max(1.0),
                "X = {}: {} vs eq 47 {eq47}",
                x0[0],
                b[0]
            );
        }
    }

    #[test]
    fn default_time_step_is_kept() {
        let m = tran_mms(&params(&[])).unwrap();
        assert_eq!(m.steps(), 2000);
        assert!((m.dt() - 1e-5).abs() < 1e-20);
    }

    #[test]
    fn rejects_inverting_amplitude_and_unstable_dt() {
        let p = params(&[("A", ParamValue::Float(-0.16))]);
        assert_eq!(check_params(&p).unwrap_err().key, "A");
        let p = params(&[("dt", ParamValue::Float(6e-4))]);
        assert_eq!(check_params(&p).unwrap_err().key, "dt");
        // The bound scales with h = L / cells: the same dt is stable on a coarser grid.
        let p = params(&[
            ("dt", ParamValue::Float(6e-4)),
            ("cells", ParamValue::Int(8)),
        ]);
        assert!(check_params(&p).is_ok());
    }
}
