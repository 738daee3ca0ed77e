//! Files inside folders a user may have received from someone else — results, sweeps,
//! policy libraries — read and written so that the folder cannot turn sapnet against its
//! user:
//!
//! - only **regular files** are read, opened without blocking (a FIFO would block
//!   `open()` forever) and without following a symbolic link planted in the folder; a
//!   file over its size bound is refused before it is read;
//! - files are **created**, never opened over what is there: a stale entry (a file, or a
//!   planted link) is removed first — removing a link removes the link, not its target —
//!   and the new file is made with `O_EXCL | O_NOFOLLOW`;
//! - a file that must never be seen half-written is written to a hidden sibling and
//!   **renamed** over its name ([`write_atomically`]);
//! - a folder written into is a real directory, not a link to somewhere else
//!   ([`real_dir`]).
//!
//! - a **name** that becomes a file name or a column of a CSV file (a policy, a library, a
//!   method's own label) is portable: letters, digits, `.`, `-` and `_`, not starting with
//!   a dot ([`is_portable_name`]).
//!
//! Paths the user names on the command line (`--config FILE`) may be links: the user
//! chose them. They are still read only if they are regular files.

use std::fs::{File, OpenOptions};
use std::io::{self, Read, Write};
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

/// Whether the last component of a path may be a symbolic link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Links {
    /// A path the user named: follow it.
    Follow,
    /// A path inside a folder: a link there was planted, and is refused.
    Refuse,
}

/// The longest portable name: a file name's limit on every common file system.
pub const MAX_NAME_BYTES: usize = 255;

/// Whether `name` may name a file in a shared folder and a column of a CSV file: not empty,
/// at most [`MAX_NAME_BYTES`], only ASCII letters, digits, `.`, `-` and `_`, not starting
/// with a dot (hidden files are temporaries). So no name can leave its folder, shift a
/// CSV column (`,` `"` a newline) or differ between systems.
pub fn is_portable_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= MAX_NAME_BYTES
        && !name.starts_with('.')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_'))
}

/// What [`is_portable_name`] expects, for messages.
pub const PORTABLE_NAME: &str =
    "letters, digits, `.`, `-` and `_`, not starting with `.`, at most 255 of them";

/// Opens `path` for reading if it is a regular file of at most `limit` bytes.
pub fn open(path: &Path, links: Links, limit: u64) -> io::Result<File> {
    let mut flags = libc::O_NONBLOCK;
    if links == Links::Refuse {
        flags |= libc::O_NOFOLLOW;
    }
    let file = OpenOptions::new()
        .read(true)
        .custom_flags(flags)
        .open(path)
        .map_err(|e| {
            if e.raw_os_error() == Some(libc::ELOOP) {
                refused("a symbolic link: a file inside a results folder, sweep or library is read only as a regular file, never through a link")
            } else {
                e
            }
        })?;
    let metadata = file.metadata()?;
    let kind = metadata.file_type();
    if !kind.is_file() {
        let what = if kind.is_fifo() {
            "a FIFO"
        } else if kind.is_dir() {
            "a directory"
        } else if kind.is_char_device() || kind.is_block_device() {
            "a device"
        } else if kind.is_socket() {
            "a socket"
        } else {
            "not a file"
        };
        return Err(refused(&format!("{what}, not a regular file")));
    }
    if metadata.len() > limit {
        return Err(refused(&format!(
            "{} bytes, more than the {limit} this file may hold",
            metadata.len()
        )));
    }
    Ok(file)
}

/// The bytes of `path` (see [`open`]); a file that grows past `limit` while it is read is
/// refused too.
pub fn read(path: &Path, links: Links, limit: u64) -> io::Result<Vec<u8>> {
    let file = open(path, links, limit)?;
    let mut bytes = Vec::new();
    file.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(refused(&format!(
            "more than the {limit} bytes this file may hold"
        )));
    }
    Ok(bytes)
}

/// The UTF-8 text of `path` (see [`read`]).
pub fn read_text(path: &Path, links: Links, limit: u64) -> io::Result<String> {
    String::from_utf8(read(path, links, limit)?).map_err(|_| refused("not UTF-8 text"))
}

