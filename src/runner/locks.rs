//! Per-run locks, so that processes running one experiment into the same results directory
//! share its runs instead of each computing all of them. The process that holds the lock of
//! a run (an exclusive flock(2) on `runs/.<run_id>.lock`) computes it; the others skip it and
//! wait for its file at the end. The kernel releases a lock when its holder exits, however it
//! exits, so a lock is never held by a dead process and needs no check of who is alive. The
//! file names its holder (`<pid>@<host>`) for whoever looks.

use std::collections::{BTreeMap, HashMap};
use std::fs::{self, File, OpenOptions, TryLockError};
use std::io::{self, Write};
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use super::needs_run;
use crate::experiment::ResolvedRun;
use crate::output::{run_path, this_host, TempHost, TempWriter};

fn lock_path(dir: &Path, run_id: &str) -> PathBuf {
    dir.join("runs").join(format!(".{run_id}.lock"))
}

/// A run lock this process holds. Dropping it removes the lock file, then releases the lock
/// (in that order, see `claim`).
pub struct RunLock {
    path: PathBuf,
    _file: File,
}

impl Drop for RunLock {
    fn drop(&mut self) {
        // Already gone only if someone removed it by hand; the lock goes with the file.
        let _ = fs::remove_file(&self.path);
    }
}

enum Claim {
    Held(RunLock),
    /// Another process holds the lock.
    Busy,
    /// The file system does not lock (some network file systems do not): the run is
    /// computed unlocked, as by a version without locks.
    Unsupported,
}

/// Takes the lock of `run_id`: at once or not at all, or with `wait` once its holder lets go.
fn claim(dir: &Path, run_id: &str, wait: bool) -> io::Result<Claim> {
    let path = lock_path(dir, run_id);
    loop {
        let mut file = OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&path)?;
        let locked = if wait {
            file.lock().map_err(TryLockError::Error)
        } else {
            file.try_lock()
        };
        match locked {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => return Ok(Claim::Busy),
            Err(TryLockError::Error(_)) => {
                // Nobody can hold a lock here, so the file is no one's.
                let _ = fs::remove_file(&path);
                return Ok(Claim::Unsupported);
            }
        }
        // A holder removes the file before it releases the lock, so a lock taken on a file
        // that is no longer at `path` was let go by a holder that finished: take the one there
        // now instead.
        let ours = file.metadata()?;
        let at_path = fs::metadata(&path).ok();
        if at_path.is_some_and(|m| m.dev() == ours.dev() && m.ino() == ours.ino()) {
            file.set_len(0)?;
            writeln!(file, "{}@{}", std::process::id(), this_host())?;
            return Ok(Claim::Held(RunLock { path, _file: file }));
        }
    }
}

/// The locks of one pass over a matrix: taken as the pool reaches each run (`take`), each
/// released when its run is written (`release`), the rest when the pass ends.
pub struct Claims<'a> {
    dir: PathBuf,
    force: bool,
    held: Mutex<HashMap<String, RunLock>>,
    /// Runs whose lock another process holds.
    busy: Mutex<Vec<&'a ResolvedRun>>,
    /// Runs whose file another process wrote while this one ran.
    elsewhere: Mutex<usize>,
}

/// What became of the runs another process held during a pass.
pub struct Waited<'a> {
    /// Written by the other process.
    pub elsewhere: usize,
    /// Not written: their holder ended first, and this process computes them in another pass.
    pub orphans: Vec<&'a ResolvedRun>,
}

impl<'a> Claims<'a> {
    pub fn new(dir: &Path, force: bool) -> Self {
        Claims {
            dir: dir.to_path_buf(),
            force,
            held: Mutex::new(HashMap::new()),
            busy: Mutex::new(Vec::new()),
            elsewhere: Mutex::new(0),
        }
    }

    /// Whether this process computes `run`: it took the run's lock, and the run still needs
    /// computing (`needs_run`). A lock that cannot be taken at all leaves the run to this process,
    /// unlocked; writing it then reports what is wrong with the directory.
    pub fn take(&self, run: &'a ResolvedRun) -> bool {
        match claim(&self.dir, &run.spec.run_id, false) {
            Ok(Claim::Held(lock)) => {
                // Another process may have written it since this one looked.
                if !needs_run(&self.dir, &run.spec.run_id, self.force) {
                    *lock_of(&self.elsewhere) += 1;
                    return false;
                }
                lock_of(&self.held).insert(run.spec.run_id.clone(), lock);
                true
            }
            Ok(Claim::Busy) => {
                lock_of(&self.busy).push(run);
                false
            }
            Ok(Claim::Unsupported) | Err(_) => true,
        }
    }

    /// Releases the lock of a run whose file is in place.
    pub fn release(&self, run_id: &str) {
        lock_of(&self.held).remove(run_id);
    }

