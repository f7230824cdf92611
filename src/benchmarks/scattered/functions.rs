//! The functions the reconstruction benchmarks sample: Gong's Tables 4.1-4.2 (1, x, x^2),
//! Figs 5.1-5.2 (1.5, x + 1) and Figs 5.3-5.4 (sin(pi x)); Wobbes et al.'s Figs 1-2
//! (sin(x) + 2, sin(x) cos(y)) with their exact integrals over boxes, which the element-wise
//! reconstruction prescribes (eq 5) and measures against.

use std::f64::consts::PI;

use nalgebra::SVector;

/// A function of `D` coordinates whose integral over any box is known in closed form.
pub trait ExactField<const D: usize> {
    /// u as the paper writes it, for titles and the run file.
    fn formula(&self) -> &'static str;
    fn value(&self, x: &SVector<f64, D>) -> f64;
    /// The integral of u over the box [lower, upper].
    fn box_integral(&self, lower: &SVector<f64, D>, upper: &SVector<f64, D>) -> f64;
}

/// Functions of x.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TestFunction {
    One,
    X,
    X2,
    SinPi,
    XPlus1,
    Const1_5,
    SinPlus2,
}

impl TestFunction {
    const ALL: [TestFunction; 7] = [
        TestFunction::One,
        TestFunction::X,
        TestFunction::X2,
        TestFunction::SinPi,
        TestFunction::XPlus1,
        TestFunction::Const1_5,
        TestFunction::SinPlus2,
    ];

    /// The names experiment files use.
    pub const NAMES: [&'static str; 7] = [
        TestFunction::One.name(),
        TestFunction::X.name(),
        TestFunction::X2.name(),
        TestFunction::SinPi.name(),
        TestFunction::XPlus1.name(),
        TestFunction::Const1_5.name(),
        TestFunction::SinPlus2.name(),
    ];

    pub const fn name(self) -> &'static str {
        match self {
            TestFunction::One => "one",
            TestFunction::X => "x",
            TestFunction::X2 => "x2",
            TestFunction::SinPi => "sin_pi",
            TestFunction::XPlus1 => "x_plus_1",
            TestFunction::Const1_5 => "const_1_5",
            TestFunction::SinPlus2 => "sin_plus_2",
        }
    }

    pub fn from_name(name: &str) -> Option<TestFunction> {
        TestFunction::ALL.into_iter().find(|f| f.name() == name)
    }

    /// u(x) as the papers write it, for table headers and figure titles.
    pub fn formula(self) -> &'static str {
        match self {
            TestFunction::One => "1",
            TestFunction::X => "x",
            TestFunction::X2 => "x^2",
            TestFunction::SinPi => "sin(pi x)",
            TestFunction::XPlus1 => "x + 1",
            TestFunction::Const1_5 => "1.5",
            TestFunction::SinPlus2 => "sin(x) + 2",
        }
    }

    pub fn eval(self, x: f64) -> f64 {
        match self {
            TestFunction::One => 1.0,
            TestFunction::X => x,
            TestFunction::X2 => x * x,
            TestFunction::SinPi => (PI * x).sin(),
            TestFunction::XPlus1 => x + 1.0,
            TestFunction::Const1_5 => 1.5,
            TestFunction::SinPlus2 => x.sin() + 2.0,
        }
    }

    /// An antiderivative of u.
    fn antiderivative(self, x: f64) -> f64 {
        match self {
            TestFunction::One => x,
            TestFunction::X => 0.5 * x * x,
            TestFunction::X2 => x * x * x / 3.0,
            TestFunction::SinPi => -(PI * x).cos() / PI,
            TestFunction::XPlus1 => 0.5 * x * x + x,
            TestFunction::Const1_5 => 1.5 * x,
            TestFunction::SinPlus2 => 2.0 * x - x.cos(),
        }
    }
}

impl ExactField<1> for TestFunction {
    fn formula(&self) -> &'static str {
        TestFunction::formula(*self)
    }

    fn value(&self, x: &SVector<f64, 1>) -> f64 {
        self.eval(x[0])
    }

    fn box_integral(&self, lower: &SVector<f64, 1>, upper: &SVector<f64, 1>) -> f64 {
        self.antiderivative(upper[0]) - self.antiderivative(lower[0])
    }
}

/// Functions of x and y.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceFunction {
    /// Wobbes Fig 2.
    SinXCosY,
    /// A quadratic with a mixed term, which a complete quadratic basis reproduces.
    X2PlusXy,
}

impl SurfaceFunction {
    const ALL: [SurfaceFunction; 2] = [SurfaceFunction::SinXCosY, SurfaceFunction::X2PlusXy];

    pub const fn name(self) -> &'static str {
        match self {
            SurfaceFunction::SinXCosY => "sin_x_cos_y",
            SurfaceFunction::X2PlusXy => "x2_plus_xy",
        }
    }
}

