//! Molinos et al., sec 6.1 and appendix A: the Dyka bar. A linear-elastic bar on [0, L], fixed at
//! x = 0 and free at x = L, whose last quarter [3L/4, L] starts at v0. With nu = 0,
//! rho0 v_t = sigma_x and sigma_t = E v_x; the exact solution is d'Alembert's with images
//! (docs/NOTES.md corrects the appendix): with V the initial velocity extended odd about x = 0
//! and even about x = L (period 4L),
//!   v = [V(x - ct) + V(x + ct)] / 2,   sigma = rho0 c [V(x + ct) - V(x - ct)] / 2,
//! evaluated at each particle's reference position (small strain). The grid extends past the
//! free end by `extra_cells` whole cells: the free end moves at most v0 L / (4c) (0.033 mm with
//! the defaults, a hundredth of a cell).

use nalgebra::{SMatrix, SVector};

use super::limits::{check_lattice, courant_time_step};
use super::{boxed, BenchmarkKind, Build};
use super::{courant_number, ParamError, Params, Probe, ProbeQuantity, Problem, TimeStep};
use super::{BenchmarkInfo, ExactState, FixedFaces, ParamDefault, ParamKind, ParamSpec};
use crate::grid::Domain;
use crate::material::{LinearElasticRate, Material};
use crate::params::{get_f64, get_usize};

const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        key: "L",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(0.1333),
        unit: "m",
        doc: "length of the bar",
    },
    ParamSpec {
        key: "cells",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(40),
        unit: "1",
        doc: "grid cells over the bar (h = L / cells; 40 gives the paper's 3.3325 mm)",
    },
    ParamSpec {
        key: "extra_cells",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(1),
        unit: "1",
        doc: "grid cells past the free end x = L, room for the bar to stretch",
    },
    ParamSpec {
        key: "ppc",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(1),
        unit: "1",
        doc: "material points per cell (the paper: one, at the cell centre)",
    },
    ParamSpec {
        key: "rho0",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(7833.0),
        unit: "kg/m^D",
        doc: "initial density",
    },
    ParamSpec {
        key: "E",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(200e9),
        unit: "Pa",
        doc: "Young's modulus (nu = 0)",
    },
    ParamSpec {
        key: "v0",
        kind: ParamKind::Real,
        default: ParamDefault::Float(5.0),
        unit: "m/s",
        doc: "initial velocity of the last quarter [3L/4, L]",
    },
    ParamSpec {
        key: "cfl",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(0.5),
        unit: "1",
        doc: "Courant number: dt = cfl h / c, shortened so that t_end is hit",
    },
    ParamSpec {
        key: "t_end",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(2e-4),
        unit: "s",
        doc: "final time (about 3.8 round trips of the wave with the defaults)",
    },
];

pub const INFO: BenchmarkInfo = BenchmarkInfo {
    name: "dyka_bar",
    kind: BenchmarkKind::Simulation,
    build: Build::Line(|params| boxed(dyka_bar(params))),
    source: "Molinos et al., sec 6.1, appendix A (Dyka & Ingel 1995)",
    description: "linear-elastic bar, x = 0 fixed, x = L free, v0 on the last quarter; probes \
                  free_end_velocity, quarter_stress, mid_stress",
    params: PARAMS,
    check: check_params,
    time_step: Some(time_step),
};

/// The size of the run, the explicit scheme's Courant bound, and a strain that keeps the
/// exact density finite.
fn check_params(params: &Params) -> Result<(), ParamError> {
    check_lattice(params, 1, "particles")?;
    let bar = DykaBar::new(params)?;
    courant_number(params)?;
    let strain = bar.v0.abs() / bar.wave_speed();
    if strain >= 1.0 {
        return Err(ParamError::new(
            "v0",
            format!(
                "|v0| / c = {strain:.4} >= 1 makes the exact strain reach -1; use |v0| < c = {:.4} m/s",
                bar.wave_speed()
            ),
        ));
    }
    Ok(())
}

/// The bar with its parameters resolved.
pub struct DykaBar {
    length: f64,
    cells: usize,
    extra_cells: usize,
    ppc: usize,
    rho0: f64,
    young: f64,
    v0: f64,
    dt: f64,
    steps: usize,
}

impl DykaBar {
    fn new(params: &Params) -> Result<Self, ParamError> {
        let length = get_f64(params, "L")?;
        let TimeStep { dt, steps } = time_step(params)?;
        Ok(DykaBar {
            length,
            cells: get_usize(params, "cells")?,
            extra_cells: get_usize(params, "extra_cells")?,
            ppc: get_usize(params, "ppc")?,
            rho0: get_f64(params, "rho0")?,
            young: get_f64(params, "E")?,
            v0: get_f64(params, "v0")?,
            dt,
            steps,
        })
    }

