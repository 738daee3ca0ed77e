//! A run in progress: everything [`train`](super::train)'s loop carries from one step to
//! the next, and what a step, the end of an episode and the end of the run do with it.

use std::sync::mpsc::Sender;
use std::time::{Duration, Instant};

use rand::rngs::StdRng;
use rand::SeedableRng;

use super::control::{Control, Next};
use super::events::{
    ActivationSnapshot, ChosenPolicy, CutEpisode, EpisodeRecord, Event, LibraryStart, LockIn,
    RunRecord, SourceSummary, StepRecord, TraceRecord,
};
use super::networks::{RunNetworks, ValueBuffers};
use super::spec::{selector, RunSpec};
use super::{CommandReceiver, Divergence, RunOutcome, TrainerError};
use crate::dqn::{DqnError, QNet, ReplayBuffer, Transition, UpdateReport};
use crate::env::{self, Environment};
use crate::reuse::{
    Actor, Combined, Deposit, EpisodeEnd, Feedback, LearnerRound, Learning, Needs, Selector,
    TdError, Tested,
};
use crate::sapnet::SapNet;
use crate::seeds;

/// Probability above which one source is said to have locked selection in (defined with
/// lock-in itself, in reuse/lock_in.rs).
pub use crate::reuse::lock_in::THRESHOLD as LOCK_IN;

/// The seeds of a run's independent random streams.
struct RunSeeds {
    weights: u64,
    /// ε-greedy and minibatch sampling.
    agent: u64,
    env: u64,
    test_env: u64,
    /// The selector's draws (SAP-Net's from eq. 6).
    selection: u64,
}

