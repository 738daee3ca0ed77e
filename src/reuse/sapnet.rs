//! SAP-Net as a selector: eq. 6 picks the source that acts, eq. 7 judges its update,
//! eq. 8–11 activate and spread (Algorithm 3). With [`SapNetKnobs::default`] this is the
//! paper; the knobs are variants beyond it: a temperature schedule, judgments by other
//! signals or over other spans than eq. 7's (episodes, k updates, the TD error, the
//! advantage, eq. 7 confirmed by the return), and activation decay.

use rand::rngs::StdRng;
use serde::{Deserialize, Serialize};

use super::definition::{check_label, MethodKind, ReuseMethod, Tested};
use super::exclusion::{Exclusion, Exclusions};
use super::parameter_schedule::Schedule;
use super::{
    Activation, Actor, Deposit, EpisodeEnd, Feedback, Learning, Library, Needs, ReuseError,
    ScoreColumn, Selector, SelectorView,
};
use crate::sapnet::{self, PolicyDescription, SapNet, SapNetError, SapNetParams, TraceStep};

/// When a source's learning is judged positive or negative, and by what. Each positive
/// judgment of π_i is one `activate(i, 𝒜)` (eq. 8–11); a negative one only counts. The
/// paper names the first; the others are its future work ("indices other than the loss",
/// per episode or every k steps).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Judgment {
    /// After every update of π_i: `T_a = E_{t+1} − E_t ≤ 0` (eq. 7, the paper), E the
    /// statistic loss `E ← 0.99·E + 0.01·loss`.
    Step,
    /// Once per episode, for each source that acted in it: positive when the episode's
    /// return is at least the mean return of the earlier episodes that source acted in (the
    /// first such episode is positive). The paper's own proposal for MountainCar.
    Episode,
    /// After every k updates of a source: eq. 7 over the k updates, `E_{t+k} − E_t ≤ 0`.
    KSteps(u32),
    /// After every update of π_i, the TD error's change instead of E's: for the step's
    /// transition (s, a, r, s', done),
    /// `δ = r + γ·(1 − done)·max_a' Q_target(s', a') − Q_online(s, a)` with π_i's online
    /// net just before its round of updates (δ_before) and just after (δ_after), the same
    /// target net; positive when `|δ_after| ≤ |δ_before|`. `done` is the update's own
    /// (terminated, or truncated under `truncation_as_terminal`).
    TdChange,
    /// At the episode's end, one judgment per step t acted by a source, in step order:
    /// `A_t = G_t − V_i(s_t) ≥ 0` positive, with `V_i(s_t) = max_a Q_i(s_t, a)` of the
    /// acting source's online net when it acted (before its update) and the return-to-go
    /// `G_t = Σ_{k=t}^{T} γ^{k−t}·r_k + γ^{T+1−t}·V_i(s_{T+1})`, the last term only when a
    /// time limit cut the episode (and `truncation_as_terminal` is off), V_i(s_{T+1}) from
    /// π_i's online net at the episode's end. An episode cut by the run's step budget
    /// never ends: its steps are never judged.
    Advantage,
    /// Eq. 7 and the episode's return both: each update's `T_a ≤ 0` is kept, and at the
    /// episode's end each kept positive of π_i is confirmed if the return is at least the
    /// mean return of the earlier episodes π_i acted in (the `Episode` rule), else it
    /// counts negative. An update with `T_a > 0` is negative at once.
    EpisodeAndLoss,
}

/// SAP-Net's variants beyond the paper (`SapNetWith(...)` in `protocol.methods`); the
/// graph and the spreading come from the config's `sapnet` section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SapNetKnobs {
    /// The name in results; `None`: `sapnet` followed by the knobs that differ from the
    /// paper, e.g. `sapnet-episode-decay0.999`.
    pub label: Option<String>,
    /// τ of eq. 6 over the learning steps (those after the warm-up); `None`: the constant
    /// `sapnet.temperature`.
    pub temperature: Option<Schedule>,
    pub judgment: Judgment,
    /// λ in (0, 1]: every activation is multiplied by λ after every learning step
    /// (1: the paper).
    pub decay: f64,
    /// Candidates by category: a category of the first prototype's whose members are judged
    /// negative `after` times in a row is left out of eq. 6 for `steps` learning steps
    /// ([`super::exclusion`]). `None`: every policy is a candidate (the paper).
    pub exclusion: Option<Exclusion>,
}

