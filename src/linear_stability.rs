//! Linear stability of the original MPM in 1D (Gong 2015, chapter 7): the largest Courant
//! number lambda = C dt / h (C the wave speed of the linearised equations) for which no
//! Fourier mode grows, with N particles per cell at x_e + (j - 1/2) h / N.
//!
//! Three bounds, derived in docs/NOTES.md ("Gong (2015), chapter 7"):
//! * [`printed_bound`]: eq 7.31 as printed, from M = CFL (1/N) sin(theta/2) / sin(theta/(2N)),
//!   which is 1 for every N (eq 7.32).
//! * [`squared_bound`]: eq 7.29 as derived, with the sin^2(theta/2) of identity 7.23 kept:
//!   CFL <= 1 / max_theta sin^2(theta/2) / (N sin(theta/(2N))), above 1 for N >= 2.
//! * [`projected_bound`]: the scheme as `mpm` runs it, where the grid velocity is rebuilt from
//!   the particles every step (FLIP update of the particle velocity, mass-weighted mapping to
//!   the nodes): lambda <= 1 / sqrt(1 + 4 q / N) with q = sum_p xi_p (1 - xi_p).
//!
//! Knows nothing of the rest of the crate; the report draws these beside measured limits.

use std::f64::consts::PI;

/// Eq 7.31 as printed: min over theta in (0, 2 pi] of N sin(theta/(2N)) / sin(theta/2). The
/// ratio rises from 1 at theta -> 0 (and without bound towards 2 pi), so this is 1 for every N.
pub fn printed_bound(n: usize) -> f64 {
    let nf = n as f64;
    // Up to 2 pi (1 - 1e-9): sin(theta/2) vanishes at 2 pi itself.
    -max_over(1e-9, 2.0 * PI * (1.0 - 1e-9), |t| {
        -nf * (t / (2.0 * nf)).sin() / (t / 2.0).sin()
    })
}

/// |M| / CFL of eq 7.29 with the square kept: sin^2(theta/2) / (N sin(theta/(2N))).
pub fn squared_symbol(n: usize, theta: f64) -> f64 {
    let nf = n as f64;
    (theta / 2.0).sin().powi(2) / (nf * (theta / (2.0 * nf)).sin())
}

/// Eq 7.29 with the square kept: |M| <= 1 for every theta in (0, 2 pi] requires
/// CFL <= 1 / max_theta [`squared_symbol`]. 1 for N = 1, 1.299 for N = 2, towards 1.380
/// (1 / max_x sin^2(x)/x) as N grows.
pub fn squared_bound(n: usize) -> f64 {
    1.0 / max_over(1e-9, 2.0 * PI, |t| squared_symbol(n, t))
}

/// q = sum over the N particles of a cell of xi_p (1 - xi_p), xi_p = (2p - 1)/(2N):
/// (2 N^2 + 1) / (12 N).
pub fn placement_moment(n: usize) -> f64 {
    let nf = n as f64;
    (2.0 * nf * nf + 1.0) / (12.0 * nf)
}

/// The symbol of M_L^-1 M_C (consistent over lumped mass matrix of the particles):
/// sigma(theta) = 1 - (4 q / N) sin^2(theta/2).
pub fn projection_symbol(n: usize, theta: f64) -> f64 {
    1.0 - 4.0 * placement_moment(n) / n as f64 * (theta / 2.0).sin().powi(2)
}

/// The bound of the scheme with the grid velocity rebuilt from the particles every step:
/// 1 / sqrt(1 + 4 q / N), reached at theta = pi. 1/sqrt(2) = 0.7071 for N = 1, 0.7559 for
/// N = 2, towards sqrt(3/5) = 0.7746.
pub fn projected_bound(n: usize) -> f64 {
    1.0 / (1.0 + 4.0 * placement_moment(n) / n as f64).sqrt()
}

/// [`projected_bound`] on a grid of `cells` cells with both ends fixed. Its modes are the
/// sines sin(j pi x), j = 1 .. cells - 1, and the bound binds at the highest, theta =
/// pi (1 - 1/cells), where s = sin(theta/2) = cos(pi/(2 cells)):
/// lambda <= 1 / sqrt(s^2 (1 + 4 q s^2 / N)). 0.7074 for N = 1 on 64 cells.
pub fn projected_bound_fixed_ends(n: usize, cells: usize) -> f64 {
    let s2 = (PI / (2.0 * cells as f64)).cos().powi(2);
    1.0 / (s2 * (1.0 + 4.0 * placement_moment(n) / n as f64 * s2)).sqrt()
}

