//! One run, whatever the method: the environment loop, the shared replay buffer, learning,
//! the events, the greedy tests. Who acts and who learns is the method's
//! [`Selector`](crate::reuse::Selector); everything else is here, once.
//!
//! For SAP-Net this is Algorithm 3 as `DESIGN.md` reads it:
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
//!
//! A method whose sources learn ([`Learning::ActingSource`]) has that warm-up; a method
//! with a learner of its own ([`Learning::Learner`]: DQN from scratch, PRQ-learning) has
//! none, and its learner waits for `replay_start_size` transitions as any DQN does.

use std::sync::mpsc::Sender;
use std::sync::Arc;
use std::time::{Duration, Instant};

use rand::rngs::StdRng;
use rand::SeedableRng;

use super::control::{Control, Next};
use super::events::{
    ActivationSnapshot, ChosenPolicy, EpisodeRecord, Event, LockIn, MethodId, RunRecord,
    SapNetStart, SourceSummary, StepRecord, StreamOptions, TraceRecord,
};
use super::{CommandReceiver, Divergence, RunOutcome, TrainerError};
use crate::dqn::DqnConfig;
use crate::dqn::{Architecture, DqnAgent, DqnError, QNet, ReplayBuffer, Transition, UpdateReport};
use crate::env::{self, EnvConfig, Environment};
use crate::reuse::Method;
use crate::reuse::{self, Actor, EpisodeEnd, Feedback, Learning, Selector, TdError};
use crate::sapnet::{PolicyDescription, SapNetParams};
use crate::seeds;

/// Probability above which one source is said to have locked selection in.
pub const LOCK_IN: f64 = 0.99;

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

/// What one run trains, how, and for how long.
#[derive(Debug, Clone)]
pub struct RunSpec {
    /// Index of the independent run (0-based).
    pub run: u32,
    pub method: MethodId,
    /// The method with its knobs: who acts and who learns.
    pub reuse: Method,
    pub env: EnvConfig,
    pub dqn: DqnConfig,
    /// SAP-Net's graph and spreading (read by SAP-Net methods only).
    pub sapnet: SapNetParams,
    /// The library a reusing method draws on (empty for DQN from scratch).
    pub sources: Arc<Vec<SourcePolicy>>,
    pub episodes: u32,
    /// Stop after this many steps even within an episode.
    pub max_steps: Option<u64>,
    pub test_episodes: u32,
    pub seed: u64,
    pub stream: StreamOptions,
}

impl RunSpec {
    /// DQN from scratch with `hidden` layers, named `label` (the library's sources are
    /// trained this way too).
    #[allow(clippy::too_many_arguments)]
    pub fn scratch(
        run: u32,
        label: &str,
        env: EnvConfig,
        dqn: DqnConfig,
        hidden: Vec<usize>,
        episodes: u32,
        test_episodes: u32,
        seed: u64,
    ) -> Self {
        let reuse = Method::Dqn { hidden };
        let mut method = MethodId::new(0, &reuse);
        method.label = label.into();
        Self {
            run,
            method,
            reuse,
            env,
            dqn,
            sapnet: SapNetParams::default(),
            sources: Arc::new(Vec::new()),
            episodes,
            max_steps: None,
            test_episodes,
            seed,
            stream: StreamOptions::episodes(),
        }
    }
}

/// The seeds of a run's independent random streams.
pub(super) struct Streams {
    pub weights: u64,
    /// ε-greedy and minibatch sampling.
    pub agent: u64,
    pub env: u64,
    pub test_env: u64,
    /// The selector's draws (SAP-Net's from eq. 6).
    pub selection: u64,
}

impl Streams {
    pub fn new(seed: u64) -> Self {
        use seeds::Part::Name;
        Self {
            weights: seeds::derive(seed, &[Name("weights")]),
            agent: seeds::derive(seed, &[Name("agent")]),
            env: seeds::derive(seed, &[Name("env")]),
            test_env: seeds::derive(seed, &[Name("test env")]),
            selection: seeds::derive(seed, &[Name("selection")]),
        }
    }
}

/// Steps each source acted, in the run and in the episode in progress.
struct Tally {
    run: Vec<u64>,
    this_episode: Vec<u32>,
}

