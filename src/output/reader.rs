use std::collections::BTreeMap;
use std::fs;
use std::io::{self, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use hdf5::types::TypeDescriptor;
use hdf5::Group;
use ndarray::s;

use super::h5::{group, open_attr, open_dataset, read_f64, read_i64, read_str, shaped};
use super::record::Unstepped;
use super::{
    elements, probes, reconstruction, shape_functions, ParticleState, ProbeRecord, RunStatus,
    RunSummary, VelocityHistory, ERROR_FIELDS_WITH_GRID, GRID_VELOCITY, NORMS, SCHEMA_VERSION,
};
use super::{
    ELEMENT_NORMS, RECONSTRUCTION_FIELDS, RECONSTRUCTION_NORMS, SHAPE_FIELDS, SHAPE_NORMS,
};
use crate::params::{ParamValue, Params};

/// A file in a results directory's `runs/` that the report cannot use.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnreadableRun {
    /// Relative to the results directory: `runs/<name>.h5`.
    pub file: PathBuf,
    /// Why, in plain words: "not an HDF5 file", "truncated: ...", "lacks /history/x", ...
    pub reason: String,
}

/// Opens an HDF5 file, or says why it cannot be opened: not an HDF5 file, truncated, or
/// damaged otherwise (in HDF5's words).
pub fn open_hdf5(path: &Path) -> Result<hdf5::File, String> {
    hdf5::File::open(path).map_err(|e| match superblock_end(path) {
        Ok(None) => "not an HDF5 file".to_string(),
        Ok(Some((len, end))) if len < end => format!("truncated: {len} of {end} bytes"),
        _ => format!("damaged: {}", hdf5_words(&e)),
    })
}

/// Opens a run file this version of the layout describes.
pub fn open_run_file(path: &Path) -> Result<hdf5::File, String> {
    let file = open_hdf5(path)?;
    let version = read_i64(&file, "schema_version").map_err(reason)?;
    if version != SCHEMA_VERSION {
        return Err(format!(
            "written with layout version {version}, this mpmlab reads version {SCHEMA_VERSION} \
             (rerun it with --force)"
        ));
    }
    Ok(file)
}

/// The `message` a run file records, if it can be read.
pub fn read_message(path: &Path) -> Option<String> {
    let file = hdf5::File::open(path).ok()?;
    read_str(&file, "message").ok()
}

/// The HDF5 signature, which the format allows at offset 0, 512, 1024, 2048, ...
const SIGNATURE: &[u8; 8] = b"\x89HDF\r\n\x1a\n";

/// The file's length and where its superblock says it ends; `None` when it has no HDF5
/// signature. The end is 0 for a superblock version this does not know.
fn superblock_end(path: &Path) -> io::Result<Option<(u64, u64)>> {
    let mut file = fs::File::open(path)?;
    let len = file.metadata()?.len();
    let mut offset = 0;
    while offset + SIGNATURE.len() as u64 <= len {
        let mut block = Vec::new();
        file.seek(SeekFrom::Start(offset))?;
        (&mut file).take(64).read_to_end(&mut block)?;
        if block.starts_with(SIGNATURE) {
            return Ok(Some((len, end_address(&block).unwrap_or(0))));
        }
        offset = if offset == 0 { 512 } else { 2 * offset };
    }
    Ok(None)
}

/// The base address plus the end-of-file address of a superblock (format versions 0 to 3),
/// i.e. the length the file must have.
fn end_address(block: &[u8]) -> Option<u64> {
    let (size_of_offsets, base_at) = match *block.get(8)? {
        0 => (*block.get(13)?, 24),
        1 => (*block.get(13)?, 28),
        2 | 3 => (*block.get(9)?, 12),
        _ => return None,
    };
    let size = usize::from(size_of_offsets);
    if ![2, 4, 8].contains(&size) {
        return None;
    }
    let address = |at: usize| {
        let bytes = block.get(at..at + size)?;
        Some(bytes.iter().rev().fold(0u64, |a, &b| a << 8 | u64::from(b)))
    };
    // The base address, then the free-space (versions 0, 1) or superblock extension (2, 3)
    // address, then the end of file.
    address(base_at)?.checked_add(address(base_at + 2 * size)?)
}

