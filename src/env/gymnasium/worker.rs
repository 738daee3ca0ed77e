//! The Python worker process of a Gymnasium task, and the one way sapnet talks to it.
//!
//! The worker is untrusted code: Gymnasium and whatever environment it makes. So:
//! - it runs from a script file of sapnet's own, in a private folder that is also its
//!   current directory, so that nothing is imported from the directory sapnet was started
//!   in (`python -c` would put it first on `sys.path`);
//! - requests travel on its fd 3 and replies on its fd 4, each reply one bounded frame
//!   (status, length, payload): what the environment prints goes to stdout, which is only
//!   kept as a log for error messages, and can never be read as a reply;
//! - every wait for a reply has a deadline ([`WorkerTimeouts`]) and ends early once
//!   [`interrupt_waits`] is called (sapnet's signal handler does, on SIGINT, SIGTERM and
//!   SIGHUP);
//! - it never outlives sapnet: it is in a process group of its own (Ctrl-C at the terminal
//!   is sapnet's to handle), the kernel kills it when the thread that started it ends
//!   (`PR_SET_PDEATHSIG`: a worker is used by the run thread that made it), and dropping a
//!   [`Worker`] ends and reaps it.

use std::collections::VecDeque;
use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd, RawFd};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::super::{EnvError, WorkerTimeouts};

/// The worker's source, written to a private folder per worker.
const SCRIPT: &str = include_str!("worker.py");

/// The script's file name: what `pgrep -f` finds a worker by.
pub const SCRIPT_NAME: &str = "sapnet-gymnasium-worker.py";

/// How much of the worker's stdout and stderr is kept for an error message.
const LOG_TAIL: usize = 4096;

/// The largest frame an error or the start's JSON may be: a message, not data.
const MAX_MESSAGE: usize = 64 * 1024;

/// How often a wait looks at its deadline and at [`interrupt_waits`].
const POLL_SLICE: Duration = Duration::from_millis(100);

static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Ends every wait for a worker's reply, now and from now on, with
/// [`EnvError::Interrupted`]: the process is stopping.
pub fn interrupt_waits() {
    INTERRUPTED.store(true, Ordering::SeqCst);
}

/// A running worker: its process, its two pipes and its log.
pub struct Worker {
    id: String,
    child: Child,
    /// Taken (and so closed) when the worker is dropped: end of its fd 3 ends it.
    requests: Option<File>,
    replies: File,
    log: Arc<Mutex<VecDeque<u8>>>,
    python: PathBuf,
    timeouts: WorkerTimeouts,
    /// Reused for every reply.
    buffer: Vec<u8>,
    /// The private folder of the script; removed once the worker is reaped.
    _folder: tempfile::TempDir,
}

impl Worker {
    /// Starts `python` on the worker script with `spec` (the task as JSON) and reads its
    /// first frame, within `timeouts.start` seconds.
    pub fn start(
        id: &str,
        python: &Path,
        spec: &str,
        timeouts: WorkerTimeouts,
    ) -> Result<(Self, Vec<u8>), EnvError> {
        let io_error = |what: &str, e: std::io::Error| {
            EnvError::Gymnasium(format!("{id}: {what} for the Python worker failed: {e}"))
        };
        let folder = tempfile::Builder::new()
            .prefix("sapnet-gymnasium-")
            .tempdir()
            .map_err(|e| io_error("making a private folder", e))?;
        let script = folder.path().join(SCRIPT_NAME);
        std::fs::write(&script, SCRIPT).map_err(|e| io_error("writing the script", e))?;
        let (request_read, request_write) = pipe().map_err(|e| io_error("a pipe", e))?;
        let (reply_read, reply_write) = pipe().map_err(|e| io_error("a pipe", e))?;
        let (log_read, log_write) = std::io::pipe().map_err(|e| io_error("a pipe", e))?;
        let log_write_too = log_write.try_clone().map_err(|e| io_error("a pipe", e))?;
        let (to_3, to_4) = (request_read.as_raw_fd(), reply_write.as_raw_fd());
        let parent = std::process::id();
        let mut command = Command::new(python);
        command
            .arg(&script)
            .arg(spec)
            .current_dir(folder.path())
            .stdin(Stdio::null())
            .stdout(log_write)
            .stderr(log_write_too)
            .process_group(0);
        // SAFETY: between fork and exec only async-signal-safe calls: dup2, prctl, getppid,
        // _exit. The two descriptors are above 9 (see `pipe`), so neither is 3 or 4.
        unsafe {
            command.pre_exec(move || {
                if libc::dup2(to_3, 3) < 0 || libc::dup2(to_4, 4) < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
                // sapnet ended before the line above: nobody will ask anything.
                if libc::getppid() as u32 != parent {
                    libc::_exit(1);
                }
                Ok(())
            });
        }
        let child = command.spawn().map_err(|e| {
            EnvError::Gymnasium(format!(
                "{id}: starting Python ({}) failed: {e}; set `python` in the task, give \
                 --python, or activate a virtualenv that has Gymnasium",
                python.display()
            ))
        })?;
        // The child's ends: closed here, so that the worker's exit is an end of file.
        drop(command);
        drop((request_read, reply_write));
        let log = Arc::new(Mutex::new(VecDeque::new()));
        let tail = Arc::clone(&log);
        std::thread::spawn(move || keep_tail(log_read, &tail));
        let mut worker = Self {
            id: id.to_string(),
            child,
            requests: Some(File::from(request_write)),
            replies: File::from(reply_read),
            log,
            python: python.to_path_buf(),
            timeouts,
            buffer: Vec::new(),
            _folder: folder,
        };
        let deadline = Duration::from_secs(u64::from(timeouts.start));
        let ok = worker.read_frame(MAX_MESSAGE, deadline, "making the environment")?;
        let payload = worker.buffer[5..].to_vec();
        if !ok {
            return Err(EnvError::Gymnasium(
                String::from_utf8_lossy(&payload).into_owned(),
            ));
        }
        Ok((worker, payload))
    }

