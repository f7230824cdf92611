//! Gong's manufactured solutions (thesis sec 4.5 and 4.7): a neo-Hookean bar (1D) and a
//! plane-strain square (2D) with U_k = G sin(pi X_k) sin(c pi t) in each direction, driven
//! by the body force that makes U exact. The 1D problem is the D = 1 case of the 2D one;
//! both are the standing wave of `sine_mms` with k = pi and omega = c pi.

use std::f64::consts::PI;

use super::limits::{check_lattice, courant_time_step};
use super::sine_mms::{SineMms, SineMmsSpec, SineWave, CELLS, PPC, RHO0};
use super::{boxed, placement, BenchmarkKind, Build, PLACEMENTS, PLACEMENT_KEY};
use super::{BenchmarkInfo, ParamDefault, ParamError, ParamKind, ParamSpec, Params, TimeStep};
use crate::material::{lame_from_young, NeoHookean};
use crate::params::{get_f64, get_usize};
use crate::particles::Placement;

const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        key: "G",
        kind: ParamKind::Real,
        default: ParamDefault::Required,
        unit: "m",
        doc: "displacement amplitude; the largest strain is pi G",
    },
    ParamSpec {
        key: "E",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(1.0e7),
        unit: "Pa",
        doc: "Young's modulus; also sets c = sqrt(E/rho0)",
    },
    ParamSpec {
        key: "nu",
        kind: ParamKind::Real,
        default: ParamDefault::Float(0.3),
        unit: "1",
        doc: "Poisson's ratio, in (-1, 0.5)",
    },
    RHO0,
    ParamSpec {
        key: "t_end",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(0.02),
        unit: "s",
        doc: "final time (0.02 s is one period for the default material)",
    },
    ParamSpec {
        key: "cfl",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(0.4),
        unit: "1",
        doc: "dt = cfl h / c with c = sqrt(E/rho0); dt is then shortened so t_end is hit exactly",
    },
    ParamSpec {
        key: "courant_limit",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(1.0),
        unit: "1",
        doc: "largest accepted Courant number dt c_p / h; raise it only to study instability",
    },
    PPC,
    ParamSpec {
        key: PLACEMENT_KEY,
        kind: ParamKind::Choice(PLACEMENTS),
        default: ParamDefault::Implicit("centres"),
        unit: "1",
        doc: "where the ppc^D points of a cell sit: centres, the sub-cell centres (Gong's \
              choice); gauss, the Gauss points, whose rule is exact for polynomials of \
              degree 2 ppc - 1 on the cell",
    },
    CELLS,
];

pub const INFO_1D: BenchmarkInfo = BenchmarkInfo {
    name: "mms1d_gong",
    kind: BenchmarkKind::Simulation,
    build: Build::Line(|params| boxed(gong_mms::<1>(params))),
    source: "Gong 2015, eqs 4.35-4.39",
    description: "neo-Hookean bar on [0,1], fixed ends, manufactured solution",
    params: PARAMS,
    check: check_params::<1>,
    time_step: Some(time_step),
};

pub const INFO_2D: BenchmarkInfo = BenchmarkInfo {
    name: "mms2d_gong",
    kind: BenchmarkKind::Simulation,
    build: Build::Plane(|params| boxed(gong_mms::<2>(params))),
    source: "Gong 2015, eqs 4.41-4.46",
    description: "plane-strain neo-Hookean square [0,1]^2, roller walls, manufactured solution",
    params: PARAMS,
    check: check_params::<2>,
    time_step: Some(time_step),
};

