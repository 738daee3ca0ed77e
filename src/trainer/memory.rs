//! What a protocol will hold in memory, checked against the machine before anything is
//! allocated: a typo such as `Dqn(hidden: [100000, 100000])` (40 GB per copy of the
//! network) is refused with what it needs, not met with an abort or a swapping machine.

use anyhow::{bail, Result};

use crate::dqn::Architecture;
use crate::trainer::Budget;
use crate::trainer::RunSpec;

/// Copies of a learning network's parameters: online, target, Adam's two moments, and the
/// gradients (a thread keeps one set per network shape, `dqn/scratch.rs`; counted per
/// learner here, an upper bound).
const LEARNER_COPIES: f64 = 5.0;

/// Bytes one stored transition takes: its record in the replay buffer
/// ([`crate::dqn::transition_bytes`]).
fn transition_bytes(obs: usize) -> f64 {
    crate::dqn::transition_bytes(obs) as f64
}

fn parameter_bytes(architecture: &Architecture) -> f64 {
    architecture
        .layer_shapes()
        .iter()
        .map(|&(out, inp)| (out as f64) * (inp as f64 + 1.0))
        .sum::<f64>()
        * 4.0
}

/// About how many bytes `spec`'s run holds at most: each network (learning ones with their
/// target, gradients and Adam state) and the replay memories, which hold at most every
/// step of the run.
pub fn run_bytes(spec: &RunSpec) -> Result<f64, crate::env::EnvError> {
    let (obs, actions) = crate::env::spaces(&spec.env)?;
    let sources = spec
        .sources
        .iter()
        .map(|s| parameter_bytes(s.net.architecture()));
    let (networks, learners) = match spec.reuse.learner_hidden() {
        // DQN from scratch, PRQ-learning: one learner; the sources only act.
        Some(hidden) => {
            let learner = parameter_bytes(&Architecture::new(obs, &hidden, actions));
            (learner * LEARNER_COPIES + sources.sum::<f64>(), 1.0)
        }
        // Selectors whose acting source learns: every source is a learner.
        None => (
            sources.sum::<f64>() * LEARNER_COPIES,
            spec.sources.len() as f64,
        ),
    };
    // A Gymnasium task's time limit may be unknown here: the replay's capacity bounds it.
    let steps = match spec.budget {
        Budget::Steps(s) => s as f64,
        Budget::Episodes(n) => spec
            .env
            .max_episode_steps()
            .map_or(f64::INFINITY, |t| f64::from(n) * f64::from(t)),
    };
    let replay = (learners * spec.dqn.replay_capacity as f64).min(steps) * transition_bytes(obs);
    // Each learner keeps its target network's value of every stored transition.
    let target_values = learners
        * (spec.dqn.replay_capacity as f64).min(steps)
        * crate::dqn::TARGET_VALUE_BYTES as f64;
    Ok(networks + replay + target_values)
}

/// Refuses `specs` run `jobs` at a time if the largest of them could not fit in this
/// machine's memory together. Machines whose memory cannot be read are not checked.
pub fn check(specs: &[RunSpec], jobs: usize) -> Result<()> {
    let Some(machine) = total_memory() else {
        return Ok(());
    };
    let sized = specs
        .iter()
        .map(|s| Ok((s, run_bytes(s)?)))
        .collect::<Result<Vec<_>, crate::env::EnvError>>()?;
    let Some((largest, bytes)) = sized.into_iter().max_by(|a, b| a.1.total_cmp(&b.1)) else {
        return Ok(());
    };
    let together = jobs.clamp(1, specs.len()) as f64;
    if bytes * together > machine as f64 {
        bail!(
            "{} needs about {} per run ({} at once with {} runs at a time), and this machine \
             has {}: use smaller networks (`hidden`, `sources.units`), a smaller \
             `dqn.replay_capacity` or fewer --jobs",
            largest.method,
            human(bytes),
            human(bytes * together),
            together,
            human(machine as f64)
        );
    }
    Ok(())
}

/// `MemTotal` of /proc/meminfo, in bytes (Linux).
fn total_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// `4.2e10` bytes → `39.1 GiB`.
fn human(bytes: f64) -> String {
    let units = ["B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut value = bytes;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < units.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit + 1 == units.len() && value >= 1024.0 {
        return format!("{bytes:.2e} B");
    }
    format!("{value:.1} {}", units[unit])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    fn dqn_spec(hidden: Vec<usize>, capacity: usize) -> RunSpec {
        let config = Config::default();
        let mut dqn = config.dqn.clone();
        dqn.replay_capacity = capacity;
        RunSpec::scratch(0, "dqn", config.env.clone(), dqn, hidden, 100, 1, 0)
    }

    #[test]
    fn a_dqn_run_needs_its_network_five_times_and_its_steps_in_replay() {
        // CartPole: 4 inputs, 2 actions; [10]: 10·5 + 2·11 = 72 parameters, 288 bytes.
        // 100 episodes of at most 500 steps under a capacity of 1,000: 1,000 records of
        // (2·4 + 2)·4 = 40 bytes, and the learner's 8-byte target value of each.
        assert_eq!(
            run_bytes(&dqn_spec(vec![10], 1_000)).unwrap(),
            5.0 * 288.0 + 40_000.0 + 8_000.0
        );
        // A capacity above the run's steps holds only the steps: 100·500.
        assert_eq!(
            run_bytes(&dqn_spec(vec![10], 1_000_000)).unwrap(),
            5.0 * 288.0 + 50_000.0 * (40.0 + 8.0)
        );
    }

    #[test]
    fn a_network_that_cannot_fit_is_refused_with_what_it_needs() {
        let specs = vec![dqn_spec(vec![100_000, 100_000], 1_000)];
        if total_memory().is_none() {
            return;
        }
        let err = check(&specs, 2).unwrap_err().to_string();
        assert!(err.contains("needs about 186.3 GiB per run"), "{err}");
        assert!(check(&[dqn_spec(vec![100, 100], 1_000_000)], 2).is_ok());
    }

    #[test]
    fn sizes_read_in_binary_units() {
        assert_eq!(human(512.0), "512.0 B");
        assert_eq!(human(1536.0), "1.5 KiB");
        assert_eq!(human(4e10), "37.3 GiB");
    }
}