    /// Sends `request` and reads the reply, which may be at most `limit` bytes: a longer
    /// one is not a reply of this request. `what` names the request in errors. An error
    /// reply is returned as the worker's message.
    pub fn ask(&mut self, request: &[u8], limit: usize, what: &str) -> Result<&[u8], EnvError> {
        let requests = self.requests.as_mut().expect("open until dropped");
        if requests.write_all(request).is_err() {
            return Err(self.died("stopped reading requests"));
        }
        let deadline = Duration::from_secs(u64::from(self.timeouts.step));
        let ok = self.read_frame(limit.max(MAX_MESSAGE), deadline, what)?;
        let length = self.buffer.len() - 5;
        if !ok {
            let message = String::from_utf8_lossy(&self.buffer[5..]).into_owned();
            return Err(EnvError::Gymnasium(message));
        }
        if length > limit {
            return Err(self.broken(&format!(
                "answered {what} with {length} bytes, more than the {limit} its reply holds"
            )));
        }
        Ok(&self.buffer[5..])
    }

    /// Reads one frame within `timeout` into `buffer` (its payload from byte 5), refusing a
    /// declared length above `limit`; returns whether its status is ok.
    fn read_frame(
        &mut self,
        limit: usize,
        timeout: Duration,
        what: &str,
    ) -> Result<bool, EnvError> {
        let deadline = Instant::now() + timeout;
        self.buffer.resize(5, 0);
        self.fill(0, deadline, timeout, what)?;
        let status = self.buffer[0];
        let length = u32::from_le_bytes(self.buffer[1..5].try_into().expect("4 bytes")) as usize;
        if status > 1 || length > limit {
            return Err(self.broken(&format!(
                "answered {what} with a frame of status {status} and {length} bytes (at most \
                 {limit}): not a reply of sapnet's worker"
            )));
        }
        self.buffer.resize(5 + length, 0);
        self.fill(5, deadline, timeout, what)?;
        Ok(status == 0)
    }

    /// Fills `buffer[from..]` from the reply pipe before `deadline`.
    fn fill(
        &mut self,
        mut from: usize,
        deadline: Instant,
        timeout: Duration,
        what: &str,
    ) -> Result<(), EnvError> {
        while from < self.buffer.len() {
            match wait_readable(self.replies.as_raw_fd(), deadline) {
                Wait::Ready => {}
                Wait::Interrupted => {
                    self.kill();
                    return Err(EnvError::Interrupted);
                }
                Wait::TimedOut => {
                    self.kill();
                    return Err(EnvError::Gymnasium(format!(
                        "{}: the Python side took more than {} s for {what} and was killed \
                         (the task's `timeouts` set the limits){}",
                        self.id,
                        timeout.as_secs(),
                        self.last_words()
                    )));
                }
            }
            match self.replies.read(&mut self.buffer[from..]) {
                Ok(0) | Err(_) => return Err(self.died(&format!("ended during {what}"))),
                Ok(n) => from += n,
            }
        }
        Ok(())
    }

    fn kill(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }

    /// The worker broke the protocol: killed, with what it said.
    fn broken(&mut self, what: &str) -> EnvError {
        self.kill();
        EnvError::Gymnasium(format!(
            "{}: the Python side ({}, PID {}) {what}; it was killed{}",
            self.id,
            self.python.display(),
            self.child.id(),
            self.last_words()
        ))
    }