/// The size of the run in `D` dimensions, and admissibility checks that involve several
/// parameters.
fn check_params<const D: usize>(params: &Params) -> Result<(), ParamError> {
    check_lattice(params, D, "particles")?;
    let g = get_f64(params, "G")?;
    if g.abs() * PI >= 1.0 {
        return Err(ParamError::new(
            "G",
            format!(
                "|G| pi = {:.4} >= 1 makes the exact deformation gradient 1 + pi G cos(pi X) \
                 sin(c pi t) reach zero; use |G| < 1/pi = {:.6}",
                g.abs() * PI,
                1.0 / PI
            ),
        ));
    }
    let nu = get_f64(params, "nu")?;
    if !(nu > -1.0 && nu < 0.5) {
        return Err(ParamError::new(
            "nu",
            format!("Poisson's ratio {nu} is outside (-1, 0.5)"),
        ));
    }
    let e = get_f64(params, "E")?;
    let cfl = get_f64(params, "cfl")?;
    let limit = get_f64(params, "courant_limit")?;
    let (lambda, mu) = lame_from_young(e, nu);
    // Gong eq 7.32: stable when the Courant number with the true wave speed is <= 1. The
    // wave speed of the linearised neo-Hookean model is sqrt((lambda + 2 mu)/rho0), not c.
    // `courant_limit` (default 1) moves the bound only for studies of the instability.
    let ratio = ((lambda + 2.0 * mu) / e).sqrt();
    if cfl * ratio > limit {
        let why = if limit == 1.0 {
            "the explicit scheme is unstable (Gong eq 7.32)".to_string()
        } else {
            format!("above courant_limit = {limit}")
        };
        return Err(ParamError::new(
            "cfl",
            format!(
                "cfl = {cfl} gives the Courant number dt c_p / h = {:.4} > {limit}, with the \
                 P-wave speed c_p = sqrt((lambda + 2 mu)/rho0) = {ratio:.4} c; {why}. Use \
                 cfl <= {:.4}, or raise courant_limit to study the instability",
                cfl * ratio,
                limit / ratio
            ),
        ));
    }
    time_step(params).map(drop)
}

/// dt = cfl h / c on the unit box, with the phase speed c = sqrt(E/rho0).
fn time_step(params: &Params) -> Result<TimeStep, ParamError> {
    courant_time_step(params, PARAMS, 1.0)
}

/// Gong's parameter set of sec 4.6 (E = 1e7, nu = 0.3, rho0 = 1e3, t_end = 0.02, cfl = 0.4)
/// with the given amplitude, cells and points per cell.
pub fn thesis_params(g: f64, cells: i64, ppc: i64) -> Params {
    let mut p = Params::new();
    for (k, v) in [
        ("G", g),
        ("E", 1e7),
        ("nu", 0.3),
        ("rho0", 1e3),
        ("t_end", 0.02),
        ("cfl", 0.4),
        ("courant_limit", 1.0),
    ] {
        p.insert(k.into(), crate::params::ParamValue::Float(v));
    }
    p.insert("ppc".into(), crate::params::ParamValue::Int(ppc));
    p.insert("cells".into(), crate::params::ParamValue::Int(cells));
    p
}

