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
                bail!(
                    "{} is in use by another sapnet process ({}): {what} cannot start there \
                     until it ends (or choose another folder)",
                    dir.display(),
                    in_use(&file)
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

/// The process holding a folder's lock, as seen from outside without taking the lock.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Holder {
    /// The holder's PID, as the kernel reports it.
    pub pid: u32,
    /// The line the holder wrote in the lock file (`running as PID 1234 on host since
    /// 10:02:07 UTC (the protocol)`), empty if it wrote none yet.
    pub says: String,
}

impl Holder {
    /// `HH:MM` of when the holder took the lock, as its line says it (`10:02`).
    pub fn since(&self) -> Option<&str> {
        let (_, after) = self.says.split_once(" since ")?;
        after
            .get(..5)
            .filter(|hm| hm.as_bytes().get(2) == Some(&b':'))
    }

    /// `PID 1234 since 10:02 UTC`, or just the PID while its line is not written yet.
    pub fn describe(&self) -> String {
        match self.since() {
            Some(since) => format!("PID {} since {since} UTC", self.pid),
            None => format!("PID {}", self.pid),
        }
    }
}

/// Who holds `dir`'s lock now, if anyone, found without taking it — not even for an
/// instant, since a protocol starting in that instant would be refused. Linux lists every
/// held `flock` in `/proc/locks` by device and inode; the lock file's are compared with
/// those. A folder without a lock file, or whose lock file no process holds (its holder
/// died), is not held.
pub fn holder(dir: &Path) -> Result<Option<Holder>> {
    use std::os::unix::fs::MetadataExt;
    let path = dir.join(LOCK_FILE);
    // Opened as the lock is, never through a planted link, and never created.
    let file = match OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(&path)
    {
        Ok(file) => file,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e).with_context(|| format!("reading {}", path.display())),
    };
    let metadata = file
        .metadata()
        .with_context(|| format!("reading {}", path.display()))?;
    if !metadata.is_file() {
        bail!(
            "{}: not a regular file, where the folder's lock belongs",
            path.display()
        );
    }
    let locks = std::fs::read_to_string("/proc/locks")
        .context("reading /proc/locks (which process writes a folder is read there, on Linux)")?;
    let (major, minor) = (libc::major(metadata.dev()), libc::minor(metadata.dev()));
    let Some(pid) = flock_holder(&locks, major, minor, metadata.ino()) else {
        return Ok(None);
    };
    let mut says = String::new();
    // The line is a few dozen bytes; a lock file grown past this was not written by sapnet.
    let _ = (&file).take(1024).read_to_string(&mut says);
    Ok(Some(Holder {
        pid,
        says: says.trim().to_string(),
    }))
}

/// The most of a lock file read: sapnet's line is a few dozen bytes; a lock file grown
/// past this (a planted one of gigabytes) was not written by sapnet.
const LOCK_TEXT_BYTES: u64 = 1024;

/// Who holds the lock on `file`: the PID the kernel names (`/proc/locks`), with the rest
/// of the line the holder wrote (`on host since 10:02:07 UTC (the protocol)`) when that
/// line names the same PID; the file's text alone is not taken as the holder.
fn in_use(file: &File) -> String {
    use std::os::unix::fs::MetadataExt;
    let mut bytes = Vec::new();
    let _ = file.take(LOCK_TEXT_BYTES).read_to_end(&mut bytes);
    let text = String::from_utf8_lossy(&bytes);
    let line = text.lines().next().unwrap_or("").trim();
    let real = file.metadata().ok().and_then(|m| {
        let locks = std::fs::read_to_string("/proc/locks").ok()?;
        flock_holder(&locks, libc::major(m.dev()), libc::minor(m.dev()), m.ino())
    });
    let claimed = line.strip_prefix("running as PID ").and_then(|rest| {
        let digits = rest
            .find(|c: char| !c.is_ascii_digit())
            .unwrap_or(rest.len());
        Some((rest[..digits].parse::<u32>().ok()?, &rest[digits..]))
    });
    let shown = |text: &str| crate::shown_text::cut(text, 200);
    match (real, claimed) {
        (Some(pid), Some((said, rest))) if said == pid => {
            format!("running as PID {pid}{}", shown(rest))
        }
        (Some(pid), _) if line.is_empty() => format!("running as PID {pid}, starting"),
        (Some(pid), _) => format!(
            "running as PID {pid}; its lock file says \"{}\"",
            shown(line)
        ),
        (None, _) if line.is_empty() => "starting".to_string(),
        (None, _) => format!("its lock file says \"{}\"", shown(line)),
    }
}

/// The PID holding a `flock` on the file `major:minor:inode` among `/proc/locks`' lines
/// (`1: FLOCK  ADVISORY  WRITE 11557 fe:00:10010626 0 EOF`: the device in hex, the inode
/// in decimal). A line `->` marks a waiter, not a holder.
fn flock_holder(locks: &str, major: u32, minor: u32, inode: u64) -> Option<u32> {
    let file = format!("{major:02x}:{minor:02x}:{inode}");
    locks.lines().find_map(|line| {
        let fields: Vec<&str> = line.split_whitespace().collect();
        match fields.as_slice() {
            [_, "FLOCK", _, _, pid, at, ..] if *at == file => pid.parse().ok(),
            _ => None,
        }
    })
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

    #[test]
    fn the_holder_is_found_without_taking_the_lock_and_gone_when_released() {
        let tmp = tempfile::tempdir().unwrap();
        assert_eq!(holder(tmp.path()).unwrap(), None, "no lock file");
        let lock = FolderLock::acquire(tmp.path(), "the protocol").unwrap();
        let found = holder(tmp.path()).unwrap().expect("held");
        assert_eq!(found.pid, std::process::id());
        assert!(found.says.contains("(the protocol)"), "{}", found.says);
        assert_eq!(found.since().map(str::len), Some(5));
        // Looking took nothing: the holder keeps it, a second lock is still refused.
        assert!(FolderLock::acquire(tmp.path(), "the protocol").is_err());
        drop(lock);
        assert_eq!(
            holder(tmp.path()).unwrap(),
            None,
            "a file left by a released lock"
        );
    }

    #[test]
    fn proc_locks_lines_are_read_by_device_and_inode() {
        let locks = "1: FLOCK  ADVISORY  WRITE 11557 fe:00:10010626 0 EOF\n\
                     2: POSIX  ADVISORY  WRITE 42 fe:00:77 0 EOF\n\
                     2: -> FLOCK  ADVISORY  WRITE 99 fe:00:10010626 0 EOF\n";
        assert_eq!(flock_holder(locks, 0xfe, 0, 10010626), Some(11557));
        assert_eq!(
            flock_holder(locks, 0xfe, 0, 77),
            None,
            "a POSIX lock is not ours"
        );
        assert_eq!(flock_holder(locks, 0xfe, 1, 10010626), None);
        let holder = Holder {
            pid: 1234,
            says: "running as PID 1234 on h since 10:02:07 UTC (the protocol)".into(),
        };
        assert_eq!(holder.describe(), "PID 1234 since 10:02 UTC");
    }
}
