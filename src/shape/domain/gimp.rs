//! GIMP (Gong sec 6.3): the hat averaged over an axis-aligned box, one axis at a time.

use crate::grid::index_to_f64;

/// The integral of the unit hat max(0, 1 - |t|) from -infinity to `xi`.
#[inline]
fn hat_integral(xi: f64) -> f64 {
    if xi <= -1.0 {
        0.0
    } else if xi <= 0.0 {
        0.5 * (1.0 + xi) * (1.0 + xi)
    } else if xi < 1.0 {
        1.0 - 0.5 * (1.0 - xi) * (1.0 - xi)
    } else {
        1.0
    }
}

#[inline]
pub(super) fn hat(xi: f64) -> f64 {
    // A compare and select, one instruction, where `f64::max`'s NaN rule takes several; the
    // same value for every input, NaN included.
    let v = 1.0 - xi.abs();
    if v > 0.0 {
        v
    } else {
        0.0
    }
}

/// Along one axis, for the nodes `first, first + 1, ...` (as many as `value` holds), the hat of
/// each node averaged over [a, b] and the average of its derivative:
/// S_j = (1/(b-a)) int_a^b N_j, dS_j = (N_j(b) - N_j(a))/(b-a) (eqs 6.19 and 6.5). Integrating
/// the hat in closed form gives every branch of the piecewise formula after eq 6.20 at once,
/// without its misprinted last gradient branch. `a` and `b` are in cell units from the grid's
/// lower end.
pub(super) fn averaged_hats(a: f64, b: f64, first: usize, value: &mut [f64], slope: &mut [f64]) {
    let inv_len = 1.0 / (b - a);
    for (j, (s, ds)) in value.iter_mut().zip(slope.iter_mut()).enumerate() {
        let node = index_to_f64(first + j);
        *s = (hat_integral(b - node) - hat_integral(a - node)) * inv_len;
        *ds = (hat(b - node) - hat(a - node)) * inv_len;
    }
}
