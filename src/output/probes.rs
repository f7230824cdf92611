//! The `/probes` group of a simulation run: one subgroup per probe, the value of one quantity
//! at one particle at every step with the benchmark's reference for it (Molinos et al. Figs
//! 5-13). Written and read with the same names. Runs of reference solvers record none.

use hdf5::{File, Group};

use super::reader::{read_i64, read_str};
use super::writer::{attr_i64, attr_str, dataset};

const GROUP: &str = "probes";
const TIME: &str = "time";
const STEP: &str = "step";
const VALUE: &str = "value";
const REFERENCE: &str = "reference";
const PARTICLE: &str = "particle";
const X0: &str = "x0";
const QUANTITY: &str = "quantity";
const COMPONENT: &str = "component";

/// What a probe's `reference` dataset holds: the exact solution, another solution the
/// benchmark gives (the quasi-static one of the Andersen block), or nothing (NaN).
pub const REFERENCE_KINDS: [&str; 3] = ["exact", "static", "none"];

/// One probe of a run: Nt entries, one per step recorded.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ProbeRecord {
    pub name: String,
    pub particle: i64,
    /// D: the particle's reference position.
    pub x0: Vec<f64>,
    /// `displacement`, `velocity` or `stress`.
    pub quantity: String,
    /// One index for a vector quantity, row and column for the stress.
    pub component: Vec<i64>,
    /// One of `REFERENCE_KINDS`.
    pub reference_kind: String,
    pub time: Vec<f64>,
    pub step: Vec<i64>,
    pub value: Vec<f64>,
    /// NaN where the benchmark gives no reference.
    pub reference: Vec<f64>,
}

impl ProbeRecord {
    /// The unit of the quantity.
    pub fn unit(&self) -> &'static str {
        match self.quantity.as_str() {
            "displacement" => "m",
            "velocity" => "m/s",
            _ => "Pa",
        }
    }
}

/// Writes `/probes` when there are any.
pub(super) fn write(file: &File, probes: &[ProbeRecord]) -> hdf5::Result<()> {
    if probes.is_empty() {
        return Ok(());
    }
    let group = file.create_group(GROUP)?;
    for probe in probes {
        let g = group.create_group(&probe.name)?;
        let nt = probe.time.len();
        dataset(&g, TIME, &probe.time, &[nt], "s")?;
        dataset(&g, STEP, &probe.step, &[nt], "1")?;
        dataset(&g, VALUE, &probe.value, &[nt], probe.unit())?;
        dataset(&g, REFERENCE, &probe.reference, &[nt], probe.unit())?;
        attr_i64(&g, PARTICLE, probe.particle)?;
        attr_list(&g, X0, &probe.x0)?;
        attr_str(&g, QUANTITY, &probe.quantity)?;
        attr_list(&g, COMPONENT, &probe.component)?;
        attr_str(&g, REFERENCE, &probe.reference_kind)?;
    }
    Ok(())
}

/// Every probe of the file, by name; none when it has no `/probes`.
pub fn read(file: &File) -> hdf5::Result<Vec<ProbeRecord>> {
    let Ok(group) = file.group(GROUP) else {
        return Ok(Vec::new());
    };
    let mut probes = Vec::new();
    for name in group.member_names()? {
        let g = group.group(&name)?;
        probes.push(ProbeRecord {
            particle: read_i64(&g, PARTICLE)?,
            x0: g.attr(X0)?.read_raw()?,
            quantity: read_str(&g, QUANTITY)?,
            component: g.attr(COMPONENT)?.read_raw()?,
            reference_kind: read_str(&g, REFERENCE)?,
            time: g.dataset(TIME)?.read_raw()?,
            step: g.dataset(STEP)?.read_raw()?,
            value: g.dataset(VALUE)?.read_raw()?,
            reference: g.dataset(REFERENCE)?.read_raw()?,
            name,
        });
    }
    Ok(probes)
}

fn attr_list<T: hdf5::H5Type>(g: &Group, name: &str, values: &[T]) -> hdf5::Result<()> {
    g.new_attr::<T>()
        .shape(values.len())
        .create(name)?
        .write_raw(values)
}
