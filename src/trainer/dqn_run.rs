//! One run of DQN from scratch: the paper's baselines, and how source policies are trained.

use std::sync::mpsc::{Receiver, Sender};
use std::time::Instant;

use rand::rngs::StdRng;
use rand::SeedableRng;

use super::control::{Control, Next};
use super::events::{Command, EpisodeRecord, Event, RunRecord, StepRecord, StreamOptions};
use super::{Divergence, RunOutcome, TrainerError};
use crate::config::DqnConfig;
use crate::dqn::{Architecture, DqnAgent, QNet, ReplayBuffer, Transition};
use crate::env::{self, EnvConfig, Environment};
use crate::seeds;

/// What a DQN run trains and for how long.
#[derive(Debug, Clone)]
pub struct DqnRunSpec {
    pub run: u32,
    pub method: String,
    pub env: EnvConfig,
    pub dqn: DqnConfig,
    pub hidden: Vec<usize>,
    pub episodes: u32,
    /// Stop after this many steps even within an episode.
    pub max_steps: Option<u64>,
    pub test_episodes: u32,
    pub seed: u64,
    pub stream: StreamOptions,
}

/// The seeds of a run's independent random streams.
pub(super) struct Streams {
    pub weights: u64,
    /// ε-greedy and minibatch sampling.
    pub agent: u64,
    pub env: u64,
    pub test_env: u64,
    /// SAP-Net's draws from eq. 6.
    pub selection: u64,
}

impl Streams {
    pub fn new(seed: u64) -> Self {
        Self {
            weights: seeds::derive(seed, &[0]),
            agent: seeds::derive(seed, &[1]),
            env: seeds::derive(seed, &[2]),
            test_env: seeds::derive(seed, &[3]),
            selection: seeds::derive(seed, &[4]),
        }
    }
}

/// Trains one DQN for `spec.episodes` episodes (or `spec.max_steps` steps, whichever comes
/// first), then tests it greedily. Sends the events of `spec.stream` and obeys `commands`
/// (see [`Command`]); a [`Command::Stop`] (or a closed command channel) ends training early,
/// and the run is then reported as stopped, untested.
///
/// On a non-finite loss the error carries the network with its last good weights.
pub fn train(
    spec: &DqnRunSpec,
    events: &Sender<Event>,
    commands: &Receiver<Command>,
) -> Result<RunOutcome, TrainerError> {
    let started = Instant::now();
    let streams = Streams::new(spec.seed);
    let mut env = env::make(&spec.env);
    let architecture = Architecture::new(env.observation_size(), &spec.hidden, env.action_count());
    let net = QNet::new(architecture, &mut StdRng::seed_from_u64(streams.weights))?;
    let mut agent = DqnAgent::new(net, &spec.dqn)?;
    let mut replay = ReplayBuffer::new(spec.dqn.replay_capacity, env.observation_size());
    let mut rng = StdRng::seed_from_u64(streams.agent);
    let mut control = Control::new(commands, spec.stream.trace);

    let _ = events.send(Event::RunStarted {
        run: spec.run,
        method: spec.method.clone(),
        planned_episodes: spec.episodes,
        sapnet: None,
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
    let mut obs = env.reset(Some(streams.env));
    let step_budget = spec.max_steps.unwrap_or(u64::MAX);
    'episodes: for episode in 1..=spec.episodes {
        let (mut reward, mut steps) = (0.0, 0);
        loop {
            if agent.steps() >= step_budget {
                break 'episodes;
            }
            if control.before_step() == Next::Stop {
                record.stopped = true;
                break 'episodes;
            }
            let action = agent.act(&obs, &mut rng)?;
            let step = env.step(action);
            replay.push(Transition {
                obs: &obs,
                action,
                reward: step.reward,
                next_obs: &step.obs,
                terminated: step.terminated,
                truncated: step.truncated,
            });
            let report = match agent.observe(&replay, &mut rng) {
                Ok(report) => report,
                Err(err) => {
                    return Err(TrainerError::Diverged(Box::new(Divergence {
                        method: spec.method.clone(),
                        run: spec.run,
                        source: err,
                        episodes: record.episodes,
                        steps: agent.steps(),
                        last_good: agent.into_online(),
                    })));
                }
            };
            if spec.stream.steps {
                let _ = events.send(Event::Step(StepRecord {
                    run: spec.run,
                    step: agent.steps(),
                    episode,
                    policy: 0,
                    action,
                    reward: step.reward,
                    loss: report.map(|r| r.loss),
                    transition: None,
                    warm_up: false,
                }));
            }
            reward += step.reward;
            steps += 1;
            obs = if step.done() {
                env.reset(None)
            } else {
                step.obs
            };
            if step.done() {
                break;
            }
        }
        record.episodes = episode;
        let _ = events.send(Event::EpisodeEnded(EpisodeRecord {
            run: spec.run,
            method: spec.method.clone(),
            episode,
            reward,
            steps,
            loss: agent.last_loss(),
            statistic_loss: agent.statistic_loss(),
            epsilon: agent.epsilon(),
            policy: None,
            wall_s: started.elapsed().as_secs_f64(),
        }));
    }
    record.steps = agent.steps();
    record.updates = agent.updates();
    let net = agent.into_online();
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

/// Returns of `episodes` greedy episodes (the paper's "Number of test").
pub fn test_greedy(
    net: &QNet,
    env: &mut dyn Environment,
    episodes: u32,
    seed: u64,
) -> Result<Vec<f64>, TrainerError> {
    let mut returns = Vec::with_capacity(episodes as usize);
    for episode in 0..episodes {
        let mut obs = env.reset((episode == 0).then_some(seed));
        let mut total = 0.0;
        loop {
            let step = env.step(net.greedy_action(&obs)?);
            total += step.reward;
            if step.done() {
                break;
            }
            obs = step.obs;
        }
        returns.push(total);
    }
    Ok(returns)
}
