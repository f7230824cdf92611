//! The standing-wave manufactured solution shared by Gong's and Tran's benchmarks: a
//! neo-Hookean box [0, L]^D with U_k = A sin(k X_k) sin(omega t) in each direction, all faces
//! fixed in the normal direction (sin(k X) vanishes there), driven by the body force that
//! makes U exact. A benchmark only maps its parameters onto amplitude, wavenumber and speed.

use nalgebra::{SMatrix, SVector};

use super::TimeStep;
use super::{ExactState, FixedFaces, ParamDefault, ParamKind, ParamSpec, Problem};
use crate::grid::Domain;
use crate::material::{Material, NeoHookean};
use crate::particles::Placement;

/// Parameters every manufactured benchmark of this family takes with the same meaning.
pub const RHO0: ParamSpec = ParamSpec {
    key: "rho0",
    kind: ParamKind::PositiveReal,
    default: ParamDefault::Float(1.0e3),
    unit: "kg/m^D",
    doc: "initial density",
};
pub const PPC: ParamSpec = ParamSpec {
    key: "ppc",
    kind: ParamKind::PositiveInt,
    default: ParamDefault::Required,
    unit: "1",
    doc: "material points per cell per direction",
};
pub const CELLS: ParamSpec = ParamSpec {
    key: "cells",
    kind: ParamKind::PositiveInt,
    default: ParamDefault::Required,
    unit: "1",
    doc: "cells per direction along the edge of the domain",
};

/// U_k = amplitude sin(wavenumber X_k) sin(omega t) with omega = speed * wavenumber.
#[derive(Clone, Copy, Debug)]
pub struct SineWave {
    pub amplitude: f64,
    pub wavenumber: f64,
    /// Phase speed omega / k. It also sets the inertia term rho0 speed^2 of the body force,
    /// so that for Gong's speed c = sqrt(E/rho0) the bracket holds E as in eq 4.39.
    pub speed: f64,
}

/// Everything that defines one manufactured problem.
#[derive(Clone, Copy, Debug)]
pub struct SineMmsSpec {
    pub wave: SineWave,
    /// Edge of the box [0, L]^D, which is both the grid and the body.
    pub length: f64,
    pub rho0: f64,
    pub material: NeoHookean,
    pub cells: usize,
    pub ppc: usize,
    pub placement: Placement,
    /// The benchmark's time step, the one its check approved.
    pub step: TimeStep,
}

/// The manufactured problem in `D` dimensions.
pub struct SineMms<const D: usize> {
    amplitude: f64,
    wavenumber: f64,
    omega: f64,
    /// rho0 (omega / k)^2, the inertia term inside the body-force bracket.
    inertia: f64,
    length: f64,
    rho0: f64,
    material: NeoHookean,
    cells: usize,
    ppc: usize,
    placement: Placement,
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

impl<const D: usize> SineMms<D> {
    pub fn new(spec: &SineMmsSpec) -> Self {
        let wave = spec.wave;
        SineMms {
            amplitude: wave.amplitude,
            wavenumber: wave.wavenumber,
            omega: wave.speed * wave.wavenumber,
            inertia: spec.rho0 * wave.speed * wave.speed,
            length: spec.length,
            rho0: spec.rho0,
            material: spec.material,
            cells: spec.cells,
            ppc: spec.ppc,
            placement: spec.placement,
            dt: spec.step.dt,
            steps: spec.step.steps,
            axes: std::array::from_fn(|_| AxisTable::default()),
            axis_index: Vec::new(),
        }
    }

    /// Diagonal of the exact deformation gradient and the displacement at `x0`, time `t`.
    fn kinematics(&self, x0: &SVector<f64, D>, t: f64) -> (SVector<f64, D>, SVector<f64, D>) {
        let (a, k) = (self.amplitude, self.wavenumber);
        let st = (self.omega * t).sin();
        let u = x0.map(|x| a * (k * x).sin() * st);
        let f = x0.map(|x| 1.0 + k * a * (k * x).cos() * st);
        (u, f)
    }
}

impl<const D: usize> Problem<D> for SineMms<D> {
    fn placement(&self) -> Placement {
        self.placement
    }
    fn domain(&self) -> Domain<D> {
        Domain {
            lower: SVector::zeros(),
            upper: SVector::repeat(self.length),
            cells: self.cells,
        }
    }

