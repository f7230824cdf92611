//! The method catalogue. A method is a composition of a shape function, a particle-to-grid
//! transfer and a time integrator; the paper names are presets over those parts.

use std::fmt;

/// Basis functions used on the background grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShapeKind {
    /// Piecewise-linear hat (tensor product in 2D), Gong eq 4.8.
    Linear,
}

/// How particle data reaches the grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransferKind {
    /// Mass-weighted nodal averages (Shepard interpolation with w = M_p N_i), Gong sec 4.3.1.
    Shepard,
}

/// How the grid equations are advanced in time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    /// Leapfrog with half-step velocities and the particle update of Gong sec 4.4.
    Leapfrog,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Method {
    pub shape: ShapeKind,
    pub transfer: TransferKind,
    pub integrator: IntegratorKind,
}

pub struct MethodPreset {
    pub name: &'static str,
    pub method: Method,
    pub source: &'static str,
    pub description: &'static str,
}

const PRESETS: &[MethodPreset] = &[MethodPreset {
    name: "mpm",
    method: Method {
        shape: ShapeKind::Linear,
        transfer: TransferKind::Shepard,
        integrator: IntegratorKind::Leapfrog,
    },
    source: "Gong 2015, ch. 4",
    description: "original MPM: linear hat basis, lumped mass, leapfrog",
}];

pub fn presets() -> &'static [MethodPreset] {
    PRESETS
}

pub fn preset(name: &str) -> Option<&'static MethodPreset> {
    PRESETS.iter().find(|p| p.name == name)
}

pub fn preset_names() -> Vec<&'static str> {
    PRESETS.iter().map(|p| p.name).collect()
}

impl fmt::Display for ShapeKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ShapeKind::Linear => "linear",
        })
    }
}

impl fmt::Display for TransferKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            TransferKind::Shepard => "shepard",
        })
    }
}

impl fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            IntegratorKind::Leapfrog => "leapfrog",
        })
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "shape={} transfer={} integrate={}",
            self.shape, self.transfer, self.integrator
        )
    }
}