impl Default for SapNetKnobs {
    fn default() -> Self {
        Self {
            label: None,
            temperature: None,
            judgment: Judgment::Step,
            decay: 1.0,
            exclusion: None,
        }
    }
}

/// SAP-Net in `protocol.methods`, in the palette's red.
pub const KIND: MethodKind = MethodKind {
    family: "SapNet",
    hue: 0,
    saturation: 72,
    reuses: true,
    tested: Tested::HighestActivation,
    picks_by_probability: true,
    spreads: true,
};

impl ReuseMethod for SapNetKnobs {
    /// The label of results: the given one, or one built from the knobs.
    fn label(&self) -> String {
        if let Some(label) = &self.label {
            return label.clone();
        }
        let mut label = String::from("sapnet");
        if let Some(schedule) = &self.temperature {
            let (kind, from, to) = match *schedule {
                Schedule::Linear { from, to, .. } => ("lin", from, to),
                Schedule::Exponential { from, to, .. } => ("exp", from, to),
            };
            label.push_str(&format!("-tau-{kind}{from}-{to}"));
        }
        match self.judgment {
            Judgment::Step => {}
            Judgment::Episode => label.push_str("-episode"),
            Judgment::KSteps(k) => label.push_str(&format!("-k{k}")),
            Judgment::TdChange => label.push_str("-td"),
            Judgment::Advantage => label.push_str("-advantage"),
            Judgment::EpisodeAndLoss => label.push_str("-episode-and-loss"),
        }
        if self.decay != 1.0 {
            label.push_str(&format!("-decay{}", self.decay));
        }
        if let Some(e) = self.exclusion {
            label.push_str(&format!("-exclude{}x{}", e.after, e.steps));
        }
        label
    }

    fn kind(&self) -> MethodKind {
        KIND
    }

    /// The ranges serde cannot check; `field` is where the knobs sit in the config.
    fn validate(&self, field: &str) -> Result<(), String> {
        if let Some(schedule) = &self.temperature {
            schedule.validate_positive(&format!("{field}.temperature"))?;
        }
        if !(self.decay > 0.0 && self.decay <= 1.0) {
            return Err(format!(
                "field `{field}.decay`: expected λ in (0, 1], got {:?}",
                self.decay
            ));
        }
        if self.judgment == Judgment::KSteps(0) {
            return Err(format!(
                "field `{field}.judgment`: expected KSteps(k) with k ≥ 1, got KSteps(0)"
            ));
        }
        if let Some(exclusion) = &self.exclusion {
            exclusion.validate(&format!("{field}.exclusion"))?;
        }
        if let Some(label) = &self.label {
            check_label(field, label)?;
        }
        Ok(())
    }

    fn selector(
        &self,
        library: Library<'_>,
        sapnet: &SapNetParams,
    ) -> Result<Box<dyn Selector>, ReuseError> {
        Ok(Box::new(SapNetSelector::new(
            library.descriptions,
            sapnet.clone(),
            self,
            library.gamma,
        )?))
    }
}

/// A step of an episode in progress as `Advantage` keeps it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct ActedStep {
    source: usize,
    reward: f64,
    /// V_i(s_t) = max_a Q_i(s_t, a) when the source acted.
    value: f64,
}

/// `A_t = G_t − V_i(s_t)` of every step of an episode, in step order, with
/// `G_t = Σ_{k=t}^{T} γ^{k−t}·r_k + γ^{T+1−t}·tail[i]` (no tail: the episode terminated).
/// Summed from the last step back: G_T = r_T, G_t = r_t + γ·G_{t+1}.
fn advantages(steps: &[ActedStep], tail: Option<&[f64]>, gamma: f64) -> Vec<f64> {
    let mut advantages = vec![0.0; steps.len()];
    let (mut rewards_to_go, mut discount) = (0.0, gamma);
    for (t, step) in steps.iter().enumerate().rev() {
        rewards_to_go = step.reward + gamma * rewards_to_go;
        let bootstrap = tail.map_or(0.0, |values| discount * values[step.source]);
        advantages[t] = rewards_to_go + bootstrap - step.value;
        discount *= gamma;
    }
    advantages
}

