use nalgebra::SMatrix;

/// Compressible neo-Hookean solid, Gong eq 4.5:
/// sigma = (lambda ln J I + mu (F F^T - I)) / J.
/// In 1D and in plane strain (2D) the out-of-plane stretch is 1, so the same formula holds
/// with D x D tensors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeoHookean {
    pub lambda: f64,
    pub mu: f64,
}

impl NeoHookean {
    /// Cauchy stress for deformation gradient `f` with determinant `j > 0`.
    #[inline]
    pub fn cauchy<const D: usize>(&self, f: &SMatrix<f64, D, D>, j: f64) -> SMatrix<f64, D, D> {
        let mut s = f * f.transpose();
        let diag = self.lambda * j.ln() - self.mu;
        for k in 0..D {
            s[(k, k)] = self.mu * s[(k, k)] + diag;
            for l in 0..D {
                if l != k {
                    s[(k, l)] *= self.mu;
                }
            }
        }
        // One division instead of D^2.
        s * (1.0 / j)
    }

    /// Small-strain P-wave modulus lambda + 2 mu: the tangent d sigma / d eps at F = I in 1D
    /// and plane strain, which sets the elastic wave speed and hence the explicit time-step bound.
    pub fn p_wave_modulus(&self) -> f64 {
        self.lambda + 2.0 * self.mu
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix2;
    type M2 = Matrix2<f64>;

    #[test]
    fn stress_free_at_identity() {
        let m = NeoHookean {
            lambda: 5.0,
            mu: 3.0,
        };
        let s = m.cauchy(&M2::identity(), 1.0);
        assert_eq!(s, M2::zeros());
    }

    #[test]
    fn matches_formula_for_general_gradient() {
        let m = NeoHookean {
            lambda: 5.0,
            mu: 3.0,
        };
        let f = M2::new(1.1, 0.2, -0.1, 0.9);
        let j = f.determinant();
        let expected = (M2::identity() * (m.lambda * j.ln())
            + (f * f.transpose() - M2::identity()) * m.mu)
            / j;
        assert!((m.cauchy(&f, j) - expected).norm() < 1e-13);
    }
}
