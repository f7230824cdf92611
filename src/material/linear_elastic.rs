use nalgebra::SMatrix;

/// Linear elasticity in rate form (hypoelastic, no objective rate):
/// sigma += dt (lambda tr(d) I + 2 mu d) with d = sym(grad v). In 1D with nu = 0 this is
/// sigma_t = E v_x, the law of Wobbes et al. 2018, sec 5.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearElasticRate {
    pub lambda: f64,
    pub mu: f64,
}

impl LinearElasticRate {
    /// Young's modulus `young` with nu = 0: lambda = 0 and 2 mu = E, so each normal stress
    /// follows its own strain rate, sigma_t = E v_x in 1D.
    pub fn without_poisson(young: f64) -> Self {
        LinearElasticRate {
            lambda: 0.0,
            mu: 0.5 * young,
        }
    }

    /// The stress after a step of length `dt` with velocity gradient `grad_v`.
    #[inline]
    pub fn advance<const D: usize>(
        &self,
        stress: &SMatrix<f64, D, D>,
        grad_v: &SMatrix<f64, D, D>,
        dt: f64,
    ) -> SMatrix<f64, D, D> {
        let d = (grad_v + grad_v.transpose()) * 0.5;
        let mut rate = d * (2.0 * self.mu);
        let volumetric = self.lambda * d.trace();
        for k in 0..D {
            rate[(k, k)] += volumetric;
        }
        stress + rate * dt
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix1, Matrix2};

    #[test]
    fn one_dimensional_rate_is_e_times_strain_rate() {
        // nu = 0: lambda = 0, 2 mu = E.
        let m = LinearElasticRate {
            lambda: 0.0,
            mu: 3.5e6,
        };
        let s = m.advance(&Matrix1::new(10.0), &Matrix1::new(0.2), 1e-3);
        assert!((s[(0, 0)] - (10.0 + 1e-3 * 7e6 * 0.2)).abs() < 1e-9);
    }

    #[test]
    fn spin_does_not_stress() {
        let m = LinearElasticRate {
            lambda: 2.0,
            mu: 1.0,
        };
        let spin = Matrix2::new(0.0, 0.3, -0.3, 0.0);
        assert_eq!(m.advance(&Matrix2::zeros(), &spin, 0.1), Matrix2::zeros());
        let grad_v = Matrix2::new(0.1, 0.4, 0.0, -0.2);
        let d = Matrix2::new(0.1, 0.2, 0.2, -0.2);
        let expected = (Matrix2::identity() * (2.0 * -0.1) + d * 2.0) * 0.5;
        assert!((m.advance(&Matrix2::zeros(), &grad_v, 0.5) - expected).norm() < 1e-15);
    }
}
