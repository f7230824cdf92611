use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use super::{write_hdf5, RunRecord};

/// Where the run with this id lives inside an experiment's results directory.
pub fn run_path(results: &Path, run_id: &str) -> PathBuf {
    results.join("runs").join(format!("{run_id}.h5"))
}

/// Writes the record under a temporary name and renames it into place, so a file with the
/// final name is always complete and an interrupted or failed write leaves the previous
/// file (if any) untouched.
pub fn write_run(results: &Path, record: &RunRecord) -> io::Result<PathBuf> {
    let path = run_path(results, &record.spec.run_id);
    let dir = path.parent().unwrap_or(Path::new("."));
    fs::create_dir_all(dir)?;
    let tmp = dir.join(format!(
        ".{}.h5.tmp-{}",
        record.spec.run_id,
        std::process::id()
    ));
    if tmp.exists() {
        fs::remove_file(&tmp)?;
    }
    if let Err(e) = write_hdf5(&tmp, record) {
        let _ = fs::remove_file(&tmp);
        return Err(io::Error::other(format!("{}: {e}", path.display())));
    }
    fs::rename(&tmp, &path)?;
    Ok(path)
}
