//! Any Gymnasium task as an [`Environment`]: the environment lives in a Python worker
//! process (`gymnasium_worker.py`, embedded in the binary), stepped over its stdin and
//! stdout, one request and one reply per step. Nothing else in the crate knows Python
//! exists, and the default build needs none: the worker is started only for a task
//! `Gymnasium(id: "…")`, with the user's Python.
//!
//! Why a worker and not Python in-process (PyO3), measured on this project's machine
//! (BENCHMARKS.md): a worker runs in whatever Python the user's virtualenv has (an
//! embedded interpreter is the one the binary was built against), its death is an error
//! the run reports instead of the process's, and its cost over Gymnasium's own
//! `env.step` is one pipe round trip, ~3 µs when the worker shares the run's core. So each
//! run thread that starts a worker is pinned to a core of its own and the worker with it:
//! across cores a wake-up cost ~40 µs on this machine, on the same core a switch.
//!
//! Python is found as a user expects: `env.python` in the config, else the active
//! virtualenv (`$VIRTUAL_ENV/bin/python`), else `python3` on the `PATH`.

use std::cell::Cell;
use std::collections::{HashMap, VecDeque};
use std::io::{BufRead, BufReader, Read, Write};
use std::path::PathBuf;
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use serde::Deserialize;

use super::{EnvError, Environment, GymnasiumParams, Step};

/// The worker's source, run with `python -c`.
const WORKER: &str = include_str!("gymnasium_worker.py");

/// How much of the worker's stderr is kept for an error message.
const STDERR_TAIL: usize = 4096;

/// How long the worker has to start (import Gymnasium, make the environment).
const START_TIMEOUT: Duration = Duration::from_secs(120);

/// Requests, as the worker reads them: an opcode, a u32 and a u64.
const STEP: u8 = b'S';
const RESET: u8 = b'R';
const SET_STATE: u8 = b'T';
const GET_STATE: u8 = b'G';

/// A Gymnasium environment stepped in its worker.
pub struct Gymnasium {
    id: String,
    obs_size: usize,
    actions: usize,
    worker: Worker,
    /// The latest observation, read into this buffer in place (no step allocates).
    obs: Vec<f32>,
    /// The reply of a step, read whole: status, observation, reward, flags.
    reply: Vec<u8>,
    state: Vec<f64>,
    elapsed: u32,
}

/// The worker process and its pipes.
struct Worker {
    child: Child,
    /// Taken (and so closed) when the worker is dropped: end of stdin ends it.
    stdin: Option<ChildStdin>,
    stdout: ChildStdout,
    stderr: Arc<Mutex<VecDeque<u8>>>,
    python: PathBuf,
}

#[derive(Deserialize)]
struct Handshake {
    obs: Option<usize>,
    actions: Option<usize>,
    error: Option<String>,
}

impl Gymnasium {
    /// Starts the worker of `params` and checks its spaces: a `Discrete` action space and a
    /// 1-D `Box` observation space (anything else is refused, naming the space found). The
    /// calling thread, which will step it, is pinned to a core with its worker.
    pub fn start(params: &GymnasiumParams) -> Result<Self, EnvError> {
        pin_this_thread();
        Self::launch(params)
    }