/// SAP-Net over the library, with its judgment's bookkeeping.
#[derive(Debug)]
pub struct SapNetSelector {
    net: SapNet,
    knobs: SapNetKnobs,
    /// The DQN's γ, for `Advantage`'s return-to-go.
    gamma: f64,
    positive: Vec<u64>,
    negative: Vec<u64>,
    /// Learning steps so far, the clock of the temperature schedule.
    steps: u64,
    /// `Episode`, `EpisodeAndLoss`: which sources acted in the episode in progress, and per
    /// source the mean return of the earlier episodes it acted in, with their count.
    acted: Vec<bool>,
    mean_return: Vec<(f64, u64)>,
    /// `KSteps`: per source, E before the window of updates in progress and its length.
    window: Vec<(f64, u32)>,
    /// `EpisodeAndLoss`: the source of each positive eq. 7 judgment of the episode in
    /// progress, in step order, waiting for the episode's return.
    kept: Vec<usize>,
    /// `Advantage`: each acting step of the episode in progress, in order, and the sources'
    /// values at the state a time limit cut it at.
    acted_steps: Vec<ActedStep>,
    tail_values: Option<Vec<f64>>,
    tracing: bool,
    traced: Vec<Activation>,
    /// What the latest positive judgment deposited (eq. 8–11).
    deposit: Deposit,
    /// Candidates by category, when the knob is set.
    exclusions: Option<Exclusions>,
}

impl SapNetSelector {
    /// `gamma` is the DQN's discount (read by `Advantage` only).
    pub fn new(
        policies: &[PolicyDescription],
        mut params: SapNetParams,
        knobs: &SapNetKnobs,
        gamma: f64,
    ) -> Result<Self, SapNetError> {
        if let Some(schedule) = &knobs.temperature {
            params.temperature = schedule.at(0);
        }
        let n = policies.len();
        let exclusions = knobs.exclusion.map(|rule| {
            let prototype = params
                .prototypes
                .first()
                .map_or(crate::sapnet::Prototype::HiddenLayers, |p| {
                    p.prototype.clone()
                });
            Exclusions::new(rule, prototype.group_indices(policies))
        });
        Ok(Self {
            exclusions,
            net: SapNet::from_policies(policies, params)?,
            knobs: knobs.clone(),
            gamma,
            positive: vec![0; n],
            negative: vec![0; n],
            steps: 0,
            acted: vec![false; n],
            mean_return: vec![(0.0, 0); n],
            window: vec![(0.0, 0); n],
            kept: Vec::new(),
            acted_steps: Vec::new(),
            tail_values: None,
            tracing: false,
            traced: Vec::new(),
            deposit: Deposit::default(),
        })
    }

    /// Eq. 6's probabilities, over the candidates while a category is excluded.
    fn probabilities(&self) -> Vec<f64> {
        match &self.exclusions {
            Some(e) if e.any() => self.net.candidate_probabilities(e.excluded()),
            _ => self.net.probabilities(),
        }
    }

    /// The SAP-Net, with its graph and activations.
    pub fn net(&self) -> &SapNet {
        &self.net
    }

    /// The `Episode` rule at an episode's end, for each source that acted in it (`None`
    /// for the others): whether `episode_return` is at least the mean return of the
    /// earlier episodes it acted in (the first is positive); folds the return into those
    /// means and clears who acted.
    fn episode_verdicts(&mut self, episode_return: f64) -> Vec<Option<bool>> {
        (0..self.acted.len())
            .map(|i| {
                if !std::mem::take(&mut self.acted[i]) {
                    return None;
                }
                let (mean, count) = self.mean_return[i];
                let positive = count == 0 || episode_return >= mean;
                let count = count + 1;
                self.mean_return[i] = (mean + (episode_return - mean) / count as f64, count);
                Some(positive)
            })
            .collect()
    }