    fn body(&self) -> (SVector<f64, D>, SVector<f64, D>) {
        (SVector::zeros(), SVector::repeat(self.length))
    }

    fn ppc(&self) -> usize {
        self.ppc
    }

    fn rho0(&self) -> f64 {
        self.rho0
    }

    fn material(&self) -> Material {
        Material::NeoHookean(self.material)
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
        x0.map(|x| self.omega * self.amplitude * (self.wavenumber * x).sin())
    }

    fn attach_particles(&mut self, x0: &[SVector<f64, D>]) {
        let k = self.wavenumber;
        for axis in 0..D {
            let mut coords: Vec<f64> = x0.iter().map(|x| x[axis]).collect();
            coords.sort_by(f64::total_cmp);
            coords.dedup();
            for (p, x) in x0.iter().enumerate() {
                if axis == 0 {
                    self.axis_index.push([0; D]);
                }
                let j = coords.partition_point(|&c| c < x[axis]);
                self.axis_index[p][axis] = j as u32;
            }
            let n = coords.len();
            self.axes[axis] = AxisTable {
                sin: coords.iter().map(|&c| (k * c).sin()).collect(),
                cos: coords.iter().map(|&c| (k * c).cos()).collect(),
                ln_f: vec![0.0; n],
                inv_f2: vec![0.0; n],
            };
        }
    }

    /// rho0 b = rho0 a - Div P with P_kk = lambda ln J / F_kk + mu (F_kk - 1/F_kk) and
    /// dF_kk/dX_k = -k^2 U_k, a_k = -omega^2 U_k:
    /// b_k = (k^2 U_k / rho0) [lambda (1 - ln J)/F_kk^2 + mu (1 + 1/F_kk^2) - rho0 (omega/k)^2],
    /// with ln J = sum_k ln F_kk (Gong eqs 4.39 and 4.46, Tran eq 47 corrected; docs/NOTES.md).
    fn body_force(&mut self, t: f64, out: &mut [SVector<f64, D>]) {
        let (a, k) = (self.amplitude, self.wavenumber);
        let st = (self.omega * t).sin();
        let (lambda, mu) = (self.material.lambda, self.material.mu);
        let amp = k * k * a * st / self.rho0;
        let gradient = k * a * st;
        for axis in &mut self.axes {
            for j in 0..axis.cos.len() {
                let f = 1.0 + gradient * axis.cos[j];
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
                    * (lambda * (1.0 - ln_j) * inv_f2 + mu * (1.0 + inv_f2) - self.inertia);
            }
        }
    }

    fn exact(&self, x0: &SVector<f64, D>, t: f64) -> Option<ExactState<D>> {
        let (u, f) = self.kinematics(x0, t);
        let ct = (self.omega * t).cos();
        let j: f64 = f.iter().product();
        let fmat = SMatrix::<f64, D, D>::from_diagonal(&f);
        let v_max = self.omega * self.amplitude;
        Some(ExactState {
            displacement: u,
            velocity: x0.map(|x| v_max * (self.wavenumber * x).sin() * ct),
            stress: self.material.cauchy(&fmat, j),
            density: self.rho0 / j,
        })
    }