    /// [`start`](Self::start) without pinning: for asking a task its spaces.
    fn launch(params: &GymnasiumParams) -> Result<Self, EnvError> {
        let python = python(params);
        let spec = serde_json::json!({
            "id": params.id,
            "kwargs": params.kwargs,
            "attributes": params.attributes,
            "max_episode_steps": params.max_episode_steps,
        });
        let mut child = Command::new(&python)
            .arg("-c")
            .arg(WORKER)
            .arg(spec.to_string())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| {
                EnvError::Gymnasium(format!(
                    "{}: starting Python ({}) failed: {e}; set `python` in the task, or \
                     activate a virtualenv that has Gymnasium",
                    params.id,
                    python.display()
                ))
            })?;
        let stderr = Arc::new(Mutex::new(VecDeque::new()));
        if let Some(pipe) = child.stderr.take() {
            let tail = Arc::clone(&stderr);
            std::thread::spawn(move || keep_tail(pipe, &tail));
        }
        let (stdin, stdout) = match (child.stdin.take(), child.stdout.take()) {
            (Some(stdin), Some(stdout)) => (stdin, stdout),
            _ => unreachable!("both pipes were requested"),
        };
        let mut worker = Worker {
            child,
            stdin: Some(stdin),
            stdout,
            stderr,
            python,
        };
        let handshake = worker.handshake(&params.id)?;
        if let Some(error) = handshake.error {
            return Err(EnvError::Gymnasium(error));
        }
        let (Some(obs_size), Some(actions)) = (handshake.obs, handshake.actions) else {
            return Err(worker.died(&params.id, "answered its start without its spaces"));
        };
        cache_spaces(params, (obs_size, actions));
        Ok(Self {
            id: params.id.clone(),
            obs_size,
            actions,
            worker,
            obs: vec![0.0; obs_size],
            reply: vec![0; 1 + 4 * obs_size + 10],
            state: Vec::new(),
            elapsed: 0,
        })
    }

    /// Sends a request and reads the reply of a step, reset or set-state into `reply`, its
    /// observation into `obs`; returns the reward and the flags.
    fn exchange(
        &mut self,
        op: u8,
        word: u32,
        seed: u64,
        extra: &[u8],
    ) -> Result<(f64, bool, bool), EnvError> {
        let mut request = [0u8; 13];
        request[0] = op;
        request[1..5].copy_from_slice(&word.to_le_bytes());
        request[5..13].copy_from_slice(&seed.to_le_bytes());
        let stdin = self.worker.stdin.as_mut().expect("open until dropped");
        let sent = if extra.is_empty() {
            stdin.write_all(&request)
        } else {
            let mut all = request.to_vec();
            all.extend_from_slice(extra);
            stdin.write_all(&all)
        };
        if sent.is_err() || self.worker.stdout.read_exact(&mut self.reply).is_err() {
            return Err(self.worker.died(&self.id, "stopped answering"));
        }
        if self.reply[0] != 0 {
            return Err(self.worker.error(&self.id, &self.reply));
        }
        let n = self.obs_size;
        for (value, bytes) in self
            .obs
            .iter_mut()
            .zip(self.reply[1..1 + 4 * n].chunks_exact(4))
        {
            *value = f32::from_le_bytes(bytes.try_into().expect("4 bytes"));
        }
        let tail = &self.reply[1 + 4 * n..];
        let reward = f64::from_le_bytes(tail[..8].try_into().expect("8 bytes"));
        Ok((reward, tail[8] != 0, tail[9] != 0))
    }
}

impl Worker {
    /// The first line the worker writes: its spaces, or why it could not start.
    fn handshake(&mut self, id: &str) -> Result<Handshake, EnvError> {
        let mut line = Vec::new();
        let started = Instant::now();
        let mut byte = [0u8; 1];
        while !line.ends_with(b"\n") {
            if started.elapsed() > START_TIMEOUT {
                let _ = self.child.kill();
                return Err(EnvError::Gymnasium(format!(
                    "{id}: the Python worker did not start within {} s",
                    START_TIMEOUT.as_secs()
                )));
            }
            match self.stdout.read(&mut byte) {
                Ok(1) => line.push(byte[0]),
                _ => return Err(self.died(id, "ended before it made the environment")),
            }
        }
        serde_json::from_slice(&line)
            .map_err(|e| self.died(id, &format!("answered its start with {e}")))
    }

    /// The error the worker replied with (status 1): its message, read from `reply` and
    /// whatever of it did not fit; the padding after it is drained.
    fn error(&mut self, id: &str, reply: &[u8]) -> EnvError {
        let length = u32::from_le_bytes(reply[1..5].try_into().expect("4 bytes")) as usize;
        let mut message = reply[5..].to_vec();
        if length > message.len() {
            let mut rest = vec![0; length - message.len()];
            if self.stdout.read_exact(&mut rest).is_err() {
                return self.died(id, "broke off its error message");
            }
            message.extend(rest);
        }
        message.truncate(length);
        EnvError::Gymnasium(String::from_utf8_lossy(&message).into_owned())
    }

