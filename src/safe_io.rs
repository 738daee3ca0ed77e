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

/// The longest portable name: a file name's limit on every common file system (255
/// bytes), less room for the longest extension a name is given (`.safetensors`).
pub const MAX_NAME_BYTES: usize = 240;

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
    "letters, digits, `.`, `-` and `_`, not starting with `.`, at most 240 of them";

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

/// The most a compressed CSV file ([`open_csv`]) may decompress to: it is read as a
/// stream, so this bounds the time a few kilobytes of xz can cost (and the rows a reader
/// could be asked to keep), not what is held at once. The docs' largest `episodes.csv` is
/// 23 MB.
pub const MAX_DECOMPRESSED_CSV_BYTES: u64 = 1 << 30;

/// The largest dictionary a compressed CSV file may declare: `xz -9`'s. The dictionary is
/// what decompressing holds (with a 64 KiB buffer), whatever the file decompresses to.
pub const MAX_XZ_DICTIONARY_BYTES: usize = 64 << 20;

/// A CSV file inside a folder (see [`open`]), or, if it is absent, its xz-compressed twin
/// `<name>.xz` decompressed as it is read: `docs/`'s folders ship their `episodes.csv` so.
/// The twin is read as the file is (a regular file, never through a link), may declare a
/// dictionary of at most [`MAX_XZ_DICTIONARY_BYTES`] and decompress to at most
/// [`MAX_DECOMPRESSED_CSV_BYTES`]; its errors name it.
pub fn open_csv(path: &Path) -> io::Result<Box<dyn Read>> {
    match open(path, Links::Refuse, MAX_CSV_BYTES) {
        Ok(file) => Ok(Box::new(file)),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            let compressed = xz_twin(path);
            match open(&compressed, Links::Refuse, MAX_CSV_BYTES) {
                Ok(file) => Ok(Box::new(XzText::new(
                    file,
                    compressed,
                    MAX_DECOMPRESSED_CSV_BYTES,
                ))),
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

/// `<name>.xz` beside `path`.
pub fn xz_twin(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".xz");
    path.with_file_name(name)
}

/// An xz file decompressed as it is read, refused past `limit` bytes out: a few kilobytes
/// of xz can stand for gigabytes. What it holds is the dictionary the file declares
/// (at most [`MAX_XZ_DICTIONARY_BYTES`]) and one input buffer, never a block. Streams
/// written one after the other (`cat a.xz b.xz`) are read as `xz -d` reads them.
struct XzText {
    decoder: Box<xz4rust::XzDecoder<'static>>,
    file: File,
    /// Compressed bytes read and not yet decoded: `buffer[start..end]`.
    buffer: Vec<u8>,
    start: usize,
    end: usize,
    /// Past a stream's end: padding, another stream or the file's end follows.
    between: bool,
    /// Whether the file held any byte.
    any: bool,
    path: PathBuf,
    out: u64,
    limit: u64,
}

impl XzText {
    fn new(file: File, path: PathBuf, limit: u64) -> Self {
        Self {
            decoder: xz4rust::XzDecoder::in_heap_with_alloc_dict_size(
                xz4rust::DICT_SIZE_MIN,
                MAX_XZ_DICTIONARY_BYTES,
            ),
            file,
            buffer: vec![0; 64 << 10],
            start: 0,
            end: 0,
            between: false,
            any: false,
            path,
            out: 0,
            limit,
        }
    }

    /// Reads more of the file behind what is left; the bytes read, 0 at its end.
    fn fill(&mut self) -> io::Result<usize> {
        self.buffer.copy_within(self.start..self.end, 0);
        self.end -= self.start;
        self.start = 0;
        let n = loop {
            match self.file.read(&mut self.buffer[self.end..]) {
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                read => break read?,
            }
        };
        self.end += n;
        self.any |= n > 0;
        Ok(n)
    }

    /// More input for the stream being decoded; its absence is a truncated file.
    fn more(&mut self) -> io::Result<()> {
        if self.fill()? > 0 {
            return Ok(());
        }
        Err(self.error(if self.any {
            "truncated: the file ends inside its xz stream (a copy cut short?); `xz -t` tests it"
        } else {
            "empty: not an xz file"
        }))
    }

    fn error(&self, why: &str) -> io::Error {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{}: {why}", self.path.display()),
        )
    }

    /// The decoder's errors in words: what was wrong with the file, and what to do.
    fn decoding_error(&self, error: &xz4rust::XzError) -> io::Error {
        match error {
            xz4rust::XzError::DictionaryTooLarge(bytes) => self.error(&format!(
                "declares an xz dictionary of {bytes} bytes, more than the {} sapnet holds \
                 (xz -9's): decompress it yourself (xz -dk) beside it",
                MAX_XZ_DICTIONARY_BYTES
            )),
            xz4rust::XzError::StreamHeaderMagicNumberMismatch => {
                self.error("not an xz file (its first bytes are not xz's)")
            }
            other => self.error(&format!(
                "damaged, or not an xz file this reader can decompress ({other}); `xz -t` \
                 tests it"
            )),
        }
    }

    /// Counts `n` bytes out against the bound.
    fn produced(&mut self, n: usize) -> io::Result<usize> {
        self.out += n as u64;
        if self.out > self.limit {
            return Err(self.error(&format!(
                "decompresses to more than the {} bytes sapnet reads from a compressed file: \
                 decompress it yourself (xz -dk) beside it",
                self.limit
            )));
        }
        Ok(n)
    }
}

impl Read for XzText {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        use xz4rust::{XzError, XzNextBlockResult};
        if buf.is_empty() {
            return Ok(0);
        }
        loop {
            if self.between {
                // Stream padding (zeros), then another stream or the end.
                while self.start < self.end && self.buffer[self.start] == 0 {
                    self.start += 1;
                }
                if self.start == self.end {
                    if self.fill()? == 0 {
                        return Ok(0);
                    }
                    continue;
                }
                self.decoder.reset();
                self.between = false;
            }
            if self.start == self.end {
                self.more()?;
            }
            match self.decoder.decode(&self.buffer[self.start..self.end], buf) {
                Ok(XzNextBlockResult::NeedMoreData(used, n)) => {
                    self.start += used;
                    if n > 0 {
                        return self.produced(n);
                    }
                    if used == 0 {
                        self.more()?;
                    }
                }
                Ok(XzNextBlockResult::EndOfStream(used, n)) => {
                    self.start += used;
                    self.between = true;
                    if n > 0 {
                        return self.produced(n);
                    }
                }
                Err(XzError::NeedsLargerInputBuffer) => self.more()?,
                Err(other) => return Err(self.decoding_error(&other)),
            }
        }
    }
}