impl RunSeeds {
    fn new(seed: u64) -> Self {
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

    fn count(&mut self, source: usize) {
        self.run[source] += 1;
        self.this_episode[source] += 1;
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

/// The sums of the episode in progress.
pub(super) struct EpisodeReturn {
    pub reward: f64,
    pub discounted: f64,
    /// `γ^t` of the next step's reward.
    discount: f64,
    pub steps: u32,
}

impl EpisodeReturn {
    pub fn new() -> Self {
        Self {
            reward: 0.0,
            discounted: 0.0,
            discount: 1.0,
            steps: 0,
        }
    }

    pub fn add(&mut self, reward: f64, gamma: f64) {
        self.reward += reward;
        self.discounted += self.discount * reward;
        self.discount *= gamma;
        self.steps += 1;
    }
}

/// What one step brought.
pub(super) struct Stepped {
    pub reward: f64,
    /// The episode is over (terminated or truncated); the environment was reset.
    pub done: bool,
}

/// What the learner of a step did with it, and what the selector made of that.
#[derive(Default)]
struct Learned {
    report: Option<UpdateReport>,
    judgment: Option<bool>,
    deposit: Option<Deposit>,
}

/// One run between its start and its end, whatever the method.
pub(super) struct Run<'a> {
    spec: &'a RunSpec,
    events: &'a Sender<Event>,
    control: Control<'a>,
    started: Instant,
    seeds: RunSeeds,
    env: Box<dyn Environment>,
    selector: Box<dyn Selector>,
    learning: Learning,
    /// What the selector asks the run to measure, asked once: a method that needs nothing
    /// measures nothing.
    needs: Needs,
    networks: RunNetworks<'a>,
    replay: ReplayBuffer,
    rng: StdRng,
    selection_rng: StdRng,
    tally: Tally,
    record: RunRecord,
    replay_start: u64,
    /// Steps of the warm-up, whose sources act in turn without learning.
    warm_up: u64,
    /// Whether the run reuses a library, and so has a selector worth showing.
    snapshots: bool,
    lock_in: Option<LockIn>,
    last_snapshot: Instant,
    /// The learner whose loss an episode's record shows: the last source that acted, or
    /// the method's own learner.
    last_source: usize,
    steps: u64,
    /// The observation acted on, and the next one, copied out of the environment each
    /// step into buffers that trade places (no allocation).
    obs: Vec<f32>,
    next_obs: Vec<f32>,
}

impl<'a> Run<'a> {
    /// Everything `spec` needs before its first step, and its `RunStarted` event sent.
    pub fn start(
        spec: &'a RunSpec,
        events: &'a Sender<Event>,
        commands: &'a CommandReceiver,
    ) -> Result<Self, TrainerError> {
        let started = Instant::now();
        let seeds = RunSeeds::new(spec.seed);
        let mut env = env::make(&spec.env)?;
        let selector = selector(spec)?;
        let learning = selector.learning();
        let needs = selector.needs();
        let n = spec.sources.len();
        let mut networks = RunNetworks::new(
            spec,
            learning,
            needs.td_error,
            env.as_ref(),
            seeds.weights,
            commands,
        )?;
        if let Some(distillation) = selector.distillation() {
            networks.distil_from(distillation.teacher, distillation.temperature)?;
        }
        let replay = ReplayBuffer::new(spec.dqn.replay_capacity, env.observation_size());
        let rng = StdRng::seed_from_u64(seeds.agent);
        let selection_rng = StdRng::seed_from_u64(seeds.selection);
        let control = Control::new(commands, spec.stream);
        let _ = events.send(Event::RunStarted {
            run: spec.run,
            method: spec.method.clone(),
            budget: spec.budget,
            library: library_start(spec, selector.as_ref()),
        });
        let replay_start = spec.dqn.replay_start_size as u64;
        let warm_up = match learning {
            Learning::ActingSource => n as u64 * replay_start,
            Learning::Learner | Learning::Frozen => 0,
        };
        let last_snapshot = Instant::now();
        let obs = env.reset(Some(seeds.env))?.to_vec();
        Ok(Self {
            spec,
            events,
            control,
            started,
            seeds,
            next_obs: vec![0.0; obs.len()],
            obs,
            env,
            selector,
            learning,
            needs,
            networks,
            replay,
            rng,
            selection_rng,
            tally: Tally::new(n),
            record: RunRecord::new(spec.run, spec.method.clone(), spec.seed),
            replay_start,
            warm_up,
            snapshots: n > 0,
            lock_in: None,
            last_snapshot,
            last_source: 0,
            steps: 0,
        })
    }

    /// Steps taken so far.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Whether the front end lets the run take its next step, after waiting while it is
    /// paused; a run it stops is recorded as stopped.
    pub fn may_step(&mut self) -> bool {
        let stop = self.control.before_step() == Next::Stop;
        self.record.stopped |= stop;
        !stop
    }

    /// One step of Algorithm 3: who acts (in turn during the warm-up, then whoever the
    /// selector draws, eq. 6), its action, the transition stored in D, the learner's
    /// update and what the selector makes of it, the step's events.
    pub fn step(&mut self, episode: u32) -> Result<Stepped, TrainerError> {
        let in_warm_up = self.steps < self.warm_up;
        let actor = if in_warm_up {
            Actor::Source((self.steps / self.replay_start) as usize)
        } else {
            self.selector.act(&mut self.selection_rng)
        };
        let Combined { action, followed } =
            self.networks
                .act(actor, self.selector.as_mut(), &self.obs, &mut self.rng)?;
        // V_i(s_t) of the acting source as it acts, before its update.
        let value = match actor.source() {
            Some(i) if self.needs.values && !in_warm_up => {
                Some((i, self.networks.value(actor, &self.obs)?))
            }
            _ => None,
        };
        let step = self.env.step(action)?;
        let (reward, terminated, truncated) = (step.reward, step.terminated, step.truncated);
        self.next_obs.copy_from_slice(step.obs);
        self.replay.push(Transition {
            obs: &self.obs,
            action,
            reward,
            next_obs: &self.next_obs,
            terminated,
            truncated,
        });
        self.steps += 1;
        if let Some(i) = actor.source() {
            self.last_source = i;
        }
        if let Some((i, value)) = value {
            self.selector.on_acted(i, reward, value);
        }
        let learned = if in_warm_up {
            Learned::default()
        } else {
            self.learn(actor, followed)?
        };
        self.send_step(StepRecord {
            method: self.spec.method.index,
            run: self.spec.run,
            step: self.steps,
            episode,
            policy: followed,
            action,
            reward,
            update: learned.report,
            judgment: learned.judgment,
            deposit: learned.deposit,
            warm_up: in_warm_up,
        });
        let done = terminated || truncated;
        if done {
            let bootstrapped = truncated && !terminated && !self.spec.dqn.truncation_as_terminal;
            if self.needs.values && bootstrapped {
                let values = self.networks.source_values(&self.next_obs)?;
                self.selector.on_truncated(&values);
            }
            self.obs.copy_from_slice(self.env.reset(None)?);
        } else {
            std::mem::swap(&mut self.obs, &mut self.next_obs);
        }
        Ok(Stepped { reward, done })
    }

    /// After the warm-up: the update of whoever learns from the step `actor` took
    /// (`T_a = E_{t+1} − E_t`, eq. 7), the selector's judgment of it (eq. 8–11), and the
    /// lock-in, the first time one source's probability passes [`LOCK_IN`].
    /// `followed` is the source whose action the step took, `actor` itself but for a
    /// combining method's step.
    fn learn(&mut self, actor: Actor, followed: Option<usize>) -> Result<Learned, TrainerError> {
        if let Some(i) = followed {
            self.tally.count(i);
        }
        let (learner, round) = match self.learning {
            Learning::ActingSource => (
                Some(actor.source().expect("sources learn only when they act")),
                LearnerRound::Online,
            ),
            Learning::Learner => (None, self.selector.learner_round()),
            Learning::Frozen => {
                self.selector.on_step();
                return Ok(Learned::default());
            }
        };
        if let Some(distillation) = self.selector.distillation() {
            self.networks
                .agent_mut(None)
                .set_distillation_weight(distillation.weight);
        }
        let result = match round {
            LearnerRound::Online => {
                let evaluate = self.selector.evaluate();
                self.networks
                    .observe_learner(learner, &self.replay, &mut self.rng)
                    .and_then(|report| {
                        self.networks
                            .observe_attention(&self.replay, &mut self.rng)
                            .map(|()| report)
                    })
                    .and_then(|report| {
                        self.networks
                            .observe_evaluators(evaluate, &self.replay, &mut self.rng)
                            .map(|()| report)
                    })
            }
            LearnerRound::Wait => Ok(None),
            LearnerRound::Offline {
                updates,
                target_interval,
            } => {
                let agent = self.networks.agent_mut(learner);
                let offline =
                    agent.offline_round(&self.replay, updates, target_interval, &mut self.rng);
                // The online phase learns from a buffer of its own (CleanRL's).
                self.replay = ReplayBuffer::new(self.replay.capacity(), self.replay.obs_size());
                offline.map(|_| None)
            }
        };
        let report = match result {
            Ok(report) => report,
            Err(error) => return Err(self.diverged(learner, error)),
        };
        let mut learned = Learned {
            report,
            ..Learned::default()
        };
        // A round without an update (update_interval > 1) has nothing to judge.
        if let (Some(report), Some(i)) = (&report, learner) {
            self.selector.set_tracing(self.control.trace());
            learned.judgment = self.selector.on_update(i, &feedback(report));
            if learned.judgment == Some(true) {
                learned.deposit = self.selector.last_deposit();
            }
            self.send_traces();
        }
        self.selector.on_step();
        // Only where the probabilities are learned does lock-in mean something
        // (reuse/lock_in.rs): the oracle's one source, say, has 1 from the start.
        if self.record.lock_in_step.is_none()
            && crate::reuse::lock_in::measured(self.spec.method.kind)
            && self.selector.top_probability().is_some_and(|p| p > LOCK_IN)
        {
            self.record.lock_in_step = Some(self.steps);
            // Once per run: which source it was, for the live view.
            let probabilities = self.selector.view().probabilities;
            self.lock_in = probabilities
                .iter()
                .position(|&p| p > LOCK_IN)
                .map(|source| LockIn {
                    source,
                    step: self.steps,
                });
        }
        Ok(learned)
    }

    /// The error of `learner` (a source, or the method's own for `None`), whose loss went
    /// non-finite, carrying its last good weights.
    fn diverged(&mut self, learner: Option<usize>, error: DqnError) -> TrainerError {
        let spec = self.spec;
        let method = match learner {
            Some(i) => format!("{} ({})", spec.method, spec.sources[i].name),
            None => spec.method.to_string(),
        };
        TrainerError::Diverged(Box::new(Divergence {
            method,
            run: spec.run,
            source: error,
            episodes: self.record.episodes,
            steps: self.steps,
            last_good: match self.networks.take_net(learner) {
                Ok(net) => net,
                Err(error) => return TrainerError::Dqn(error),
            },
        }))
    }

    /// The step budget ran out in the episode in progress, `sums` so far: the record keeps
    /// it as truncated there (its steps are already in the run's).
    pub fn cut_episode(&mut self, sums: &EpisodeReturn) {
        if sums.steps > 0 {
            self.record.cut_episode = Some(CutEpisode {
                steps: sums.steps,
                reward: sums.reward,
            });
        }
    }

    /// Episode `episode` ended with `sums`: the selector hears it, and the front ends.
    pub fn end_episode(&mut self, episode: u32, sums: &EpisodeReturn) {
        self.record.episodes = episode;
        self.selector.set_tracing(self.control.trace());
        self.selector.on_episode_end(&EpisodeEnd {
            episode_return: sums.reward,
            discounted_return: sums.discounted,
        });
        self.send_traces();
        if self.snapshots {
            self.send_snapshot(episode);
        }
        let shown = match self.learning {
            Learning::ActingSource => Some(self.networks.agent(Some(self.last_source))),
            Learning::Learner => Some(self.networks.agent(None)),
            Learning::Frozen => None,
        };
        let _ = self.events.send(Event::EpisodeEnded(EpisodeRecord {
            run: self.spec.run,
            method: self.spec.method.clone(),
            episode,
            reward: sums.reward,
            steps: sums.steps,
            loss: shown.and_then(|a| a.last_loss()),
            statistic_loss: shown.map_or(0.0, |a| a.statistic_loss()),
            // Frozen sources act greedily: no exploration.
            epsilon: shown.map_or(0.0, |a| a.epsilon()),
            policy: if self.snapshots {
                self.tally.end_episode()
            } else {
                None
            },
            wall_s: self.started.elapsed().as_secs_f64(),
        }));
    }

    /// The run's result: the chosen source or the method's own learner, tested greedily
    /// unless the run was stopped, and the record of it all, sent as `RunEnded`.
    pub fn finish(mut self) -> Result<RunOutcome, TrainerError> {
        let spec = self.spec;
        let mut record = self.record;
        record.steps = self.steps;
        record.updates = self.networks.updates();
        record.non_greedy_steps = self.networks.non_greedy_steps();
        record.source_steps = self.tally.run;
        let view = self.selector.view();
        (record.positive, record.negative) = (view.positive.clone(), view.negative.clone());
        record.exclusions = self.selector.exclusions_made();
        let chosen = self.selector.chosen();
        record.chosen = chosen.map(|chosen| ChosenPolicy {
            index: chosen,
            name: spec.sources[chosen].name.clone(),
            hidden: spec.sources[chosen].description.hidden.clone(),
            score: view.scores[chosen],
            score_name: view.score.name.into(),
        });
        let net = self.networks.take_net(chosen)?;
        if !record.stopped {
            let mut test_env = env::make(&spec.env)?;
            let (episodes, seed) = (spec.test_episodes, self.seeds.test_env);
            record.test_returns = if spec.reuse.kind().tested == Tested::Combined {
                // The learner with the library, as the method acts greedily.
                let mut values = ValueBuffers::default();
                let selector = self.selector.as_mut();
                let networks = self.networks.combining(&net);
                let greedy = |obs: &[f32]| {
                    let choice = values.combine(selector, false, networks, obs, None)?;
                    Ok(choice.action)
                };
                test_policy(greedy, test_env.as_mut(), episodes, seed)?
            } else {
                test_greedy(&net, test_env.as_mut(), episodes, seed)?
            };
        }
        record.wall_s = self.started.elapsed().as_secs_f64();
        let _ = self.events.send(Event::RunEnded(record.clone()));
        Ok(RunOutcome { record, net })
    }

    /// The step's event, if the front ends asked for every step, and a snapshot when one
    /// is due: every step of a run someone watches step by step, else once the stream's
    /// interval has passed (the clock looked at every 16 steps).
    fn send_step(&mut self, step: StepRecord) {
        let episode = step.episode;
        let stream = self.control.stream();
        if stream.steps {
            let _ = self.events.send(Event::Step(step));
        }
        let interval = stream.snapshot_interval;
        if self.snapshots
            && (self.control.is_slow()
                || (interval != Duration::MAX
                    && self.steps.is_multiple_of(16)
                    && self.last_snapshot.elapsed() >= interval))
        {
            self.send_snapshot(episode);
            self.last_snapshot = Instant::now();
        }
    }

    fn send_snapshot(&self, episode: u32) {
        let view = self.selector.view();
        let _ = self.events.send(Event::Activations(ActivationSnapshot {
            run: self.spec.run,
            method: self.spec.method.clone(),
            step: self.steps,
            episode,
            score: view.score,
            activations: view.scores,
            probabilities: view.probabilities,
            selections: self.tally.run.clone(),
            positive: view.positive,
            negative: view.negative,
            lock_in: self.lock_in,
            excluded: view.excluded,
        }));
    }

    fn send_traces(&mut self) {
        for activation in self.selector.take_activations() {
            let _ = self.events.send(Event::Trace(TraceRecord {
                run: self.spec.run,
                method: self.spec.method.clone(),
                step: self.steps,
                policy: activation.policy,
                calls: activation.calls,
            }));
        }
    }
}

/// The library as front ends draw it: SAP-Net's own net, or for another selector the
/// library's graph under the config's SAP-Net section (none without a library, or if that
/// graph cannot be built).
fn library_start(spec: &RunSpec, selector: &dyn Selector) -> Option<Box<LibraryStart>> {
    if spec.sources.is_empty() {
        return None;
    }
    let net = match selector.graph() {
        Some(net) => net.clone(),
        None => SapNet::from_policies(&spec.descriptions(), spec.sapnet.clone()).ok()?,
    };
    Some(Box::new(LibraryStart {
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
        score: selector.view().score,
    }))
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

/// Returns of `episodes` greedy episodes of `net` (the paper's "Number of test").
pub fn test_greedy(
    net: &QNet,
    env: &mut dyn Environment,
    episodes: u32,
    seed: u64,
) -> Result<Vec<f64>, TrainerError> {
    test_policy(|obs| net.greedy_action(obs), env, episodes, seed)
}

/// Returns of `episodes` episodes acted by `policy`, the first reset with `seed`.
fn test_policy(
    mut policy: impl FnMut(&[f32]) -> Result<usize, DqnError>,
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
            let step = env.step(policy(&obs)?)?;
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
    /// `seed 1, method 0` the seeds of `seed 0, method 1`).
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
                let s = RunSeeds::new(spec.seed);
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
