//! CPDI (Gong secs 6.4-6.6): the hat interpolated from the corners of the particle domain,
//! S_i^p = sum_a N_a^p(x) N_i(x_a), then averaged over the domain. Only the corner weights
//! w_a = (1/V) int N_a^p and gradient vectors g_a = (1/V) int grad N_a^p depend on the shape
//! of the domain: S_ip = sum_a w_a N_i(x_a), grad S_ip = sum_a g_a N_i(x_a).

use nalgebra::SVector;

/// Corners are numbered as in Gong Figs/eqs 6.26-6.32: in 1D left then right; in 2D
/// counter-clockwise from the lower left, (-,-), (+,-), (+,+), (-,+) in the reference square.
pub(super) const MAX_CORNERS: usize = 4;

/// Signs of the reference corners along each axis, in corner order.
pub(super) fn reference_corner<const D: usize>(a: usize) -> SVector<f64, D> {
    const SIGNS_2D: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
    match D {
        1 => SVector::repeat(if a == 0 { -1.0 } else { 1.0 }),
        _ => SVector::from_fn(|k, _| SIGNS_2D[a][k]),
    }
}

/// The corner weights, gradient vectors and volume of one domain.
pub(super) struct CornerWeights<const D: usize> {
    pub value: [f64; MAX_CORNERS],
    pub gradient: [SVector<f64, D>; MAX_CORNERS],
    pub volume: f64,
}

/// Weights of the interval [x_0, x_1] (1D) or of the bilinear quadrilateral with the given
/// corners (2D); `None` when the domain is inverted or degenerate.
///
/// 2D: with x(xi, eta) = a0 + a1 xi + a2 eta + a3 xi eta, the Jacobian is
/// J = J0 + J1 xi + J2 eta (J0 = a1 x a2, J1 = a1 x a3, J2 = a3 x a2), the area is 4 J0 and
/// int N_a = J0 + (J1 xi_a + J2 eta_a)/3. This is eq 6.30 with its "1" read as 6 V_p (as
/// printed, the weights would not sum to one). int grad N_a is half the outward normal of
/// the two edges at corner a: ((y_{a+1} - y_{a-1}), (x_{a-1} - x_{a+1}))/2, eq 6.32.
#[inline(always)]
pub(super) fn corner_weights<const D: usize>(
    corners: &[SVector<f64, D>],
) -> Option<CornerWeights<D>> {
    let mut w = CornerWeights {
        value: [0.0; MAX_CORNERS],
        gradient: [SVector::zeros(); MAX_CORNERS],
        volume: 0.0,
    };
    if D == 1 {
        let len = corners[1][0] - corners[0][0];
        w.volume = len;
        w.value[..2].fill(0.5);
        w.gradient[0] = SVector::repeat(-1.0 / len);
        w.gradient[1] = SVector::repeat(1.0 / len);
    } else {
        let (j0, j1, j2) = jacobian_coefficients(corners);
        w.volume = 4.0 * j0;
        // Opposite corners have opposite reference signs and swap next and prev, and IEEE
        // rounding is symmetric: their terms are exact negatives, so each division is done
        // for two corners. Divisions set the pace here; a zero's sign, the only possible
        // difference, changes no sum of these terms.
        let third = [(j1 + j2) / 3.0, (j1 - j2) / 3.0];
        for a in 0..2 {
            let r = reference_corner::<2>(a);
            let t = third[a] * r[0];
            w.value[a] = (j0 + t) / w.volume;
            w.value[a + 2] = (j0 - t) / w.volume;
            let (next, prev) = (corners[a + 1], corners[(a + 3) % 4]);
            w.gradient[a] = SVector::from_fn(|k, _| match k {
                0 => next[1] - prev[1],
                _ => prev[0] - next[0],
            }) / (2.0 * w.volume);
            w.gradient[a + 2] = -w.gradient[a];
        }
    }
    // Written so that NaN fails the test.
    (w.volume > 0.0).then_some(w)
}

/// J0, J1 and J2 of the bilinear quadrilateral with the given corners (`corner_weights`); 2D.
#[inline(always)]
pub(super) fn jacobian_coefficients<const D: usize>(
    corners: &[SVector<f64, D>],
) -> (f64, f64, f64) {
    let [x1, x2, x3, x4] = [0, 1, 2, 3].map(|a| (corners[a][0], corners[a][1]));
    let a1 = (
        (-x1.0 + x2.0 + x3.0 - x4.0) / 4.0,
        (-x1.1 + x2.1 + x3.1 - x4.1) / 4.0,
    );
    let a2 = (
        (-x1.0 - x2.0 + x3.0 + x4.0) / 4.0,
        (-x1.1 - x2.1 + x3.1 + x4.1) / 4.0,
    );
    let a3 = (
        (x1.0 - x2.0 + x3.0 - x4.0) / 4.0,
        (x1.1 - x2.1 + x3.1 - x4.1) / 4.0,
    );
    let cross = |u: (f64, f64), v: (f64, f64)| u.0 * v.1 - u.1 * v.0;
    (cross(a1, a2), cross(a1, a3), cross(a3, a2))
}