    /// Counts the judgment, then activates `i` (eq. 8–11) if it was positive.
    fn judged(&mut self, i: usize, positive: bool) {
        if let Some(exclusions) = &mut self.exclusions {
            exclusions.judged(i, positive, self.steps);
        }
        if !positive {
            self.negative[i] += 1;
            return;
        }
        self.positive[i] += 1;
        let own_before = self.net.activations()[i];
        let total_before: f64 = self.net.activations().iter().sum();
        if self.tracing {
            let mut calls: Vec<TraceStep> = Vec::new();
            self.net.activate_traced(i, true, &mut calls);
            self.traced.push(Activation { policy: i, calls });
        } else {
            self.net.activate(i, true);
        }
        let own = self.net.activations()[i] - own_before;
        let total: f64 = self.net.activations().iter().sum::<f64>() - total_before;
        self.deposit = Deposit {
            own,
            others: total - own,
        };
    }
}

/// SAP-Net's score: each source's activation A (eq. 5).
pub const SCORE: ScoreColumn = ScoreColumn {
    name: "A",
    meaning: "A: activation (eq. 5); P: the softmax of A (eq. 6)",
    counted: false,
};

impl Selector for SapNetSelector {
    fn learning(&self) -> Learning {
        Learning::ActingSource
    }

    fn exclusions_made(&self) -> u64 {
        self.exclusions.as_ref().map_or(0, Exclusions::made)
    }

    /// Eq. 6.
    fn act(&mut self, rng: &mut StdRng) -> Actor {
        let i = match &self.exclusions {
            Some(e) if e.any() => self.net.select_candidate(e.excluded(), rng),
            _ => self.net.select(rng),
        };
        self.acted[i] = true;
        Actor::Source(i)
    }

    fn needs(&self) -> Needs {
        Needs {
            td_error: self.knobs.judgment == Judgment::TdChange,
            values: self.knobs.judgment == Judgment::Advantage,
        }
    }

    fn on_update(&mut self, source: usize, report: &Feedback) -> Option<bool> {
        let positive = match self.knobs.judgment {
            Judgment::Step => sapnet::judge(report.previous_statistic_loss, report.statistic_loss),
            Judgment::Episode | Judgment::Advantage => return None,
            Judgment::TdChange => {
                let td = report
                    .td
                    .expect("the run measures the TD error when the selector needs it");
                td.after.abs() <= td.before.abs()
            }
            Judgment::EpisodeAndLoss => {
                if sapnet::judge(report.previous_statistic_loss, report.statistic_loss) {
                    // Confirmed or not by the episode's return.
                    self.kept.push(source);
                    return None;
                }
                false
            }
            Judgment::KSteps(k) => {
                let (start, count) = &mut self.window[source];
                if *count == 0 {
                    *start = report.previous_statistic_loss;
                }
                *count += 1;
                if *count < k {
                    return None;
                }
                *count = 0;
                sapnet::judge(*start, report.statistic_loss)
            }
        };
        self.judged(source, positive);
        Some(positive)
    }

    fn on_step(&mut self) {
        self.steps += 1;
        if let Some(exclusions) = &mut self.exclusions {
            exclusions.at_step(self.steps);
        }
        if self.knobs.decay != 1.0 {
            self.net.decay(self.knobs.decay);
        }
        if let Some(schedule) = &self.knobs.temperature {
            self.net
                .set_temperature(schedule.at(self.steps))
                .expect("a validated schedule stays > 0");
        }
    }

    fn on_acted(&mut self, source: usize, reward: f64, value: f64) {
        if self.knobs.judgment == Judgment::Advantage {
            self.acted_steps.push(ActedStep {
                source,
                reward,
                value,
            });
        }
    }

    fn on_truncated(&mut self, values: &[f64]) {
        if self.knobs.judgment == Judgment::Advantage {
            self.tail_values = Some(values.to_vec());
        }
    }

    fn on_episode_end(&mut self, end: &EpisodeEnd) {
        match self.knobs.judgment {
            Judgment::Episode => {
                let verdicts = self.episode_verdicts(end.episode_return);
                for (i, verdict) in verdicts.into_iter().enumerate() {
                    if let Some(positive) = verdict {
                        self.judged(i, positive);
                    }
                }
            }
            Judgment::EpisodeAndLoss => {
                let verdicts = self.episode_verdicts(end.episode_return);
                for i in std::mem::take(&mut self.kept) {
                    let confirmed = verdicts[i].expect("a source judged by eq. 7 acted");
                    self.judged(i, confirmed);
                }
            }
            Judgment::Advantage => {
                let steps = std::mem::take(&mut self.acted_steps);
                let tail = self.tail_values.take();
                let advantages = advantages(&steps, tail.as_deref(), self.gamma);
                for (step, advantage) in steps.iter().zip(advantages) {
                    self.judged(step.source, advantage >= 0.0);
                }
            }
            Judgment::Step | Judgment::KSteps(_) | Judgment::TdChange => {}
        }
    }