    /// Releases every lock this pass still holds (those of runs whose write failed), then
    /// waits for each run another process held: its file, or its lock once the holder has
    /// ended without writing it.
    pub fn wait_for_others(self, name: &str) -> io::Result<Waited<'a>> {
        drop(self.held);
        let busy = into_inner(self.busy);
        let mut waited = Waited {
            elsewhere: into_inner(self.elsewhere),
            orphans: Vec::new(),
        };
        if let Some(first) = busy.first() {
            let holder =
                fs::read_to_string(lock_path(&self.dir, &first.spec.run_id)).unwrap_or_default();
            eprintln!(
                "{name}: waiting for {} run(s) another process is computing (e.g. {}, held by {})",
                busy.len(),
                first.spec.run_id,
                holder.trim()
            );
        }
        for run in busy {
            let _lock = claim(&self.dir, &run.spec.run_id, true)?;
            if run_path(&self.dir, &run.spec.run_id).exists() {
                waited.elsewhere += 1;
            } else {
                waited.orphans.push(run);
            }
        }
        Ok(waited)
    }
}

/// A mutex's value; one that a panicking thread poisoned holds a value as good as any, since
/// every update above is a single step.
fn lock_of<T>(mutex: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    mutex
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

fn into_inner<T>(mutex: Mutex<T>) -> T {
    mutex
        .into_inner()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Removes from `runs/` what killed processes leave: temporary files whose writer has ended
/// (`TempWriter::is_gone`), and lock files nobody holds. A temporary file of a run whose name
/// does not say its host (`.<run_id>.h5.tmp-<pid>`, as earlier versions wrote them) may be a
/// live process's on another host, so it goes only once this process holds the run's lock.
pub fn remove_leftovers(dir: &Path) -> io::Result<()> {
    let runs = dir.join("runs");
    // Run id -> its temporary files of unnamed hosts (none for a lock file alone).
    let mut of_run: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    for entry in fs::read_dir(&runs)? {
        let entry = entry?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if let Some(writer) = TempWriter::of(&name).filter(TempWriter::is_gone) {
            let run_id = ["h5", "xdmf"]
                .iter()
                .find_map(|ext| writer.target.strip_suffix(&format!(".{ext}")));
            match (&writer.host, run_id) {
                (TempHost::Unnamed, Some(run_id)) => of_run
                    .entry(run_id.to_string())
                    .or_default()
                    .push(entry.path()),
                (TempHost::Unnamed, None) => {}
                _ => remove_all(&[entry.path()])?,
            }
        } else if let Some(run_id) = name.strip_prefix('.').and_then(|n| n.strip_suffix(".lock")) {
            of_run.entry(run_id.to_string()).or_default();
        }
    }
    for (run_id, temps) in of_run {
        if let Claim::Held(lock) = claim(dir, &run_id, false)? {
            remove_all(&temps)?;
            drop(lock);
        }
    }
    Ok(())
}

fn remove_all(paths: &[PathBuf]) -> io::Result<()> {
    paths
        .iter()
        .try_for_each(|path| match fs::remove_file(path) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => Err(e),
            _ => Ok(()),
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::host_tag;

    fn held(claim: Claim) -> RunLock {
        match claim {
            Claim::Held(lock) => lock,
            Claim::Busy => panic!("busy"),
            Claim::Unsupported => panic!("this file system does not lock"),
        }
    }

    #[test]
    fn a_lock_is_held_once_and_removed_with_its_holder() {
        let dir = tempfile::tempdir().unwrap();
        fs::create_dir(dir.path().join("runs")).unwrap();
        let lock = held(claim(dir.path(), "a", false).unwrap());
        let path = lock_path(dir.path(), "a");
        let holder = fs::read_to_string(&path).unwrap();
        assert_eq!(holder, format!("{}@{}\n", std::process::id(), this_host()));
        assert!(matches!(
            claim(dir.path(), "a", false).unwrap(),
            Claim::Busy
        ));
        drop(lock);
        assert!(!path.exists());
        drop(held(claim(dir.path(), "a", false).unwrap()));
    }

    #[test]
    fn leftovers_of_dead_writers_go_and_held_runs_keep_theirs() {
        let dir = tempfile::tempdir().unwrap();
        let runs = dir.path().join("runs");
        fs::create_dir(&runs).unwrap();
        // No process has an id above the kernel's largest pid_max (2^22).
        let dead = 1 << 23;
        let (me, here) = (std::process::id(), host_tag());
        let gone = [
            format!(".a.h5.tmp-{dead}"),
            format!(".a.xdmf.tmp-{dead}"),
            format!(".b.h5.tmp-{dead}@{here}"),
            format!("..experiment-source.tmp-{dead}@{here}"),
            ".d.lock".to_string(),
        ];
        let kept = [
            // The run's lock is held: its unnamed temporary files may be a live writer's.
            format!(".b.h5.tmp-{dead}"),
            ".b.lock".to_string(),
            format!(".c.h5.tmp-{me}@{here}"),
            format!(".c.h5.tmp-{dead}@0badc0de"),
            "e.h5".to_string(),
        ];
        for name in gone.iter().chain(&kept).filter(|n| *n != ".b.lock") {
            fs::write(runs.join(name), "x").unwrap();
        }
        let b = held(claim(dir.path(), "b", false).unwrap());
        remove_leftovers(dir.path()).unwrap();
        for name in &gone {
            assert!(!runs.join(name).exists(), "{name}");
        }
        for name in &kept {
            assert!(runs.join(name).exists(), "{name}");
        }
        drop(b);
    }
}
