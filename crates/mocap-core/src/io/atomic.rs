//! Atomic file writes: the data goes to a temporary file in the same folder,
//! is flushed to disk, then renamed over the target. A crash or a full disk
//! leaves either the old file or the new one, never half of one.
//!
//! The temporary file of `out.bvh` is `.out.bvh.PID.tmp` (PID: the writing
//! process). It is removed when the write fails or is abandoned, and, when
//! the program calls [`remove_unfinished_files`] from its signal handling, on
//! Ctrl-C or `kill`. A process killed outright (SIGKILL, power loss) cannot
//! clean up: the next write to the same path removes the temporary files of
//! processes that no longer run.

use std::collections::BTreeSet;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::{Error, Result};

/// The temporary files this process is writing now.
static UNFINISHED: Mutex<BTreeSet<PathBuf>> = Mutex::new(BTreeSet::new());

fn unfinished() -> std::sync::MutexGuard<'static, BTreeSet<PathBuf>> {
    // A panic while the set was held leaves it whole: keep using it.
    UNFINISHED.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes the temporary files of every write in progress in this process and
/// returns how many there were. For a signal handler's thread, just before the
/// process exits: the outputs being written are left as they were.
pub fn remove_unfinished_files() -> usize {
    let files = std::mem::take(&mut *unfinished());
    files
        .iter()
        .filter(|tmp| std::fs::remove_file(tmp).is_ok())
        .count()
}

/// A file being written atomically: write into it, then [`AtomicFile::commit`].
/// Dropped without a commit (an error, a panic), it removes its temporary
/// file and leaves the target as it was.
pub struct AtomicFile {
    path: PathBuf,
    tmp: PathBuf,
    out: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Starts writing `path`. Temporary files that earlier, killed processes
    /// left for the same path are removed first.
    pub fn create(path: &Path) -> Result<AtomicFile> {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let file_name = path
            .file_name()
            .ok_or_else(|| Error::Invalid(format!("{}: not a file path", path.display())))?
            .to_string_lossy()
            .into_owned();
        remove_stale_temp_files(dir, &file_name);
        let tmp = dir.join(format!(".{file_name}.{}.tmp", std::process::id()));
        unfinished().insert(tmp.clone());
        let file = File::create(&tmp).map_err(|e| {
            unfinished().remove(&tmp);
            Error::io(path, e)
        })?;
        Ok(AtomicFile {
            path: path.to_path_buf(),
            tmp,
            out: Some(BufWriter::with_capacity(1 << 20, file)),
        })
    }

    /// The file this will become.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes the data to disk and renames the temporary file over the
    /// target.
    pub fn commit(mut self) -> Result<()> {
        let out = self.out.take().expect("an AtomicFile is committed once");
        let result = (|| {
            let file = out.into_inner().map_err(|e| e.into_error())?;
            file.sync_all()?;
            std::fs::rename(&self.tmp, &self.path)
        })();
        if result.is_ok() {
            unfinished().remove(&self.tmp);
        }
        // On an error, Drop removes the temporary file.
        result.map_err(|e| Error::io(&self.path, e))
    }

    fn out(&mut self) -> &mut BufWriter<File> {
        self.out.as_mut().expect("not yet committed")
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.out().write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        self.out().write_all(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.out().flush()
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if unfinished().remove(&self.tmp) {
            drop(self.out.take());
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Removes `.NAME.PID.tmp` files in `dir` whose process no longer runs (and
/// this process's own, which it is not writing). Where process ids cannot be
/// checked (no `/proc`), nothing is removed.
fn remove_stale_temp_files(dir: &Path, name: &str) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let prefix = format!(".{name}.");
    let mine = std::process::id();
    for entry in entries.flatten() {
        let entry_name = entry.file_name();
        let Some(pid) = entry_name
            .to_str()
            .and_then(|n| n.strip_prefix(&prefix))
            .and_then(|n| n.strip_suffix(".tmp"))
            .and_then(|pid| pid.parse::<u32>().ok())
        else {
            continue;
        };
        let path = entry.path();
        let stale = if pid == mine {
            !unfinished().contains(&path)
        } else {
            !Path::new(&format!("/proc/{pid}")).exists()
        };
        if stale {
            let _ = std::fs::remove_file(&path);
        }
    }
}

/// Writes `path` atomically with what `write` puts into the buffered writer.
pub fn write_atomically<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut dyn Write) -> std::io::Result<()>,
{
    let mut file = AtomicFile::create(path)?;
    write(&mut file).map_err(|e| Error::io(path, e))?;
    file.commit()
}

/// Writes `bytes` to `path` atomically.
pub fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomically(path, |w| w.write_all(bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names_in(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.bvh");
        std::fs::write(&path, "old").unwrap();
        let e = write_atomically(&path, |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert!(e.to_string().contains("disk full"), "{e}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        assert_eq!(names_in(dir.path()), ["out.bvh"]);

        let abandoned = AtomicFile::create(&path).unwrap();
        drop(abandoned);
        assert_eq!(names_in(dir.path()), ["out.bvh"]);
    }

    #[test]
    fn temporary_files_of_dead_processes_are_swept_on_the_next_write() {
        let dir = tempfile::tempdir().unwrap();
        // A child that has exited gives the id of a process that no longer
        // runs.
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let stale = dir.path().join(format!(".out.bvh.{dead}.tmp"));
        let other_output = dir.path().join(format!(".other.bvh.{dead}.tmp"));
        let alive = dir.path().join(".out.bvh.1.tmp"); // init runs
        for p in [&stale, &other_output, &alive] {
            std::fs::write(p, "left by a killed run").unwrap();
        }
        write_bytes_atomically(&dir.path().join("out.bvh"), b"new").unwrap();
        let names = names_in(dir.path());
        assert!(
            !names.contains(&format!(".out.bvh.{dead}.tmp")),
            "{names:?}"
        );
        assert!(
            names.contains(&format!(".other.bvh.{dead}.tmp")),
            "{names:?}"
        );
        assert!(names.contains(&".out.bvh.1.tmp".to_string()), "{names:?}");
        assert!(names.contains(&"out.bvh".to_string()), "{names:?}");
    }
}