    fn view(&self) -> SelectorView {
        SelectorView {
            score: SCORE,
            scores: self.net.activations().to_vec(),
            probabilities: self.probabilities(),
            positive: self.positive.clone(),
            negative: self.negative.clone(),
            excluded: self
                .exclusions
                .as_ref()
                .map_or_else(Vec::new, |e| e.excluded().to_vec()),
        }
    }

    fn last_deposit(&self) -> Option<Deposit> {
        Some(self.deposit)
    }

    fn top_probability(&self) -> Option<f64> {
        match &self.exclusions {
            Some(e) if e.any() => self.probabilities().into_iter().reduce(f64::max),
            _ => Some(self.net.top_probability()),
        }
    }

    /// The highest activation (Algorithm 3).
    fn chosen(&self) -> Option<usize> {
        Some(self.net.chosen())
    }

    fn graph(&self) -> Option<&SapNet> {
        Some(&self.net)
    }

    fn set_tracing(&mut self, on: bool) {
        self.tracing = on;
    }

    fn take_activations(&mut self) -> Vec<Activation> {
        std::mem::take(&mut self.traced)
    }
}

#[cfg(test)]
mod tests {
    use super::super::TdError;
    use super::*;

    fn report(before: f64, after: f64) -> Feedback {
        Feedback {
            loss: 0.0,
            previous_statistic_loss: before,
            statistic_loss: after,
            td: None,
        }
    }

    /// Two unrelated policies (one and two hidden layers): no edge, no spreading.
    fn selector(knobs: SapNetKnobs) -> SapNetSelector {
        let policies = [
            PolicyDescription::new(vec![8], "t"),
            PolicyDescription::new(vec![8, 8], "t"),
        ];
        SapNetSelector::new(&policies, SapNetParams::default(), &knobs, 0.99).unwrap()
    }

    /// Policy 0 (one hidden layer) judged negative twice in a row: its category is out of
    /// eq. 6 for 5 steps, never drawn and at probability 0 meanwhile, though it holds the
    /// larger activation; then it is a candidate again.
    #[test]
    fn an_excluded_category_is_never_selected_while_excluded() {
        use rand::SeedableRng;
        let mut s = selector(SapNetKnobs {
            exclusion: Some(Exclusion { after: 2, steps: 5 }),
            ..SapNetKnobs::default()
        });
        assert_eq!(s.on_update(0, &report(0.5, 0.4)), Some(true));
        assert_eq!(s.view().scores, vec![1.0, 0.0]);
        s.on_update(0, &report(0.4, 0.6));
        assert!(s.view().excluded.iter().all(|e| !e), "one negative of two");
        s.on_update(0, &report(0.6, 0.7));
        assert_eq!(s.view().excluded, vec![true, false]);
        assert_eq!(s.view().probabilities, vec![0.0, 1.0]);
        assert_eq!(s.top_probability(), Some(1.0));
        let mut rng = StdRng::seed_from_u64(1);
        for _ in 0..4 {
            for _ in 0..100 {
                assert_eq!(s.act(&mut rng), Actor::Source(1));
            }
            s.on_step();
        }
        assert_eq!(s.view().excluded, vec![true, false], "step 4 of 5");
        s.on_step();
        assert_eq!(s.view().excluded, vec![false, false]);
        let p = s.view().probabilities;
        assert!(
            (p[0] - 1.0_f64.exp() / (1.0 + 1.0_f64.exp())).abs() < 1e-12,
            "{p:?}"
        );
        assert_eq!(s.exclusions_made(), 1);
        assert_eq!(s.knobs.label(), "sapnet-exclude2x5");
    }

    #[test]
    fn the_paper_judges_every_update_by_eq_7() {
        let mut s = selector(SapNetKnobs::default());
        s.on_update(0, &report(0.5, 0.4));
        s.on_update(0, &report(0.4, 0.6));
        s.on_update(1, &report(0.4, 0.4));
        let view = s.view();
        assert_eq!(view.scores, vec![1.0, 1.0]);
        assert_eq!((view.positive, view.negative), (vec![1, 1], vec![1, 0]));
    }

