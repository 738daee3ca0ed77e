//! Replays the trajectories recorded from Gymnasium (`shared/vectors/*.json`, schema in
//! that folder's README) through the native environments and demands the same `f64` state
//! and `f32` observation bit for bit, and the same reward and flags, at every step.
//! A trajectory with a `params` object (task variants, `variants/README.md`) runs on the
//! environment with those constants changed.
//!
//! The folder is `$SAPNET_VECTORS_DIR`, or `../shared/vectors` beside the crate; its
//! `*.json` files and those of its subfolders (`variants/`) are replayed, with and without
//! `params` alike.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use sapnet::env::{EnvConfig, Environment};
use serde::Deserialize;
use serde_json::{Map, Value};

#[derive(Deserialize)]
struct VectorFile {
    env_id: String,
    max_episode_steps: u32,
    trajectories: Vec<Trajectory>,
}

#[derive(Deserialize)]
struct Trajectory {
    name: String,
    /// Constants changed from Gymnasium's defaults, named as the config's fields.
    #[serde(default)]
    params: Option<Map<String, Value>>,
    reset_seed: Option<u64>,
    initial_state_bits: Vec<String>,
    initial_obs_bits: Vec<String>,
    actions: Vec<usize>,
    steps: Vec<RecordedStep>,
    length: usize,
    ended_by: String,
}

#[derive(Deserialize)]
struct RecordedStep {
    obs_bits: Vec<String>,
    state_bits: Vec<String>,
    reward: f64,
    terminated: bool,
    truncated: bool,
}

#[derive(Default)]
struct Counts {
    files: usize,
    trajectories: usize,
    /// Trajectories with `params`.
    variants: usize,
    steps: usize,
}

fn vectors_dir() -> PathBuf {
    std::env::var_os("SAPNET_VECTORS_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/vectors"))
}

/// The native environment of `env_id` with the file's time limit and the trajectory's
/// `params` over the defaults, read as a config reads them (unknown names and physics that
/// make no sense are errors).
fn make_env(
    env_id: &str,
    max_episode_steps: u32,
    params: Option<&Map<String, Value>>,
) -> Result<Box<dyn Environment>, String> {
    let variant = match env_id {
        "CartPole-v0" | "CartPole-v1" => "CartPole",
        "MountainCar-v0" => "MountainCar",
        "Acrobot-v1" => "Acrobot",
        other => return Err(format!("no native environment for env_id {other:?}")),
    };
    let mut fields = params.cloned().unwrap_or_default();
    fields.insert("max_episode_steps".into(), max_episode_steps.into());
    let config: EnvConfig = serde_json::from_value(Value::Object(Map::from_iter([(
        variant.into(),
        fields.into(),
    )])))
    .map_err(|e| format!("params {params:?}: {e}"))?;
    config.validate("params")?;
    sapnet::env::make(&config).map_err(|e| e.to_string())
}

/// The `*.json` files of `dir` and of its subfolders.
fn json_files(dir: &Path, found: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_dir() {
            json_files(&path, found)?;
        } else if path.extension().is_some_and(|x| x == "json") {
            found.push(path);
        }
    }
    Ok(())
}

fn f64s(bits: &[String]) -> Vec<f64> {
    bits.iter()
        .map(|b| f64::from_bits(u64::from_str_radix(b, 16).expect("f64 bits in hex")))
        .collect()
}

fn f32s(bits: &[String]) -> Vec<f32> {
    bits.iter()
        .map(|b| f32::from_bits(u32::from_str_radix(b, 16).expect("f32 bits in hex")))
        .collect()
}

/// `Some(description)` when `got` is not `expected` to the bit.
fn f64_mismatch(what: &str, expected: &[f64], got: &[f64]) -> Option<String> {
    let same = expected.len() == got.len()
        && expected
            .iter()
            .zip(got)
            .all(|(e, g)| e.to_bits() == g.to_bits());
    (!same).then(|| format!("{what}: expected {expected:?}, got {got:?}"))
}

fn f32_mismatch(what: &str, expected: &[f32], got: &[f32]) -> Option<String> {
    let same = expected.len() == got.len()
        && expected
            .iter()
            .zip(got)
            .all(|(e, g)| e.to_bits() == g.to_bits());
    (!same).then(|| format!("{what}: expected {expected:?}, got {got:?}"))
}

