//! Weight functions of the local least-squares fits, as functions of the distance in units
//! of a support length `scale * h`. Tensor products in more than one dimension.

use std::fmt;

use nalgebra::SVector;

/// A 1D weight w(r), r = |x - x_p| / (scale h), in B-spline form.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Weight {
    /// 1 - r on r < 1: the linear hat (Gong eq 4.8; Tran's "linear basis function").
    Hat,
    /// The quadratic B-spline, support r < 3/2 (Gong eq 5.2, Tran eq 27).
    QuadraticSpline,
    /// The cubic B-spline, support r < 2, w(0) = 2/3. Gong eq 5.1 writes the same function
    /// with r' = r/2 on r' < 1.
    CubicSpline,
}

impl Weight {
    pub const ALL: [Weight; 3] = [Weight::Hat, Weight::QuadraticSpline, Weight::CubicSpline];
    /// The names experiment files use, in the order of `ALL`.
    pub const NAMES: [&'static str; 3] = [
        Weight::Hat.name(),
        Weight::QuadraticSpline.name(),
        Weight::CubicSpline.name(),
    ];

    pub const fn name(self) -> &'static str {
        match self {
            Weight::Hat => "hat",
            Weight::QuadraticSpline => "quadratic",
            Weight::CubicSpline => "cubic",
        }
    }

    pub fn from_name(name: &str) -> Option<Weight> {
        Weight::ALL.into_iter().find(|w| w.name() == name)
    }

    /// Support radius in units of the support length.
    pub fn radius(self) -> f64 {
        match self {
            Weight::Hat => 1.0,
            Weight::QuadraticSpline => 1.5,
            Weight::CubicSpline => 2.0,
        }
    }

    /// w(r) for r >= 0; zero outside the support.
    #[inline]
    pub fn eval(self, r: f64) -> f64 {
        match self {
            Weight::Hat => (1.0 - r).max(0.0),
            Weight::QuadraticSpline => {
                if r < 0.5 {
                    0.75 - r * r
                } else if r < 1.5 {
                    0.5 * (1.5 - r) * (1.5 - r)
                } else {
                    0.0
                }
            }
            Weight::CubicSpline => {
                if r < 1.0 {
                    2.0 / 3.0 - r * r + 0.5 * r * r * r
                } else if r < 2.0 {
                    let s = 2.0 - r;
                    s * s * s / 6.0
                } else {
                    0.0
                }
            }
        }
    }
}

/// A weight and its support length in cells: w(d) = prod_k weight(|d_k| / (scale h)).
/// Gong scales every weight with h (scale 1); Tran eq 27 scales the quadratic spline
/// with 2 l_e (scale 2), which doubles its support.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kernel {
    pub weight: Weight,
    pub scale: f64,
}

impl Kernel {
    /// Support radius in units of h.
    pub fn radius_cells(&self) -> f64 {
        self.weight.radius() * self.scale
    }

    /// Tensor-product weight of the offset `d`, given in units of h.
    #[inline]
    pub fn eval<const D: usize>(&self, d: &SVector<f64, D>) -> f64 {
        let inv = 1.0 / self.scale;
        d.iter()
            .map(|&dk| self.weight.eval(dk.abs() * inv))
            .product()
    }
}

impl fmt::Display for Weight {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl fmt::Display for Kernel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}({}h)", self.weight, self.scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each weight is the B-spline of its order: integer translates sum to one, and it is
    /// continuous at its knots.
    #[test]
    fn weights_are_b_splines() {
        for weight in [Weight::Hat, Weight::QuadraticSpline, Weight::CubicSpline] {
            // Translates by whole cells form a partition of unity (the hat and cubic are
            // centred on nodes, the quadratic on cell centres: both sum to one).
            for &x in &[0.0, 0.13, 0.5, 0.77] {
                let sum: f64 = (-4..=4).map(|i| weight.eval((x - i as f64).abs())).sum();
                assert!((sum - 1.0).abs() < 1e-14, "{weight}: sum {sum} at {x}");
            }
            let r = weight.radius();
            assert_eq!(weight.eval(r), 0.0);
            for knot in [0.5, 1.0, 1.5] {
                let jump = (weight.eval(knot - 1e-12) - weight.eval(knot + 1e-12)).abs();
                assert!(jump < 1e-10, "{weight} jumps by {jump} at {knot}");
            }
        }
        // Gong eq 5.1 in its own variable r' = |x - x_p| / (2h).
        let gong = |rp: f64| {
            if rp <= 0.5 {
                2.0 / 3.0 - 4.0 * rp * rp + 4.0 * rp * rp * rp
            } else {
                4.0 / 3.0 - 4.0 * rp + 4.0 * rp * rp - 4.0 / 3.0 * rp * rp * rp
            }
        };
        for &r in &[0.0, 0.3, 0.9, 1.0, 1.4, 1.99] {
            assert!((Weight::CubicSpline.eval(r) - gong(r / 2.0)).abs() < 1e-14);
        }
    }

    #[test]
    fn kernel_scales_the_support() {
        let k = Kernel {
            weight: Weight::QuadraticSpline,
            scale: 2.0,
        };
        assert_eq!(k.radius_cells(), 3.0);
    }
}
