//! One process per folder: an advisory lock (`flock`) on `<folder>/.sapnet.lock`, held
//! while a protocol writes its `--out`, a library trains, or a sweep's cell runs. The
//! file names its holder — PID, host, since when — so that a second process is refused
//! with who is there. The lock goes with the process however it ends (`kill -9`
//! included): a lock file left behind by a dead process holds no lock, and is taken over.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

use anyhow::{bail, Context, Result};

/// The lock's file in a locked folder.
pub const LOCK_FILE: &str = ".sapnet.lock";

/// A held lock; dropped, it is released.
#[derive(Debug)]
pub struct FolderLock {
    _file: File,
    pub path: PathBuf,
}

impl FolderLock {
    /// Locks `dir` (which must exist) for `what` (`the protocol`, `the library`, `cell
    /// 0003`), or says who holds it.
    pub fn acquire(dir: &Path, what: &str) -> Result<Self> {
        Self::acquire_file(&dir.join(LOCK_FILE), dir, what)
    }

    /// The lock of `dir` held in the file `path` (a cell's lock lives beside its results).
    pub fn acquire_file(path: &Path, dir: &Path, what: &str) -> Result<Self> {
        // The lock file itself is never followed through a planted link. Another user's
        // lock file (a folder shared between accounts) locks read-only, without the
        // holder's line.
        let open = |write: bool| {
            OpenOptions::new()
                .read(true)
                .write(write)
                .create(write)
                .truncate(false)
                .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
                .open(path)
        };
        let (mut file, writable) = match open(true) {
            Ok(file) => (file, true),
            Err(e) if e.kind() == std::io::ErrorKind::PermissionDenied && path.exists() => (
                open(false).with_context(|| format!("locking {}", dir.display()))?,
                false,
            ),
            Err(e) => {
                return Err(e).with_context(|| {
                    format!("locking {}: opening {}", dir.display(), path.display())
                })
            }
        };
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                let holder = holder.trim();
                bail!(
                    "{} is in use by another sapnet process ({}): {what} cannot start there \
                     until it ends (or choose another folder)",
                    dir.display(),
                    if holder.is_empty() {
                        "starting"
                    } else {
                        holder
                    }
                );
            }
            Err(std::fs::TryLockError::Error(e)) => {
                return Err(e).with_context(|| format!("locking {}", path.display()))
            }
        }
        if !writable {
            return Ok(Self {
                _file: file,
                path: path.to_path_buf(),
            });
        }
        let since = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
            .map(|h| h.trim().to_string())
            .unwrap_or_else(|_| "this host".into());
        let text = format!(
            "running as PID {} on {host} since {} ({what})\n",
            std::process::id(),
            clock(since)
        );
        file.set_len(0)
            .and_then(|()| file.rewind())
            .and_then(|()| file.write_all(text.as_bytes()))
            .with_context(|| format!("writing {}", path.display()))?;
        Ok(Self {
            _file: file,
            path: path.to_path_buf(),
        })
    }
}

/// `HH:MM:SS UTC` of a Unix time (the day is rarely in doubt for a live process).
fn clock(secs: u64) -> String {
    let day = secs % 86_400;
    format!(
        "{:02}:{:02}:{:02} UTC",
        day / 3600,
        day % 3600 / 60,
        day % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_is_refused_naming_the_first_and_released_on_drop() {
        let tmp = tempfile::tempdir().unwrap();
        let first = FolderLock::acquire(tmp.path(), "the protocol").unwrap();
        let err = FolderLock::acquire(tmp.path(), "the protocol")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(&format!("running as PID {}", std::process::id())),
            "{err}"
        );
        assert!(err.contains("in use by another sapnet process"), "{err}");
        drop(first);
        FolderLock::acquire(tmp.path(), "the protocol").unwrap();
        assert_eq!(clock(3 * 3600 + 25 * 60 + 7), "03:25:07 UTC");
    }
}
