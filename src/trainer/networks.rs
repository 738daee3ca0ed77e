//! The Q-networks of a run: the sources as recorded, a copy of each fine-tuned as a
//! learner of its own (when sources learn), the method's own learner (when it has one), an
//! attention over them (A2T), and an estimate of each source's value on the target task
//! (GPI's evaluation).

use rand::rngs::StdRng;
use rand::SeedableRng;

use super::spec::{RunSpec, SourcePolicy};
use super::CommandReceiver;
use crate::dqn::{
    Architecture, AttentionLearner, DqnAgent, DqnError, QNet, ReplayBuffer, UpdateReport,
};
use crate::env::Environment;
use crate::reuse::{Actor, Combined, Evaluate, Learning, Selector, StateValues};

pub(super) struct RunNetworks<'a> {
    sources: &'a [SourcePolicy],
    agents: Vec<DqnAgent>,
    learner: Option<DqnAgent>,
    /// The attention over the sources and the learner, for a method that has one (A2T).
    attention: Option<AttentionLearner>,
    /// Per source, the estimate of its greedy policy's value on the target task, for a
    /// method that evaluates its sources (GPI), and its target copy interval in updates.
    evaluators: Vec<DqnAgent>,
    evaluation_interval: u64,
    /// Whether the learner's targets bootstrap on the action the combination of the
    /// learner and the sources' values picks at `s′` (SFQL's), not on its own maximum.
    gpi_bootstrap: bool,
    /// The Q-values a combining method chooses from, kept between steps.
    values: ValueBuffers,
    /// Steps whose action was not the method's own learner's greedy action at the state:
    /// its exploration, and what the library changed of its behaviour.
    non_greedy: u64,
}

/// The networks a combining method's choice reads.
#[derive(Clone, Copy)]
pub(super) struct Combining<'a> {
    pub learner: &'a QNet,
    pub sources: &'a [SourcePolicy],
    /// Each source's value estimated on the target task, taking the place of its recorded
    /// Q-values; empty for a method that takes the sources as recorded.
    pub evaluated: &'a [DqnAgent],
    pub attention: Option<&'a AttentionLearner>,
}

/// Every network's Q-values of one state, in buffers kept between steps.
#[derive(Default)]
pub(super) struct ValueBuffers {
    learner: Vec<f32>,
    sources: Vec<Vec<f32>>,
    attention: Vec<f32>,
}

impl ValueBuffers {
    /// The choice `selector` makes from the `networks`' Q-values of `obs` (the learner's,
    /// the sources' as recorded or as evaluated, and the attention's weights, if the method
    /// has one), with `explored` the learner's exploring action, if its coin fell on one;
    /// `selector` hears it when `acting`.
    pub fn combine(
        &mut self,
        selector: &mut dyn Selector,
        acting: bool,
        networks: Combining<'_>,
        obs: &[f32],
        explored: Option<usize>,
    ) -> Result<Combined, DqnError> {
        let Combining {
            learner,
            sources,
            evaluated,
            attention,
        } = networks;
        self.learner = learner.q_values(obs)?;
        self.sources.resize_with(sources.len(), Vec::new);
        // A2T's attention keeps the sources' values of the state the last step led to.
        let kept = attention.and_then(|a| a.kept_source_values(obs));
        let actions = self.learner.len();
        for (i, (values, source)) in self.sources.iter_mut().zip(sources).enumerate() {
            match (kept, evaluated.get(i)) {
                (Some(kept), _) => {
                    values.clear();
                    values.extend_from_slice(&kept[i * actions..(i + 1) * actions]);
                }
                (None, Some(evaluator)) => *values = evaluator.online().q_values(obs)?,
                (None, None) => *values = source.acting().q_values(obs)?,
            }
        }
        if let Some(attention) = attention {
            self.attention = attention.weights(obs)?;
        }
        let values = StateValues {
            learner: &self.learner,
            sources: &self.sources,
            explored,
            attention: attention.map(|_| self.attention.as_slice()),
        };
        let choice = selector.combine(&values);
        if acting {
            selector.on_combined(&values, choice);
        }
        Ok(choice)
    }
}