/// The largest CSV file of a results folder read back: a protocol's episodes run to
/// hundreds of megabytes; this bounds what a doctored folder can make sapnet read.
pub const MAX_CSV_BYTES: u64 = 16 << 30;

/// The most a compressed CSV file ([`open_csv`]) may decompress to: it is held in memory.
/// The docs' largest `episodes.csv` is 23 MB.
pub const MAX_DECOMPRESSED_CSV_BYTES: u64 = 1 << 30;

/// A CSV file inside a folder (see [`open`]), or, if it is absent, its xz-compressed twin
/// `<name>.xz` decompressed in memory: `docs/`'s folders ship their `episodes.csv` so. The
/// twin is read as the file is (a regular file, never through a link) and may decompress to
/// at most [`MAX_DECOMPRESSED_CSV_BYTES`].
pub fn open_csv(path: &Path) -> io::Result<Box<dyn Read>> {
    match open(path, Links::Refuse, MAX_CSV_BYTES) {
        Ok(file) => Ok(Box::new(file)),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            let compressed = xz_twin(path);
            match open(&compressed, Links::Refuse, MAX_CSV_BYTES) {
                Ok(file) => decompress_xz(file, MAX_DECOMPRESSED_CSV_BYTES)
                    .map(|bytes| Box::new(io::Cursor::new(bytes)) as Box<dyn Read>)
                    .map_err(|why| {
                        io::Error::new(why.kind(), format!("{}: {why}", compressed.display()))
                    }),
                // Neither: the error names the file asked for.
                Err(twin) if twin.kind() == io::ErrorKind::NotFound => Err(e),
                Err(twin) => Err(io::Error::new(
                    twin.kind(),
                    format!("{}: {twin}", compressed.display()),
                )),
            }
        }
        Err(e) => Err(e),
    }
}

/// Whether `path` or its compressed twin ([`open_csv`]) is a regular file.
pub fn csv_exists(path: &Path) -> bool {
    [path.to_path_buf(), xz_twin(path)]
        .iter()
        .any(|p| std::fs::symlink_metadata(p).is_ok_and(|m| m.is_file()))
}

fn xz_twin(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".xz");
    path.with_file_name(name)
}

/// The bytes an xz stream decompresses to, refused past `limit`: a few kilobytes of xz can
/// stand for gigabytes.
fn decompress_xz(file: File, limit: u64) -> io::Result<Vec<u8>> {
    struct Bounded {
        bytes: Vec<u8>,
        limit: u64,
    }
    impl Write for Bounded {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            if (self.bytes.len() + buf.len()) as u64 > self.limit {
                return Err(refused(&format!(
                    "decompresses to more than the {} bytes sapnet reads into memory: \
                     decompress it yourself (xz -dk)",
                    self.limit
                )));
            }
            self.bytes.extend_from_slice(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }
    let mut out = Bounded {
        bytes: Vec::new(),
        limit,
    };
    lzma_rs::xz_decompress(&mut io::BufReader::new(file), &mut out).map_err(|e| match e {
        lzma_rs::error::Error::IoError(e) => e,
        other => refused(&format!(
            "not an xz file this reader can decompress: {other}"
        )),
    })?;
    Ok(out.bytes)
}

/// A CSV reader over `path`, a file inside a folder, or its compressed twin (see
/// [`open_csv`]).
pub fn csv_reader(path: &Path) -> io::Result<csv::Reader<Box<dyn Read>>> {
    Ok(csv::Reader::from_reader(open_csv(path)?))
}

/// A new file at `path`, whatever was there: a stale file or a planted link is removed
/// (the link, not what it points to) and the file is created with `O_EXCL | O_NOFOLLOW`.
/// A directory in the way is an error.
pub fn create(path: &Path) -> io::Result<File> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => return Err(refused("a directory is in the way")),
        Ok(_) => std::fs::remove_file(path)?,
        Err(e) if e.kind() == io::ErrorKind::NotFound => {}
        Err(e) => return Err(e),
    }
    OpenOptions::new()
        .write(true)
        .create_new(true)
        .custom_flags(libc::O_NOFOLLOW)
        .open(path)
}