    /// Table II by hand: two one-layer policies joined at 0.95 (< T_ω = 1). Activating
    /// one deposits 𝒜 = 1 on it and η/(h·Ω) = 1/0.95 on its only neighbour; the next hop
    /// back has Ω = 1.9 and stops.
    #[test]
    fn a_positive_judgment_reports_what_it_deposited() {
        let policies = [
            PolicyDescription::new(vec![8], "t"),
            PolicyDescription::new(vec![9], "t"),
        ];
        let mut s = SapNetSelector::new(
            &policies,
            SapNetParams::default(),
            &SapNetKnobs::default(),
            0.99,
        )
        .unwrap();
        assert_eq!(s.on_update(0, &report(0.5, 0.4)), Some(true));
        let deposit = s.last_deposit().unwrap();
        assert_eq!(deposit.own, 1.0);
        assert!((deposit.others - 1.0 / 0.95).abs() < 1e-12, "{deposit:?}");
    }

    #[test]
    fn k_steps_judges_the_change_of_e_over_k_updates() {
        let mut s = selector(SapNetKnobs {
            judgment: Judgment::KSteps(3),
            ..SapNetKnobs::default()
        });
        // E: 1.0 → 1.2 → 1.1 → 0.9: up twice, but lower after three updates.
        for (before, after) in [(1.0, 1.2), (1.2, 1.1), (1.1, 0.9)] {
            s.on_update(0, &report(before, after));
        }
        // E: 0.9 → 0.8 → 0.7 → 1.0: higher after three.
        for (before, after) in [(0.9, 0.8), (0.8, 0.7), (0.7, 1.0)] {
            s.on_update(0, &report(before, after));
        }
        let view = s.view();
        assert_eq!((view.positive[0], view.negative[0]), (1, 1));
        assert_eq!(view.scores[0], 1.0);
    }

    #[test]
    fn an_episode_judgment_compares_with_the_sources_running_mean() {
        let mut s = selector(SapNetKnobs {
            judgment: Judgment::Episode,
            ..SapNetKnobs::default()
        });
        let episode = |s: &mut SapNetSelector, ret: f64| {
            s.acted = vec![true, false];
            s.on_episode_end(&EpisodeEnd {
                episode_return: ret,
                discounted_return: 0.0,
            });
        };
        // First episode: positive. Mean 10 → 12 ≥ 10 positive → mean 11 → 10.5 < 11 negative.
        for ret in [10.0, 12.0, 10.5] {
            episode(&mut s, ret);
        }
        // Source 1 never acted: it was never judged.
        let view = s.view();
        assert_eq!((view.positive, view.negative), (vec![2, 0], vec![1, 0]));
        assert_eq!(view.scores, vec![2.0, 0.0]);
        assert!((s.mean_return[0].0 - 32.5 / 3.0).abs() < 1e-12);
        assert_eq!(s.mean_return[0].1, 3);
    }

    fn td_report(before: f64, after: f64) -> Feedback {
        Feedback {
            td: Some(TdError { before, after }),
            ..report(0.0, 0.0)
        }
    }

    fn end(episode_return: f64) -> EpisodeEnd {
        EpisodeEnd {
            episode_return,
            discounted_return: 0.0,
        }
    }

    #[test]
    fn td_change_judges_every_update_by_the_size_of_the_td_error() {
        let mut s = selector(SapNetKnobs {
            judgment: Judgment::TdChange,
            ..SapNetKnobs::default()
        });
        assert_eq!(
            s.needs(),
            Needs {
                td_error: true,
                values: false
            }
        );
        // |δ| 3.46 → 3.45: smaller, positive; −0.5 → 0.5: the same size, positive;
        // 0.2 → −0.3: larger, negative (the sign does not matter, the size does).
        assert_eq!(s.on_update(0, &td_report(3.46, 3.45)), Some(true));
        assert_eq!(s.on_update(0, &td_report(-0.5, 0.5)), Some(true));
        assert_eq!(s.on_update(1, &td_report(0.2, -0.3)), Some(false));
        // E rose on every one of them: eq. 7 would have said negative; E is not read.
        let view = s.view();
        assert_eq!((view.positive, view.negative), (vec![2, 0], vec![0, 1]));
        assert_eq!(view.scores, vec![2.0, 0.0]);
    }

