use std::collections::BTreeMap;
use std::path::Path;

use hdf5::types::{TypeDescriptor, VarLenUnicode};
use hdf5::Location;
use ndarray::s;

use super::{
    elements, probes, reconstruction, shape_functions, ParticleState, ProbeRecord, RunStatus,
    RunSummary, VelocityHistory, ERROR_FIELDS_WITH_GRID, GRID_VELOCITY, NORMS,
};
use super::{
    ELEMENT_NORMS, RECONSTRUCTION_FIELDS, RECONSTRUCTION_NORMS, SHAPE_FIELDS, SHAPE_NORMS,
};
use crate::params::{ParamValue, Params};

/// Reads what the report needs from one run file. A reconstruction or shape-function run has
/// no time steps: its `steps` is 0 and its `dt` NaN.
pub fn read_summary(path: &Path) -> Result<RunSummary, String> {
    let context = |e: hdf5::Error| format!("{}: {e}", path.display());
    let file = hdf5::File::open(path).map_err(context)?;
    let status_text = read_str(&file, "status").map_err(context)?;
    let status = RunStatus::parse(&status_text)
        .ok_or_else(|| format!("{}: unknown status '{status_text}'", path.display()))?;
    let reconstruction = reconstruction::read(&file).map_err(context)?;
    let elements = elements::read(&file).map_err(context)?;
    let shape_functions = shape_functions::read(&file).map_err(context)?;
    let unstepped = match (&reconstruction, &elements, &shape_functions) {
        (Some(r), _, _) => Some(unstepped_norms(
            &RECONSTRUCTION_FIELDS,
            &RECONSTRUCTION_NORMS,
            &[r.l2, r.max],
        )),
        (None, Some(r), _) => Some(unstepped_norms(
            &RECONSTRUCTION_FIELDS,
            &ELEMENT_NORMS,
            &[r.rms, r.integral_error],
        )),
        (None, None, Some(r)) => Some(unstepped_norms(&SHAPE_FIELDS, &SHAPE_NORMS, &r.max_errors)),
        (None, None, None) => None,
    };
    let (final_norms, steps, dt, velocity_history) = match unstepped {
        Some(norms) => (norms, 0, f64::NAN, None),
        None => (
            simulation_norms(&file).map_err(context)?,
            read_i64(&file, "steps").map_err(context)? as usize,
            read_f64(&file, "dt").map_err(context)?,
            velocity_history(&file).map_err(context)?,
        ),
    };
    let matrix = file.group("matrix").map_err(context)?;
    Ok(RunSummary {
        run_id: read_str(&file, "run_id").map_err(context)?,
        experiment: read_str(&file, "experiment").map_err(context)?,
        benchmark: read_str(&file, "benchmark").map_err(context)?,
        method: read_str(&file, "method").map_err(context)?,
        dim: read_i64(&file, "dim").map_err(context)? as usize,
        cells: read_i64(&file, "cells").map_err(context)? as usize,
        ppc: read_i64(&file, "ppc").map_err(context)? as usize,
        h: read_f64(&file, "h").map_err(context)?,
        dt,
        steps,
        status,
        message: read_str(&file, "message").map_err(context)?,
        wall_seconds: read_f64(&file, "wall_seconds").map_err(context)?,
        axes: read_params(&matrix).map_err(context)?,
        final_norms,
        reconstruction,
        elements,
        shape_functions,
        velocity_history,
        max_mass_error: conservation_attr(&file, "max_mass_error"),
        max_momentum_error: conservation_attr(&file, "max_momentum_error"),
        profile: None,
        probes: Vec::new(),
        final_state: None,
    })
}

/// A `/conservation` attribute; NaN where the file has none (unstepped runs).
fn conservation_attr(file: &hdf5::File, name: &str) -> f64 {
    file.group("conservation")
        .and_then(|g| read_f64(&g, name))
        .unwrap_or(f64::NAN)
}

/// The `/probes` of a run file (none for a run without them).
pub fn read_probes(path: &Path) -> Result<Vec<ProbeRecord>, String> {
    let context = |e: hdf5::Error| format!("{}: {e}", path.display());
    let file = hdf5::File::open(path).map_err(context)?;
    probes::read(&file).map_err(context)
}