/// A CSV reader over `path`, a file inside a folder, or its compressed twin (see
/// [`open_csv`]), its lines bounded ([`bounded_lines`]).
pub fn csv_reader(path: &Path) -> io::Result<csv::Reader<Box<dyn Read>>> {
    Ok(csv::Reader::from_reader(Box::new(bounded_lines(
        open_csv(path)?,
        path,
    ))))
}

/// The longest line of a CSV file sapnet reads (a row, quoted line breaks and all): a CSV
/// reader holds a row whole, so a file of one endless line (a sparse file's hole, a
/// gigabyte without a line break) would be held whole. A row of `activations.csv` for
/// 10,000 sources (`MAX_SOURCES`) is under 1 MiB.
pub const MAX_CSV_LINE_BYTES: u64 = 4 << 20;

/// `text`, read from `path`, refused at a line (outside quotes) longer than
/// [`MAX_CSV_LINE_BYTES`], naming the file and the line.
pub fn bounded_lines<R: Read>(text: R, path: &Path) -> impl Read {
    BoundedLines {
        text,
        path: path.to_path_buf(),
        line: 1,
        length: 0,
        quoted: false,
    }
}

struct BoundedLines<R> {
    text: R,
    path: PathBuf,
    /// The line being read, 1 for the first.
    line: u64,
    /// Its bytes so far.
    length: u64,
    /// Inside a quoted field, where a line break is the field's.
    quoted: bool,
}

