//! One run of transfer learning with SAP-Net: Algorithm 3 as `DESIGN.md` reads it.
//!
//! ```text
//! load the N source policies, each with its own target network and Adam state
//! one shared replay buffer D for the target task
//! warm-up: the first N × replay_start_size steps of the run, π_0, π_1, … act in turn,
//!          replay_start_size steps each, storing transitions, without learning
//! every later step:
//!     i  ~ P(π_i) = softmax(A / τ)                       # eq. 6
//!     a  = π_i's ε-greedy action; store (s, a, r, s') in D
//!     π_i does one gradient update on a minibatch of D; T_a = E_{t+1} − E_t   # eq. 7
//!     activate(i, 𝒜) if T_a ≤ 0 else activate(i, 0)    # eq. 8–11
//! the chosen policy is argmax_i A_i; it is tested greedily
//! ```

use std::sync::mpsc::{Receiver, Sender};
use std::sync::Arc;
use std::time::{Duration, Instant};

use rand::rngs::StdRng;
use rand::SeedableRng;

use super::control::{Control, Next};
use super::dqn_run::{test_greedy, Streams};
use super::events::{
    ActivationSnapshot, ChosenPolicy, Command, EpisodeRecord, Event, RunRecord, SapNetStart,
    SourceSummary, StepRecord, StreamOptions, TraceRecord,
};
use super::{Divergence, RunOutcome, TrainerError};
use crate::config::DqnConfig;
use crate::dqn::{DqnAgent, QNet, ReplayBuffer, Transition};
use crate::env::{self, EnvConfig};
use crate::sapnet::{PolicyDescription, SapNet, SapNetParams, TraceStep};

/// A policy of the source library, ready to be reused.
#[derive(Debug)]
pub struct SourcePolicy {
    /// Its name in the library, e.g. `source-3`.
    pub name: String,
    /// The trained network; every run learns on a copy of it.
    pub net: QNet,
    pub description: PolicyDescription,
    pub final_score: Option<f64>,
}

/// What a transfer run reuses and for how long.
#[derive(Debug, Clone)]
pub struct TransferRunSpec {
    pub run: u32,
    pub method: String,
    pub env: EnvConfig,
    pub dqn: DqnConfig,
    pub sapnet: SapNetParams,
    pub sources: Arc<Vec<SourcePolicy>>,
    pub episodes: u32,
    /// Stop after this many steps even within an episode.
    pub max_steps: Option<u64>,
    pub test_episodes: u32,
    pub seed: u64,
    pub stream: StreamOptions,
}

/// Selections and judgments of every policy since the run started.
struct Tally {
    selections: Vec<u64>,
    positive: Vec<u64>,
    negative: Vec<u64>,
    /// Steps each policy acted in the current episode, for its most frequent one.
    this_episode: Vec<u32>,
}

impl Tally {
    fn new(n: usize) -> Self {
        Self {
            selections: vec![0; n],
            positive: vec![0; n],
            negative: vec![0; n],
            this_episode: vec![0; n],
        }
    }

    /// The policy that acted most in this episode (the lowest index on a tie), and a fresh
    /// count for the next one.
    fn end_episode(&mut self) -> Option<u32> {
        let mut best: Option<usize> = None;
        for (i, &n) in self.this_episode.iter().enumerate() {
            if n > 0 && best.is_none_or(|b| n > self.this_episode[b]) {
                best = Some(i);
            }
        }
        self.this_episode.iter_mut().for_each(|n| *n = 0);
        best.map(|b| b as u32)
    }
}