/// Writes `path` through a hidden sibling ([`create`]d, synced) renamed over it: a reader
/// sees the old file or the new one, never a part; a kill leaves at most the sibling,
/// which the next write replaces. `write` fills the file.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut io::BufWriter<File>) -> io::Result<()>,
) -> io::Result<()> {
    let tmp = sibling(path, "tmp");
    let result = (|| {
        let mut out = io::BufWriter::new(create(&tmp)?);
        write(&mut out)?;
        let file = out.into_inner().map_err(io::IntoInnerError::into_error)?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes `path`, a file the user named (`teach --save FILE`), as [`write_atomically`]
/// does, without destroying what is there: renaming over a FIFO, a device, a socket or a
/// directory would replace it, so they are refused; an existing file keeps its
/// permissions (a 0600 file stays 0600); a link the user named is written through, the
/// link kept. A new file gets the usual permissions.
pub fn write_user_file(
    path: &Path,
    write: impl FnOnce(&mut io::BufWriter<File>) -> io::Result<()>,
) -> io::Result<()> {
    let target = match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => std::fs::canonicalize(path).map_err(|e| {
            refused(&format!(
                "a symbolic link to nothing ({e}): name the file itself"
            ))
        })?,
        _ => path.to_path_buf(),
    };
    let permissions = match std::fs::metadata(&target) {
        Ok(m) if m.is_file() => Some(m.permissions()),
        Ok(m) => {
            return Err(refused(&format!(
                "{}, not a regular file: sapnet writes only a regular file (replaced \
                 whole) or a new one",
                kind_name(m.file_type())
            )))
        }
        Err(e) if e.kind() == io::ErrorKind::NotFound => None,
        Err(e) => return Err(e),
    };
    write_atomically(&target, |out| {
        if let Some(permissions) = permissions {
            out.get_ref().set_permissions(permissions)?;
        }
        write(out)
    })
}

/// What a file that is not a regular file is, for refusals.
fn kind_name(kind: std::fs::FileType) -> &'static str {
    if kind.is_fifo() {
        "a FIFO"
    } else if kind.is_dir() {
        "a directory"
    } else if kind.is_char_device() || kind.is_block_device() {
        "a device"
    } else if kind.is_socket() {
        "a socket"
    } else {
        "not a file"
    }
}

/// `write_atomically` of `bytes`.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomically(path, |out| out.write_all(bytes))
}

/// `.name.<suffix>` beside `path`, keeping its extension last (`.tests.tmp.png` for
/// `tests.png`: the plot backends choose their format by it).
pub fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let hidden = match name.rsplit_once('.') {
        Some((stem, ext)) => format!(".{stem}.{suffix}.{ext}"),
        None => format!(".{name}.{suffix}"),
    };
    path.with_file_name(hidden)
}

/// `path` as a real directory, created if missing: a link planted where a folder belongs
/// (a library's `chosen/` pointing elsewhere) is refused, not written through.
pub fn real_dir(path: &Path) -> io::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(m) if m.file_type().is_symlink() => Err(refused(
            "a symbolic link where a directory belongs: sapnet writes only into real directories",
        )),
        Ok(_) => Err(refused("a file where a directory belongs")),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            std::fs::create_dir_all(path)?;
            real_dir(path)
        }
        Err(e) => Err(e),
    }
}

