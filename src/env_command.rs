//! `sapnet env`: episodes with uniformly random actions, a quick look at an environment
//! and its physics.

use std::io::Write;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use crate::env::{EnvError, Environment};
use crate::seeds;

/// How one episode went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpisodeSummary {
    pub steps: u32,
    pub episode_return: f64,
    /// Ended by the task's terminal condition rather than only by the time limit.
    pub terminated: bool,
}

/// Runs `episodes` episodes with actions drawn uniformly. The actions and the environment's
/// resets draw from two streams derived from `seed`; resets after the first continue the
/// environment's generator.
pub fn run(
    env: &mut dyn Environment,
    episodes: u32,
    seed: u64,
) -> Result<Vec<EpisodeSummary>, EnvError> {
    let mut rng = StdRng::seed_from_u64(seeds::derive(seed, &[seeds::Part::Name("actions")]));
    let env_seed = seeds::derive(seed, &[seeds::Part::Name("env")]);
    (0..episodes)
        .map(|episode| {
            env.reset((episode == 0).then_some(env_seed))?;
            let mut summary = EpisodeSummary {
                steps: 0,
                episode_return: 0.0,
                terminated: false,
            };
            loop {
                let actions = env.action_count();
                let step = env.step(rng.random_range(0..actions))?;
                summary.steps += 1;
                summary.episode_return += step.reward;
                if step.done() {
                    summary.terminated = step.terminated;
                    return Ok(summary);
                }
            }
        })
        .collect()
}

/// Writes one line per episode and a closing mean.
pub fn print(
    out: &mut dyn Write,
    env_id: &str,
    episodes: &[EpisodeSummary],
) -> std::io::Result<()> {
    writeln!(out, "{env_id}: {} random-action episodes", episodes.len())?;
    writeln!(
        out,
        "{:>7}  {:>6}  {:>9}  ended by",
        "episode", "steps", "return"
    )?;
    for (i, e) in episodes.iter().enumerate() {
        let ended_by = if e.terminated {
            "terminated"
        } else {
            "truncated"
        };
        writeln!(
            out,
            "{:>7}  {:>6}  {:>9.1}  {ended_by}",
            i + 1,
            e.steps,
            e.episode_return
        )?;
    }
    if !episodes.is_empty() {
        let n = episodes.len() as f64;
        let mean_steps = episodes.iter().map(|e| f64::from(e.steps)).sum::<f64>() / n;
        let mean_return = episodes.iter().map(|e| e.episode_return).sum::<f64>() / n;
        writeln!(out, "{:>7}  {mean_steps:>6.1}  {mean_return:>9.1}", "mean")?;
    }
    Ok(())
}
