//! The `/shape_functions` group of a shape-function run: the evaluation points, the recorded
//! nodes, N_a and grad N_a of those nodes at every point, and per point the consistency errors
//! of the whole basis, with their maxima and the Newton failures of an LME basis. Written and
//! read with the same names, so the report and a reader with h5py see exactly what the file
//! holds.

use hdf5::{File, Group};

use super::h5::{
    attr_f64, attr_i64, attr_str, dataset, open_dataset, read_f64, read_i64, read_str,
};
use super::SHAPE_FIELDS;

const GROUP: &str = "shape_functions";
/// Coordinates are in units of h = 1; the errors below are dimensionless.
const UNIT: &str = "1";
/// The per-point dataset of each field of `SHAPE_FIELDS` is `<field>_error`, its maximum the
/// attribute `max_<field>_error`.
fn error_name(field: &str) -> String {
    format!("{field}_error")
}

fn max_name(field: &str) -> String {
    format!("max_{field}_error")
}

/// One evaluation in `dim` dimensions: Np points, Nn recorded nodes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShapeFunctionRecord {
    /// `lme`, `linear` or `quadratic_bspline`.
    pub basis: String,
    pub dim: usize,
    /// LME only (NaN otherwise): gamma = beta h^2, the cut-off tolerance and radius (in h).
    pub gamma: f64,
    pub tolerance: f64,
    pub radius: f64,
    /// Np x D.
    pub x: Vec<f64>,
    /// Nn: the recorded nodes (DOFs) by flat grid index, the centre node and its neighbours
    /// along x, ascending; `centre` is the centre node's place in this list.
    pub nodes: Vec<i64>,
    pub centre: i64,
    /// Nn x D: their positions.
    pub node_x: Vec<f64>,
    /// Np x Nn: N_a(x_p), zero where a node is outside the point's stencil.
    pub value: Vec<f64>,
    /// Np x Nn x D: grad N_a(x_p).
    pub gradient: Vec<f64>,
    /// Per field of `SHAPE_FIELDS`, Np values over all nodes of each point's stencil:
    /// |sum N_a - 1|, |sum N_a x_a - x| / h, h |sum grad N_a|, |sum grad N_a (x) x_a - I|_F.
    pub errors: [Vec<f64>; 4],
    /// Their maxima over the points (NaN if any is).
    pub max_errors: [f64; 4],
    /// LME points where Newton stopped short of the residual tolerance, and the most Newton
    /// steps any point took (zero for the other bases).
    pub failures: i64,
    pub max_newton_steps: i64,
}

impl ShapeFunctionRecord {
    /// Recorded nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Evaluation points.
    pub fn point_count(&self) -> usize {
        self.x.len().checked_div(self.dim).unwrap_or(0)
    }
}

pub(super) fn write(file: &File, r: &ShapeFunctionRecord) -> hdf5::Result<()> {
    let group = file.create_group(GROUP)?;
    attr_str(&group, "basis", &r.basis)?;
    for (name, value) in [
        ("gamma", r.gamma),
        ("tolerance", r.tolerance),
        ("radius", r.radius),
    ] {
        attr_f64(&group, name, value)?;
    }
    for (name, value) in [
        ("centre", r.centre),
        ("failures", r.failures),
        ("max_newton_steps", r.max_newton_steps),
    ] {
        attr_i64(&group, name, value)?;
    }
    let (d, np, nn) = (r.dim, r.point_count(), r.node_count());
    dataset(&group, "x", &r.x, &[np, d], UNIT)?;
    dataset(&group, "nodes", &r.nodes, &[nn], UNIT)?;
    dataset(&group, "node_x", &r.node_x, &[nn, d], UNIT)?;
    dataset(&group, "value", &r.value, &[np, nn], UNIT)?;
    dataset(&group, "gradient", &r.gradient, &[np, nn, d], UNIT)?;
    for (f, field) in SHAPE_FIELDS.iter().enumerate() {
        dataset(&group, &error_name(field), &r.errors[f], &[np], UNIT)?;
        attr_f64(&group, &max_name(field), r.max_errors[f])?;
    }
    Ok(())
}

/// The group of a shape-function run; `None` for any other run.
pub(super) fn read(file: &File) -> hdf5::Result<Option<ShapeFunctionRecord>> {
    if !file.link_exists(GROUP) {
        return Ok(None);
    }
    let group: Group = file.group(GROUP)?;
    let real = |name: &str| open_dataset(&group, name)?.read_raw::<f64>();
    let x = open_dataset(&group, "x")?;
    let mut errors: [Vec<f64>; 4] = Default::default();
    let mut max_errors = [f64::NAN; 4];
    for (f, field) in SHAPE_FIELDS.iter().enumerate() {
        errors[f] = real(&error_name(field))?;
        max_errors[f] = read_f64(&group, &max_name(field))?;
    }
    Ok(Some(ShapeFunctionRecord {
        basis: read_str(&group, "basis")?,
        dim: x.shape().get(1).copied().unwrap_or(0),
        gamma: read_f64(&group, "gamma")?,
        tolerance: read_f64(&group, "tolerance")?,
        radius: read_f64(&group, "radius")?,
        x: x.read_raw::<f64>()?,
        nodes: open_dataset(&group, "nodes")?.read_raw::<i64>()?,
        centre: read_i64(&group, "centre")?,
        node_x: real("node_x")?,
        value: real("value")?,
        gradient: real("gradient")?,
        errors,
        max_errors,
        failures: read_i64(&group, "failures")?,
        max_newton_steps: read_i64(&group, "max_newton_steps")?,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What is written is read back unchanged, NaN and all.
    #[test]
    fn round_trips_through_a_file() {
        let record = ShapeFunctionRecord {
            basis: "lme".into(),
            dim: 2,
            gamma: 0.8,
            tolerance: 1e-6,
            radius: 4.15,
            x: vec![0.0, 0.0, 0.5, 0.0, 1.0, 0.0],
            nodes: vec![3, 4],
            centre: 1,
            node_x: vec![1.0, 1.0, 2.0, 1.0],
            value: vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.0],
            gradient: (0..12).map(f64::from).collect(),
            errors: [
                vec![1e-16, 0.0, 2e-16],
                vec![0.0; 3],
                vec![f64::NAN, 0.0, 0.0],
                vec![1e-15; 3],
            ],
            max_errors: [2e-16, 0.0, f64::NAN, 1e-15],
            failures: 1,
            max_newton_steps: 27,
        };
        assert_eq!((record.point_count(), record.node_count()), (3, 2));
        let dir = tempfile::tempdir().unwrap();
        let file = File::create(dir.path().join("s.h5")).unwrap();
        write(&file, &record).unwrap();
        let back = read(&file).unwrap().unwrap();
        assert_eq!(format!("{back:?}"), format!("{record:?}"));
        assert!(read(&File::create(dir.path().join("t.h5")).unwrap())
            .unwrap()
            .is_none());
    }
}
