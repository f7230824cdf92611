use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use super::{write_hdf5, write_record, write_xdmf, xdmf_path, HistoryLayout, RunRecord};

/// Where the run with this id lives inside an experiment's results directory.
pub fn run_path(results: &Path, run_id: &str) -> PathBuf {
    results.join("runs").join(format!("{run_id}.h5"))
}

/// Writes a record kept in memory under a temporary name and renames it into place, then
/// likewise the XDMF description of its particle history, if it has one.
pub fn write_run(results: &Path, record: &RunRecord) -> io::Result<PathBuf> {
    let path = run_path(results, &record.spec.run_id);
    write_atomically(&path, |tmp| write_hdf5(tmp, record).map_err(naming(&path)))?;
    describe(&path, record)?;
    Ok(path)
}

/// Computes the run `run_id` into its file: `compute` is given the new file, under its
/// temporary name, to stream the history into, and returns the record, whose rest is written
/// before the file is renamed into place (and its XDMF description written). An error leaves
/// no file of the run.
pub fn compute_run(
    results: &Path,
    run_id: &str,
    compute: impl FnOnce(&hdf5::File) -> RunRecord,
) -> io::Result<RunRecord> {
    let path = run_path(results, run_id);
    let mut computed = None;
    write_atomically(&path, |tmp| {
        let file = hdf5::File::create_excl(tmp).map_err(naming(&path))?;
        let record = computed.insert(compute(&file));
        let written = match record.stream.take() {
            Some(Err(e)) => Err(hdf5::Error::from(e)),
            stream => write_record(&file, record, stream.and_then(Result::ok)),
        };
        written.and_then(|()| file.close()).map_err(naming(&path))
    })?;
    let record = computed.ok_or_else(|| io::Error::other("the run was not computed"))?;
    describe(&path, &record)?;
    Ok(record)
}

/// Writes the XDMF description of a run's particle history, if it has one.
fn describe(path: &Path, record: &RunRecord) -> io::Result<()> {
    match HistoryLayout::of(record) {
        Some(layout) => write_xdmf(path, &layout),
        None => Ok(()),
    }
}

fn naming(path: &Path) -> impl Fn(hdf5::Error) -> io::Error + '_ {
    move |e| io::Error::other(format!("{}: {e}", path.display()))
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
    let tmp = temp_path(path);
    if tmp.exists() {
        fs::remove_file(&tmp)?;
    }
    if let Err(e) = write(&tmp) {
        let _ = fs::remove_file(&tmp);
        return Err(e);
    }
    fs::rename(&tmp, path)
}

/// Writes every file of a set under its temporary name, each synced to disk, and only then
/// renames them into place in the given order. A failure before the renames (a full disk, a
/// target that is a directory) leaves every previous file as it was and removes the
/// temporary files; the renames themselves are one per file, so only a failure between two
/// of them leaves the set part new, part old.
pub fn write_all_atomically(files: &[(PathBuf, Vec<u8>)]) -> io::Result<()> {
    let mut staged = Vec::with_capacity(files.len());
    let naming = |path: &Path| {
        let path = path.display().to_string();
        move |e: io::Error| io::Error::new(e.kind(), format!("{path}: {e}"))
    };
    let written = files.iter().try_for_each(|(path, contents)| {
        // rename(2) cannot replace a directory, and would fail half way through the set.
        if path.is_dir() {
            return Err(io::Error::other(format!(
                "{} is a directory",
                path.display()
            )));
        }
        let tmp = temp_path(path);
        staged.push(tmp.clone());
        write_synced(&tmp, contents).map_err(naming(path))
    });
    let renamed = written.and_then(|()| {
        files
            .iter()
            .zip(&staged)
            .try_for_each(|((path, _), tmp)| fs::rename(tmp, path).map_err(naming(path)))
    });
    if renamed.is_err() {
        for tmp in &staged {
            let _ = fs::remove_file(tmp);
        }
    }
    renamed
}

/// A new file with `contents`, on disk before it is renamed: a full disk or a quota shows as
/// an error here rather than as a short file after the rename.
fn write_synced(path: &Path, contents: &[u8]) -> io::Result<()> {
    let mut file = fs::File::create(path)?;
    file.write_all(contents)?;
    file.sync_all()
}

/// The hidden name a file is written under before it is renamed into place:
/// `.<name>.tmp-<pid>@<host tag>` beside it (`host_tag`), unique to this process on this host
/// so that processes on several hosts can write into one directory.
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(Default::default, |n| n.to_string_lossy());
    let dir = path.parent().unwrap_or(Path::new("."));
    dir.join(format!(".{name}.tmp-{}@{}", std::process::id(), host_tag()))
}

/// This machine's host name.
pub fn this_host() -> String {
    fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::env::var("HOSTNAME"))
        .unwrap_or_default()
        .trim()
        .to_string()
}

/// Eight hex digits for this host in temporary names (the FNV-1a hash of its name): a host
/// name may be as long as a file name leaves room for.
pub fn host_tag() -> String {
    let hash = this_host().bytes().fold(0x811c_9dc5_u32, |h, b| {
        (h ^ u32::from(b)).wrapping_mul(0x0100_0193)
    });
    format!("{hash:08x}")
}

