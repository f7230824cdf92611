//! Gong's manufactured solutions (thesis sec 4.5 and 4.7): a neo-Hookean bar (1D) and a
//! plane-strain square (2D) with U_k = G sin(pi X_k) sin(c pi t) in each direction, driven
//! by the body force that makes U exact. The 1D problem is the D = 1 case of the 2D one.

use std::f64::consts::PI;

use nalgebra::{SMatrix, SVector};

use super::{BenchmarkInfo, Domain, ExactState, FixedFaces, ParamDefault, ParamKind, ParamSpec};
use super::{ParamError, Params, Problem};
use crate::material::{lame_from_young, NeoHookean};
use crate::params::{get_f64, get_usize};

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
    ParamSpec {
        key: "rho0",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(1.0e3),
        unit: "kg/m^D",
        doc: "initial density",
    },
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
        key: "ppc",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Required,
        unit: "1",
        doc: "material points per cell per direction",
    },
    ParamSpec {
        key: "cells",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Required,
        unit: "1",
        doc: "cells per direction on the unit interval or square",
    },
];

pub const INFO_1D: BenchmarkInfo = BenchmarkInfo {
    name: "mms1d_gong",
    dim: 1,
    source: "Gong 2015, eqs 4.35-4.39",
    description: "neo-Hookean bar on [0,1], fixed ends, manufactured solution",
    params: PARAMS,
    check: check_params,
};

pub const INFO_2D: BenchmarkInfo = BenchmarkInfo {
    name: "mms2d_gong",
    dim: 2,
    source: "Gong 2015, eqs 4.41-4.46",
    description: "plane-strain neo-Hookean square [0,1]^2, roller walls, manufactured solution",
    params: PARAMS,
    check: check_params,
};

/// Admissibility checks that involve several parameters.
fn check_params(params: &Params) -> Result<(), ParamError> {
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
    let (lambda, mu) = lame_from_young(e, nu);
    // Gong eq 7.32: stable when the Courant number with the true wave speed is <= 1. The
    // wave speed of the linearised neo-Hookean model is sqrt((lambda + 2 mu)/rho0), not c.
    let ratio = ((lambda + 2.0 * mu) / e).sqrt();
    if cfl * ratio > 1.0 {
        return Err(ParamError::new(
            "cfl",
            format!(
                "cfl = {cfl} gives the Courant number dt c_p / h = {:.4} > 1, with the P-wave \
                 speed c_p = sqrt((lambda + 2 mu)/rho0) = {ratio:.4} c; the explicit scheme is \
                 unstable (Gong eq 7.32). Use cfl <= {:.4}",
                cfl * ratio,
                1.0 / ratio
            ),
        ));
    }
    Ok(())
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
    ] {
        p.insert(k.into(), crate::params::ParamValue::Float(v));
    }
    p.insert("ppc".into(), crate::params::ParamValue::Int(ppc));
    p.insert("cells".into(), crate::params::ParamValue::Int(cells));
    p
}

/// The manufactured problem in `D` dimensions.
pub struct GongMms<const D: usize> {
    g: f64,
    e: f64,
    rho0: f64,
    c: f64,
    material: NeoHookean,
    cells: usize,
    ppc: usize,
    dt: f64,
    steps: usize,
    /// The body force of particle p depends on each X_k separately, and particles seeded on
    /// a lattice share few distinct X_k: per axis, the time-dependent factors are computed
    /// once per distinct coordinate and step, and particles look them up.
    axes: [AxisTable; D],
    /// Per particle, the index of its X_k in `axes[k]`.
    axis_index: Vec<[u32; D]>,
}

/// Distinct reference coordinates along one axis and the factors of the body force there.
#[derive(Clone, Debug, Default)]
struct AxisTable {
    sin: Vec<f64>,
    cos: Vec<f64>,
    /// Refilled every step: ln F_kk and 1/F_kk^2.
    ln_f: Vec<f64>,
    inv_f2: Vec<f64>,
}