/// Trains the target task by reusing `spec.sources` through SAP-Net (Algorithm 3), then
/// tests the chosen policy greedily. Events and commands as for [`super::train`]; the
/// returned network is the chosen policy after training.
pub fn train_transfer(
    spec: &TransferRunSpec,
    events: &Sender<Event>,
    commands: &Receiver<Command>,
) -> Result<RunOutcome, TrainerError> {
    let started = Instant::now();
    let streams = Streams::new(spec.seed);
    let mut env = env::make(&spec.env);
    let descriptions: Vec<PolicyDescription> =
        spec.sources.iter().map(|s| s.description.clone()).collect();
    let mut sapnet = SapNet::from_policies(&descriptions, spec.sapnet.clone())?;
    let n = spec.sources.len();
    let mut agents = spec
        .sources
        .iter()
        .map(|s| DqnAgent::new(s.net.deep_copy()?, &spec.dqn))
        .collect::<Result<Vec<_>, _>>()?;
    let mut replay = ReplayBuffer::new(spec.dqn.replay_capacity, env.observation_size());
    let mut rng = StdRng::seed_from_u64(streams.agent);
    let mut selection_rng = StdRng::seed_from_u64(streams.selection);
    let mut control = Control::new(commands, spec.stream.trace);
    let mut tally = Tally::new(n);

    let _ = events.send(Event::RunStarted {
        run: spec.run,
        method: spec.method.clone(),
        planned_episodes: spec.episodes,
        sapnet: Some(Box::new(SapNetStart {
            policies: spec
                .sources
                .iter()
                .map(|s| SourceSummary {
                    name: s.name.clone(),
                    description: s.description.clone(),
                    final_score: s.final_score,
                })
                .collect(),
            net: sapnet.clone(),
        })),
    });
    let mut record = RunRecord {
        run: spec.run,
        method: spec.method.clone(),
        seed: spec.seed,
        episodes: 0,
        steps: 0,
        updates: 0,
        chosen: None,
        test_returns: Vec::new(),
        stopped: false,
        wall_s: 0.0,
    };
    let replay_start = spec.dqn.replay_start_size as u64;
    let warm_up = n as u64 * replay_start;
    let step_budget = spec.max_steps.unwrap_or(u64::MAX);
    let snapshot = |sapnet: &SapNet, tally: &Tally, step: u64, episode: u32| {
        Event::Activations(ActivationSnapshot {
            run: spec.run,
            step,
            episode,
            activations: sapnet.activations().to_vec(),
            probabilities: sapnet.probabilities(),
            selections: tally.selections.clone(),
            positive: tally.positive.clone(),
            negative: tally.negative.clone(),
        })
    };
    let mut last_snapshot = Instant::now();
    let mut last_policy;
    let mut steps: u64 = 0;
    let mut obs = env.reset(Some(streams.env));

    'episodes: for episode in 1..=spec.episodes {
        let mut reward = 0.0;
        let mut episode_steps = 0;
        loop {
            if steps >= step_budget {
                break 'episodes;
            }
            if control.before_step() == Next::Stop {
                record.stopped = true;
                break 'episodes;
            }
            let in_warm_up = steps < warm_up;
            let i = if in_warm_up {
                (steps / replay_start) as usize
            } else {
                sapnet.select(&mut selection_rng)
            };
            let action = agents[i].act(&obs, &mut rng)?;
            let step = env.step(action);
            replay.push(Transition {
                obs: &obs,
                action,
                reward: step.reward,
                next_obs: &step.obs,
                terminated: step.terminated,
                truncated: step.truncated,
            });
            steps += 1;
            last_policy = i;

            let mut report = None;
            if !in_warm_up {
                tally.selections[i] += 1;
                tally.this_episode[i] += 1;
                report = match agents[i].observe(&replay, &mut rng) {
                    Ok(report) => report,
                    Err(source) => {
                        return Err(TrainerError::Diverged(Box::new(Divergence {
                            method: format!("{} ({})", spec.method, spec.sources[i].name),
                            run: spec.run,
                            source,
                            episodes: record.episodes,
                            steps,
                            last_good: agents.swap_remove(i).into_online(),
                        })));
                    }
                };
                // A round without an update (update_interval > 1) has nothing to judge.
                if let Some(report) = report {
                    let positive = report.transition() <= 0.0;
                    if positive {
                        tally.positive[i] += 1;
                        if control.trace() {
                            let mut calls: Vec<TraceStep> = Vec::new();
                            sapnet.activate_traced(i, true, &mut calls);
                            let _ = events.send(Event::Trace(TraceRecord {
                                run: spec.run,
                                step: steps,
                                policy: i,
                                calls,
                            }));
                        } else {
                            sapnet.activate(i, true);
                        }
                    } else {
                        tally.negative[i] += 1;
                    }
                }
            }
            if spec.stream.steps {
                let _ = events.send(Event::Step(StepRecord {
                    run: spec.run,
                    step: steps,
                    episode,
                    policy: i,
                    action,
                    reward: step.reward,
                    loss: report.map(|r| r.loss),
                    transition: report.map(|r| r.transition()),
                    warm_up: in_warm_up,
                }));
            }
            if control.is_slow()
                || (spec.stream.snapshot_interval != Duration::MAX
                    && steps % 16 == 0
                    && last_snapshot.elapsed() >= spec.stream.snapshot_interval)
            {
                let _ = events.send(snapshot(&sapnet, &tally, steps, episode));
                last_snapshot = Instant::now();
            }
            reward += step.reward;
            episode_steps += 1;
            let done = step.done();
            obs = if done { env.reset(None) } else { step.obs };
            if done {
                break;
            }
        }
        record.episodes = episode;
        let _ = events.send(snapshot(&sapnet, &tally, steps, episode));
        let actor = &agents[last_policy];
        let _ = events.send(Event::EpisodeEnded(EpisodeRecord {
            run: spec.run,
            method: spec.method.clone(),
            episode,
            reward,
            steps: episode_steps,
            loss: actor.last_loss(),
            statistic_loss: actor.statistic_loss(),
            epsilon: actor.epsilon(),
            policy: tally.end_episode(),
            wall_s: started.elapsed().as_secs_f64(),
        }));
    }

    record.steps = steps;
    record.updates = agents.iter().map(DqnAgent::updates).sum();
    let chosen = sapnet.chosen();
    record.chosen = Some(ChosenPolicy {
        index: chosen,
        name: spec.sources[chosen].name.clone(),
        hidden: spec.sources[chosen].description.hidden.clone(),
        activation: sapnet.activations()[chosen],
    });
    let net = agents.swap_remove(chosen).into_online();
    if !record.stopped {
        let mut test_env = env::make(&spec.env);
        record.test_returns = test_greedy(
            &net,
            test_env.as_mut(),
            spec.test_episodes,
            streams.test_env,
        )?;
    }
    record.wall_s = started.elapsed().as_secs_f64();
    let _ = events.send(Event::RunEnded(record.clone()));
    Ok(RunOutcome { record, net })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_most_frequent_policy_of_an_episode_wins_and_the_count_restarts() {
        let mut tally = Tally::new(3);
        tally.this_episode = vec![2, 5, 5];
        assert_eq!(tally.end_episode(), Some(1));
        assert_eq!(tally.this_episode, vec![0, 0, 0]);
        // An episode spent in the warm-up selected nobody.
        assert_eq!(tally.end_episode(), None);
    }
}