    /// The worker is gone or broken: how it ended, and the last lines it wrote to stderr.
    fn died(&mut self, id: &str, what: &str) -> EnvError {
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
                let _ = self.child.kill();
                "was still running, and was killed".into()
            }
        };
        let tail = self.stderr.lock().map_or_else(
            |_| String::new(),
            |t| String::from_utf8_lossy(&t.iter().copied().collect::<Vec<u8>>()).into_owned(),
        );
        let last: Vec<&str> = tail.lines().rev().take(5).collect();
        let last: Vec<&str> = last.into_iter().rev().collect();
        EnvError::Gymnasium(format!(
            "{id}: the Python side ({}, PID {}) {what} and {ended}{}",
            self.python.display(),
            self.child.id(),
            if last.is_empty() {
                String::new()
            } else {
                format!("; its last words: {}", last.join(" / "))
            }
        ))
    }
}

impl Drop for Worker {
    /// End of stdin ends the worker; one that does not leave within a second is killed.
    fn drop(&mut self) {
        let deadline = Instant::now() + Duration::from_secs(1);
        drop(self.stdin.take());
        loop {
            match self.child.try_wait() {
                Ok(Some(_)) | Err(_) => return,
                Ok(None) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(2));
                }
                Ok(None) => {
                    let _ = self.child.kill();
                    let _ = self.child.wait();
                    return;
                }
            }
        }
    }
}

impl Environment for Gymnasium {
    fn id(&self) -> &str {
        &self.id
    }

    fn observation_size(&self) -> usize {
        self.obs_size
    }

    fn action_count(&self) -> usize {
        self.actions
    }

    fn reset(&mut self, seed: Option<u64>) -> Result<&[f32], EnvError> {
        self.exchange(RESET, u32::from(seed.is_some()), seed.unwrap_or(0), &[])?;
        self.elapsed = 0;
        Ok(&self.obs)
    }

    fn step(&mut self, action: usize) -> Result<Step<'_>, EnvError> {
        assert!(
            action < self.actions,
            "{}: action {action} is not below {}",
            self.id,
            self.actions
        );
        let (reward, terminated, truncated) = self.exchange(STEP, action as u32, 0, &[])?;
        self.elapsed += 1;
        Ok(Step {
            obs: &self.obs,
            reward,
            terminated,
            truncated,
        })
    }

    fn observation(&self) -> &[f32] {
        &self.obs
    }

    /// The unwrapped environment's `state`, as of the last [`set_state`](Self::set_state)
    /// or [`fetch_state`](Gymnasium::fetch_state) (empty before).
    fn state(&self) -> &[f64] {
        &self.state
    }

    /// Sets `env.unwrapped.state`, as tests of Gymnasium's classic-control tasks do; the
    /// observation becomes the state's (`_get_ob()` where the task has one).
    fn set_state(&mut self, state: &[f64]) -> Result<(), EnvError> {
        let bytes: Vec<u8> = state.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.exchange(SET_STATE, state.len() as u32, 0, &bytes)?;
        self.state = state.to_vec();
        Ok(())
    }

    fn elapsed_steps(&self) -> u32 {
        self.elapsed
    }
}

