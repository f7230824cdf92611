//! The `/probes` group of a simulation run: one subgroup per probe, the value of one quantity
//! at one particle at every step with the benchmark's reference for it (Molinos et al. Figs
//! 5-13). Written and read with the same names. Runs of reference solvers record none.

use hdf5::{File, Group};

use super::h5::{attr_f64, attr_i64, attr_str, open_attr, open_dataset, read_i64, read_str};

pub(super) const GROUP: &str = "probes";
pub(super) const TIME: &str = "time";
pub(super) const STEP: &str = "step";
pub(super) const VALUE: &str = "value";
pub(super) const REFERENCE: &str = "reference";
const PARTICLE: &str = "particle";
const X0: &str = "x0";
const QUANTITY: &str = "quantity";
const COMPONENT: &str = "component";
const TOTAL_VARIATION: &str = "total_variation";
const REFERENCE_TOTAL_VARIATION: &str = "reference_total_variation";
const OVERSHOOT: &str = "overshoot";

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

/// How much a probe's history wiggles, against its reference (Molinos et al. sec 4: the
/// predictor-corrector "mitigates the presence of wiggles and overshoot").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wiggles {
    /// sum_k |value_{k+1} - value_k| over the recorded steps.
    pub total_variation: f64,
    /// The same of the reference; NaN where there is none.
    pub reference_total_variation: f64,
    /// How far the value goes past the range of the reference over the whole history,
    /// max(max value - max reference, min reference - min value, 0); NaN without a reference.
    pub overshoot: f64,
}

impl ProbeRecord {
    /// The wiggle measures of the recorded history.
    pub fn wiggles(&self) -> Wiggles {
        let mut tally = WiggleTally::default();
        for (&value, &reference) in self.value.iter().zip(&self.reference) {
            tally.push(value, reference);
        }
        tally.wiggles()
    }

    /// The unit of the quantity.
    pub fn unit(&self) -> &'static str {
        match self.quantity.as_str() {
            "displacement" => "m",
            "velocity" => "m/s",
            _ => "Pa",
        }
    }
}

/// The wiggle measures of a history taken one step at a time, as it is recorded.
#[derive(Clone, Copy, Debug)]
pub struct WiggleTally {
    steps: usize,
    last: (f64, f64),
    total_variation: f64,
    reference_total_variation: f64,
    /// The least and the largest value, and of the reference.
    range: (f64, f64),
    reference_range: (f64, f64),
    reference_known: bool,
}

impl Default for WiggleTally {
    fn default() -> Self {
        WiggleTally {
            steps: 0,
            last: (f64::NAN, f64::NAN),
            total_variation: 0.0,
            reference_total_variation: 0.0,
            range: (f64::INFINITY, f64::NEG_INFINITY),
            reference_range: (f64::INFINITY, f64::NEG_INFINITY),
            reference_known: true,
        }
    }
}

impl WiggleTally {
    /// The next step's value and reference (NaN when there is none).
    pub fn push(&mut self, value: f64, reference: f64) {
        if self.steps > 0 {
            self.total_variation += (value - self.last.0).abs();
            self.reference_total_variation += (reference - self.last.1).abs();
        }
        let widen = |(low, high): (f64, f64), v: f64| (low.min(v), high.max(v));
        self.range = widen(self.range, value);
        self.reference_range = widen(self.reference_range, reference);
        self.reference_known &= reference.is_finite();
        self.last = (value, reference);
        self.steps += 1;
    }

    pub fn wiggles(&self) -> Wiggles {
        let has_reference = self.steps > 0 && self.reference_known;
        let ((low, high), (ref_low, ref_high)) = (self.range, self.reference_range);
        let if_reference = |x: f64| if has_reference { x } else { f64::NAN };
        Wiggles {
            total_variation: self.total_variation,
            reference_total_variation: if_reference(self.reference_total_variation),
            overshoot: if_reference((high - ref_high).max(ref_low - low).max(0.0)),
        }
    }
}

/// Writes the attributes of the probes whose groups and datasets `HistoryStream` wrote, in
/// its order, with each one's wiggle measures.
pub(super) fn write_attributes(
    file: &File,
    probes: &[ProbeRecord],
    wiggles: &[Wiggles],
) -> hdf5::Result<()> {
    for (probe, wiggles) in probes.iter().zip(wiggles) {
        let g = file.group(GROUP)?.group(&probe.name)?;
        attr_i64(&g, PARTICLE, probe.particle)?;
        attr_list(&g, X0, &probe.x0)?;
        attr_str(&g, QUANTITY, &probe.quantity)?;
        attr_list(&g, COMPONENT, &probe.component)?;
        attr_str(&g, REFERENCE, &probe.reference_kind)?;
        attr_f64(&g, TOTAL_VARIATION, wiggles.total_variation)?;
        attr_f64(
            &g,
            REFERENCE_TOTAL_VARIATION,
            wiggles.reference_total_variation,
        )?;
        attr_f64(&g, OVERSHOOT, wiggles.overshoot)?;
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
            x0: open_attr(&g, X0)?.read_raw()?,
            quantity: read_str(&g, QUANTITY)?,
            component: open_attr(&g, COMPONENT)?.read_raw()?,
            reference_kind: read_str(&g, REFERENCE)?,
            time: open_dataset(&g, TIME)?.read_raw()?,
            step: open_dataset(&g, STEP)?.read_raw()?,
            value: open_dataset(&g, VALUE)?.read_raw()?,
            reference: open_dataset(&g, REFERENCE)?.read_raw()?,
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

#[cfg(test)]
mod tests {
    use super::*;

    fn probe(value: &[f64], reference: &[f64]) -> ProbeRecord {
        ProbeRecord {
            value: value.to_vec(),
            reference: reference.to_vec(),
            ..Default::default()
        }
    }

    #[test]
    fn wiggles_of_a_ringing_history() {
        // The reference steps from 5 to 0; the value overshoots to 6, undershoots to -1 and
        // rings back: total variation 1 + 7 + 1 = 9 against 5, overshoot 1.
        let w = probe(&[5.0, 6.0, -1.0, 0.0], &[5.0, 5.0, 0.0, 0.0]).wiggles();
        assert_eq!(w.total_variation, 9.0);
        assert_eq!(w.reference_total_variation, 5.0);
        assert_eq!(w.overshoot, 1.0);
        // Inside the reference's range there is no overshoot.
        assert_eq!(probe(&[4.0, 1.0], &[5.0, 0.0]).wiggles().overshoot, 0.0);
    }

    #[test]
    fn no_reference_no_comparison() {
        let w = probe(&[1.0, 2.0], &[f64::NAN, f64::NAN]).wiggles();
        assert_eq!(w.total_variation, 1.0);
        assert!(w.reference_total_variation.is_nan() && w.overshoot.is_nan());
    }
}