    /// Per axis, the root of g(X) = X + b sin(k X) - x with b = A sin(omega t). The benchmarks
    /// keep |b k| < 1, so g' = F_kk > 0 and the root is unique and within |b| of x; Newton
    /// from X = x, bisecting the bracket [x - |b|, x + |b|] when a step would leave it.
    fn material_point(&self, x: &SVector<f64, D>, t: f64) -> Option<SVector<f64, D>> {
        // The body is the box, whose faces do not move; a node computed as i h may miss the
        // upper face by rounding.
        let tolerance = f64::EPSILON * self.length;
        let slack = 4.0 * tolerance;
        let inside = x.iter().all(|&c| c >= -slack && c <= self.length + slack);
        if !inside {
            return None;
        }
        let k = self.wavenumber;
        let b = self.amplitude * (self.omega * t).sin();
        let invert = |target: f64| {
            let (mut lo, mut hi) = (target - b.abs(), target + b.abs());
            let mut root = target;
            for _ in 0..MAX_INVERSE_ITERATIONS {
                let g = root + b * (k * root).sin() - target;
                if g == 0.0 {
                    break;
                }
                if g < 0.0 {
                    lo = root;
                } else {
                    hi = root;
                }
                let newton = root - g / (1.0 + b * k * (k * root).cos());
                let next = if newton > lo && newton < hi {
                    newton
                } else {
                    0.5 * (lo + hi)
                };
                let step = (next - root).abs();
                root = next;
                if step <= tolerance {
                    break;
                }
            }
            root
        };
        Some(x.map(invert))
    }
}

/// Newton converges in a handful of steps; bisection alone would need about 60 to reach
/// round-off from a bracket of width 2|b| <= 2 L.
const MAX_INVERSE_ITERATIONS: usize = 100;

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// First Piola stress P_kk of the exact solution, for the finite-difference check.
    fn piola<const D: usize>(m: &SineMms<D>, x0: &SVector<f64, D>, t: f64) -> SVector<f64, D> {
        let (_, f) = m.kinematics(x0, t);
        let ln_j = f.iter().product::<f64>().ln();
        f.map(|fk| m.material.lambda * ln_j / fk + m.material.mu * (fk - 1.0 / fk))
    }

    /// Scattered reference points inside [0, L]^D, off the lattice the solver seeds.
    pub(in crate::benchmarks) fn probe_points<const D: usize>(length: f64) -> Vec<SVector<f64, D>> {
        [0.13, 0.37, 0.71, 0.94]
            .iter()
            .map(|&a| SVector::from_fn(|k, _| length * ((a + 0.21 * k as f64) % 1.0)))
            .collect()
    }

    /// rho0 b must equal rho0 a - Div P, with a and Div P by central differences of the
    /// manufactured displacement and stress.
    pub(in crate::benchmarks) fn check_body_force<const D: usize>(mut m: SineMms<D>, t: f64) {
        let points = probe_points::<D>(m.length);
        m.attach_particles(&points);
        let mut b = vec![SVector::zeros(); points.len()];
        m.body_force(t, &mut b);
        let (hx, ht) = (1e-5 * m.length, 1e-7);
        for (x0, b) in points.iter().zip(&b) {
            let u = |t| m.kinematics(x0, t).0;
            let acc = (u(t + ht) - 2.0 * u(t) + u(t - ht)) / (ht * ht);
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

    /// A wave of strain amplitude 0.3 (Gong's largest is 0.31), so that X and x differ by
    /// up to 0.1 L.
    fn strong_wave<const D: usize>() -> SineMms<D> {
        let (lambda, mu) = crate::material::lame_from_young(1e7, 0.3);
        SineMms::new(&SineMmsSpec {
            wave: SineWave {
                amplitude: 0.3 / std::f64::consts::PI,
                wavenumber: std::f64::consts::PI,
                speed: 100.0,
            },
            length: 1.0,
            rho0: 1e3,
            material: NeoHookean { lambda, mu },
            cells: 8,
            ppc: 2,
            placement: Placement::SubCellCentres,
            step: TimeStep {
                dt: 1e-3,
                steps: 20,
            },
        })
    }

    /// x = X + U(X, t) mapped back by `material_point` gives X to round-off, in the interior
    /// and on the faces, at times of either sign of sin(omega t) and at t = 0 (x = X).
    fn check_inverse_motion<const D: usize>() {
        let m = strong_wave::<D>();
        let mut points = probe_points::<D>(m.length);
        points.push(SVector::zeros());
        points.push(SVector::repeat(m.length));
        for t in [0.0, 0.0037, 0.005, 0.0149] {
            for x0 in &points {
                let x = x0 + m.exact(x0, t).unwrap().displacement;
                let back = m.material_point(&x, t).unwrap();
                assert!(
                    (back - x0).amax() <= 4.0 * f64::EPSILON,
                    "D={D}, t={t}: X = {x0:?} came back as {back:?}"
                );
            }
        }
        let outside = SVector::repeat(1.0 + 1e-12);
        assert!(m.material_point(&outside, 0.005).is_none());
    }

    #[test]
    fn material_point_inverts_the_motion() {
        check_inverse_motion::<1>();
        check_inverse_motion::<2>();
    }
}