/// The reason a read failed: the words of the checks below, or HDF5's for damage they do not
/// see.
fn reason(e: hdf5::Error) -> String {
    match e {
        hdf5::Error::Internal(words) => words,
        other => format!("damaged: {}", hdf5_words(&other)),
    }
}

/// HDF5's description of an error without the library function it names
/// (`H5Fopen(): unable to open file: ...`).
fn hdf5_words(e: &hdf5::Error) -> String {
    let text = e.to_string();
    match text.split_once("(): ") {
        Some((function, words)) if function.starts_with("H5") => words.to_string(),
        _ => text,
    }
}

/// Reads what the report needs from a run file (`open_run_file`). A reconstruction or
/// shape-function run has no time steps: its `steps` is 0 and its `dt` NaN.
pub fn read_summary(file: &hdf5::File) -> Result<RunSummary, String> {
    summary(file).map_err(reason)
}

fn summary(file: &hdf5::File) -> hdf5::Result<RunSummary> {
    let status_text = read_str(file, "status")?;
    let status =
        RunStatus::parse(&status_text).ok_or_else(|| format!("unknown status '{status_text}'"))?;
    let unstepped = if let Some(r) = reconstruction::read(file)? {
        Unstepped::Reconstruction(r)
    } else if let Some(r) = elements::read(file)? {
        Unstepped::Elements(r)
    } else if let Some(r) = shape_functions::read(file)? {
        Unstepped::ShapeFunctions(r)
    } else {
        Unstepped::None
    };
    let unstepped_norms = match &unstepped {
        Unstepped::Reconstruction(r) => Some(unstepped_norms(
            &RECONSTRUCTION_FIELDS,
            &RECONSTRUCTION_NORMS,
            &[r.l2, r.max],
        )),
        Unstepped::Elements(r) => Some(unstepped_norms(
            &RECONSTRUCTION_FIELDS,
            &ELEMENT_NORMS,
            &[r.rms, r.integral_error],
        )),
        Unstepped::ShapeFunctions(r) => {
            Some(unstepped_norms(&SHAPE_FIELDS, &SHAPE_NORMS, &r.max_errors))
        }
        Unstepped::None => None,
    };
    let (final_norms, steps, dt, velocity_history) = match unstepped_norms {
        Some(norms) => (norms, 0, f64::NAN, None),
        None => (
            simulation_norms(file)?,
            read_i64(file, "steps")? as usize,
            read_f64(file, "dt")?,
            velocity_history(file)?,
        ),
    };
    let matrix = group(file, "matrix")?;
    Ok(RunSummary {
        run_id: read_str(file, "run_id")?,
        experiment: read_str(file, "experiment")?,
        benchmark: read_str(file, "benchmark")?,
        method: read_str(file, "method")?,
        dim: read_i64(file, "dim")? as usize,
        cells: read_i64(file, "cells")? as usize,
        ppc: read_i64(file, "ppc")? as usize,
        h: read_f64(file, "h")?,
        dt,
        steps,
        status,
        message: read_str(file, "message")?,
        wall_seconds: read_f64(file, "wall_seconds")?,
        // Files written before the attribute existed have no step time, nothing else missing.
        step_seconds: if file.attr_names()?.iter().any(|n| n == "step_seconds") {
            read_f64(file, "step_seconds")?
        } else {
            f64::NAN
        },
        axes: read_params(&matrix)?,
        final_norms,
        unstepped,
        velocity_history,
        max_mass_error: conservation_attr(file, "max_mass_error"),
        max_momentum_error: conservation_attr(file, "max_momentum_error"),
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
pub fn read_probes(file: &hdf5::File) -> Result<Vec<ProbeRecord>, String> {
    probes::read(file).map_err(reason)
}

/// The last sample of a simulation run; `None` for a run without samples.
pub fn read_final_state(file: &hdf5::File) -> Result<Option<ParticleState>, String> {
    final_state(file).map_err(reason)
}

fn final_state(file: &hdf5::File) -> hdf5::Result<Option<ParticleState>> {
    let times = shaped(file, "history/time", &[None])?.read_raw::<f64>()?;
    let Some(&time) = times.last() else {
        return Ok(None);
    };
    let (samples, last) = (Some(times.len()), times.len() - 1);
    let (x0, np, dim) = particles(file)?;
    // Row `last` of a dataset whose first axis is the sample, flattened.
    let read = |name: &str, per_particle: &[Option<usize>]| -> hdf5::Result<Vec<f64>> {
        let shape: Vec<Option<usize>> = [samples, np].iter().chain(per_particle).copied().collect();
        let ds = shaped(file, name, &shape)?;
        Ok(match per_particle.len() {
            0 => ds.read_slice_1d::<f64, _>(s![last, ..])?.to_vec(),
            1 => ds
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
    Ok(Some(ParticleState {
        dim: dim.unwrap_or(0),
        time,
        x0,
        x: read("history/x", &[dim])?,
        velocity: read("history/v", &[dim])?,
        stress: read("history/stress", &[dim, dim])?,
        density: read("history/density", &[])?,
        volume: read("errors/volume", &[])?,
    }))
}

/// `/particles/X` (Np x D, flattened) with Np and D, which the shapes of the per-particle
/// datasets must repeat. D is at least 1.
fn particles(file: &hdf5::File) -> hdf5::Result<(Vec<f64>, Option<usize>, Option<usize>)> {
    let x0 = shaped(file, "particles/X", &[None, None])?;
    let (np, dim) = (x0.shape()[0], x0.shape()[1]);
    if dim == 0 {
        return Err("dataset /particles/X has no coordinates".into());
    }
    Ok((x0.read_raw::<f64>()?, Some(np), Some(dim)))
}

/// The l2 velocity error per sample and the l2 norm of the velocity at the first sample;
/// `None` for a run without samples (a failed run's datasets are empty). Reads only the first
/// row of `/history/v` and `/errors/volume`.
fn velocity_history(file: &hdf5::File) -> hdf5::Result<Option<VelocityHistory>> {
    let time = shaped(file, "errors/time", &[None])?.read_raw::<f64>()?;
    if time.is_empty() {
        return Ok(None);
    }
    let samples = Some(time.len());
    let l2_error = shaped(file, "errors/norms/l2_velocity", &[samples])?.read_raw::<f64>()?;
    let (_, np, dim) = particles(file)?;
    let v =
        shaped(file, "history/v", &[samples, np, dim])?.read_slice_2d::<f64, _>(s![0, .., ..])?;
    let volume =
        shaped(file, "errors/volume", &[samples, np])?.read_slice_1d::<f64, _>(s![0, ..])?;
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
    let norms = group(file, "errors/norms")?;
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

/// The parameter values of a group, typed as they were written: scalars as its attributes,
/// lists as its datasets.
fn read_params(group: &Group) -> hdf5::Result<Params> {
    let mut params = Params::new();
    for name in group.attr_names()? {
        let attr = open_attr(group, &name)?;
        let value = match attr.dtype()?.to_descriptor()? {
            TypeDescriptor::Integer(_) => ParamValue::Int(read_i64(group, &name)?),
            TypeDescriptor::Float(_) => ParamValue::Float(read_f64(group, &name)?),
            _ => ParamValue::Str(read_str(group, &name)?),
        };
        params.insert(name, value);
    }
    for name in group.member_names()? {
        let values = open_dataset(group, &name)?.read_raw::<f64>()?;
        params.insert(name, ParamValue::List(values));
    }
    Ok(params)
}