fn refused(why: &str) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, why.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::symlink;

    #[test]
    fn a_fifo_a_device_a_link_and_an_oversized_file_are_refused_at_once() {
        let tmp = tempfile::tempdir().unwrap();
        let fifo = tmp.path().join("fifo");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        // Returns at once (O_NONBLOCK), refused for what it is.
        let err = read(&fifo, Links::Follow, 100).unwrap_err();
        assert!(err.to_string().contains("a FIFO"), "{err}");
        let err = read(Path::new("/dev/zero"), Links::Follow, 100).unwrap_err();
        assert!(err.to_string().contains("a device"), "{err}");
        let target = tmp.path().join("target");
        std::fs::write(&target, "secret").unwrap();
        let link = tmp.path().join("link");
        symlink(&target, &link).unwrap();
        let err = read(&link, Links::Refuse, 100).unwrap_err();
        assert!(err.to_string().contains("symbolic link"), "{err}");
        assert_eq!(read(&link, Links::Follow, 100).unwrap(), b"secret");
        let err = read(&target, Links::Refuse, 3).unwrap_err();
        assert!(err.to_string().contains("more than the 3"), "{err}");
        let dir = read(tmp.path(), Links::Refuse, 3).unwrap_err();
        assert!(dir.to_string().contains("a directory"), "{dir}");
    }

    fn xz(bytes: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        lzma_rs::xz_compress(&mut &bytes[..], &mut out).unwrap();
        out
    }

    fn read_csv(path: &Path) -> io::Result<String> {
        let mut text = String::new();
        open_csv(path)?.read_to_string(&mut text)?;
        Ok(text)
    }

    #[test]
    fn a_csv_file_is_read_from_itself_or_its_compressed_twin() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("episodes.csv");
        assert!(!csv_exists(&path));
        let err = read_csv(&path).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::NotFound);
        std::fs::write(
            tmp.path().join("episodes.csv.xz"),
            xz(b"run,reward\n0,1.5\n"),
        )
        .unwrap();
        assert!(csv_exists(&path));
        assert_eq!(read_csv(&path).unwrap(), "run,reward\n0,1.5\n");
        // The file itself, where both are, as a protocol's own folder after `xz -dk`.
        std::fs::write(&path, "run,reward\n0,2.5\n").unwrap();
        assert_eq!(read_csv(&path).unwrap(), "run,reward\n0,2.5\n");
    }

    #[test]
    fn a_compressed_twin_is_refused_through_a_link_damaged_or_past_its_bound() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("episodes.csv");
        let twin = tmp.path().join("episodes.csv.xz");
        let elsewhere = tmp.path().join("elsewhere.xz");
        std::fs::write(&elsewhere, xz(b"secret\n")).unwrap();
        symlink(&elsewhere, &twin).unwrap();
        assert!(!csv_exists(&path));
        let err = read_csv(&path).unwrap_err().to_string();
        assert!(
            err.contains("episodes.csv.xz") && err.contains("symbolic link"),
            "{err}"
        );
        std::fs::remove_file(&twin).unwrap();
        let whole = xz(b"run,reward\n0,1.5\n");
        std::fs::write(&twin, &whole[..whole.len() - 9]).unwrap();
        let err = read_csv(&path).unwrap_err().to_string();
        assert!(err.contains("episodes.csv.xz"), "{err}");
        // A megabyte of zeros, read with a kilobyte's bound.
        let bomb = xz(&vec![0; 1 << 20]);
        let err = decompress_xz(File::open(write_tmp(&tmp, &bomb)).unwrap(), 1024).unwrap_err();
        assert!(
            err.to_string().contains("more than the 1024 bytes"),
            "{err}"
        );
    }

    fn write_tmp(tmp: &tempfile::TempDir, bytes: &[u8]) -> PathBuf {
        let path = tmp.path().join("bomb.xz");
        std::fs::write(&path, bytes).unwrap();
        path
    }

    #[test]
    fn creating_over_a_planted_link_replaces_the_link_not_its_target() {
        let tmp = tempfile::tempdir().unwrap();
        let victim = tmp.path().join("victim");
        std::fs::write(&victim, "keep").unwrap();
        let planted = tmp.path().join("summary.json.tmp");
        symlink(&victim, &planted).unwrap();
        create(&planted).unwrap().write_all(b"new").unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"keep");
        assert_eq!(std::fs::read(&planted).unwrap(), b"new");
        // The atomic write's sibling, planted as a link, is replaced the same way.
        let path = tmp.path().join("tests.png");
        symlink(&victim, sibling(&path, "tmp")).unwrap();
        write_bytes(&path, b"png").unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"keep");
        assert_eq!(std::fs::read(&path).unwrap(), b"png");
        assert_eq!(sibling(&path, "tmp"), tmp.path().join(".tests.tmp.png"));
        assert!(!sibling(&path, "tmp").exists());
    }

    #[test]
    fn a_link_where_a_directory_belongs_is_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let elsewhere = tmp.path().join("elsewhere");
        std::fs::create_dir(&elsewhere).unwrap();
        let chosen = tmp.path().join("chosen");
        symlink(&elsewhere, &chosen).unwrap();
        let err = real_dir(&chosen).unwrap_err();
        assert!(err.to_string().contains("symbolic link"), "{err}");
        real_dir(&tmp.path().join("a/b")).unwrap();
        assert!(tmp.path().join("a/b").is_dir());
    }
}