/// The last sample of a simulation run; `None` for a run without samples.
pub fn read_final_state(path: &Path) -> Result<Option<ParticleState>, String> {
    let context = |e: hdf5::Error| format!("{}: {e}", path.display());
    let file = hdf5::File::open(path).map_err(context)?;
    let times = file
        .dataset("history/time")
        .and_then(|t| t.read_raw::<f64>())
        .map_err(context)?;
    let Some(&time) = times.last() else {
        return Ok(None);
    };
    let last = times.len() - 1;
    // Row `last` of a dataset whose first axis is the sample, flattened.
    let read = |name: &str| -> hdf5::Result<Vec<f64>> {
        let ds = file.dataset(name)?;
        Ok(match ds.ndim() {
            2 => ds.read_slice_1d::<f64, _>(s![last, ..])?.to_vec(),
            3 => ds
                .read_slice_2d::<f64, _>(s![last, .., ..])?
                .iter()
                .copied()
                .collect(),
            _ => ds
                .read_slice::<f64, _, ndarray::Ix3>(s![last, .., .., ..])?
                .iter()
                .copied()
                .collect(),
        })
    };
    let x0 = file.dataset("particles/X").map_err(context)?;
    Ok(Some(ParticleState {
        dim: x0.shape().get(1).copied().unwrap_or(0),
        time,
        x0: x0.read_raw::<f64>().map_err(context)?,
        x: read("history/x").map_err(context)?,
        velocity: read("history/v").map_err(context)?,
        stress: read("history/stress").map_err(context)?,
        density: read("history/density").map_err(context)?,
        volume: read("errors/volume").map_err(context)?,
    }))
}

/// The l2 velocity error per sample and the l2 norm of the velocity at the first sample;
/// `None` for a run without samples (a failed run's datasets are empty). Reads only the first
/// row of `/history/v` and `/errors/volume`.
fn velocity_history(file: &hdf5::File) -> hdf5::Result<Option<VelocityHistory>> {
    let time = file.dataset("errors/time")?.read_raw::<f64>()?;
    if time.is_empty() {
        return Ok(None);
    }
    let l2_error = file
        .dataset("errors/norms/l2_velocity")?
        .read_raw::<f64>()?;
    let v = file
        .dataset("history/v")?
        .read_slice_2d::<f64, _>(s![0, .., ..])?;
    let volume = file
        .dataset("errors/volume")?
        .read_slice_1d::<f64, _>(s![0, ..])?;
    let sum: f64 = v
        .rows()
        .into_iter()
        .zip(&volume)
        .map(|(vp, w)| w * vp.iter().map(|c| c * c).sum::<f64>())
        .sum();
    Ok(Some(VelocityHistory {
        time,
        l2_error,
        initial_l2: sum.sqrt(),
    }))
}

type FinalNorms = BTreeMap<(String, String), f64>;

/// The final norms of every field; the grid velocity's only when the file has them (a file
/// written before they existed leaves them out, and the report shows them empty).
fn simulation_norms(file: &hdf5::File) -> hdf5::Result<FinalNorms> {
    let norms = file.group("errors/norms")?;
    let written = norms.attr_names()?;
    let mut final_norms = BTreeMap::new();
    for field in ERROR_FIELDS_WITH_GRID {
        for norm in NORMS {
            let name = format!("{norm}_{field}");
            if field == GRID_VELOCITY && !written.contains(&name) {
                continue;
            }
            let value = read_f64(&norms, &name)?;
            final_norms.insert((field.to_string(), norm.to_string()), value);
        }
    }
    Ok(final_norms)
}

/// The final norms of a run that does not step: `values` holds every field in every norm,
/// norms fastest.
fn unstepped_norms(fields: &[&str], norms: &[&str], values: &[f64]) -> FinalNorms {
    let pairs = fields
        .iter()
        .flat_map(|field| norms.iter().map(move |norm| (field, norm)));
    pairs
        .zip(values)
        .map(|((field, norm), &value)| ((field.to_string(), norm.to_string()), value))
        .collect()
}

/// Attributes of a group as parameter values, typed as they were written.
fn read_params(loc: &Location) -> hdf5::Result<Params> {
    let mut params = Params::new();
    for name in loc.attr_names()? {
        let attr = loc.attr(&name)?;
        let value = match attr.dtype()?.to_descriptor()? {
            TypeDescriptor::Integer(_) => ParamValue::Int(attr.read_scalar::<i64>()?),
            TypeDescriptor::Float(_) if attr.is_scalar() => {
                ParamValue::Float(attr.read_scalar::<f64>()?)
            }
            TypeDescriptor::Float(_) => ParamValue::List(attr.read_raw::<f64>()?),
            _ => ParamValue::Str(attr.read_scalar::<VarLenUnicode>()?.to_string()),
        };
        params.insert(name, value);
    }
    Ok(params)
}

pub(super) fn read_str(loc: &Location, name: &str) -> hdf5::Result<String> {
    Ok(loc.attr(name)?.read_scalar::<VarLenUnicode>()?.to_string())
}

pub(super) fn read_f64(loc: &Location, name: &str) -> hdf5::Result<f64> {
    loc.attr(name)?.read_scalar::<f64>()
}

pub(super) fn read_i64(loc: &Location, name: &str) -> hdf5::Result<i64> {
    loc.attr(name)?.read_scalar::<i64>()
}
