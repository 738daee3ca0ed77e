//! Any Gymnasium task as an [`Environment`]: the environment lives in a Python worker
//! process ([`worker`]: `worker.py`, embedded in the binary), one request and one reply per
//! step. Nothing else in the crate knows Python exists, and the default build needs none:
//! the worker is started only for a task `Gymnasium(id: "…")`, with the user's Python.
//!
//! Why a worker and not Python in-process (PyO3), measured on this project's machine
//! (BENCHMARKS.md): a worker runs in whatever Python the user's virtualenv has (an
//! embedded interpreter is the one the binary was built against), its death is an error
//! the run reports instead of the process's, and its cost over Gymnasium's own
//! `env.step` is one pipe round trip, ~3 µs when the worker shares the run's core. So each
//! run thread that starts a worker is pinned to a core of its own and the worker with it:
//! across cores a wake-up cost ~40 µs on this machine, on the same core a switch.
//!
//! Python is found as a user expects: `python` in the task (which a config the user names
//! may set, and `--python` overrides; a stored config never chooses it), else the active
//! virtualenv (`$VIRTUAL_ENV/bin/python`), else `python3` on the `PATH`.

mod params;
mod worker;

pub use params::{known_task, GymnasiumParams, KnownTask, PythonSettings, WorkerTimeouts};

use std::cell::Cell;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};

use serde::Deserialize;

pub use worker::{interrupt_waits, SCRIPT_NAME};

use super::{EnvError, Environment, Step};
use worker::Worker;

/// Requests, as the worker reads them: an opcode, a u32 and a u64.
const STEP: u8 = b'S';
const RESET: u8 = b'R';
const SET_STATE: u8 = b'T';
const GET_STATE: u8 = b'G';

/// The most state values a get-state reply may carry.
const MAX_STATE: usize = 1 << 16;

/// A Gymnasium environment stepped in its worker.
pub struct Gymnasium {
    id: String,
    obs_size: usize,
    actions: usize,
    worker: Worker,
    /// The latest observation, read into this buffer in place (no step allocates).
    obs: Vec<f32>,
    /// A request, built in place.
    request: Vec<u8>,
    state: Vec<f64>,
    elapsed: u32,
}

#[derive(Deserialize)]
struct Handshake {
    obs: usize,
    actions: usize,
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
        let spec = serde_json::json!({
            "id": params.id,
            "kwargs": params.kwargs,
            "attributes": params.attributes,
            "max_episode_steps": params.max_episode_steps,
            "module_dir": params.module_dir,
            "pip": pip_requirement(&params.id),
        });
        let (worker, start) = Worker::start(
            &params.id,
            &python(params),
            &spec.to_string(),
            params.timeouts,
        )?;
        let Handshake { obs, actions } = serde_json::from_slice(&start).map_err(|e| {
            EnvError::Gymnasium(format!(
                "{}: the Python side answered its start with {e}",
                params.id
            ))
        })?;
        if obs > MAX_STATE || actions > MAX_STATE {
            return Err(EnvError::Gymnasium(format!(
                "{}: an observation of {obs} values and {actions} actions: sapnet's Q-networks \
                 take at most {MAX_STATE} of either",
                params.id
            )));
        }
        cache_spaces(params, (obs, actions));
        Ok(Self {
            id: params.id.clone(),
            obs_size: obs,
            actions,
            worker,
            obs: vec![0.0; obs],
            request: Vec::with_capacity(13),
            state: Vec::new(),
            elapsed: 0,
        })
    }

    /// Sends a request (`extra` after its 13 bytes) whose reply is an observation, a reward
    /// and the flags: the observation is read into `obs`; returns the reward and the flags.
    fn exchange(
        &mut self,
        op: u8,
        word: u32,
        seed: u64,
        extra: &[u8],
        what: &str,
    ) -> Result<(f64, bool, bool), EnvError> {
        self.request.clear();
        self.request.push(op);
        self.request.extend_from_slice(&word.to_le_bytes());
        self.request.extend_from_slice(&seed.to_le_bytes());
        self.request.extend_from_slice(extra);
        let n = self.obs_size;
        let size = 4 * n + 10;
        let reply = self.worker.ask(&self.request, size, what)?;
        if reply.len() != size {
            return Err(EnvError::Gymnasium(format!(
                "{}: the Python side answered {what} with {} bytes, where an observation of \
                 {n} values, a reward and two flags take {size}",
                self.id,
                reply.len()
            )));
        }
        for (value, bytes) in self.obs.iter_mut().zip(reply[..4 * n].chunks_exact(4)) {
            *value = f32::from_le_bytes(bytes.try_into().expect("4 bytes"));
        }
        let tail = &reply[4 * n..];
        let reward = f64::from_le_bytes(tail[..8].try_into().expect("8 bytes"));
        Ok((reward, tail[8] != 0, tail[9] != 0))
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
        self.exchange(
            RESET,
            u32::from(seed.is_some()),
            seed.unwrap_or(0),
            &[],
            "a reset",
        )?;
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
        let (reward, terminated, truncated) =
            self.exchange(STEP, action as u32, 0, &[], "a step")?;
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
        self.exchange(
            SET_STATE,
            state.len() as u32,
            0,
            &bytes,
            "setting the state",
        )?;
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
        let values = self
            .worker
            .ask(&request, 8 * MAX_STATE, "reading the state")?;
        if values.len() % 8 != 0 {
            return Err(EnvError::Gymnasium(format!(
                "{}: the Python side answered reading the state with {} bytes, not f64s",
                self.id,
                values.len()
            )));
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

/// What `pip install` installs for `id`: Gymnasium, with the extra a Box2D task needs.
fn pip_requirement(id: &str) -> &'static str {
    let task = id.rsplit(':').next().unwrap_or(id);
    if ["LunarLander", "BipedalWalker", "CarRacing"]
        .iter()
        .any(|family| task.starts_with(family))
    {
        "\"gymnasium[box2d]\""
    } else {
        "gymnasium"
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