    /// The worker is gone or broken: how it ended, and the last lines of its log.
    fn died(&mut self, what: &str) -> EnvError {
        // A worker that closed its pipes is ending: wait a moment for its status.
        let deadline = Instant::now() + Duration::from_millis(500);
        let status = loop {
            match self.child.try_wait() {
                Ok(Some(status)) => break Some(status),
                Ok(None) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(5));
                }
                _ => break None,
            }
        };
        let ended = match status {
            Some(status) => {
                use std::os::unix::process::ExitStatusExt;
                match (status.code(), status.signal()) {
                    (_, Some(signal)) => format!("was killed by signal {signal}"),
                    (Some(code), _) => format!("exited with code {code}"),
                    _ => "ended".into(),
                }
            }
            None => {
                self.kill();
                "was still running, and was killed".into()
            }
        };
        EnvError::Gymnasium(format!(
            "{}: the Python side ({}, PID {}) {what} and {ended}{}",
            self.id,
            self.python.display(),
            self.child.id(),
            self.last_words()
        ))
    }

    /// The last lines the worker printed, as the end of an error message.
    fn last_words(&self) -> String {
        let tail = self.log.lock().map_or_else(
            |_| String::new(),
            |t| String::from_utf8_lossy(&t.iter().copied().collect::<Vec<u8>>()).into_owned(),
        );
        let last: Vec<&str> = tail.lines().rev().take(5).collect();
        if last.is_empty() {
            return String::new();
        }
        let last: Vec<&str> = last.into_iter().rev().collect();
        format!("; its last words: {}", last.join(" / "))
    }
}

impl Drop for Worker {
    /// End of its fd 3 ends the worker; one that does not leave within a second is killed.
    /// Either way it is reaped before its folder is removed.
    fn drop(&mut self) {
        let deadline = Instant::now() + Duration::from_secs(1);
        drop(self.requests.take());
        loop {
            match self.child.try_wait() {
                Ok(Some(_)) | Err(_) => return,
                Ok(None) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(2));
                }
                Ok(None) => return self.kill(),
            }
        }
    }
}

enum Wait {
    Ready,
    TimedOut,
    Interrupted,
}

/// Waits until `fd` has bytes (or its end), `deadline` passes, or [`interrupt_waits`] is
/// called, whichever is first.
fn wait_readable(fd: RawFd, deadline: Instant) -> Wait {
    loop {
        if INTERRUPTED.load(Ordering::SeqCst) {
            return Wait::Interrupted;
        }
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Wait::TimedOut;
        }
        let slice = left.min(POLL_SLICE).as_millis().max(1) as libc::c_int;
        let mut poll = libc::pollfd {
            fd,
            events: libc::POLLIN,
            revents: 0,
        };
        // SAFETY: one valid pollfd, for the call's duration.
        let ready = unsafe { libc::poll(&mut poll, 1, slice) };
        if ready > 0 {
            return Wait::Ready;
        }
        // 0: the slice passed; < 0: EINTR (a signal): look at the flag and the time again.
    }
}

/// A pipe whose two ends are above fd 9 and close on exec: the worker's fds 3 and 4 are
/// made from them by `dup2`, which would not clear close-on-exec on an fd already 3 or 4.
fn pipe() -> std::io::Result<(OwnedFd, OwnedFd)> {
    let mut fds = [0 as RawFd; 2];
    // SAFETY: `fds` has room for the two descriptors pipe2 writes.
    if unsafe { libc::pipe2(fds.as_mut_ptr(), libc::O_CLOEXEC) } != 0 {
        return Err(std::io::Error::last_os_error());
    }
    // SAFETY: both were just opened and are owned by nothing else.
    let (read, write) = unsafe { (OwnedFd::from_raw_fd(fds[0]), OwnedFd::from_raw_fd(fds[1])) };
    Ok((above_nine(read)?, above_nine(write)?))
}

fn above_nine(fd: OwnedFd) -> std::io::Result<OwnedFd> {
    // SAFETY: F_DUPFD_CLOEXEC on a valid descriptor returns a new one, owned here.
    let moved = unsafe { libc::fcntl(fd.as_raw_fd(), libc::F_DUPFD_CLOEXEC, 10) };
    if moved < 0 {
        return Err(std::io::Error::last_os_error());
    }
    // SAFETY: `moved` was just opened and is owned by nothing else.
    Ok(unsafe { OwnedFd::from_raw_fd(moved) })
}

/// Keeps the last [`LOG_TAIL`] bytes the worker writes to stdout and stderr.
fn keep_tail(pipe: impl Read, tail: &Mutex<VecDeque<u8>>) {
    let mut reader = BufReader::new(pipe);
    let mut line = Vec::new();
    while reader.read_until(b'\n', &mut line).is_ok_and(|n| n > 0) {
        if let Ok(mut tail) = tail.lock() {
            tail.extend(line.drain(..));
            while tail.len() > LOG_TAIL {
                tail.pop_front();
            }
        }
    }
}
