//! Constitutive models.

mod linear_elastic;
mod neo_hookean;
mod tensor;

use nalgebra::SMatrix;

pub use linear_elastic::LinearElasticRate;
pub use neo_hookean::NeoHookean;
pub use tensor::det;

/// The constitutive model of a problem, as the particle update sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Hyperelastic: the stress is a function of F.
    NeoHookean(NeoHookean),
    /// Hypoelastic: the stress is advanced with the rate of deformation.
    LinearElasticRate(LinearElasticRate),
}

impl Material {
    /// The Cauchy stress after a step of length `dt` with velocity gradient `grad_v` that
    /// took the deformation gradient to `f` (determinant `j > 0`) from the state with `stress`.
    #[inline(always)]
    pub fn stress<const D: usize>(
        &self,
        stress: &SMatrix<f64, D, D>,
        f: &SMatrix<f64, D, D>,
        j: f64,
        grad_v: &SMatrix<f64, D, D>,
        dt: f64,
    ) -> SMatrix<f64, D, D> {
        match self {
            Material::NeoHookean(m) => m.cauchy(f, j),
            Material::LinearElasticRate(m) => m.advance(stress, grad_v, dt),
        }
    }

    /// Small-strain P-wave modulus lambda + 2 mu (1D and plane strain): it sets the elastic
    /// wave speed and hence the explicit time-step bound.
    pub fn p_wave_modulus(&self) -> f64 {
        match self {
            Material::NeoHookean(m) => m.p_wave_modulus(),
            Material::LinearElasticRate(m) => m.lambda + 2.0 * m.mu,
        }
    }
}

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
