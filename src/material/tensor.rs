use nalgebra::SMatrix;

/// Determinant of a 1x1, 2x2 or 3x3 matrix. nalgebra's `determinant` needs trait bounds
/// that a generic `const D` cannot state, and these closed forms are what it computes.
#[inline]
pub fn det<const D: usize>(m: &SMatrix<f64, D, D>) -> f64 {
    match D {
        1 => m[(0, 0)],
        2 => m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)],
        3 => {
            m[(0, 0)] * (m[(1, 1)] * m[(2, 2)] - m[(1, 2)] * m[(2, 1)])
                - m[(0, 1)] * (m[(1, 0)] * m[(2, 2)] - m[(1, 2)] * m[(2, 0)])
                + m[(0, 2)] * (m[(1, 0)] * m[(2, 1)] - m[(1, 1)] * m[(2, 0)])
        }
        _ => unreachable!("mpmlab supports 1 to 3 dimensions"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix3};

    #[test]
    fn agrees_with_nalgebra() {
        let a = Matrix2::<f64>::new(1.3, -0.2, 0.4, 0.9);
        assert!((det(&a) - a.determinant()).abs() < 1e-15);
        let b = Matrix3::<f64>::new(1.3, -0.2, 0.1, 0.4, 0.9, -0.5, 0.2, 0.3, 1.1);
        assert!((det(&b) - b.determinant()).abs() < 1e-14);
    }
}
