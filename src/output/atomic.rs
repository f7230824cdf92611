use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use super::{write_hdf5, RunRecord};

/// Where the run with this id lives inside an experiment's results directory.
pub fn run_path(results: &Path, run_id: &str) -> PathBuf {
    results.join("runs").join(format!("{run_id}.h5"))
}

/// Writes the record under a temporary name and renames it into place.
pub fn write_run(results: &Path, record: &RunRecord) -> io::Result<PathBuf> {
    let path = run_path(results, &record.spec.run_id);
    write_atomically(&path, |tmp| {
        write_hdf5(tmp, record).map_err(|e| io::Error::other(format!("{}: {e}", path.display())))
    })?;
    Ok(path)
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