/// The process that wrote a temporary file, read from its name: `.<name>.tmp-<pid>@<tag>`
/// (`temp_path`), or as earlier versions named them, `.<name>.tmp-<pid>` and, for the
/// experiment copy, `.<name>.tmp-<host>-<pid>-<nanos>`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TempWriter {
    /// The file the temporary one was to become, `<name>`.
    pub target: String,
    pub pid: u32,
    pub host: TempHost,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TempHost {
    /// `host_tag` of the writer's host.
    Tag(String),
    Name(String),
    /// The name does not say (`.<name>.tmp-<pid>`).
    Unnamed,
}

impl TempWriter {
    pub fn of(file_name: &str) -> Option<TempWriter> {
        let hidden = file_name.strip_prefix('.')?;
        let (target, writer) = hidden.rsplit_once(".tmp-")?;
        let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
        let (pid, host) = if let Some((pid, tag)) = writer.split_once('@') {
            (pid, TempHost::Tag(tag.to_string()))
        } else {
            match writer.rsplitn(3, '-').collect::<Vec<_>>()[..] {
                [pid] => (pid, TempHost::Unnamed),
                [nanos, pid, host] if digits(nanos) => (pid, TempHost::Name(host.to_string())),
                _ => return None,
            }
        };
        if !digits(pid) {
            return None;
        }
        Some(TempWriter {
            target: target.to_string(),
            pid: pid.parse().ok()?,
            host,
        })
    }

    /// Whether the writer has ended: it ran on this host (a name that does not say is taken
    /// for this host) and no process has its id. A file written on another host is never taken
    /// for dead, since its process cannot be seen.
    pub fn is_gone(&self) -> bool {
        let here = match &self.host {
            TempHost::Tag(tag) => *tag == host_tag(),
            TempHost::Name(name) => *name == this_host(),
            TempHost::Unnamed => true,
        };
        here && !Path::new("/proc").join(self.pid.to_string()).exists()
    }
}

/// Removes the temporary files in `dir` whose writer has ended (`TempWriter::is_gone`): what
/// a process killed while writing leaves. Returns the paths removed.
pub fn remove_dead_temps(dir: &Path) -> io::Result<Vec<PathBuf>> {
    let mut removed = Vec::new();
    let entries = match fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(removed),
        Err(e) => return Err(e),
    };
    for entry in entries {
        let entry = entry?;
        let name = entry.file_name();
        let dead = TempWriter::of(&name.to_string_lossy()).is_some_and(|w| w.is_gone());
        if dead && entry.file_type()?.is_file() {
            fs::remove_file(entry.path())?;
            removed.push(entry.path());
        }
    }
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporary_names_say_who_wrote_them() {
        let own = temp_path(Path::new("runs/a-cells8-0123.h5"));
        let name = own.file_name().unwrap().to_string_lossy();
        let writer = TempWriter::of(&name).unwrap();
        assert_eq!(writer.target, "a-cells8-0123.h5");
        assert_eq!(writer.pid, std::process::id());
        assert_eq!(writer.host, TempHost::Tag(host_tag()));
        assert!(!writer.is_gone());

        // No process has an id above the kernel's largest pid_max (2^22).
        let dead = 1 << 23;
        let elsewhere = TempWriter::of(&format!(".a.h5.tmp-{dead}@0badc0de")).unwrap();
        assert_eq!(elsewhere.is_gone(), host_tag() == "0badc0de");
        let here = TempWriter::of(&format!(".a.h5.tmp-{dead}@{}", host_tag())).unwrap();
        assert!(here.is_gone());
        let unnamed = TempWriter::of(&format!(".a.xdmf.tmp-{dead}")).unwrap();
        assert_eq!(
            (unnamed.target.as_str(), &unnamed.host),
            ("a.xdmf", &TempHost::Unnamed)
        );
        assert!(unnamed.is_gone());

        let copy = TempWriter::of(".experiment.yaml.tmp-node-07.cluster-4242-1712345678").unwrap();
        assert_eq!(copy.target, "experiment.yaml");
        assert_eq!(copy.pid, 4242);
        assert_eq!(copy.host, TempHost::Name("node-07.cluster".into()));

        for other in [
            "a.h5",
            ".a.h5",
            ".a.h5.tmp-",
            ".a.h5.tmp-x1",
            "a.h5.tmp-12",
            ".a.tmp-@x",
        ] {
            assert_eq!(TempWriter::of(other), None, "{other}");
        }
    }

    #[test]
    fn a_set_of_files_is_written_whole_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.csv"), dir.path().join("b.csv"));
        fs::write(&a, "old a").unwrap();
        fs::write(&b, "old b").unwrap();
        // A directory where the second file's temporary name goes: the set fails before any
        // rename.
        fs::create_dir(temp_path(&b)).unwrap();
        let set = [
            (a.clone(), b"new a".to_vec()),
            (b.clone(), b"new b".to_vec()),
        ];
        assert!(write_all_atomically(&set).is_err());
        assert_eq!(fs::read_to_string(&a).unwrap(), "old a");
        assert_eq!(fs::read_to_string(&b).unwrap(), "old b");
        assert!(!temp_path(&a).exists());

        fs::remove_dir(temp_path(&b)).unwrap();
        write_all_atomically(&set).unwrap();
        assert_eq!(fs::read_to_string(&a).unwrap(), "new a");
        assert_eq!(fs::read_to_string(&b).unwrap(), "new b");
        let left: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(left.len(), 2);
    }
}