impl<const D: usize> GongMms<D> {
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        check_params(params)?;
        let e = get_f64(params, "E")?;
        let nu = get_f64(params, "nu")?;
        let rho0 = get_f64(params, "rho0")?;
        let t_end = get_f64(params, "t_end")?;
        let cfl = get_f64(params, "cfl")?;
        let cells = get_usize(params, "cells")?;
        let (lambda, mu) = lame_from_young(e, nu);
        let c = (e / rho0).sqrt();
        let h = 1.0 / cells as f64;
        let (dt, steps) = fit_time_step(cfl * h / c, t_end);
        Ok(GongMms {
            g: get_f64(params, "G")?,
            e,
            rho0,
            c,
            material: NeoHookean { lambda, mu },
            cells,
            ppc: get_usize(params, "ppc")?,
            dt,
            steps,
            axes: std::array::from_fn(|_| AxisTable::default()),
            axis_index: Vec::new(),
        })
    }

    /// Diagonal of the exact deformation gradient and the displacement at `x0`, time `t`.
    fn kinematics(&self, x0: &SVector<f64, D>, t: f64) -> (SVector<f64, D>, SVector<f64, D>) {
        let st = (self.c * PI * t).sin();
        let u = x0.map(|x| self.g * (PI * x).sin() * st);
        let f = x0.map(|x| 1.0 + PI * self.g * (PI * x).cos() * st);
        (u, f)
    }
}

/// The largest step not above `dt_max` that divides `t_end` into a whole number of steps.
/// The ratio is rounded first so that t_end/dt_max = 40.000000000000004 does not add a step.
pub fn fit_time_step(dt_max: f64, t_end: f64) -> (f64, usize) {
    let ratio = t_end / dt_max;
    let nearest = ratio.round();
    let steps = if (ratio - nearest).abs() <= 1e-9 * nearest {
        nearest
    } else {
        ratio.ceil()
    };
    let steps = (steps as usize).max(1);
    (t_end / steps as f64, steps)
}

impl<const D: usize> Problem<D> for GongMms<D> {
    fn domain(&self) -> Domain<D> {
        Domain {
            lower: SVector::zeros(),
            upper: SVector::repeat(1.0),
            cells: self.cells,
        }
    }

    fn body(&self) -> (SVector<f64, D>, SVector<f64, D>) {
        (SVector::zeros(), SVector::repeat(1.0))
    }

    fn ppc(&self) -> usize {
        self.ppc
    }

    fn rho0(&self) -> f64 {
        self.rho0
    }

    fn material(&self) -> NeoHookean {
        self.material
    }

    fn dt(&self) -> f64 {
        self.dt
    }

    fn steps(&self) -> usize {
        self.steps
    }

    fn fixed_faces(&self) -> FixedFaces<D> {
        [[true, true]; D]
    }

    fn initial_velocity(&self, x0: &SVector<f64, D>) -> SVector<f64, D> {
        x0.map(|x| self.c * PI * self.g * (PI * x).sin())
    }

    fn attach_particles(&mut self, x0: &[SVector<f64, D>]) {
        for k in 0..D {
            let mut coords: Vec<f64> = x0.iter().map(|x| x[k]).collect();
            coords.sort_by(f64::total_cmp);
            coords.dedup();
            for (p, x) in x0.iter().enumerate() {
                if k == 0 {
                    self.axis_index.push([0; D]);
                }
                let j = coords.partition_point(|&c| c < x[k]);
                self.axis_index[p][k] = j as u32;
            }
            let n = coords.len();
            self.axes[k] = AxisTable {
                sin: coords.iter().map(|&c| (PI * c).sin()).collect(),
                cos: coords.iter().map(|&c| (PI * c).cos()).collect(),
                ln_f: vec![0.0; n],
                inv_f2: vec![0.0; n],
            };
        }
    }

