//! Constitutive models.

mod neo_hookean;
mod tensor;

pub use neo_hookean::NeoHookean;
pub use tensor::det;

/// Lame constants from Young's modulus and Poisson's ratio.
/// (Gong sec 4.5 prints E = lambda(1+mu)(1-2mu)/mu; the inverse used here is the standard
/// lambda = E nu / ((1+nu)(1-2nu)), mu = E / (2(1+nu)); see docs/NOTES.md.)
pub fn lame_from_young(e: f64, nu: f64) -> (f64, f64) {
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    (lambda, mu)
}

/// Young's modulus from the Lame constants, E = mu (3 lambda + 2 mu) / (lambda + mu).
pub fn young_from_lame(lambda: f64, mu: f64) -> f64 {
    mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn young_and_lame_are_inverse() {
        let (lambda, mu) = lame_from_young(1e7, 0.3);
        assert!((young_from_lame(lambda, mu) - 1e7).abs() < 1e-8);
    }
}