impl Tally {
    fn new(n: usize) -> Self {
        Self {
            run: vec![0; n],
            this_episode: vec![0; n],
        }
    }

    /// The source that acted most in this episode (the lowest index on a tie), and a fresh
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

/// Who acts and learns in a run: a copy of each source as a learner of its own (when
/// sources learn) and the method's own learner (when it has one).
struct Learners<'a> {
    sources: &'a [SourcePolicy],
    agents: Vec<DqnAgent>,
    learner: Option<DqnAgent>,
}

impl Learners<'_> {
    fn act(&self, actor: Actor, obs: &[f32], rng: &mut StdRng) -> Result<usize, DqnError> {
        match actor {
            Actor::Source(i) => self.agents[i].act(obs, rng),
            Actor::SourceGreedy(i) => self.sources[i].net.greedy_action(obs),
            Actor::Learner => self.learner().act(obs, rng),
        }
    }

    /// `max_a Q(obs, a)` of the network that acts as `actor`.
    fn value(&self, actor: Actor, obs: &[f32]) -> Result<f64, DqnError> {
        match actor {
            Actor::Source(i) => self.agents[i].value(obs),
            Actor::SourceGreedy(i) => self.sources[i].net.max_q(obs).map(f64::from),
            Actor::Learner => self.learner().value(obs),
        }
    }

    /// `max_a Q_j(obs, a)` of every source: its learning copy, if sources learn.
    fn source_values(&self, obs: &[f32]) -> Result<Vec<f64>, DqnError> {
        if self.agents.is_empty() {
            let values = self.sources.iter().map(|s| s.net.max_q(obs).map(f64::from));
            values.collect()
        } else {
            self.agents.iter().map(|a| a.value(obs)).collect()
        }
    }

    fn learner(&self) -> &DqnAgent {
        self.learner
            .as_ref()
            .expect("a method whose selector picks its learner has one")
    }

    fn updates(&self) -> u64 {
        let own = self.learner.as_ref().map_or(0, DqnAgent::updates);
        self.agents.iter().map(DqnAgent::updates).sum::<u64>() + own
    }
}

/// The library as front ends draw it: SAP-Net's own net, or for another selector the
/// library's graph under the config's SAP-Net section (none without a library, or if that
/// graph cannot be built).
fn library_start(
    spec: &RunSpec,
    selector: &dyn Selector,
    descriptions: &[PolicyDescription],
) -> Option<Box<SapNetStart>> {
    if spec.sources.is_empty() {
        return None;
    }
    let net = match selector.sapnet() {
        Some(net) => net.clone(),
        None => crate::sapnet::SapNet::from_policies(descriptions, spec.sapnet.clone()).ok()?,
    };
    Some(Box::new(SapNetStart {
        policies: spec
            .sources
            .iter()
            .map(|s| SourceSummary {
                name: s.name.clone(),
                description: s.description.clone(),
                final_score: s.final_score,
            })
            .collect(),
        net,
        score_name: selector.view().score_name,
    }))
}

/// The selector of `spec`'s method over its sources: a run's first step, and a check a
/// front end makes before starting any run (an 𝒜 the graph cannot take, a best source
/// without scores).
pub fn selector(spec: &RunSpec) -> Result<Box<dyn reuse::Selector>, TrainerError> {
    let descriptions: Vec<PolicyDescription> =
        spec.sources.iter().map(|s| s.description.clone()).collect();
    let scores: Vec<Option<f64>> = spec.sources.iter().map(|s| s.final_score).collect();
    let library = reuse::Library {
        descriptions: &descriptions,
        scores: &scores,
        gamma: spec.dqn.gamma,
        return_range: spec.env.return_range(),
        discounted_return_range: spec.env.discounted_return_range(spec.dqn.gamma),
    };
    Ok(reuse::build(&spec.reuse, library, &spec.sapnet)?)
}

