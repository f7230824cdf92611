use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use super::{write_hdf5, write_xdmf, xdmf_path, HistoryLayout, RunRecord};

/// Where the run with this id lives inside an experiment's results directory.
pub fn run_path(results: &Path, run_id: &str) -> PathBuf {
    results.join("runs").join(format!("{run_id}.h5"))
}

/// Writes the record under a temporary name and renames it into place, then likewise the
/// XDMF description of its particle history, if it has one.
pub fn write_run(results: &Path, record: &RunRecord) -> io::Result<PathBuf> {
    let path = run_path(results, &record.spec.run_id);
    write_atomically(&path, |tmp| {
        write_hdf5(tmp, record).map_err(|e| io::Error::other(format!("{}: {e}", path.display())))
    })?;
    if let Some(layout) = HistoryLayout::of(record) {
        write_xdmf(&path, &layout)?;
    }
    Ok(path)
}

/// Writes the XDMF description of a complete run file that has a particle history but no
/// description: one written before descriptions were, or interrupted between the two files.
pub fn describe_if_missing(run_file: &Path) -> io::Result<()> {
    if xdmf_path(run_file).exists() {
        return Ok(());
    }
    let layout = HistoryLayout::read(run_file)
        .map_err(|e| io::Error::other(format!("{}: {e}", run_file.display())))?;
    match layout {
        Some(layout) => write_xdmf(run_file, &layout),
        None => Ok(()),
    }
}

/// Runs `write` on a temporary file beside `path` and renames it to `path` when it
/// succeeds, so a file with the final name is always complete and a failed or interrupted
/// write leaves the previous file (if any) untouched.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> io::Result<()>,
) -> io::Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    fs::create_dir_all(dir)?;
    let name = path
        .file_name()
        .map_or_else(Default::default, |n| n.to_string_lossy());
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    if tmp.exists() {
        fs::remove_file(&tmp)?;
    }
    if let Err(e) = write(&tmp) {
        let _ = fs::remove_file(&tmp);
        return Err(e);
    }
    fs::rename(&tmp, path)
}