impl<'a> RunNetworks<'a> {
    /// The learners `spec`'s method trains on `env`: the sources' copies measure the TD
    /// error when `td_error` asks for it; the learner's weights are drawn from the seed
    /// `weights`. All stop a long round of updates when `commands` is told to stop.
    pub fn new(
        spec: &'a RunSpec,
        learning: Learning,
        td_error: bool,
        env: &dyn Environment,
        weights: u64,
        commands: &CommandReceiver,
    ) -> Result<Self, DqnError> {
        let mut agents = match learning {
            Learning::ActingSource => spec
                .sources
                .iter()
                .map(|s| DqnAgent::new(s.net.deep_copy()?, &spec.dqn))
                .collect::<Result<Vec<_>, _>>()?,
            Learning::Learner | Learning::Frozen => Vec::new(),
        };
        for agent in &mut agents {
            agent.measure_td_error(td_error);
            agent.interrupt_rounds_with(commands.stop_flag());
        }
        let learner = match spec.reuse.learner_hidden() {
            Some(hidden) => {
                let architecture =
                    Architecture::new(env.observation_size(), &hidden, env.action_count());
                let net = QNet::with_init(
                    architecture,
                    spec.dqn.init,
                    &mut StdRng::seed_from_u64(weights),
                )?;
                let mut learner = DqnAgent::new(net, &spec.dqn)?;
                learner.interrupt_rounds_with(commands.stop_flag());
                Some(learner)
            }
            None => None,
        };
        let attention = match spec.reuse.attention_hidden() {
            Some(hidden) => {
                let seed = crate::seeds::derive(weights, &[crate::seeds::Part::Name("attention")]);
                let mut attention = AttentionLearner::new(
                    env.observation_size(),
                    &hidden,
                    spec.sources.len(),
                    spec.dqn.init,
                    &spec.dqn,
                    &mut StdRng::seed_from_u64(seed),
                )?;
                attention.interrupt_rounds_with(commands.stop_flag());
                Some(attention)
            }
            None => None,
        };
        let evaluation_interval = spec.reuse.source_evaluation();
        let mut evaluators = Vec::new();
        if evaluation_interval.is_some() {
            for source in spec.sources.iter() {
                // Starts from what the source believes of its own task, and learns what its
                // policy is worth on this one, with this task's γ.
                let mut evaluator = DqnAgent::new(source.net.deep_copy()?, &spec.dqn)?;
                evaluator.evaluate_policy_of(source.net.deep_copy()?);
                evaluator.interrupt_rounds_with(commands.stop_flag());
                evaluators.push(evaluator);
            }
        }
        Ok(Self {
            sources: &spec.sources,
            agents,
            learner,
            attention,
            evaluators,
            evaluation_interval: evaluation_interval.unwrap_or(1),
            gpi_bootstrap: spec.reuse.definition().gpi_bootstrap(),
            values: ValueBuffers::default(),
            non_greedy: 0,
        })
    }

    /// The networks a combining choice reads, with `learner` the method's own.
    pub fn combining<'b>(&'b self, learner: &'b QNet) -> Combining<'b> {
        Combining {
            learner,
            sources: self.sources,
            evaluated: &self.evaluators,
            attention: self.attention.as_ref(),
        }
    }

    /// The round of `learner` (a source's copy, or the method's own for `None`) on the step
    /// just stored in `replay`; the method's own bootstraps on the GPI action when the
    /// method asks, the sources' values being their estimates on the target task (or, not
    /// evaluated, their networks as recorded).
    pub fn observe_learner(
        &mut self,
        learner: Option<usize>,
        replay: &ReplayBuffer,
        rng: &mut StdRng,
    ) -> Result<Option<UpdateReport>, DqnError> {
        let Some(i) = learner else {
            let own = self.learner.as_mut().expect("the method has a learner");
            if !self.gpi_bootstrap {
                return own.observe(replay, rng);
            }
            let joined: Vec<&QNet> = if self.evaluators.is_empty() {
                self.sources.iter().map(|s| &s.net).collect()
            } else {
                self.evaluators.iter().map(DqnAgent::online).collect()
            };
            return own.observe_joined(replay, rng, &joined);
        };
        self.agents[i].observe(replay, rng)
    }

    /// The round of the sources' value estimates on the step just stored in `replay`:
    /// those `which` names learn once each.
    pub fn observe_evaluators(
        &mut self,
        which: Evaluate,
        replay: &ReplayBuffer,
        rng: &mut StdRng,
    ) -> Result<(), DqnError> {
        let interval = self.evaluation_interval;
        match which {
            Evaluate::Nobody => Ok(()),
            Evaluate::Source(i) => match self.evaluators.get_mut(i) {
                Some(evaluator) => evaluator.learn_once(replay, interval, rng).map(drop),
                None => Ok(()),
            },
            Evaluate::Every => self
                .evaluators
                .iter_mut()
                .try_for_each(|e| e.learn_once(replay, interval, rng).map(drop)),
        }
    }

