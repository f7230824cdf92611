use std::path::Path;

use hdf5::Group;

use super::h5::{attr_f64, attr_i64, attr_str, dataset, string_dataset};
use super::record::Unstepped;
use super::stream::{HistoryStream, StreamShape};
use super::{
    elements, field_unit, probes, reconstruction, shape_functions, RunRecord, CONFIG_YAML,
    ERROR_FIELDS, GRID_VELOCITY, SCHEMA_VERSION,
};
use crate::params::ParamValue;

/// Writes the whole record, kept in memory, into a new HDF5 file at `path` (which must not
/// exist).
pub fn write_hdf5(path: &Path, r: &RunRecord) -> hdf5::Result<()> {
    let file = hdf5::File::create_excl(path)?;
    write_record(&file, r, None)
}

/// Writes the record into `file`. A run that streamed its growing arrays into `file` passes
/// its `stream`, which the record's arrays continue; without one they are all in `r`.
pub fn write_record(
    file: &hdf5::File,
    r: &RunRecord,
    stream: Option<HistoryStream>,
) -> hdf5::Result<()> {
    write_identity(file, r)?;
    // An unstepped run's file is its identity and its one group.
    let written = match &r.unstepped {
        Unstepped::Reconstruction(record) => reconstruction::write(file, record),
        Unstepped::Elements(record) => elements::write(file, record),
        Unstepped::ShapeFunctions(record) => shape_functions::write(file, record),
        Unstepped::None => return write_stepped(file, r, stream),
    };
    written.and_then(|()| file.flush())
}

/// The particle, history, grid, error, conservation and probe groups of a stepped run.
fn write_stepped(
    file: &hdf5::File,
    r: &RunRecord,
    stream: Option<HistoryStream>,
) -> hdf5::Result<()> {
    let d = r.dim;
    let np = r.particles.len();
    let nt = r.history.time.len();
    let nn = r.grid.weight.len();
    let stream = match stream {
        Some(stream) => stream,
        None => {
            let steps = r.probes.first().map_or(0, |p| p.time.len());
            let shape = StreamShape {
                dim: d,
                particles: np,
                dofs: nn,
                samples: nt,
                steps,
            };
            let mut stream = HistoryStream::create(file, shape, &r.probes)?;
            stream.append_samples(nt, &r.history, &r.grid, &r.errors)?;
            stream.append_probes(&r.probes)?;
            stream
        }
    };
    let wiggles = stream.finish()?;

    for (name, value) in [
        ("shape", &r.parts.shape),
        ("transfer", &r.parts.transfer),
        ("integrator", &r.parts.integrator),
    ] {
        attr_str(file, name, value)?;
    }
    attr_i64(file, "steps", r.steps as i64)?;
    for (name, value) in [("dt", r.dt), ("t_end", r.t_end)] {
        attr_f64(file, name, value)?;
    }

    let particles = file.create_group("particles")?;
    dataset(&particles, "X", &r.particles.x0, &[np, d], "m")?;
    dataset(&particles, "mass", &r.particles.mass, &[np], "kg")?;
    dataset(&particles, "volume0", &r.particles.volume0, &[np], "m^D")?;

    let history = file.group("history")?;
    dataset(&history, "time", &r.history.time, &[nt], "s")?;
    dataset(&history, "step", &r.history.step, &[nt], "1")?;

    let grid = file.group("grid")?;
    dataset(&grid, "x", &r.grid.x, &[nn, d], "m")?;
    dataset(&grid, "weight", &r.grid.weight, &[nn], "m^D")?;
    dataset(&grid, "time", &r.grid.time, &[nt], "s")?;

    let errors = file.group("errors")?;
    dataset(&errors, "time", &r.history.time, &[nt], "s")?;
    let norms = errors.create_group("norms")?;
    let e = &r.errors;
    let grid_velocity = &e.grid_velocity;
    let fields = ERROR_FIELDS
        .iter()
        .enumerate()
        .map(|(f, &field)| (field, [&e.l2[f], &e.rms[f]]))
        .chain([(GRID_VELOCITY, [&grid_velocity.l2, &grid_velocity.rms])]);
    for (field, [l2, rms]) in fields {
        let unit = field_unit(field);
        for (norm, values) in [("l2", l2), ("rms", rms)] {
            let name = format!("{norm}_{field}");
            dataset(&norms, &name, values, &[nt], unit)?;
            attr_f64(&norms, &name, values.last().copied().unwrap_or(f64::NAN))?;
        }
    }
    let conservation = file.create_group("conservation")?;
    dataset(&conservation, "time", &r.history.time, &[nt], "s")?;
    for (name, values) in [
        ("particle_mass", &r.conservation.particle_mass),
        ("grid_mass", &r.conservation.grid_mass),
    ] {
        dataset(&conservation, name, values, &[nt], "kg")?;
    }
    for (name, value) in [
        ("max_mass_error", r.conservation.max_mass_error),
        ("max_momentum_error", r.conservation.max_momentum_error),
    ] {
        attr_f64(&conservation, name, value)?;
    }
    let diagnostics = file.create_group("diagnostics")?;
    for (name, value) in [
        ("reconstructions", r.diagnostics.reconstructions),
        ("rank_deficient", r.diagnostics.rank_deficient),
        ("grid_crossings", r.diagnostics.grid_crossings),
        ("lme_failures", r.diagnostics.lme_failures),
    ] {
        attr_i64(&diagnostics, name, value as i64)?;
    }
    probes::write_attributes(file, &r.probes, &wiggles)?;
    file.flush()
}

/// What every run file has: the root attributes that identify the run and its outcome, and
/// the `/params` and `/matrix` groups.
fn write_identity(file: &hdf5::File, r: &RunRecord) -> hdf5::Result<()> {
    attr_i64(file, "schema_version", SCHEMA_VERSION)?;
    for (name, value) in [
        ("run_id", r.spec.run_id.as_str()),
        ("experiment", &r.spec.experiment),
        ("benchmark", &r.spec.benchmark),
        ("method", &r.spec.method),
        ("status", r.status.as_str()),
        ("message", &r.message),
        ("mpmlab_version", env!("CARGO_PKG_VERSION")),
    ] {
        attr_str(file, name, value)?;
    }
    // A dataset, since an attribute holds at most 64 KiB and a configuration with long lists
    // is longer.
    string_dataset(file, CONFIG_YAML, &r.spec.config_yaml)?;
    for (name, value) in [("dim", r.dim), ("cells", r.cells), ("ppc", r.ppc)] {
        attr_i64(file, name, value as i64)?;
    }
    for (name, value) in [
        ("h", r.h),
        ("wall_seconds", r.wall_seconds),
        ("step_seconds", r.step_seconds),
    ] {
        attr_f64(file, name, value)?;
    }
    for (name, values) in [("params", &r.spec.params), ("matrix", &r.spec.axes)] {
        let group = file.create_group(name)?;
        for (key, value) in values {
            write_param(&group, key, value)?;
        }
    }
    Ok(())
}

/// A scalar parameter as an attribute of `group`, a list as a dataset in it (of any length,
/// which an attribute is not).
fn write_param(group: &Group, key: &str, value: &ParamValue) -> hdf5::Result<()> {
    match value {
        ParamValue::Int(i) => attr_i64(group, key, *i),
        ParamValue::Float(x) => attr_f64(group, key, *x),
        ParamValue::Str(s) => attr_str(group, key, s),
        ParamValue::List(values) => group
            .new_dataset::<f64>()
            .shape(values.len())
            .create(key)?
            .write_raw(values),
    }
}
