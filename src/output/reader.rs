use std::collections::BTreeMap;
use std::path::Path;

use hdf5::types::{TypeDescriptor, VarLenUnicode};
use hdf5::Location;

use super::{RunStatus, RunSummary, ERROR_FIELDS, NORMS};
use crate::params::{ParamValue, Params};

/// Reads what the report needs from one run file.
pub fn read_summary(path: &Path) -> Result<RunSummary, String> {
    let context = |e: hdf5::Error| format!("{}: {e}", path.display());
    let file = hdf5::File::open(path).map_err(context)?;
    let status_text = read_str(&file, "status").map_err(context)?;
    let status = RunStatus::parse(&status_text)
        .ok_or_else(|| format!("{}: unknown status '{status_text}'", path.display()))?;
    let norms = file.group("errors/norms").map_err(context)?;
    let mut final_norms = BTreeMap::new();
    for field in ERROR_FIELDS {
        for norm in NORMS {
            let value = read_f64(&norms, &format!("{norm}_{field}")).map_err(context)?;
            final_norms.insert((field.to_string(), norm.to_string()), value);
        }
    }
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
        dt: read_f64(&file, "dt").map_err(context)?,
        steps: read_i64(&file, "steps").map_err(context)? as usize,
        status,
        message: read_str(&file, "message").map_err(context)?,
        wall_seconds: read_f64(&file, "wall_seconds").map_err(context)?,
        axes: read_params(&matrix).map_err(context)?,
        final_norms,
    })
}

/// Attributes of a group as parameter values, typed as they were written.
fn read_params(loc: &Location) -> hdf5::Result<Params> {
    let mut params = Params::new();
    for name in loc.attr_names()? {
        let attr = loc.attr(&name)?;
        let value = match attr.dtype()?.to_descriptor()? {
            TypeDescriptor::Integer(_) => ParamValue::Int(attr.read_scalar::<i64>()?),
            TypeDescriptor::Float(_) => ParamValue::Float(attr.read_scalar::<f64>()?),
            _ => ParamValue::Str(attr.read_scalar::<VarLenUnicode>()?.to_string()),
        };
        params.insert(name, value);
    }
    Ok(params)
}

fn read_str(loc: &Location, name: &str) -> hdf5::Result<String> {
    Ok(loc.attr(name)?.read_scalar::<VarLenUnicode>()?.to_string())
}

fn read_f64(loc: &Location, name: &str) -> hdf5::Result<f64> {
    loc.attr(name)?.read_scalar::<f64>()
}

fn read_i64(loc: &Location, name: &str) -> hdf5::Result<i64> {
    loc.attr(name)?.read_scalar::<i64>()
}