/// Replays one trajectory; `Err` describes the first step that differs.
fn replay(env: &mut dyn Environment, t: &Trajectory, counts: &mut Counts) -> Result<(), String> {
    if t.actions.len() != t.length || t.steps.len() != t.length {
        return Err(format!(
            "malformed: length {} but {} actions and {} steps",
            t.length,
            t.actions.len(),
            t.steps.len()
        ));
    }
    env.reset(t.reset_seed).map_err(|e| e.to_string())?;
    let initial_state = f64s(&t.initial_state_bits);
    env.set_state(&initial_state).map_err(|e| e.to_string())?;
    if let Some(m) = f64_mismatch("initial state", &initial_state, env.state()) {
        return Err(m);
    }
    if let Some(m) = f32_mismatch("initial obs", &f32s(&t.initial_obs_bits), env.observation()) {
        return Err(m);
    }

    for (i, (&action, want)) in t.actions.iter().zip(&t.steps).enumerate() {
        let got = env.step(action).map_err(|e| e.to_string())?;
        let got_obs = got.obs.to_vec();
        let got = (got.reward, got.terminated, got.truncated);
        let got = Outcome {
            reward: got.0,
            terminated: got.1,
            truncated: got.2,
        };
        counts.steps += 1;
        let at = |m: String| format!("step {i} (action {action}): {m}");
        if let Some(m) = f64_mismatch("state", &f64s(&want.state_bits), env.state()) {
            return Err(at(m));
        }
        if let Some(m) = f32_mismatch("obs", &f32s(&want.obs_bits), &got_obs) {
            return Err(at(m));
        }
        let flags = (want.reward.to_bits(), want.terminated, want.truncated);
        if flags != (got.reward.to_bits(), got.terminated, got.truncated) {
            return Err(at(format!(
                "(reward, terminated, truncated): expected ({}, {}, {}), got ({}, {}, {})",
                want.reward,
                want.terminated,
                want.truncated,
                got.reward,
                got.terminated,
                got.truncated
            )));
        }
    }
    if let Some(last) = t.steps.last() {
        let ended_as_recorded = match t.ended_by.as_str() {
            "terminated" => last.terminated,
            "truncated" => last.truncated,
            other => return Err(format!("unknown ended_by {other:?}")),
        };
        if !ended_as_recorded {
            return Err(format!(
                "malformed: ended_by {} but the last step's flag is unset",
                t.ended_by
            ));
        }
    }
    Ok(())
}

#[test]
fn native_environments_replay_gymnasium_trajectories_bit_for_bit() {
    let dir = vectors_dir();
    let hint = "set SAPNET_VECTORS_DIR to the folder holding the recorded Gymnasium \
                trajectories (cartpole.json, …), e.g. SAPNET_VECTORS_DIR=/path/to/shared/vectors \
                cargo test --release --test it env_vectors";
    let mut files = Vec::new();
    json_files(&dir, &mut files)
        .unwrap_or_else(|e| panic!("cannot read vectors folder {}: {e}; {hint}", dir.display()));
    files.sort();
    assert!(!files.is_empty(), "no *.json in {}; {hint}", dir.display());

    let mut counts = Counts::default();
    let mut failures = String::new();
    for path in &files {
        let text = std::fs::read_to_string(path)
            .unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
        let file: VectorFile = serde_json::from_str(&text)
            .unwrap_or_else(|e| panic!("parsing {}: {e}", path.display()));
        counts.files += 1;
        for t in &file.trajectories {
            counts.trajectories += 1;
            counts.variants += usize::from(t.params.is_some());
            let replayed = make_env(&file.env_id, file.max_episode_steps, t.params.as_ref())
                .and_then(|mut env| replay(env.as_mut(), t, &mut counts));
            if let Err(m) = replayed {
                let _ = writeln!(failures, "{} / {}: {m}", path.display(), t.name);
            }
        }
    }
    assert!(
        failures.is_empty(),
        "trajectories differ from Gymnasium:\n{failures}"
    );
    assert!(
        counts.trajectories > 0 && counts.steps > 0,
        "no trajectory steps in {}",
        dir.display()
    );
    eprintln!(
        "checked {} files, {} trajectories ({} with changed physics), {} steps: all bit-exact",
        counts.files, counts.trajectories, counts.variants, counts.steps
    );
}

/// A step's outcome without its borrowed observation.
struct Outcome {
    reward: f64,
    terminated: bool,
    truncated: bool,
}
