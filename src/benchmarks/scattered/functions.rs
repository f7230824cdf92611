//! The functions the reconstruction benchmarks sample: Gong's Tables 4.1-4.2 (1, x, x^2),
//! Figs 5.1-5.2 (1.5, x + 1) and Figs 5.3-5.4 (sin(pi x)).

use std::f64::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TestFunction {
    One,
    X,
    X2,
    SinPi,
    XPlus1,
    Const1_5,
}

impl TestFunction {
    const ALL: [TestFunction; 6] = [
        TestFunction::One,
        TestFunction::X,
        TestFunction::X2,
        TestFunction::SinPi,
        TestFunction::XPlus1,
        TestFunction::Const1_5,
    ];

    /// The names experiment files use.
    pub const NAMES: [&'static str; 6] = [
        TestFunction::One.name(),
        TestFunction::X.name(),
        TestFunction::X2.name(),
        TestFunction::SinPi.name(),
        TestFunction::XPlus1.name(),
        TestFunction::Const1_5.name(),
    ];

    pub const fn name(self) -> &'static str {
        match self {
            TestFunction::One => "one",
            TestFunction::X => "x",
            TestFunction::X2 => "x2",
            TestFunction::SinPi => "sin_pi",
            TestFunction::XPlus1 => "x_plus_1",
            TestFunction::Const1_5 => "const_1_5",
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
    }
}