/// Gong's problem in `D` dimensions: the unit box, k = pi, phase speed c = sqrt(E/rho0).
pub fn gong_mms<const D: usize>(params: &Params) -> Result<SineMms<D>, ParamError> {
    check_params::<D>(params)?;
    let e = get_f64(params, "E")?;
    let nu = get_f64(params, "nu")?;
    let rho0 = get_f64(params, "rho0")?;
    let cells = get_usize(params, "cells")?;
    let (lambda, mu) = lame_from_young(e, nu);
    let c = (e / rho0).sqrt();
    let length = 1.0;
    Ok(SineMms::new(&SineMmsSpec {
        wave: SineWave {
            amplitude: get_f64(params, "G")?,
            wavenumber: PI,
            speed: c,
        },
        length,
        rho0,
        material: NeoHookean { lambda, mu },
        cells,
        ppc: get_usize(params, "ppc")?,
        placement: placement(params, Placement::SubCellCentres)?,
        step: time_step(params)?,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmarks::sine_mms::tests::check_body_force;
    use crate::benchmarks::Problem;
    use crate::params::ParamValue;
    use nalgebra::{SMatrix, SVector};

    #[test]
    fn body_force_matches_finite_differences_1d() {
        check_body_force(gong_mms::<1>(&thesis_params(0.1, 16, 2)).unwrap(), 0.0037);
    }

    #[test]
    fn body_force_matches_finite_differences_2d() {
        check_body_force(gong_mms::<2>(&thesis_params(0.1, 16, 2)).unwrap(), 0.0037);
    }

    #[test]
    fn thesis_time_step_divides_one_period() {
        let m = gong_mms::<1>(&thesis_params(1e-4, 8, 2)).unwrap();
        assert_eq!(m.steps(), 40);
        assert!((m.dt() - 5e-4).abs() < 1e-18);
    }

    #[test]
    fn exact_state_is_consistent() {
        let m = gong_mms::<2>(&thesis_params(0.05, 8, 2)).unwrap();
        let x0 = SVector::<f64, 2>::new(0.3, 0.8);
        let s = m.exact(&x0, 0.0).unwrap();
        assert_eq!(s.displacement, SVector::<f64, 2>::zeros());
        assert_eq!(s.stress, SMatrix::<f64, 2, 2>::zeros());
        assert!((s.velocity - m.initial_velocity(&x0)).norm() < 1e-12);
    }

    #[test]
    fn rejects_unstable_cfl_and_inverting_amplitude() {
        let mut p = thesis_params(0.1, 8, 2);
        p.insert("cfl".into(), ParamValue::Float(0.9));
        assert_eq!(check_params::<1>(&p).unwrap_err().key, "cfl");
        let p = thesis_params(0.4, 8, 2);
        assert_eq!(check_params::<1>(&p).unwrap_err().key, "G");
    }

    #[test]
    fn courant_limit_moves_the_bound_for_stability_studies() {
        // nu = 0.3: c_p = 1.1602 c, so cfl 1.2 is the Courant number 1.392.
        let mut p = thesis_params(1e-4, 8, 2);
        p.insert("cfl".into(), ParamValue::Float(1.2));
        let e = check_params::<1>(&p).unwrap_err();
        assert!(e.message.contains("Use cfl <= 0.8619"), "{e}");
        assert!(e.message.contains("raise courant_limit"), "{e}");
        p.insert("courant_limit".into(), ParamValue::Float(1.5));
        assert!(check_params::<1>(&p).is_ok());
        p.insert("cfl".into(), ParamValue::Float(1.3));
        let e = check_params::<1>(&p).unwrap_err();
        assert_eq!(e.key, "cfl");
        assert!(
            e.message.contains("> 1.5") && e.message.contains("Use cfl <= 1.2928"),
            "{e}"
        );
    }

    /// `placement` is left out of a run's parameters unless the run sets it, so adding it kept
    /// every run's id; unset it seeds the sub-cell centres, `gauss` the 2-point Gauss points.
    #[test]
    fn placement_is_implicit_and_seeds_the_centres_or_the_gauss_points() {
        assert!(!crate::benchmarks::default_params(PARAMS).contains_key(PLACEMENT_KEY));
        let seeded = |params: &Params| -> Vec<f64> {
            let m = gong_mms::<1>(params).unwrap();
            let grid = crate::grid::Grid::new(&m.domain());
            m.seed_particles(&grid).x0.iter().map(|x| x[0]).collect()
        };
        let mut params = thesis_params(1e-4, 4, 2);
        let h = 0.25;
        let offset = 0.5 / 3f64.sqrt();
        for (placement, inner) in [(None, 0.25), (Some("gauss"), 0.5 - offset)] {
            if let Some(name) = placement {
                params.insert(PLACEMENT_KEY.into(), ParamValue::Str(name.into()));
            }
            let x = seeded(&params);
            assert_eq!(x.len(), 8);
            for (c, pair) in x.chunks(2).enumerate() {
                let expected = [(c as f64 + inner) * h, (c as f64 + 1.0 - inner) * h];
                for (got, want) in pair.iter().zip(expected) {
                    assert!(
                        (got - want).abs() < 1e-15,
                        "{placement:?}: {got} against {want}"
                    );
                }
            }
        }
    }
}