    fn wave_speed(&self) -> f64 {
        (self.young / self.rho0).sqrt()
    }

    /// The initial velocity on [0, L]: v0 on the last quarter.
    fn initial(&self, x: f64) -> f64 {
        if x >= 0.75 * self.length {
            self.v0
        } else {
            0.0
        }
    }

    /// `y` mapped into [-2L, 2L) by the period 4L, then folded to [0, 2L] with the sign the
    /// odd extension about 0 gives it.
    fn fold_period(&self, y: f64) -> (f64, f64) {
        let period = 4.0 * self.length;
        let y = y - period * ((y + 2.0 * self.length) / period).floor();
        if y < 0.0 {
            (-1.0, -y)
        } else {
            (1.0, y)
        }
    }

    /// V: the initial velocity extended odd about x = 0 and even about x = L.
    fn extended(&self, y: f64) -> f64 {
        let (sign, y) = self.fold_period(y);
        // Even about L: [L, 2L] mirrors [0, L].
        let y = if y > self.length {
            2.0 * self.length - y
        } else {
            y
        };
        sign * self.initial(y)
    }

    /// W, the antiderivative of V with W(0) = 0: even (V is odd) and periodic (V has zero mean
    /// over a period), linear between the breaks of V.
    fn extended_integral(&self, y: f64) -> f64 {
        let (_, y) = self.fold_period(y);
        let on_bar = |y: f64| self.v0 * (y - 0.75 * self.length).max(0.0);
        if y > self.length {
            2.0 * on_bar(self.length) - on_bar(2.0 * self.length - y)
        } else {
            on_bar(y)
        }
    }
}

/// dt = cfl h / c over the bar's cells, with c = sqrt(E/rho0).
fn time_step(params: &Params) -> Result<TimeStep, ParamError> {
    courant_time_step(params, PARAMS, get_f64(params, "L")?)
}

/// Builds the bar from validated parameters.
pub fn dyka_bar(params: &Params) -> Result<DykaBar, ParamError> {
    check_params(params)?;
    DykaBar::new(params)
}

