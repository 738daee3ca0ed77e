//! Writing an event file that TensorBoard reads while it grows.

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{SystemTime, UNIX_EPOCH};

use super::event::{encode_file_version, encode_summary, scalar_value};
use super::hparams::{self, HParamValue, SessionStatus};
use super::record;

/// An event file being written: `events.out.tfevents.<unix seconds>.<host>.<pid>.<n>` in
/// its directory, the name TensorBoard's own writers give (TensorBoard reads any file
/// whose name holds `tfevents`; the process id and a count of the writers this process
/// opened keep two runs started in the same second apart).
///
/// Events are buffered: [`flush`](Self::flush) puts them on disk (a caller flushes at
/// each episode's end, so TensorBoard shows the run as it trains); dropping the writer
/// flushes too, ignoring an error it could not report.
#[derive(Debug)]
pub struct EventWriter {
    path: PathBuf,
    out: BufWriter<File>,
}

impl EventWriter {
    /// Starts a new event file in `dir`, made if missing (a real directory, never a link
    /// to elsewhere: see [`crate::safe_io::real_dir`]); its first event says the file's
    /// version. A file already at the name is an error, never overwritten.
    pub fn create(dir: &Path) -> io::Result<Self> {
        static WRITERS: AtomicU64 = AtomicU64::new(0);
        crate::safe_io::real_dir(dir)?;
        let name = format!(
            "events.out.tfevents.{:010}.{}.{}.{}",
            now().trunc() as u64,
            hostname(),
            std::process::id(),
            WRITERS.fetch_add(1, Ordering::Relaxed)
        );
        let path = dir.join(name);
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .custom_flags(libc::O_NOFOLLOW)
            .open(&path)?;
        let mut writer = Self {
            path,
            out: BufWriter::new(file),
        };
        writer.write_event(&encode_file_version(now()))?;
        Ok(writer)
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Logs `value` under `tag` at training step `step`.
    pub fn scalar(&mut self, tag: &str, step: i64, value: f32) -> io::Result<()> {
        self.write_event(&encode_summary(now(), step, &[scalar_value(tag, value)]))
    }

    /// Logs the run's hyper-parameters for the HParams plugin, which then lists the run
    /// with them beside its scalars. Call it once, before or after the first scalar.
    pub fn hparams(&mut self, hparams: &[(&str, HParamValue)]) -> io::Result<()> {
        let start = hparams::session_start(hparams.iter().map(|(n, v)| (*n, v)), now());
        self.write_event(&encode_summary(now(), 0, &[start]))
    }

    /// Tells the HParams plugin how the run ended.
    pub fn end_session(&mut self, status: SessionStatus) -> io::Result<()> {
        let end = hparams::session_end(status, now());
        self.write_event(&encode_summary(now(), 0, &[end]))
    }

    /// Puts the buffered events in the file.
    pub fn flush(&mut self) -> io::Result<()> {
        io::Write::flush(&mut self.out)
    }

    fn write_event(&mut self, event: &[u8]) -> io::Result<()> {
        record::write(&mut self.out, event)
    }
}

impl Drop for EventWriter {
    fn drop(&mut self) {
        let _ = self.flush();
    }
}

/// Seconds since the Unix epoch, as events time themselves.
fn now() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

/// This machine's name, as it goes into a file name: `localhost` if it has none, a `/`
/// (which no host name should hold) made `_`.
fn hostname() -> String {
    let mut buf = [0u8; 256];
    // SAFETY: gethostname writes at most `buf.len()` bytes into `buf`.
    let status = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) };
    let len = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    let name = String::from_utf8_lossy(&buf[..len]).replace('/', "_");
    if status != 0 || name.is_empty() {
        "localhost".to_string()
    } else {
        name
    }
}
