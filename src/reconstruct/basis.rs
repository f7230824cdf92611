//! Polynomial bases of the local fits: monomials in the offset from the evaluation point,
//! in units of h, so that the moment matrix is O(1) whatever the grid size and the basis
//! evaluated at the evaluation point itself is (1, 0, ..., 0).

use nalgebra::SVector;

/// Largest basis size: the complete quadratic in 2D, [1, x, y, x^2, xy, y^2] (Tran eq 15).
pub const MAX_TERMS: usize = 6;

/// Complete polynomial degree of a basis: 0 (constants: the fit is a Shepard average),
/// 1 (linear, Gong's "second-order MLS") or 2 (quadratic).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Degree(u8);

impl Degree {
    pub const CONSTANT: Degree = Degree(0);
    pub const LINEAR: Degree = Degree(1);
    pub const QUADRATIC: Degree = Degree(2);

    pub fn new(degree: usize) -> Option<Degree> {
        (degree <= 2).then_some(Degree(degree as u8))
    }

    pub fn value(self) -> usize {
        self.0 as usize
    }

    /// Number of monomials of total degree <= this one in `d` dimensions (1D and 2D).
    pub fn terms(self, d: usize) -> usize {
        match (self.0, d) {
            (0, _) => 1,
            (1, d) => 1 + d,
            (_, 1) => 3,
            _ => 6,
        }
    }
}

/// The degree whose basis has `T` terms in `D` dimensions (1D and 2D): a constant where
/// both are.
#[inline(always)]
pub(super) fn degree_of<const T: usize, const D: usize>() -> Degree {
    match T {
        1 => Degree::CONSTANT,
        _ if T == 1 + D => Degree::LINEAR,
        _ => Degree::QUADRATIC,
    }
}

/// Fills `q` with the monomials of `d` (ordered by degree, then x before y) and returns
/// how many there are.
#[inline]
pub fn monomials<const D: usize>(
    degree: Degree,
    d: &SVector<f64, D>,
    q: &mut [f64; MAX_TERMS],
) -> usize {
    q[0] = 1.0;
    if degree.0 == 0 {
        return 1;
    }
    for k in 0..D {
        q[1 + k] = d[k];
    }
    if degree.0 == 1 {
        return 1 + D;
    }
    let mut n = 1 + D;
    for k in 0..D {
        for l in k..D {
            q[n] = d[k] * d[l];
            n += 1;
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_order() {
        let mut q = [0.0; MAX_TERMS];
        let d2 = SVector::<f64, 2>::new(2.0, 3.0);
        assert_eq!(monomials(Degree::QUADRATIC, &d2, &mut q), 6);
        assert_eq!(q, [1.0, 2.0, 3.0, 4.0, 6.0, 9.0]);
        let d1 = SVector::<f64, 1>::new(-0.5);
        assert_eq!(monomials(Degree::QUADRATIC, &d1, &mut q), 3);
        assert_eq!(&q[..3], &[1.0, -0.5, 0.25]);
        assert_eq!(monomials(Degree::LINEAR, &d2, &mut q), 3);
        assert_eq!(monomials(Degree::CONSTANT, &d2, &mut q), 1);
        for (deg, d, n) in [
            (0, 1, 1),
            (1, 1, 2),
            (2, 1, 3),
            (0, 2, 1),
            (1, 2, 3),
            (2, 2, 6),
        ] {
            assert_eq!(Degree::new(deg).unwrap().terms(d), n);
        }
        assert!(Degree::new(3).is_none());
    }
}