/// Trains `spec` for its episodes (or `spec.max_steps` steps, whichever comes first), then
/// tests the result greedily: the chosen source, or the method's own learner. Sends the
/// events of `spec.stream` and obeys `commands` (see [`Command`]); a [`Command::Stop`] (or
/// a closed command channel) ends training early, and the run is then reported as
/// stopped, untested.
///
/// On a non-finite loss the error carries the network with its last good weights.
pub fn train(
    spec: &RunSpec,
    events: &Sender<Event>,
    commands: &CommandReceiver,
) -> Result<RunOutcome, TrainerError> {
    let started = Instant::now();
    let streams = Streams::new(spec.seed);
    let mut env = env::make(&spec.env)?;
    let descriptions: Vec<PolicyDescription> =
        spec.sources.iter().map(|s| s.description.clone()).collect();
    let mut selector = selector(spec)?;
    let learning = selector.learning();
    // Asked once: a method that needs nothing measures nothing.
    let needs = selector.needs();
    let n = spec.sources.len();
    let mut agents = match learning {
        Learning::ActingSource => spec
            .sources
            .iter()
            .map(|s| DqnAgent::new(s.net.deep_copy()?, &spec.dqn))
            .collect::<Result<Vec<_>, _>>()?,
        Learning::Learner => Vec::new(),
    };
    for agent in &mut agents {
        agent.measure_td_error(needs.td_error);
        agent.interrupt_rounds_with(commands.stop_flag());
    }
    let learner = match spec.reuse.learner_hidden() {
        Some(hidden) => {
            let architecture =
                Architecture::new(env.observation_size(), &hidden, env.action_count());
            let net = QNet::with_init(
                architecture,
                spec.dqn.init,
                &mut StdRng::seed_from_u64(streams.weights),
            )?;
            let mut learner = DqnAgent::new(net, &spec.dqn)?;
            learner.interrupt_rounds_with(commands.stop_flag());
            Some(learner)
        }
        None => None,
    };
    let mut learners = Learners {
        sources: &spec.sources,
        agents,
        learner,
    };
    let mut replay = ReplayBuffer::new(spec.dqn.replay_capacity, env.observation_size());
    let mut rng = StdRng::seed_from_u64(streams.agent);
    let mut selection_rng = StdRng::seed_from_u64(streams.selection);
    let mut control = Control::new(commands, spec.stream.trace);
    let mut tally = Tally::new(n);

    let _ = events.send(Event::RunStarted {
        run: spec.run,
        method: spec.method.clone(),
        planned_episodes: spec.episodes,
        sapnet: library_start(spec, selector.as_ref(), &descriptions),
    });
    let mut record = RunRecord {
        run: spec.run,
        method: spec.method.clone(),
        seed: spec.seed,
        episodes: 0,
        steps: 0,
        updates: 0,
        chosen: None,
        source_steps: Vec::new(),
        lock_in_step: None,
        positive: Vec::new(),
        negative: Vec::new(),
        exclusions: 0,
        test_returns: Vec::new(),
        stopped: false,
        wall_s: 0.0,
    };
    let replay_start = spec.dqn.replay_start_size as u64;
    let warm_up = match learning {
        Learning::ActingSource => n as u64 * replay_start,
        Learning::Learner => 0,
    };
    let step_budget = spec.max_steps.unwrap_or(u64::MAX);
    let snapshots = n > 0;
    let mut lock_in: Option<LockIn> = None;
    let snapshot = |selector: &dyn Selector,
                    tally: &Tally,
                    step: u64,
                    episode: u32,
                    lock_in: Option<LockIn>| {
        let view = selector.view();
        Event::Activations(ActivationSnapshot {
            run: spec.run,
            method: spec.method.clone(),
            step,
            episode,
            score_name: view.score_name,
            activations: view.scores,
            probabilities: view.probabilities,
            selections: tally.run.clone(),
            positive: view.positive,
            negative: view.negative,
            lock_in,
            excluded: view.excluded,
        })
    };
    let send_traces = |selector: &mut dyn Selector, step: u64| {
        for activation in selector.take_activations() {
            let _ = events.send(Event::Trace(TraceRecord {
                run: spec.run,
                method: spec.method.clone(),
                step,
                policy: activation.policy,
                calls: activation.calls,
            }));
        }
    };
    let mut last_snapshot = Instant::now();
    // The learner whose loss an episode's record shows: the last source that acted, or the
    // method's own learner.
    let mut last_source = 0;
    let mut steps: u64 = 0;
    // The observation acted on, copied out of the environment each step (no allocation).
    let mut obs: Vec<f32> = env.reset(Some(streams.env))?.to_vec();

    'episodes: for episode in 1..=spec.episodes {
        let mut reward = 0.0;
        let mut discounted = 0.0;
        let mut discount = 1.0;
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
            let actor = if in_warm_up {
                Actor::Source((steps / replay_start) as usize)
            } else {
                selector.act(&mut selection_rng)
            };
            let action = learners.act(actor, &obs, &mut rng)?;
            // V_i(s_t) of the acting source as it acts, before its update.
            let value = match actor.source() {
                Some(i) if needs.values && !in_warm_up => Some((i, learners.value(actor, &obs)?)),
                _ => None,
            };
            let step = env.step(action)?;
            replay.push(Transition {
                obs: &obs,
                action,
                reward: step.reward,
                next_obs: step.obs,
                terminated: step.terminated,
                truncated: step.truncated,
            });
            steps += 1;
            if let Some(i) = actor.source() {
                last_source = i;
            }
            if let Some((i, value)) = value {
                selector.on_acted(i, step.reward, value);
            }

            let mut report = None;
            let mut judgment = None;
            let mut deposit = None;
            if !in_warm_up {
                if let Some(i) = actor.source() {
                    tally.run[i] += 1;
                    tally.this_episode[i] += 1;
                }
                let (agent, name) = match learning {
                    Learning::ActingSource => {
                        let i = actor.source().expect("sources learn only when they act");
                        (&mut learners.agents[i], Some(i))
                    }
                    Learning::Learner => (
                        learners.learner.as_mut().expect("the method has a learner"),
                        None,
                    ),
                };
                report = match agent.observe(&replay, &mut rng) {
                    Ok(report) => report,
                    Err(source) => {
                        let method = match name {
                            Some(i) => format!("{} ({})", spec.method, spec.sources[i].name),
                            None => spec.method.to_string(),
                        };
                        let last_good = match name {
                            Some(i) => learners.agents.swap_remove(i).into_online(),
                            None => learners.learner.take().expect("observed").into_online(),
                        };
                        return Err(TrainerError::Diverged(Box::new(Divergence {
                            method,
                            run: spec.run,
                            source,
                            episodes: record.episodes,
                            steps,
                            last_good,
                        })));
                    }
                };
                // A round without an update (update_interval > 1) has nothing to judge.
                if let (Some(report), Some(i)) = (&report, name) {
                    selector.set_tracing(control.trace());
                    judgment = selector.on_update(i, &feedback(report));
                    if judgment == Some(true) {
                        deposit = selector.last_deposit();
                    }
                    send_traces(selector.as_mut(), steps);
                }
                selector.on_step();
                if record.lock_in_step.is_none()
                    && selector.top_probability().is_some_and(|p| p > LOCK_IN)
                {
                    record.lock_in_step = Some(steps);
                    // Once per run: which source it was, for the live view.
                    let probabilities = selector.view().probabilities;
                    lock_in = probabilities
                        .iter()
                        .position(|&p| p > LOCK_IN)
                        .map(|source| LockIn {
                            source,
                            step: steps,
                        });
                }
            }
            if spec.stream.steps {
                let _ = events.send(Event::Step(StepRecord {
                    run: spec.run,
                    step: steps,
                    episode,
                    policy: actor.source(),
                    action,
                    reward: step.reward,
                    update: report,
                    judgment,
                    deposit,
                    warm_up: in_warm_up,
                }));
            }
            if snapshots
                && (control.is_slow()
                    || (spec.stream.snapshot_interval != Duration::MAX
                        && steps.is_multiple_of(16)
                        && last_snapshot.elapsed() >= spec.stream.snapshot_interval))
            {
                let _ = events.send(snapshot(selector.as_ref(), &tally, steps, episode, lock_in));
                last_snapshot = Instant::now();
            }
            reward += step.reward;
            discounted += discount * step.reward;
            discount *= spec.dqn.gamma;
            episode_steps += 1;
            if step.done() {
                let bootstrapped =
                    step.truncated && !step.terminated && !spec.dqn.truncation_as_terminal;
                if needs.values && bootstrapped {
                    selector.on_truncated(&learners.source_values(step.obs)?);
                }
                obs.copy_from_slice(env.reset(None)?);
                break;
            }
            obs.copy_from_slice(step.obs);
        }
        record.episodes = episode;
        selector.set_tracing(control.trace());
        selector.on_episode_end(&EpisodeEnd {
            episode_return: reward,
            discounted_return: discounted,
        });
        send_traces(selector.as_mut(), steps);
        if snapshots {
            let _ = events.send(snapshot(selector.as_ref(), &tally, steps, episode, lock_in));
        }
        let shown = match learning {
            Learning::ActingSource => &learners.agents[last_source],
            Learning::Learner => learners.learner(),
        };
        let _ = events.send(Event::EpisodeEnded(EpisodeRecord {
            run: spec.run,
            method: spec.method.clone(),
            episode,
            reward,
            steps: episode_steps,
            loss: shown.last_loss(),
            statistic_loss: shown.statistic_loss(),
            epsilon: shown.epsilon(),
            policy: if snapshots { tally.end_episode() } else { None },
            wall_s: started.elapsed().as_secs_f64(),
        }));
    }

    record.steps = steps;
    record.updates = learners.updates();
    record.source_steps = tally.run.clone();
    let view = selector.view();
    (record.positive, record.negative) = (view.positive.clone(), view.negative.clone());
    record.exclusions = selector.exclusions_made();
    let net = match selector.chosen() {
        Some(chosen) => {
            record.chosen = Some(ChosenPolicy {
                index: chosen,
                name: spec.sources[chosen].name.clone(),
                hidden: spec.sources[chosen].description.hidden.clone(),
                score: view.scores[chosen],
                score_name: view.score_name.into(),
            });
            learners.agents.swap_remove(chosen).into_online()
        }
        None => learners
            .learner
            .take()
            .expect("a method that chooses no source has a learner")
            .into_online(),
    };
    if !record.stopped {
        let mut test_env = env::make(&spec.env)?;
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

/// What a selector hears of a learner's round of updates.
fn feedback(report: &UpdateReport) -> Feedback {
    Feedback {
        loss: report.loss,
        previous_statistic_loss: report.previous_statistic_loss,
        statistic_loss: report.statistic_loss,
        td: report.td.map(|td| TdError {
            before: td.before,
            after: td.after,
        }),
    }
}

/// Returns of `episodes` greedy episodes (the paper's "Number of test").
pub fn test_greedy(
    net: &QNet,
    env: &mut dyn Environment,
    episodes: u32,
    seed: u64,
) -> Result<Vec<f64>, TrainerError> {
    let mut returns = Vec::with_capacity(episodes as usize);
    let mut obs = Vec::with_capacity(env.observation_size());
    for episode in 0..episodes {
        obs.clear();
        obs.extend_from_slice(env.reset((episode == 0).then_some(seed))?);
        let mut total = 0.0;
        loop {
            let step = env.step(net.greedy_action(&obs)?)?;
            total += step.reward;
            if step.done() {
                break;
            }
            obs.copy_from_slice(step.obs);
        }
        returns.push(total);
    }
    Ok(returns)
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

    /// Every stream of every run of a protocol, and of a sweep over its `seed`, is its own:
    /// no run's seed or stream equals another's (the derivation before 2026-12 gave
    /// `seed 1, method 0` the streams of `seed 0, method 1`).
    #[test]
    fn every_stream_of_a_sweep_over_seeds_is_distinct() {
        let mut config = crate::config::Config::from_ron(
            include_str!("../../assets/reuse_cartpole.ron"),
            "reuse_cartpole.ron",
        )
        .unwrap();
        config.protocol.runs = 20;
        let mut seen = std::collections::HashSet::new();
        let mut count = 0;
        for seed in 0..10 {
            config.seed = seed;
            for spec in crate::experiment::run_specs(&config, None) {
                let s = Streams::new(spec.seed);
                for stream in [
                    spec.seed,
                    s.weights,
                    s.agent,
                    s.env,
                    s.test_env,
                    s.selection,
                ] {
                    seen.insert(stream);
                    count += 1;
                }
            }
        }
        assert_eq!(count, 10 * 20 * 11 * 6);
        assert_eq!(seen.len(), count);
    }
}