    /// The action of `actor` on `obs`, and the source it followed; `selector` makes the
    /// choice of an [`Actor::Combined`] step, around the learner's exploration.
    pub fn act(
        &mut self,
        actor: Actor,
        selector: &mut dyn Selector,
        obs: &[f32],
        rng: &mut StdRng,
    ) -> Result<Combined, DqnError> {
        let own = |action| Combined {
            action,
            followed: actor.source(),
        };
        match actor {
            Actor::Source(i) => self.agents[i].act(obs, rng).map(own),
            Actor::SourceGreedy(i) => self.sources[i].acting().greedy_action(obs).map(own),
            Actor::Learner => {
                // DQN's ε-greedy choice, its coin drawn apart to see whether it explored;
                // the greedy action is looked up then only (the same draws as `act`).
                let learner = self.learner();
                let action = match learner.explore(rng) {
                    Some(explored) => {
                        if explored != learner.greedy_action(obs)? {
                            self.non_greedy += 1;
                        }
                        explored
                    }
                    None => learner.greedy_action(obs)?,
                };
                Ok(own(action))
            }
            Actor::Combined => {
                let learner = self
                    .learner
                    .as_ref()
                    .expect("a method that combines has a learner");
                let explored = learner.explore(rng);
                let networks = Combining {
                    learner: learner.online(),
                    sources: self.sources,
                    evaluated: &self.evaluators,
                    attention: self.attention.as_ref(),
                };
                let choice = self
                    .values
                    .combine(selector, true, networks, obs, explored)?;
                if choice.action != crate::reuse::argmax_f32(&self.values.learner) {
                    self.non_greedy += 1;
                }
                Ok(choice)
            }
        }
    }

    /// `max_a Q(obs, a)` of the network that acts as `actor`.
    pub fn value(&self, actor: Actor, obs: &[f32]) -> Result<f64, DqnError> {
        match actor {
            Actor::Source(i) => self.agents[i].value(obs),
            Actor::SourceGreedy(i) => self.sources[i].acting().max_q(obs).map(f64::from),
            Actor::Learner | Actor::Combined => self.learner().value(obs),
        }
    }

    /// `max_a Q_j(obs, a)` of every source: its learning copy, if sources learn.
    pub fn source_values(&self, obs: &[f32]) -> Result<Vec<f64>, DqnError> {
        if self.agents.is_empty() {
            let values = self
                .sources
                .iter()
                .map(|s| s.acting().max_q(obs).map(f64::from));
            values.collect()
        } else {
            self.agents.iter().map(|a| a.value(obs)).collect()
        }
    }

    /// The method's learner distils source `teacher` (a copy of it) from now on.
    pub fn distil_from(&mut self, teacher: usize, temperature: f64) -> Result<(), DqnError> {
        let net = self.sources[teacher].net.deep_copy()?;
        self.learner
            .as_mut()
            .expect("a method that distils has a learner")
            .distil_from(net, temperature);
        Ok(())
    }

    /// The attention's round on the step just stored in `replay` (a method with one).
    pub fn observe_attention(
        &mut self,
        replay: &ReplayBuffer,
        rng: &mut StdRng,
    ) -> Result<(), DqnError> {
        let (Some(attention), Some(learner)) = (self.attention.as_mut(), self.learner.as_ref())
        else {
            return Ok(());
        };
        let sources: Vec<&QNet> = self.sources.iter().map(|s| &s.net).collect();
        attention.observe(replay, rng, &sources, (learner.online(), learner.target()))?;
        Ok(())
    }

    /// The learning copy of source `source`, or the method's own learner for `None`.
    pub fn agent(&self, source: Option<usize>) -> &DqnAgent {
        match source {
            Some(i) => &self.agents[i],
            None => self.learner(),
        }
    }

    pub fn agent_mut(&mut self, source: Option<usize>) -> &mut DqnAgent {
        match source {
            Some(i) => &mut self.agents[i],
            None => self.learner.as_mut().expect("the method has a learner"),
        }
    }

    /// The online network of [`agent`](Self::agent)`(source)`, taken out of the run: a
    /// copy of the source as recorded when sources do not learn.
    pub fn take_net(&mut self, source: Option<usize>) -> Result<QNet, DqnError> {
        Ok(match source {
            Some(i) if self.agents.is_empty() => self.sources[i].net.deep_copy()?,
            Some(i) => self.agents.swap_remove(i).into_online(),
            None => self
                .learner
                .take()
                .expect("a method that ends with no source has a learner")
                .into_online(),
        })
    }

    fn learner(&self) -> &DqnAgent {
        self.learner
            .as_ref()
            .expect("a method whose selector picks its learner has one")
    }

    /// Steps whose action was not the method's own learner's greedy action, for a method
    /// with a learner.
    pub fn non_greedy_steps(&self) -> Option<u64> {
        self.learner.as_ref().map(|_| self.non_greedy)
    }

    pub fn updates(&self) -> u64 {
        let own = self.learner.as_ref().map_or(0, DqnAgent::updates)
            + self.attention.as_ref().map_or(0, AttentionLearner::updates)
            + self.evaluators.iter().map(DqnAgent::updates).sum::<u64>();
        self.agents.iter().map(DqnAgent::updates).sum::<u64>() + own
    }
}