/// Trace and determinant of the per-mode step [v; F] -> [[1, sigma A], [A, 1 + A^2]] [v; F]
/// with A = 2 i lambda sin(theta/2): A^2 = -4 lambda^2 s^2 is real, so both are real.
pub fn projected_trace_det(n: usize, lambda: f64, theta: f64) -> (f64, f64) {
    let a2 = -4.0 * lambda * lambda * (theta / 2.0).sin().powi(2);
    let sigma = projection_symbol(n, theta);
    (2.0 + a2, 1.0 + a2 * (1.0 - sigma))
}

/// The largest value of `f` over [lo, hi]: a scan of 4096 points, then golden-section search
/// around the best one (f is smooth and has one maximum near the best sample).
fn max_over(lo: f64, hi: f64, f: impl Fn(f64) -> f64) -> f64 {
    const SAMPLES: usize = 4096;
    let at = |k: usize| lo + (hi - lo) * k as f64 / SAMPLES as f64;
    let best = (0..=SAMPLES)
        .max_by(|&a, &b| f(at(a)).total_cmp(&f(at(b))))
        .unwrap_or(0);
    let (mut a, mut b) = (at(best.saturating_sub(1)), at((best + 1).min(SAMPLES)));
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..200 {
        let c = b - ratio * (b - a);
        let d = a + ratio * (b - a);
        if f(c) >= f(d) {
            b = d;
        } else {
            a = c;
        }
    }
    f(0.5 * (a + b)).max(f(at(best)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Complex, DMatrix, Matrix2};
    use std::f64::consts::FRAC_1_SQRT_2;

    const NS: [usize; 5] = [1, 2, 3, 4, 8];

    #[test]
    fn eq_7_31_as_printed_is_one_for_every_n() {
        for n in NS {
            assert!((printed_bound(n) - 1.0).abs() < 1e-12, "N = {n}");
        }
    }

    #[test]
    fn eq_7_29_with_the_square_kept_allows_more_than_one() {
        assert!((squared_bound(1) - 1.0).abs() < 1e-12);
        // N = 2: sin^2(theta/2) / (2 sin(theta/4)) = 2 sin u cos^2 u, u = theta/4, has its
        // maximum 4 / (3 sqrt 3) at sin u = 1/sqrt 3.
        assert!((squared_bound(2) - 3.0 * 3f64.sqrt() / 4.0).abs() < 1e-12);
        assert!((squared_bound(3) - 1.34479).abs() < 1e-5);
        assert!((squared_bound(4) - 1.36035).abs() < 1e-5);
        // N -> infinity: 1 / max_x sin^2(x) / x, the maximum where tan x = 2 x.
        let x = 1.165_561_185_207_211_f64;
        assert!((x.tan() - 2.0 * x).abs() < 1e-9);
        let limit = x / x.sin().powi(2);
        assert!((limit - 1.380).abs() < 1e-3);
        let large = squared_bound(1000);
        assert!((large - limit).abs() < 1e-5, "{large} against {limit}");
        for pair in NS.windows(2) {
            assert!(squared_bound(pair[0]) < squared_bound(pair[1]));
        }
    }

    #[test]
    fn placement_moment_sums_the_particles() {
        for n in 1..=16 {
            let q: f64 = (1..=n)
                .map(|p| (2 * p - 1) as f64 / (2 * n) as f64)
                .map(|xi| xi * (1.0 - xi))
                .sum();
            assert!((q - placement_moment(n)).abs() < 1e-14, "N = {n}");
        }
    }

    #[test]
    fn projected_bound_values() {
        // N = 1: 1/sqrt(2).
        let expected = [FRAC_1_SQRT_2, 0.755_929, 0.766_131, 0.769_800, 0.773_389];
        for (n, want) in NS.into_iter().zip(expected) {
            assert!((projected_bound(n) - want).abs() < 1e-6, "N = {n}");
        }
        assert!((projected_bound(100_000) - 0.6f64.sqrt()).abs() < 1e-6);
    }

    /// The per-mode step matrix with complex entries, as derived (not through the trace and
    /// determinant formulas).
    fn amplification(n: usize, lambda: f64, theta: f64) -> Matrix2<Complex<f64>> {
        let a = Complex::new(0.0, 2.0 * lambda * (theta / 2.0).sin());
        let one = Complex::new(1.0, 0.0);
        let sigma = Complex::new(projection_symbol(n, theta), 0.0);
        Matrix2::new(one, sigma * a, a, one + a * a)
    }

    /// Largest |eigenvalue| of a complex 2 x 2 matrix from its characteristic polynomial.
    fn radius2(m: &Matrix2<Complex<f64>>) -> f64 {
        let t = m[(0, 0)] + m[(1, 1)];
        let d = m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)];
        let root = (t * t - d * 4.0).sqrt();
        ((t + root) / 2.0).norm().max(((t - root) / 2.0).norm())
    }

    fn max_radius(n: usize, lambda: f64) -> f64 {
        (0..=2000)
            .map(|k| PI * k as f64 / 1000.0)
            .map(|theta| radius2(&amplification(n, lambda, theta)))
            .fold(0.0, f64::max)
    }

    #[test]
    fn projected_bound_is_where_the_amplification_matrix_turns_unstable() {
        for n in NS {
            let bound = projected_bound(n);
            assert!(max_radius(n, bound - 1e-4) <= 1.0 + 1e-12, "N = {n}");
            assert!(max_radius(n, bound + 1e-4) > 1.0 + 1e-4, "N = {n}");
            // Schur-Cohn on the trace and determinant at theta = pi gives the same bound.
            let (t, d) = projected_trace_det(n, bound, PI);
            assert!((-t - (1.0 + d)).abs() < 1e-12, "N = {n}");
            let m = amplification(n, 0.6, 1.3);
            let (t, d) = projected_trace_det(n, 0.6, 1.3);
            assert!((m[(0, 0)] + m[(1, 1)] - t).norm() < 1e-14);
            assert!((m.determinant() - d).norm() < 1e-14);
        }
    }

    /// The ends of the grid in `particle_step`.
    #[derive(Clone, Copy, PartialEq)]
    enum Ends {
        Periodic,
        /// Velocity and acceleration held at zero at the two end nodes, as `mpm` runs
        /// `mms1d_gong`.
        Fixed,
    }

    /// One step of the linearised MPM on a grid of `cells` cells with N particles per cell,
    /// every particle's velocity and F as unknowns (E = rho = h = 1, so dt = lambda):
    /// v_i = sum_p m_p N_ip v_p / m_i, a_i = -sum_p V_p F_p grad N_ip / m_i,
    /// v_p += dt sum_i N_ip a_i, F_p += dt sum_i grad N_ip (v_i + dt a_i).
    /// With `project` false the grid velocity is a state of its own, v_i += dt a_i, as in
    /// Gong's eqs 7.13-7.14.
    fn particle_step(
        cells: usize,
        n: usize,
        lambda: f64,
        project: bool,
        ends: Ends,
    ) -> DMatrix<f64> {
        let np = cells * n;
        let nodes = if ends == Ends::Periodic {
            cells
        } else {
            cells + 1
        };
        let mut shape = DMatrix::<f64>::zeros(nodes, np);
        let mut grad = DMatrix::<f64>::zeros(nodes, np);
        for c in 0..cells {
            for j in 0..n {
                let xi = (2 * j + 1) as f64 / (2 * n) as f64;
                let p = c * n + j;
                let right = (c + 1) % nodes;
                shape[(c, p)] += 1.0 - xi;
                shape[(right, p)] += xi;
                grad[(c, p)] -= 1.0;
                grad[(right, p)] += 1.0;
            }
        }
        let (mp, vp) = (1.0 / n as f64, 1.0 / n as f64);
        let mut to_grid = shape.clone() * mp;
        let mut accel = grad.clone() * -vp;
        for i in 0..nodes {
            let fixed = ends == Ends::Fixed && (i == 0 || i == cells);
            let scale = if fixed {
                0.0
            } else {
                1.0 / (shape.row(i).sum() * mp)
            };
            to_grid.row_mut(i).scale_mut(scale);
            accel.row_mut(i).scale_mut(scale);
        }
        let dt = lambda;
        let gt = grad.transpose();
        let f_to_f = DMatrix::identity(np, np) + &gt * &accel * (dt * dt);
        if project {
            let mut m = DMatrix::identity(2 * np, 2 * np);
            m.view_mut((0, np), (np, np))
                .copy_from(&(shape.transpose() * &accel * dt));
            m.view_mut((np, 0), (np, np))
                .copy_from(&(&gt * &to_grid * dt));
            m.view_mut((np, np), (np, np)).copy_from(&f_to_f);
            m
        } else {
            let mut m = DMatrix::identity(nodes + np, nodes + np);
            m.view_mut((0, nodes), (nodes, np))
                .copy_from(&(&accel * dt));
            m.view_mut((nodes, 0), (np, nodes)).copy_from(&(&gt * dt));
            m.view_mut((nodes, nodes), (np, np)).copy_from(&f_to_f);
            m
        }
    }

    /// The spectral radius from ||M^n||^(1/n) with n = 2^20, by repeated squaring with the
    /// scale kept as a logarithm. (General eigenvalue solvers stall on these matrices, whose
    /// eigenvalue 1 has a large multiplicity.) A radius of 1 with Jordan blocks of size m
    /// reads as at most 1 + (m - 1) 14 / 2^20 + ln C / 2^20, well below the 1 + 5e-4 that
    /// the tests tell unstable runs by.
    fn radius(m: DMatrix<f64>) -> f64 {
        const SQUARINGS: i32 = 20;
        let mut log_scale = m.norm().ln();
        let mut p = &m / m.norm();
        for _ in 0..SQUARINGS {
            let q = &p * &p;
            let norm = q.norm();
            log_scale = 2.0 * log_scale + norm.ln();
            p = q / norm;
        }
        (log_scale / 2f64.powi(SQUARINGS)).exp()
    }

    /// The reduction to one 2 x 2 matrix per mode (cell-average F, symbol sigma of the
    /// projection) holds for the full particle system: on 8 periodic cells (theta = pi is a
    /// mode) its spectral radius crosses 1 at the projected bound.
    #[test]
    fn particle_system_turns_unstable_at_the_projected_bound() {
        for n in [1, 2, 3, 4] {
            let bound = projected_bound(n);
            let step = |lambda| particle_step(8, n, lambda, true, Ends::Periodic);
            let below = radius(step(bound - 2e-3));
            let above = radius(step(bound + 2e-3));
            assert!(below <= 1.0 + 1e-4, "N = {n}: {below}");
            assert!(above > 1.005, "N = {n}: {above}");
        }
    }

    /// With fixed ends the sine modes are exact eigenmodes, so the bound of the highest one
    /// holds to the digit: 12 cells put it 0.008-0.010 above the periodic bound.
    #[test]
    fn fixed_ends_bound_the_highest_sine_mode() {
        for n in [1, 2, 3] {
            let bound = projected_bound_fixed_ends(n, 12);
            assert!(bound > projected_bound(n) + 0.007, "N = {n}");
            let step = |lambda| particle_step(12, n, lambda, true, Ends::Fixed);
            let below = radius(step(bound - 2e-4));
            let above = radius(step(bound + 2e-4));
            assert!(below <= 1.0 + 1e-4, "N = {n}: {below}");
            assert!(above > 1.0 + 5e-4, "N = {n}: {above}");
        }
        assert!((projected_bound_fixed_ends(1, 64) - 0.707_43).abs() < 1e-5);
        assert!((projected_bound_fixed_ends(4, 64) - 0.770_13).abs() < 1e-5);
    }

    /// Gong's linear system keeps the grid velocity between steps, so the particles of a cell
    /// get the same F increment and only the cell average matters: the N = 1 staggered scheme,
    /// stable up to CFL = 1 for every N, whatever eq 7.29 says.
    #[test]
    fn gong_linear_system_is_stable_up_to_one_for_every_n() {
        for n in [1, 2, 3, 4] {
            let below = radius(particle_step(8, n, 0.998, false, Ends::Periodic));
            let above = radius(particle_step(8, n, 1.002, false, Ends::Periodic));
            assert!(below <= 1.0 + 1e-4, "N = {n}: {below}");
            assert!(above > 1.01, "N = {n}: {above}");
        }
        // So for N = 2 the squared eq 7.29 (1.299) and the printed eq 7.31 (1) differ, and
        // the system they describe follows neither's N dependence.
        assert!(squared_bound(2) > 1.29);
    }
}
