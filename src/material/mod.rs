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
