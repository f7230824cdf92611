//! Gauss-Legendre rules on [-1, 1]: the tabulated 1- to 3-point rules of the evaluation
//! lattices (`gauss_legendre`), and rules of any order (`gauss_legendre_rule`) for integrals
//! that need more points.

use std::f64::consts::PI;

/// Newton steps are taken until the step is below this (the roots are then exact to
/// rounding); a few more than the usual five or six are allowed for large n.
const ROOT_TOLERANCE: f64 = 1e-15;
const MAX_NEWTON_STEPS: usize = 100;

/// Gauss-Legendre abscissae and weights on [-1, 1].
pub fn gauss_legendre(n: usize) -> (&'static [f64], &'static [f64]) {
    const A2: f64 = 0.577_350_269_189_625_8; // 1/sqrt(3)
    const A3: f64 = 0.774_596_669_241_483_4; // sqrt(3/5)
    match n {
        1 => (&[0.0], &[2.0]),
        2 => (&[-A2, A2], &[1.0, 1.0]),
        3 => (&[-A3, 0.0, A3], &[5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0]),
        _ => panic!("Gauss-Legendre rules with 1 to 3 points are tabulated, not {n}"),
    }
}

/// Abscissae (ascending) and weights of the `n`-point Gauss-Legendre rule on [-1, 1]: exact for
/// polynomials of degree 2n - 1. The abscissae are the roots of P_n, found by Newton's method
/// from Tricomi's estimate cos(pi (i + 3/4)/(n + 1/2)); w_i = 2/((1 - x_i^2) P_n'(x_i)^2). The
/// rule is made exactly symmetric by computing one half and mirroring it.
pub fn gauss_legendre_rule(n: usize) -> (Vec<f64>, Vec<f64>) {
    assert!(n >= 1, "a Gauss-Legendre rule needs at least one point");
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        for _ in 0..MAX_NEWTON_STEPS {
            let (p, dp) = legendre(n, x);
            let step = p / dp;
            x -= step;
            if step.abs() < ROOT_TOLERANCE {
                break;
            }
        }
        // The middle root of an odd rule is 0 exactly.
        if 2 * i + 1 == n {
            x = 0.0;
        }
        let slope = legendre(n, x).1;
        let w = 2.0 / ((1.0 - x * x) * slope * slope);
        // Tricomi's estimates descend from near 1: root i is the (i+1)-th largest.
        nodes[n - 1 - i] = x;
        nodes[i] = -x;
        weights[n - 1 - i] = w;
        weights[i] = w;
    }
    (nodes, weights)
}

/// P_n(x) and P_n'(x) by Bonnet's recurrence (n >= 1, |x| < 1).
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p_prev, mut p) = (1.0, x);
    for k in 2..=n {
        let k = k as f64;
        let next = ((2.0 * k - 1.0) * x * p - (k - 1.0) * p_prev) / k;
        p_prev = p;
        p = next;
    }
    let dp = n as f64 * (x * p - p_prev) / (x * x - 1.0);
    (p, dp)
}

#[cfg(test)]
mod tests {
    use super::gauss_legendre;
    use super::*;

    #[test]
    fn agrees_with_the_tabulated_rules() {
        for n in 1..=3 {
            let (x, w) = gauss_legendre_rule(n);
            let (tx, tw) = gauss_legendre(n);
            for i in 0..n {
                assert!(
                    (x[i] - tx[i]).abs() < 1e-15,
                    "n = {n}: {x:?} against {tx:?}"
                );
                assert!(
                    (w[i] - tw[i]).abs() < 1e-15,
                    "n = {n}: {w:?} against {tw:?}"
                );
            }
        }
    }

    /// Exact for x^k, k <= 2n - 1: the integral of x^k over [-1, 1] is 2/(k + 1) for even k
    /// and 0 for odd k.
    #[test]
    fn integrates_polynomials_up_to_degree_2n_minus_1() {
        for n in [1, 2, 4, 5, 10, 16] {
            let (x, w) = gauss_legendre_rule(n);
            assert!(x.windows(2).all(|p| p[0] < p[1]), "n = {n}: not ascending");
            let integral = |k: i32| -> f64 { x.iter().zip(&w).map(|(x, w)| w * x.powi(k)).sum() };
            for k in 0..2 * n as i32 {
                let exact = if k % 2 == 0 {
                    2.0 / (k + 1) as f64
                } else {
                    0.0
                };
                let got = integral(k);
                assert!(
                    (got - exact).abs() < 1e-14,
                    "n = {n}, x^{k}: {got} against {exact}"
                );
            }
            // The error for x^{2n}, 2^{2n+1} (n!)^4 / ((2n+1) ((2n)!)^2), falls below
            // rounding for large n; for small n it shows the rule is not exact beyond 2n - 1.
            let k = 2 * n as i32;
            if n <= 5 {
                assert!(
                    (integral(k) - 2.0 / (k + 1) as f64).abs() > 1e-4,
                    "n = {n}: x^{k}"
                );
            }
        }
    }
}