impl<R: Read> Read for BoundedLines<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.text.read(buf)?;
        for &byte in &buf[..n] {
            match byte {
                b'"' => self.quoted = !self.quoted,
                b'\n' if !self.quoted => {
                    self.line += 1;
                    self.length = 0;
                    continue;
                }
                _ => {}
            }
            self.length += 1;
            if self.length > MAX_CSV_LINE_BYTES {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidData,
                    format!(
                        "{}: line {} is longer than the {MAX_CSV_LINE_BYTES} bytes a row may \
                         hold{}: not a CSV file of runs",
                        self.path.display(),
                        self.line,
                        if self.quoted {
                            " (a quote opened and never closed)"
                        } else {
                            ""
                        }
                    ),
                ));
            }
        }
        Ok(n)
    }
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
        let bomb = write_tmp(&tmp, &xz(&vec![0; 1 << 20]));
        let mut text = XzText::new(File::open(&bomb).unwrap(), bomb.clone(), 1024);
        let err = io::copy(&mut text, &mut io::sink()).unwrap_err();
        assert!(
            err.to_string().contains("more than the 1024 bytes"),
            "{err}"
        );
        // At the bound exactly, it is read whole.
        let mut text = XzText::new(File::open(&bomb).unwrap(), bomb, 1 << 20);
        assert_eq!(io::copy(&mut text, &mut io::sink()).unwrap(), 1 << 20);
    }

    /// `xz` itself, where the machine has it (real compression, real dictionaries).
    fn xz_tool(args: &[&str], input: &[u8]) -> Option<Vec<u8>> {
        let mut child = std::process::Command::new("xz")
            .args(args)
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped())
            .spawn()
            .ok()?;
        let mut stdin = child.stdin.take().unwrap();
        let input = input.to_vec();
        let writer = std::thread::spawn(move || stdin.write_all(&input));
        let output = child.wait_with_output().ok()?;
        writer.join().unwrap().ok()?;
        output.status.success().then_some(output.stdout)
    }

    #[test]
    fn a_truncated_file_a_huge_dictionary_and_concatenated_streams_are_said_plainly() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("episodes.csv");
        let twin = tmp.path().join("episodes.csv.xz");
        let rows: String = (0..20_000).map(|i| format!("0,{i}.5\n")).collect();
        let Some(whole) = xz_tool(&["-c"], rows.as_bytes()) else {
            eprintln!("no xz on this machine: skipped");
            return;
        };
        std::fs::write(&twin, &whole[..whole.len() / 2]).unwrap();
        let err = read_csv(&path).unwrap_err().to_string();
        assert!(
            err.contains("episodes.csv.xz: truncated: the file ends inside its xz stream"),
            "{err}"
        );
        // Two streams one after the other, with stream padding between them, as `xz -d`.
        let mut two = whole.clone();
        two.extend_from_slice(&[0; 8]);
        two.extend_from_slice(&whole);
        std::fs::write(&twin, &two).unwrap();
        assert_eq!(read_csv(&path).unwrap(), rows.repeat(2));
        // A dictionary past xz -9's is refused before it is allocated.
        let big = xz_tool(&["-c", "--lzma2=dict=128MiB"], b"run\n").unwrap();
        std::fs::write(&twin, big).unwrap();
        let err = read_csv(&path).unwrap_err().to_string();
        assert!(
            err.contains("declares an xz dictionary of 134217728 bytes, more than the 67108864"),
            "{err}"
        );
        std::fs::write(&twin, b"run,reward\n0,1\n").unwrap();
        let err = read_csv(&path).unwrap_err().to_string();
        assert!(err.contains("not an xz file"), "{err}");
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
