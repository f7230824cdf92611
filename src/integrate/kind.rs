//! The time integrators a method can step with, by name: the registry of experiment files'
//! `integrator` parameter and the method presets.

use std::fmt;

use crate::catalog::{names_of, Catalog, Entry, Parts};

/// How the grid equations are advanced in time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    /// Leapfrog with half-step velocities and the particle update of Gong sec 4.4.
    Leapfrog,
    /// Whole-step velocities, particles moved first, velocity gradient from the nodal
    /// velocity rebuilt from the moved particles (Tran eqs 31-40; Sulsky's MUSL).
    Musl,
    /// Whole-step velocities, particles kicked and moved with the updated nodal velocity and
    /// deformed with it (update stress last, no remap): what the CPLS code of Tran et al.
    /// runs for MPM, CPDI and IMLS-MPM.
    Usl,
    /// Sulsky et al. 1994 as Molinos et al. eqs 21-22 write it: whole-step velocities,
    /// v_p += dt sum_i N_ip a_i, x_p += dt sum_i N_ip v_i with the start-of-step nodal
    /// velocity, the stress from the updated nodal velocity v_i + dt a_i.
    Euler,
    /// Eqs 23-24 (Zhang et al. 2016): the particle update of eqs 21-22 written with nodal
    /// momenta, and the stress from the nodal velocity rebuilt from the updated particle
    /// velocities, which stays bounded where a nodal mass vanishes.
    EulerCorrected,
    /// The explicit Newmark predictor-corrector (gamma = 1/2) of Molinos et al. sec 4 as the
    /// authors' code runs it: the predictor mapped from the particles' v_p + dt/2 a_p every
    /// step, the stress from it, the corrector with half the new acceleration
    /// (`integrate::predictor_corrector`).
    PredictorCorrector,
}

impl IntegratorKind {
    pub fn name(self) -> &'static str {
        INTEGRATORS
            .name_of(&self)
            .expect("every integrator is registered")
    }

    /// Whether the particles carry v^{s-1/2} between steps and start with a half kick: the
    /// leapfrog alone.
    pub fn staggers_velocity(self) -> bool {
        self == IntegratorKind::Leapfrog
    }

    /// Whether the strain rate comes from the nodal velocity rebuilt from the moved
    /// particles (MUSL, eqs 23-24) rather than from the grid solve's.
    pub fn remaps_velocity(self) -> bool {
        matches!(self, IntegratorKind::Musl | IntegratorKind::EulerCorrected)
    }
}

impl fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

const ENTRIES: &[Entry<IntegratorKind>] = &[
    Entry {
        name: "leapfrog",
        value: IntegratorKind::Leapfrog,
        description: "half-step velocities, the particle update of Gong sec 4.4",
    },
    Entry {
        name: "musl",
        value: IntegratorKind::Musl,
        description: "whole-step velocities, stress from the remapped nodal velocity (Tran eqs \
                      31-40)",
    },
    Entry {
        name: "usl",
        value: IntegratorKind::Usl,
        description: "whole-step velocities, stress from the updated nodal velocity, no remap",
    },
    Entry {
        name: "euler",
        value: IntegratorKind::Euler,
        description: "Sulsky et al. 1994 as Molinos et al. eqs 21-22 write it",
    },
    Entry {
        name: "euler_corrected",
        value: IntegratorKind::EulerCorrected,
        description: "eqs 23-24: the stress from the velocity rebuilt from the particles",
    },
    Entry {
        name: "predictor_corrector",
        value: IntegratorKind::PredictorCorrector,
        description: "the explicit Newmark predictor-corrector of Molinos et al. sec 4",
    },
];

pub const INTEGRATORS: Parts<IntegratorKind> = Catalog {
    kind: "integrator",
    entries: ENTRIES,
};

/// The names the `integrator` parameter takes.
pub const INTEGRATOR_NAMES: [&str; ENTRIES.len()] = names_of(ENTRIES);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_integrator_is_found_by_its_name() {
        for entry in INTEGRATORS.entries {
            assert_eq!(entry.value.name(), entry.name);
        }
        assert!(INTEGRATORS.find("rk4").is_none());
    }
}