impl Gymnasium {
    /// Reads `env.unwrapped.state` from the worker (empty for a task without one).
    pub fn fetch_state(&mut self) -> Result<&[f64], EnvError> {
        let mut request = [0u8; 13];
        request[0] = GET_STATE;
        let mut head = [0u8; 5];
        let stdin = self.worker.stdin.as_mut().expect("open until dropped");
        if stdin.write_all(&request).is_err() || self.worker.stdout.read_exact(&mut head).is_err() {
            return Err(self.worker.died(&self.id, "stopped answering"));
        }
        let count = u32::from_le_bytes(head[1..5].try_into().expect("4 bytes")) as usize;
        if head[0] != 0 {
            let mut padded = head.to_vec();
            padded.resize(self.reply.len(), 0);
            let mut rest = vec![0; self.reply.len().saturating_sub(5)];
            if self.worker.stdout.read_exact(&mut rest).is_err() {
                return Err(self.worker.died(&self.id, "stopped answering"));
            }
            padded[5..].copy_from_slice(&rest);
            return Err(self.worker.error(&self.id, &padded));
        }
        let mut values = vec![0u8; 8 * count];
        if self.worker.stdout.read_exact(&mut values).is_err() {
            return Err(self.worker.died(&self.id, "stopped answering"));
        }
        self.state = values
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
            .collect();
        Ok(&self.state)
    }
}

/// The Python that runs the worker: the task's `python`, else the active virtualenv's,
/// else `python3`.
fn python(params: &GymnasiumParams) -> PathBuf {
    if let Some(python) = &params.python {
        return python.clone();
    }
    if let Some(venv) = std::env::var_os("VIRTUAL_ENV") {
        let python = PathBuf::from(venv).join("bin").join("python");
        if python.exists() {
            return python;
        }
    }
    PathBuf::from("python3")
}

/// Keeps the last [`STDERR_TAIL`] bytes the worker writes to stderr.
fn keep_tail(pipe: impl Read, tail: &Mutex<VecDeque<u8>>) {
    let mut reader = BufReader::new(pipe);
    let mut line = Vec::new();
    while reader.read_until(b'\n', &mut line).is_ok_and(|n| n > 0) {
        if let Ok(mut tail) = tail.lock() {
            tail.extend(line.drain(..));
            while tail.len() > STDERR_TAIL {
                tail.pop_front();
            }
        }
    }
}

/// The spaces of each task started in this process, so that planning (the memory check)
/// does not start a worker per run.
fn known_spaces() -> &'static Mutex<HashMap<String, (usize, usize)>> {
    static SPACES: OnceLock<Mutex<HashMap<String, (usize, usize)>>> = OnceLock::new();
    SPACES.get_or_init(|| Mutex::new(HashMap::new()))
}

fn key(params: &GymnasiumParams) -> String {
    serde_json::to_string(params).unwrap_or_default()
}

fn cache_spaces(params: &GymnasiumParams, spaces: (usize, usize)) {
    if let Ok(mut known) = known_spaces().lock() {
        known.insert(key(params), spaces);
    }
}

/// The observation size and action count of `params`' task: asked of a worker the first
/// time, then kept for the process.
pub fn spaces(params: &GymnasiumParams) -> Result<(usize, usize), EnvError> {
    if let Some(&spaces) = known_spaces()
        .lock()
        .ok()
        .and_then(|k| k.get(&key(params)).copied())
        .as_ref()
    {
        return Ok(spaces);
    }
    let env = Gymnasium::launch(params)?;
    Ok((env.obs_size, env.actions))
}

/// The core each run thread that starts a worker is pinned to (with its workers), handed
/// out in turn among the cores this process may use.
fn pin_this_thread() {
    thread_local! {
        static PINNED: Cell<bool> = const { Cell::new(false) };
    }
    if PINNED.with(Cell::get) || std::env::var_os("SAPNET_GYMNASIUM_NO_PIN").is_some() {
        return;
    }
    PINNED.with(|p| p.set(true));
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    // SAFETY: plain libc calls on a zeroed cpu_set_t of this thread.
    unsafe {
        let mut allowed: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut allowed) != 0 {
            return;
        }
        let cpus: Vec<usize> = (0..libc::CPU_SETSIZE as usize)
            .filter(|&c| libc::CPU_ISSET(c, &allowed))
            .collect();
        if cpus.len() < 2 {
            return;
        }
        let cpu = cpus[NEXT.fetch_add(1, Ordering::Relaxed) % cpus.len()];
        let mut one: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut one);
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &one);
    }
}