    /// γ = 0.5 for round numbers. Steps (source, r, V): (0, 1, 1.5), (1, 1, 0.5),
    /// (0, 2, 3.0). Terminated: G_2 = 2, G_1 = 1 + 0.5·2 = 2, G_0 = 1 + 0.5·2 = 2, so
    /// A = 2 − 1.5, 2 − 0.5, 2 − 3 = 0.5, 1.5, −1. Cut by the time limit with
    /// V_0(s_3) = 4, V_1(s_3) = 8: G_2 += 0.5·4 = 4, G_1 += 0.25·8 = 4, G_0 += 0.125·4 =
    /// 2.5, so A = 1, 3.5, 1.
    #[test]
    fn the_advantage_is_the_return_to_go_over_the_value_estimate() {
        let steps = [(0, 1.0, 1.5), (1, 1.0, 0.5), (0, 2.0, 3.0)].map(|(source, reward, value)| {
            ActedStep {
                source,
                reward,
                value,
            }
        });
        assert_eq!(advantages(&steps, None, 0.5), vec![0.5, 1.5, -1.0]);
        assert_eq!(
            advantages(&steps, Some(&[4.0, 8.0]), 0.5),
            vec![1.0, 3.5, 1.0]
        );

        // The selector judges them at the episode's end, one per step, in step order.
        let mut s = SapNetSelector::new(
            &[
                PolicyDescription::new(vec![8], "t"),
                PolicyDescription::new(vec![8, 8], "t"),
            ],
            SapNetParams::default(),
            &SapNetKnobs {
                judgment: Judgment::Advantage,
                ..SapNetKnobs::default()
            },
            0.5,
        )
        .unwrap();
        assert!(s.needs().values && !s.needs().td_error);
        for step in &steps {
            s.on_acted(step.source, step.reward, step.value);
            // Nothing is judged before the episode ends.
            assert_eq!(s.on_update(step.source, &report(0.5, 0.4)), None);
        }
        assert_eq!(s.view().positive, vec![0, 0]);
        s.on_episode_end(&end(4.0));
        let view = s.view();
        assert_eq!((view.positive, view.negative), (vec![1, 1], vec![1, 0]));
        // The next episode, cut by its time limit: all three positive.
        for step in &steps {
            s.on_acted(step.source, step.reward, step.value);
        }
        s.on_truncated(&[4.0, 8.0]);
        s.on_episode_end(&end(4.0));
        let view = s.view();
        assert_eq!((view.positive, view.negative), (vec![3, 2], vec![1, 0]));
        assert_eq!(view.scores, vec![3.0, 2.0]);
        // The tail was the cut episode's alone: a terminated one after it has none.
        s.on_acted(0, 1.0, 1.5);
        s.on_episode_end(&end(1.0));
        assert_eq!(s.view().negative, vec![2, 0]);
    }

    #[test]
    fn episode_and_loss_confirms_eq_7_positives_by_the_episodes_return() {
        let mut s = selector(SapNetKnobs {
            judgment: Judgment::EpisodeAndLoss,
            ..SapNetKnobs::default()
        });
        assert_eq!(s.needs(), Needs::default());
        let act = |s: &mut SapNetSelector, i: usize| {
            s.acted[i] = true;
        };
        // Episode 1 (return 10, source 0's first: its verdict is positive). E falls, rises,
        // falls: two kept positives, one negative at once.
        act(&mut s, 0);
        assert_eq!(s.on_update(0, &report(0.5, 0.4)), None);
        assert_eq!(s.on_update(0, &report(0.4, 0.6)), Some(false));
        assert_eq!(s.on_update(0, &report(0.6, 0.5)), None);
        assert_eq!((s.view().positive[0], s.view().negative[0]), (0, 1));
        s.on_episode_end(&end(10.0));
        assert_eq!((s.view().positive[0], s.view().negative[0]), (2, 1));
        // Episode 2 (return 8 < mean 10): its kept positive counts negative; source 1 acted
        // for the first time and its kept positive is confirmed.
        act(&mut s, 0);
        act(&mut s, 1);
        assert_eq!(s.on_update(0, &report(0.5, 0.4)), None);
        assert_eq!(s.on_update(1, &report(0.5, 0.4)), None);
        s.on_episode_end(&end(8.0));
        let view = s.view();
        assert_eq!((view.positive, view.negative), (vec![2, 1], vec![2, 0]));
        assert_eq!(view.scores, vec![2.0, 1.0]);
        // Episode 3 (return 9.5 ≥ source 0's mean 9): confirmed.
        act(&mut s, 0);
        s.on_update(0, &report(0.5, 0.4));
        s.on_episode_end(&end(9.5));
        assert_eq!(s.view().positive[0], 3);
        assert_eq!(s.mean_return[0], (27.5 / 3.0, 3));
    }

