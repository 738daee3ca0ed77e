//! The Q-networks of a run: the sources as recorded, a copy of each fine-tuned as a
//! learner of its own (when sources learn), and the method's own learner (when it has one).

use rand::rngs::StdRng;
use rand::SeedableRng;

use super::spec::{RunSpec, SourcePolicy};
use super::CommandReceiver;
use crate::dqn::{Architecture, AttentionLearner, DqnAgent, DqnError, QNet, ReplayBuffer};
use crate::env::Environment;
use crate::reuse::{Actor, Combined, Learning, Selector, StateValues};

pub(super) struct RunNetworks<'a> {
    sources: &'a [SourcePolicy],
    agents: Vec<DqnAgent>,
    learner: Option<DqnAgent>,
    /// The attention over the sources and the learner, for a method that has one (A2T).
    attention: Option<AttentionLearner>,
    /// The Q-values a combining method chooses from, kept between steps.
    values: ValueBuffers,
}

/// Every network's Q-values of one state, in buffers kept between steps.
#[derive(Default)]
pub(super) struct ValueBuffers {
    learner: Vec<f32>,
    sources: Vec<Vec<f32>>,
    attention: Vec<f32>,
}

impl ValueBuffers {
    /// The choice `selector` makes from `learner`'s and the (frozen) `sources`' Q-values of
    /// `obs` (and `attention`'s weights, if the method has one), with `explored` the
    /// learner's exploring action, if its coin fell on one; `selector` hears it when
    /// `acting`.
    #[allow(clippy::too_many_arguments)]
    pub fn combine(
        &mut self,
        selector: &mut dyn Selector,
        acting: bool,
        learner: &QNet,
        sources: &[SourcePolicy],
        attention: Option<&AttentionLearner>,
        obs: &[f32],
        explored: Option<usize>,
    ) -> Result<Combined, DqnError> {
        self.learner = learner.q_values(obs)?;
        self.sources.resize_with(sources.len(), Vec::new);
        // A2T's attention keeps the sources' values of the state the last step led to.
        let kept = attention.and_then(|a| a.kept_source_values(obs));
        let actions = self.learner.len();
        for (i, (values, source)) in self.sources.iter_mut().zip(sources).enumerate() {
            match kept {
                Some(kept) => {
                    values.clear();
                    values.extend_from_slice(&kept[i * actions..(i + 1) * actions]);
                }
                None => *values = source.acting().q_values(obs)?,
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
            Learning::Learner => Vec::new(),
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
        Ok(Self {
            sources: &spec.sources,
            agents,
            learner,
            attention,
            values: ValueBuffers::default(),
        })
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
            Actor::Learner => self.learner().act(obs, rng).map(own),
            Actor::Combined => {
                let learner = self
                    .learner
                    .as_ref()
                    .expect("a method that combines has a learner");
                let explored = learner.explore(rng);
                let net = learner.online();
                let attention = self.attention.as_ref();
                self.values
                    .combine(selector, true, net, self.sources, attention, obs, explored)
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

    /// The attention network, for a method that has one.
    pub fn attention(&self) -> Option<&AttentionLearner> {
        self.attention.as_ref()
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

    /// The online network of [`agent`](Self::agent)`(source)`, taken out of the run.
    pub fn take_net(&mut self, source: Option<usize>) -> QNet {
        match source {
            Some(i) => self.agents.swap_remove(i).into_online(),
            None => self
                .learner
                .take()
                .expect("a method that ends with no source has a learner")
                .into_online(),
        }
    }

    fn learner(&self) -> &DqnAgent {
        self.learner
            .as_ref()
            .expect("a method whose selector picks its learner has one")
    }

    pub fn updates(&self) -> u64 {
        let own = self.learner.as_ref().map_or(0, DqnAgent::updates)
            + self.attention.as_ref().map_or(0, AttentionLearner::updates);
        self.agents.iter().map(DqnAgent::updates).sum::<u64>() + own
    }
}
