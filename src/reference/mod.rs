//! Reference solvers: methods other than MPM that a benchmark without an exact solution is
//! compared against. They run through the normal runner as a `method` and write the same run
//! file, with one point per element standing in for the particles.

mod ulfem;

pub use ulfem::UlFem;

use crate::catalog::{Catalog, Named};

/// Catalogue entry of a reference method.
pub struct ReferenceMethod {
    pub name: &'static str,
    /// The benchmarks it can solve.
    pub benchmarks: &'static [&'static str],
    pub source: &'static str,
    pub description: &'static str,
}

impl Named for ReferenceMethod {
    fn name(&self) -> &'static str {
        self.name
    }
}

pub const METHODS: Catalog<ReferenceMethod> = Catalog {
    kind: "reference solver",
    entries: &[ReferenceMethod {
        name: "ulfem",
        benchmarks: &["vibrating_bar"],
        source: "Wobbes et al. 2018, sec 5 (ULFEM reference)",
        description: "updated-Lagrangian FEM: 2-node elements, lumped mass, one Gauss point, \
                      central differences",
    }],
};

/// Why `method` cannot run on `benchmark`, if it is a reference method that does not solve it.
pub fn unsupported(method: &str, benchmark: &str) -> Option<String> {
    let m = METHODS.find(method)?;
    (!m.benchmarks.contains(&benchmark)).then(|| {
        format!(
            "method '{method}' is a reference solver for {} only, not {benchmark}",
            m.benchmarks.join(", ")
        )
    })
}