impl ExactField<2> for SurfaceFunction {
    fn formula(&self) -> &'static str {
        match self {
            SurfaceFunction::SinXCosY => "sin(x) cos(y)",
            SurfaceFunction::X2PlusXy => "x^2 + x y",
        }
    }

    fn value(&self, p: &SVector<f64, 2>) -> f64 {
        let (x, y) = (p[0], p[1]);
        match self {
            SurfaceFunction::SinXCosY => x.sin() * y.cos(),
            SurfaceFunction::X2PlusXy => x * x + x * y,
        }
    }

    fn box_integral(&self, lower: &SVector<f64, 2>, upper: &SVector<f64, 2>) -> f64 {
        let (a, b, c, d) = (lower[0], upper[0], lower[1], upper[1]);
        match self {
            SurfaceFunction::SinXCosY => (a.cos() - b.cos()) * (d.sin() - c.sin()),
            SurfaceFunction::X2PlusXy => {
                (b * b * b - a * a * a) / 3.0 * (d - c) + 0.25 * (b * b - a * a) * (d * d - c * c)
            }
        }
    }
}

/// A function of the element-wise benchmark, of x or of x and y: its dimension is the run's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ElementFunction {
    Line(TestFunction),
    Surface(SurfaceFunction),
}

impl ElementFunction {
    /// The names experiment files use: the functions of x, then those of x and y.
    pub const NAMES: [&'static str; 9] = [
        TestFunction::NAMES[0],
        TestFunction::NAMES[1],
        TestFunction::NAMES[2],
        TestFunction::NAMES[3],
        TestFunction::NAMES[4],
        TestFunction::NAMES[5],
        TestFunction::NAMES[6],
        SurfaceFunction::SinXCosY.name(),
        SurfaceFunction::X2PlusXy.name(),
    ];

    pub fn from_name(name: &str) -> Option<ElementFunction> {
        TestFunction::from_name(name)
            .map(ElementFunction::Line)
            .or_else(|| {
                SurfaceFunction::ALL
                    .into_iter()
                    .find(|f| f.name() == name)
                    .map(ElementFunction::Surface)
            })
    }

    pub fn name(self) -> &'static str {
        match self {
            ElementFunction::Line(f) => f.name(),
            ElementFunction::Surface(f) => f.name(),
        }
    }

    pub fn dim(self) -> usize {
        match self {
            ElementFunction::Line(_) => 1,
            ElementFunction::Surface(_) => 2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for f in TestFunction::ALL {
            assert_eq!(TestFunction::from_name(f.name()), Some(f));
        }
        assert_eq!(TestFunction::from_name("x3"), None);
        assert_eq!(TestFunction::X2.eval(-0.5), 0.25);
        assert!(TestFunction::SinPi.eval(1.0).abs() < 1e-15);
        for name in ElementFunction::NAMES {
            assert_eq!(ElementFunction::from_name(name).unwrap().name(), name);
        }
        assert_eq!(ElementFunction::from_name("sin_x_cos_y").unwrap().dim(), 2);
        assert_eq!(ElementFunction::from_name("sin_plus_2").unwrap().dim(), 1);
    }

    /// The box integrals against 10-point Gauss quadrature per axis (exact for the
    /// polynomials, far below 1e-12 for the others on boxes of size 1), and Wobbes' printed
    /// totals: 8 pi for sin(x) + 2 on [0, 4 pi], -6.8691e-1 for sin(x) cos(y) on [0, 5]^2.
    #[test]
    fn box_integrals_match_quadrature_and_the_paper() {
        let (nodes, weights) = crate::gauss::gauss_legendre_rule(10);
        let (a, b) = (0.3, 1.1);
        for f in TestFunction::ALL {
            let sum: f64 = nodes
                .iter()
                .zip(&weights)
                .map(|(s, w)| w * 0.4 * f.eval(0.7 + 0.4 * s))
                .sum();
            let exact = f.box_integral(&[a].into(), &[b].into());
            assert!((sum - exact).abs() < 1e-14, "{f:?}: {sum} against {exact}");
        }
        for f in SurfaceFunction::ALL {
            let mut sum = 0.0;
            for (s, ws) in nodes.iter().zip(&weights) {
                for (t, wt) in nodes.iter().zip(&weights) {
                    let p = SVector::<f64, 2>::new(0.7 + 0.4 * s, -0.5 + 0.5 * t);
                    sum += ws * wt * 0.4 * 0.5 * f.value(&p);
                }
            }
            let exact = f.box_integral(&[a, -1.0].into(), &[b, 0.0].into());
            assert!((sum - exact).abs() < 1e-14, "{f:?}: {sum} against {exact}");
        }
        let total = TestFunction::SinPlus2.box_integral(&[0.0].into(), &[4.0 * PI].into());
        assert!((total - 8.0 * PI).abs() < 1e-14);
        let surface =
            SurfaceFunction::SinXCosY.box_integral(&[0.0, 0.0].into(), &[5.0, 5.0].into());
        assert!((surface + 0.68691).abs() < 0.5e-5, "{surface}");
    }
}