    /// Gong eq 4.46 (eq 4.39 for D = 1) with E read as rho0 c^2:
    /// B_k = (pi^2 U_k / rho0) [lambda (1 - ln J)/F_kk^2 + mu (1 + 1/F_kk^2) - rho0 c^2],
    /// with ln J = sum_k ln F_kk.
    fn body_force(&mut self, t: f64, out: &mut [SVector<f64, D>]) {
        let st = (self.c * PI * t).sin();
        let (lambda, mu) = (self.material.lambda, self.material.mu);
        let amp = PI * PI * self.g * st / self.rho0;
        let gpi = PI * self.g * st;
        for axis in &mut self.axes {
            for j in 0..axis.cos.len() {
                let f = 1.0 + gpi * axis.cos[j];
                axis.ln_f[j] = f.ln();
                axis.inv_f2[j] = 1.0 / (f * f);
            }
        }
        for (b, index) in out.iter_mut().zip(&self.axis_index) {
            let ln_j: f64 = (0..D).map(|k| self.axes[k].ln_f[index[k] as usize]).sum();
            for k in 0..D {
                let j = index[k] as usize;
                let inv_f2 = self.axes[k].inv_f2[j];
                b[k] = amp
                    * self.axes[k].sin[j]
                    * (lambda * (1.0 - ln_j) * inv_f2 + mu * (1.0 + inv_f2) - self.e);
            }
        }
    }

    fn exact(&self, x0: &SVector<f64, D>, t: f64) -> Option<ExactState<D>> {
        let (u, f) = self.kinematics(x0, t);
        let ct = (self.c * PI * t).cos();
        let j: f64 = f.iter().product();
        let fmat = SMatrix::<f64, D, D>::from_diagonal(&f);
        Some(ExactState {
            displacement: u,
            velocity: x0.map(|x| self.c * PI * self.g * (PI * x).sin() * ct),
            stress: self.material.cauchy(&fmat, j),
            density: self.rho0 / j,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::ParamValue;

    /// First Piola stress P_kk of the exact solution, for the finite-difference check.
    fn piola<const D: usize>(m: &GongMms<D>, x0: &SVector<f64, D>, t: f64) -> SVector<f64, D> {
        let (_, f) = m.kinematics(x0, t);
        let ln_j = f.iter().product::<f64>().ln();
        f.map(|fk| m.material.lambda * ln_j / fk + m.material.mu * (fk - 1.0 / fk))
    }

    /// rho0 B must equal rho0 A - Div P, with A and Div P by central differences of the
    /// manufactured displacement and stress.
    fn check_body_force<const D: usize>() {
        let mut m = GongMms::<D>::from_params(&thesis_params(0.1, 16, 2)).unwrap();
        let points: Vec<SVector<f64, D>> = [0.13, 0.37, 0.71, 0.94]
            .iter()
            .map(|&a| SVector::from_fn(|k, _| (a + 0.21 * k as f64) % 1.0))
            .collect();
        m.attach_particles(&points);
        let t = 0.0037;
        let mut b = vec![SVector::zeros(); points.len()];
        m.body_force(t, &mut b);
        let (hx, ht) = (1e-5, 1e-7);
        for (x0, b) in points.iter().zip(&b) {
            let acc = (m.kinematics(x0, t + ht).0 - 2.0 * m.kinematics(x0, t).0
                + m.kinematics(x0, t - ht).0)
                / (ht * ht);
            for k in 0..D {
                let mut xp = *x0;
                let mut xm = *x0;
                xp[k] += hx;
                xm[k] -= hx;
                let div_p = (piola(&m, &xp, t)[k] - piola(&m, &xm, t)[k]) / (2.0 * hx);
                let expected = acc[k] - div_p / m.rho0;
                let scale = acc[k].abs().max(1.0);
                assert!(
                    (b[k] - expected).abs() < 1e-5 * scale,
                    "D={D} k={k}: body force {} vs finite differences {expected}",
                    b[k]
                );
            }
        }
    }

    #[test]
    fn body_force_matches_finite_differences_1d() {
        check_body_force::<1>();
    }

    #[test]
    fn body_force_matches_finite_differences_2d() {
        check_body_force::<2>();
    }

    #[test]
    fn thesis_time_step_divides_one_period() {
        let m = GongMms::<1>::from_params(&thesis_params(1e-4, 8, 2)).unwrap();
        assert_eq!(m.steps, 40);
        assert!((m.dt - 5e-4).abs() < 1e-18);
    }

    #[test]
    fn exact_state_is_consistent() {
        let m = GongMms::<2>::from_params(&thesis_params(0.05, 8, 2)).unwrap();
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
        assert_eq!(check_params(&p).unwrap_err().key, "cfl");
        let p = thesis_params(0.4, 8, 2);
        assert_eq!(check_params(&p).unwrap_err().key, "G");
    }
}