impl Problem<1> for DykaBar {
    fn domain(&self) -> Domain<1> {
        Domain::padded(self.length, self.cells, self.extra_cells)
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

    /// x = 0 fixed; the upper face of the grid lies past the free end and holds nothing.
    fn fixed_faces(&self) -> FixedFaces<1> {
        [[true, false]]
    }

    fn initial_velocity(&self, x0: &SVector<f64, 1>) -> SVector<f64, 1> {
        SVector::repeat(self.initial(x0[0]))
    }

    fn body_force(&mut self, _t: f64, out: &mut [SVector<f64, 1>]) {
        out.fill(SVector::zeros());
    }

    fn attach_particles(&mut self, _x0: &[SVector<f64, 1>]) {}

    /// d'Alembert with images; u = [W(x + ct) - W(x - ct)] / (2c) integrates v in time
    /// exactly, and the strain u_x = sigma / E gives the density rho0 / (1 + strain).
    fn exact(&self, x0: &SVector<f64, 1>, t: f64) -> Option<ExactState<1>> {
        let c = self.wave_speed();
        let (x, ct) = (x0[0], c * t);
        let (ahead, behind) = (self.extended(x + ct), self.extended(x - ct));
        let u = (self.extended_integral(x + ct) - self.extended_integral(x - ct)) / (2.0 * c);
        let strain = (ahead - behind) / (2.0 * c);
        Some(ExactState {
            displacement: SVector::repeat(u),
            velocity: SVector::repeat(0.5 * (ahead + behind)),
            stress: SMatrix::repeat(self.young * strain),
            density: self.rho0 / (1.0 + strain),
        })
    }

    /// The velocity of the particle nearest the free end (Molinos Figs 5-8, 12), the stress in
    /// the middle of the last quarter, X = 7L/8 (Fig 13: "the stress in the last quarter"), and
    /// the stress at mid-length. With 40 cells and one particle per cell both X = 7L/8 and
    /// X = L/2 are cell faces with a particle either side; the tie picks the lower, X = 7L/8 -
    /// h/2 (0.1150 m) and X = L/2 - h/2 (0.0650 m) with the defaults.
    fn probes(&self) -> Vec<Probe<1>> {
        vec![
            Probe {
                name: "free_end_velocity",
                at: SVector::repeat(self.length),
                quantity: ProbeQuantity::Velocity(0),
            },
            Probe {
                name: "quarter_stress",
                at: SVector::repeat(0.875 * self.length),
                quantity: ProbeQuantity::Stress(0, 0),
            },
            Probe {
                name: "mid_stress",
                at: SVector::repeat(0.5 * self.length),
                quantity: ProbeQuantity::Stress(0, 0),
            },
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell(bar: &DykaBar) -> f64 {
        bar.length / bar.cells as f64
    }
    use crate::benchmarks::{default_params, CATALOG};
    use crate::params::ParamValue;

    fn bar(overrides: &[(&str, ParamValue)]) -> DykaBar {
        let mut p = default_params(PARAMS);
        for (key, value) in overrides {
            p.insert(key.to_string(), value.clone());
        }
        dyka_bar(&p).unwrap()
    }

    fn state(bar: &DykaBar, x: f64, t: f64) -> ExactState<1> {
        bar.exact(&SVector::repeat(x), t).unwrap()
    }

    #[test]
    fn is_in_the_catalogue_with_the_papers_grid_and_steps() {
        assert!(CATALOG.entries.iter().any(|b| b.name == "dyka_bar"));
        let bar = bar(&[]);
        assert!((cell(&bar) - 3.3325e-3).abs() < 1e-15);
        // c = sqrt(200e9 / 7833) = 5053.02 m/s, so dt = 0.5 h / c = 3.2975e-7 s and
        // t_end / dt = 606.52: 607 steps of t_end / 607.
        let c = bar.wave_speed();
        assert!((c - 5053.02).abs() < 0.01, "{c}");
        assert_eq!(bar.steps(), 607);
        assert!((bar.dt() * 607.0 - 2e-4).abs() < 1e-18);
        assert!(bar.dt() <= 0.5 * cell(&bar) / c);
        let domain = bar.domain();
        assert_eq!(domain.cells, 41);
        assert!((domain.upper[0] - 41.0 * cell(&bar)).abs() < 1e-15);
    }

    /// rho0 v_t = sigma_x and sigma_t = E v_x by central differences, at points and times
    /// away from the fronts (which sit at x = 3L/4 +- ct and their images), where the fields
    /// are constant; the fronts are checked by their jumps below.
    #[test]
    fn exact_solution_satisfies_the_equations_away_from_the_fronts() {
        let bar = bar(&[("v0", ParamValue::Float(5.0))]);
        let c = bar.wave_speed();
        let l = bar.length;
        let (dx, dt) = (1e-5 * l, 1e-5 * l / c);
        let mut checked = 0;
        for t in [0.1, 0.4, 1.3, 2.7, 3.6].map(|r| r * l / c) {
            for x in [0.05, 0.3, 0.55, 0.7, 0.9, 0.97].map(|r| r * l) {
                let far = |front: f64| {
                    let (_, y) = bar.fold_period(front);
                    let d = (y - 0.75 * l).abs().min((y - 1.25 * l).abs());
                    d > 10.0 * dx
                };
                if !far(x - c * t) || !far(x + c * t) {
                    continue;
                }
                let v = |x: f64, t: f64| state(&bar, x, t).velocity[0];
                let sigma = |x: f64, t: f64| state(&bar, x, t).stress[(0, 0)];
                let v_t = (v(x, t + dt) - v(x, t - dt)) / (2.0 * dt);
                let sigma_x = (sigma(x + dx, t) - sigma(x - dx, t)) / (2.0 * dx);
                let sigma_t = (sigma(x, t + dt) - sigma(x, t - dt)) / (2.0 * dt);
                let v_x = (v(x + dx, t) - v(x - dx, t)) / (2.0 * dx);
                assert_eq!(bar.rho0 * v_t, sigma_x, "x = {x}, t = {t}");
                assert_eq!(sigma_t, bar.young * v_x, "x = {x}, t = {t}");
                let u = |t: f64| state(&bar, x, t).displacement[0];
                let u_t = (u(t + dt) - u(t - dt)) / (2.0 * dt);
                assert!((u_t - v(x, t)).abs() < 1e-6 * bar.v0, "x = {x}, t = {t}");
                checked += 1;
            }
        }
        assert!(checked > 15, "{checked}");
    }

    /// Across each front, the jumps satisfy the equations in the weak sense (Rankine-Hugoniot):
    /// a front at speed s has [sigma] = -rho0 s [v] and -s [sigma] = E [v]. This fixes the sign
    /// of sigma: the moving quarter pulls the bar, so the first fronts leave tension behind. The
    /// breaks of V are at +-3L/4 + 2kL; x - ct on one is a front at +c, x + ct one at -c.
    #[test]
    fn fronts_satisfy_the_jump_conditions() {
        let bar = bar(&[]);
        let c = bar.wave_speed();
        let l = bar.length;
        let eps = 1e-9 * l;
        let mut checked = 0;
        for r in [0.1, 0.3, 0.9, 1.4, 2.2, 3.1, 3.7] {
            let ct = r * l;
            for k in -3..=3 {
                for b in [0.75 * l, -0.75 * l].map(|b| b + 2.0 * k as f64 * l) {
                    for (x, s) in [(b + ct, c), (b - ct, -c)] {
                        if x <= eps || x >= l - eps {
                            continue;
                        }
                        let (left, right) = (
                            state(&bar, x - eps, r * l / c),
                            state(&bar, x + eps, r * l / c),
                        );
                        let jump_v = right.velocity[0] - left.velocity[0];
                        let jump_sigma = right.stress[(0, 0)] - left.stress[(0, 0)];
                        assert!(jump_v.abs() > 0.1 * bar.v0, "no front at x = {x}");
                        let scale = bar.rho0 * c * bar.v0;
                        assert!((jump_sigma + bar.rho0 * s * jump_v).abs() < 1e-9 * scale);
                        assert!((-s * jump_sigma - bar.young * jump_v).abs() < 1e-9 * scale * c);
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked >= 14, "{checked}");
        let t = 0.1 * l / c;
        assert_eq!(state(&bar, 0.75 * l, t).velocity[0], 2.5);
        assert_eq!(
            state(&bar, 0.75 * l, t).stress[(0, 0)],
            0.5 * bar.rho0 * c * bar.v0
        );
    }

    #[test]
    fn boundary_and_initial_conditions_hold() {
        let bar = bar(&[]);
        let c = bar.wave_speed();
        let l = bar.length;
        for r in [0.0, 0.13, 0.5, 1.1, 1.9, 2.6, 3.3, 3.8] {
            let t = r * l / c;
            assert_eq!(state(&bar, 0.0, t).velocity[0], 0.0, "t = {t}");
            assert_eq!(state(&bar, 0.0, t).displacement[0], 0.0, "t = {t}");
            assert_eq!(state(&bar, l, t).stress[(0, 0)], 0.0, "t = {t}");
        }
        for r in [0.0, 0.2, 0.74, 0.76, 0.9, 1.0] {
            let s = state(&bar, r * l, 0.0);
            assert_eq!(
                s.velocity[0],
                bar.initial_velocity(&SVector::repeat(r * l))[0]
            );
            assert_eq!(s.stress[(0, 0)], 0.0);
            assert_eq!(s.displacement[0], 0.0);
        }
    }

    /// Kinetic plus strain energy over the bar stays (1/2) rho0 v0^2 L / 4. The fields are
    /// constant between the points where x - ct or x + ct crosses a multiple of L/4 (the breaks
    /// of V and their images), so the midpoint value of each piece integrates it exactly.
    #[test]
    fn conserves_energy() {
        let bar = bar(&[]);
        let c = bar.wave_speed();
        let l = bar.length;
        let initial = 0.5 * bar.rho0 * bar.v0 * bar.v0 * l / 4.0;
        for r in [0.0, 0.1, 0.37, 1.0, 1.6, 2.25, 3.05, 3.79] {
            let ct = r * l;
            let mut breaks = vec![0.0, l];
            for k in -20..=20 {
                for x in [k as f64 * l / 4.0 + ct, k as f64 * l / 4.0 - ct] {
                    if x > 0.0 && x < l {
                        breaks.push(x);
                    }
                }
            }
            breaks.sort_by(f64::total_cmp);
            let energy: f64 = breaks
                .windows(2)
                .map(|w| {
                    let s = state(&bar, 0.5 * (w[0] + w[1]), ct / c);
                    let (v, sigma) = (s.velocity[0], s.stress[(0, 0)]);
                    (w[1] - w[0]) * (0.5 * bar.rho0 * v * v + 0.5 * sigma * sigma / bar.young)
                })
                .sum();
            assert!(
                (energy - initial).abs() < 1e-12 * initial,
                "ct = {r} L: {energy} against {initial}"
            );
        }
    }

    #[test]
    fn probes_are_the_free_end_velocity_and_the_quarter_and_mid_stresses() {
        let bar = bar(&[]);
        let h = cell(&bar);
        let x0: Vec<SVector<f64, 1>> = (0..40)
            .map(|i| SVector::repeat((i as f64 + 0.5) * h))
            .collect();
        let probes = bar.probes();
        assert_eq!(probes[0].nearest(&x0), Some(39));
        // X = 34.5 h and 35.5 h are equally far from 7L/8 = 35 h, X = 19.5 h and 20.5 h from
        // L/2 = 20 h: the lower wins.
        assert_eq!(probes[1].nearest(&x0), Some(34));
        assert_eq!(probes[2].nearest(&x0), Some(19));
    }

    #[test]
    fn rejects_an_unstable_courant_number() {
        let mut p = default_params(PARAMS);
        p.insert("cfl".into(), ParamValue::Float(1.5));
        assert_eq!(check_params(&p).unwrap_err().key, "cfl");
    }
}