    #[test]
    fn decay_and_the_schedule_act_after_every_step() {
        let mut s = selector(SapNetKnobs {
            temperature: Some(Schedule::Linear {
                from: 2.0,
                to: 0.5,
                steps: 2,
            }),
            decay: 0.5,
            ..SapNetKnobs::default()
        });
        assert_eq!(s.net.params().temperature, 2.0);
        s.on_update(0, &report(1.0, 0.5));
        s.on_step();
        assert_eq!(s.net.activations(), &[0.5, 0.0]);
        assert_eq!(s.net.params().temperature, 1.25);
        s.on_step();
        assert_eq!(s.net.activations(), &[0.25, 0.0]);
        assert_eq!(s.net.params().temperature, 0.5);
    }

    #[test]
    fn labels_name_what_differs_from_the_paper() {
        assert_eq!(SapNetKnobs::default().label(), "sapnet");
        let knobs = SapNetKnobs {
            temperature: Some(Schedule::Exponential {
                from: 4.0,
                to: 0.5,
                steps: 100,
            }),
            judgment: Judgment::Episode,
            decay: 0.999,
            label: None,
            exclusion: Some(Exclusion {
                after: 3,
                steps: 40,
            }),
        };
        assert_eq!(
            knobs.label(),
            "sapnet-tau-exp4-0.5-episode-decay0.999-exclude3x40"
        );
        let judged = |judgment| {
            SapNetKnobs {
                judgment,
                ..SapNetKnobs::default()
            }
            .label()
        };
        assert_eq!(judged(Judgment::TdChange), "sapnet-td");
        assert_eq!(judged(Judgment::Advantage), "sapnet-advantage");
        assert_eq!(judged(Judgment::EpisodeAndLoss), "sapnet-episode-and-loss");
    }

    #[test]
    fn a_label_that_cannot_name_a_file_is_refused() {
        for label in ["my/slash", "", ".hidden", "back\\slash", "a,b", "new\nline"] {
            let knobs = SapNetKnobs {
                label: Some(label.to_string()),
                ..SapNetKnobs::default()
            };
            let err = knobs.validate("protocol.methods[1]").unwrap_err();
            assert!(
                err.starts_with(
                    "field `protocol.methods[1].label`: expected a name of letters, digits"
                ),
                "{label}: {err}"
            );
        }
        let fine = SapNetKnobs {
            label: Some("sapnet-mine".to_string()),
            ..SapNetKnobs::default()
        };
        assert!(fine.validate("protocol.methods[1]").is_ok());
    }

    #[test]
    fn bad_knobs_are_located() {
        let bad = |knobs: SapNetKnobs| knobs.validate("protocol.methods[1]").unwrap_err();
        let decay = bad(SapNetKnobs {
            decay: 0.0,
            ..SapNetKnobs::default()
        });
        assert_eq!(
            decay,
            "field `protocol.methods[1].decay`: expected λ in (0, 1], got 0.0"
        );
        assert!(bad(SapNetKnobs {
            decay: 1.5,
            ..SapNetKnobs::default()
        })
        .contains("decay"));
        assert!(bad(SapNetKnobs {
            judgment: Judgment::KSteps(0),
            ..SapNetKnobs::default()
        })
        .contains("`protocol.methods[1].judgment`"));
        assert!(bad(SapNetKnobs {
            temperature: Some(Schedule::Linear {
                from: -1.0,
                to: 1.0,
                steps: 5
            }),
            ..SapNetKnobs::default()
        })
        .contains("`protocol.methods[1].temperature.from`"));
    }
}
