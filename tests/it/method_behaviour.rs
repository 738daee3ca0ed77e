//! What defines each of the field's reuse baselines, checked on its own mechanism rather
//! than on its labels or counters (issue 49, item 6): GPI's evaluation of its sources on the
//! target task, the Q-switch's exploration, QDagger's distillation and its phases, A2T's
//! attention and base.
//!
//! The toy task of several tests is a one-state bandit, episodes of one step: action 0 pays
//! 1, action 1 pays 0, so every policy's true values are `Q(s, ·) = (1, 0)`. Networks of one
//! input, two hidden ReLU units and two outputs are set by hand to output chosen Q-values.

use candle_core::{Device, Tensor};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use sapnet::dqn::{
    Architecture, AttentionLearner, DqnAgent, DqnConfig, EpsilonGreedy, Exploration, Init, QNet,
    ReplayBuffer, Transition,
};
use sapnet::reuse::gpi::{Evaluation, Gpi};
use sapnet::reuse::qdagger::{QDagger, QDaggerKnobs};
use sapnet::reuse::qswitch::{Proposal, QSwitch};
use sapnet::reuse::{Actor, EpisodeEnd, Evaluate, Selector, StateValues};

const STATE: [f32; 1] = [1.0];

/// A network whose Q-values of [`STATE`] are `q`: both hidden units are 1, each output the
/// sum of two equal weights.
fn net_with(q: [f32; 2]) -> QNet {
    let tensor =
        |values: Vec<f32>, shape: &[usize]| Tensor::from_vec(values, shape, &Device::Cpu).unwrap();
    QNet::from_parameters(
        Architecture::new(1, &[2], 2),
        vec![
            tensor(vec![1.0, 1.0], &[2, 1]),
            tensor(vec![0.0, 0.0], &[2]),
            tensor(
                vec![q[0] / 2.0, q[0] / 2.0, q[1] / 2.0, q[1] / 2.0],
                &[2, 2],
            ),
            tensor(vec![0.0, 0.0], &[2]),
        ],
    )
    .unwrap()
}

fn config() -> DqnConfig {
    DqnConfig {
        learning_rate: 0.01,
        batch_size: 8,
        replay_start_size: 1,
        target_update_interval: 10,
        exploration: Exploration::Constant { epsilon: 0.0 },
        ..DqnConfig::default()
    }
}

/// The bandit's step: its reward; every episode ends with it.
fn pay(action: usize) -> f64 {
    if action == 0 {
        1.0
    } else {
        0.0
    }
}

fn store(replay: &mut ReplayBuffer, action: usize) {
    replay.push(Transition {
        obs: &STATE,
        action,
        reward: pay(action),
        next_obs: &STATE,
        terminated: true,
        truncated: false,
    });
}

/// GPI on the bandit for `steps` steps, its sources' values evaluated as `evaluation` says:
/// the step of the last time the over-estimating source won, if it ever did.
fn gpi_last_follows_the_overestimate(evaluation: Evaluation, steps: u32) -> Option<u32> {
    // Source 0 believes action 1 worth 50 (on the target it pays 0): over-estimated, and
    // its greedy policy is the bad one. Source 1 is right: (1, 0), greedy on action 0.
    let sources = [net_with([0.0, 50.0]), net_with([1.0, 0.0])];
    let mut evaluators: Vec<DqnAgent> = sources
        .iter()
        .map(|s| {
            let mut e = DqnAgent::new(s.deep_copy().unwrap(), &config()).unwrap();
            e.evaluate_policy_of(s.deep_copy().unwrap());
            e
        })
        .collect();
    let mut learner = DqnAgent::new(net_with([0.0, 0.0]), &config()).unwrap();
    let mut gpi = Gpi::new(2, evaluation);
    let mut replay = ReplayBuffer::new(10_000, 1);
    let mut rng = StdRng::seed_from_u64(7);
    let mut last = None;
    for step in 0..steps {
        assert_eq!(gpi.act(&mut rng), Actor::Combined);
        let learner_q = learner.online().q_values(&STATE).unwrap();
        let source_q: Vec<Vec<f32>> = match evaluation {
            Evaluation::Off => sources
                .iter()
                .map(|s| s.q_values(&STATE).unwrap())
                .collect(),
            _ => evaluators
                .iter()
                .map(|e| e.online().q_values(&STATE).unwrap())
                .collect(),
        };
        let values = StateValues {
            learner: &learner_q,
            sources: &source_q,
            explored: None,
            attention: None,
        };
        let choice = gpi.combine(&values);
        gpi.on_combined(&values, choice);
        if choice.followed == Some(0) {
            last = Some(step);
        }
        store(&mut replay, choice.action);
        learner.observe(&replay, &mut rng).unwrap();
        match gpi.evaluate() {
            Evaluate::Source(i) => {
                evaluators[i].learn_once(&replay, 10, &mut rng).unwrap();
            }
            Evaluate::Every => {
                for e in &mut evaluators {
                    e.learn_once(&replay, 10, &mut rng).unwrap();
                }
            }
            Evaluate::Nobody => {}
        }
    }
    last
}

/// Unevaluated, GPI takes the over-estimated network at its word for ever; evaluated on the
/// target task, that source's value falls to what its policy earns there (0) and GPI leaves
/// it for the source that is right, within 1,000 steps (measured on this seed: the last step
/// that followed it is step 48 evaluating the winner, 330 evaluating every source).
#[test]
fn evaluated_gpi_leaves_a_source_that_over_estimates_and_unevaluated_gpi_does_not() {
    let steps = 6_000;
    assert_eq!(
        gpi_last_follows_the_overestimate(Evaluation::Off, steps),
        Some(steps - 1),
        "unevaluated GPI follows the over-estimate to the end"
    );
    for evaluation in [Evaluation::Winner, Evaluation::All] {
        let last = gpi_last_follows_the_overestimate(evaluation, steps)
            .expect("it follows the over-estimate at first");
        assert!(
            last < 1_000,
            "{evaluation:?}: still followed source 0 at step {last}"
        );
    }
}

/// The evaluation estimates the value of the source's own greedy policy, not the best
/// action's: on a two-step chain whose second step the source's policy handles badly, the
/// bootstrap takes the source's action at `s′`, not the maximum.
#[test]
fn a_sources_value_is_estimated_by_bootstrapping_on_its_own_policy() {
    // s′ (obs 1): the source's greedy action there is 1 (its Q (0, 2)), which the target
    // network values at 2; the maximum would be 5 (action 0 of a target valuing (5, 2)).
    let policy = net_with([0.0, 2.0]);
    let mut evaluator = DqnAgent::new(
        net_with([5.0, 2.0]),
        &DqnConfig {
            learning_rate: 0.05,
            gamma: 0.5,
            ..config()
        },
    )
    .unwrap();
    evaluator.evaluate_policy_of(policy);
    let mut replay = ReplayBuffer::new(100, 1);
    replay.push(Transition {
        obs: &STATE,
        action: 0,
        reward: 0.0,
        next_obs: &STATE,
        terminated: false,
        truncated: false,
    });
    let mut rng = StdRng::seed_from_u64(1);
    // The target network is copied only after 1,000 updates: y = 0 + ½·2 = 1 throughout.
    for _ in 0..600 {
        evaluator.learn_once(&replay, 1_000, &mut rng).unwrap();
    }
    let q = evaluator.online().q_values(&STATE).unwrap()[0];
    assert!(
        (q - 1.0).abs() < 0.05,
        "Q̂(s, 0) = {q}, expected y = ½·2 = 1, not ½·5"
    );
}

/// The Q-switch's exploration is DQN's: with every source proposing the learner's greedy
/// action (the case where the proposal of the learner's ε-greedy action overruled every
/// exploring step), the share of non-greedy actions of the sampled switch is ε·(1 − 1/|A|),
/// as DQN's, and the behaviour proposal's is 0.
#[test]
fn the_q_switch_explores_as_dqn_does() {
    let epsilon = 0.2;
    let explorer = EpsilonGreedy::new(Exploration::Constant { epsilon });
    let learner = [1.0f32, 0.0];
    let sources = vec![vec![10.0f32, 0.0]; 3];
    let steps = 20_000;
    let share = |proposal: Proposal| {
        let mut switch = QSwitch::new(3, proposal, 1.0);
        let mut rng = StdRng::seed_from_u64(3);
        let mut non_greedy = 0;
        for _ in 0..steps {
            switch.act(&mut rng);
            let explored = explorer.explore(0, 2, &mut rng);
            let choice = switch.combine(&StateValues {
                learner: &learner,
                sources: &sources,
                explored,
                attention: None,
            });
            non_greedy += usize::from(choice.action != 0);
        }
        non_greedy as f64 / steps as f64
    };
    // DQN's: ε·½ = 0.1; 20,000 steps put the share within ±0.0042 (1σ = 0.0021) of it.
    let sampled = share(Proposal::Sampled);
    assert!((sampled - 0.1).abs() < 0.01, "sampled switch: {sampled}");
    assert_eq!(
        share(Proposal::Behaviour),
        0.0,
        "behaviour proposals cancel exploration"
    );
}

/// With λ = 0 the student's update is DQN's, bit for bit; with λ > 0 the distillation moves
/// the student's softmax toward the teacher's.
#[test]
fn qdagger_distils_only_with_a_positive_weight_and_then_toward_the_teacher() {
    let teacher = net_with([3.0, -3.0]);
    let student = net_with([0.0, 0.5]);
    let mut replay = ReplayBuffer::new(100, 1);
    for action in [0, 1, 0, 1] {
        store(&mut replay, action);
    }
    let train = |weight: Option<f64>| {
        let mut agent = DqnAgent::new(student.deep_copy().unwrap(), &config()).unwrap();
        if let Some(weight) = weight {
            agent.distil_from(teacher.deep_copy().unwrap(), 1.0);
            agent.set_distillation_weight(weight);
        }
        let mut rng = StdRng::seed_from_u64(5);
        for _ in 0..50 {
            agent.learn_once(&replay, 1_000, &mut rng).unwrap();
        }
        agent.online().q_values(&STATE).unwrap()
    };
    let dqn = train(None);
    let bits = |q: &[f32]| q.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&train(Some(0.0))), bits(&dqn), "λ = 0 is DQN's update");
    let distilled = train(Some(1.0));
    // The teacher's softmax puts ≈ 1 on action 0; the gap Q(a0) − Q(a1) is its log-odds.
    let gap = |q: &[f32]| q[0] - q[1];
    assert!(
        gap(&distilled) > gap(&dqn) + 0.1,
        "distilled {distilled:?} against DQN's {dqn:?}"
    );
}

/// λ_t = max(1 − R̄_student/R̄_teacher, 0) falls as the student's returns rise, to 0.
#[test]
fn qdagger_lambda_decays_as_the_student_catches_up() {
    let knobs = QDaggerKnobs {
        teacher_eval_episodes: 1,
        teacher_steps: 1,
        offline_steps: 1,
        ..QDaggerKnobs::default()
    };
    let mut q = QDagger::new(&knobs, 2, 0, (0.0, 500.0));
    let mut rng = StdRng::seed_from_u64(0);
    let end = |q: &mut QDagger, episode_return: f64| {
        q.on_episode_end(&EpisodeEnd {
            episode_return,
            discounted_return: 0.0,
        })
    };
    // The teacher's evaluation: 400.
    q.act(&mut rng);
    q.learner_round();
    end(&mut q, 400.0);
    // Its data step, then the offline round: the student's phase.
    for _ in 0..3 {
        q.act(&mut rng);
        q.learner_round();
    }
    let mut weights = Vec::new();
    for episode_return in (0..60).map(|k| 10.0 * f64::from(k)) {
        end(&mut q, episode_return);
        weights.push(q.distillation().unwrap().weight);
    }
    assert!(weights[..9].iter().all(|&w| w == 1.0), "{weights:?}");
    assert!(weights[9] < 1.0 && weights[9] > 0.0, "{weights:?}");
    assert!(
        weights.windows(2).skip(9).all(|w| w[1] <= w[0]),
        "{weights:?}"
    );
    assert_eq!(
        *weights.last().unwrap(),
        0.0,
        "a student at the teacher's level"
    );
}

/// The offline phase makes exactly its updates, its target copied every
/// `target_interval` of them.
#[test]
fn qdaggers_offline_round_counts_its_updates_and_copies_its_target_on_cadence() {
    let mut replay = ReplayBuffer::new(100, 1);
    for action in [0, 1, 0, 1] {
        store(&mut replay, action);
    }
    let round = |updates: u64, target_interval: u64| {
        let mut agent = DqnAgent::new(net_with([0.0, 0.5]), &config()).unwrap();
        let mut rng = StdRng::seed_from_u64(9);
        agent
            .offline_round(&replay, updates, target_interval, &mut rng)
            .unwrap();
        let online = agent.online().q_values(&STATE).unwrap();
        let target = agent.target().q_values(&STATE).unwrap();
        (agent.updates(), online == target, target)
    };
    // 6 updates, copied after the 3rd and the 6th: the target is the online net.
    assert_eq!(round(6, 3).0, 6);
    assert!(round(6, 3).1);
    // 7: the last copy after the 6th, one update behind.
    let (updates, equal, _) = round(7, 3);
    assert_eq!((updates, equal), (7, false));
    // Never copied: the target is the initial network.
    assert_eq!(round(7, 100).2, vec![0.0, 0.5]);
}

/// A2T's weights are a softmax over the sources and the base: they sum to 1.
#[test]
fn a2ts_weights_sum_to_one_over_the_sources_and_the_base() {
    let mut rng = StdRng::seed_from_u64(2);
    let attention =
        AttentionLearner::new(4, &[16], 3, Init::LecunNormal, &config(), &mut rng).unwrap();
    for _ in 0..20 {
        let obs: Vec<f32> = (0..4).map(|_| rng.random_range(-2.0..2.0)).collect();
        let weights = attention.weights(&obs).unwrap();
        assert_eq!(weights.len(), 4, "3 sources and the base");
        let sum: f32 = weights.iter().sum();
        assert!((sum - 1.0).abs() < 1e-5, "{weights:?} sums to {sum}");
        assert!(weights.iter().all(|&w| w > 0.0));
    }
}

/// On the bandit, with a good source (its Q (1, 0), right) and a bad one (Q (0, 1): it
/// prefers the action that pays nothing) and a base that knows nothing yet, the attention
/// learned by the mixture's TD error comes to weigh the good source above the bad one.
#[test]
fn a2ts_attention_comes_to_prefer_the_good_source() {
    let good = net_with([1.0, 0.0]);
    let bad = net_with([0.0, 1.0]);
    let base = net_with([0.0, 0.0]);
    let mut rng = StdRng::seed_from_u64(4);
    let mut attention = AttentionLearner::new(
        1,
        &[8],
        2,
        Init::LecunNormal,
        &DqnConfig {
            learning_rate: 0.01,
            ..config()
        },
        &mut rng,
    )
    .unwrap();
    let mut replay = ReplayBuffer::new(10_000, 1);
    let before = attention.weights(&STATE).unwrap();
    for step in 0..2_000 {
        // Both actions in turn: the data of a behaviour that tries each.
        store(&mut replay, step % 2);
        attention
            .observe(&replay, &mut rng, &[&good, &bad], (&base, &base))
            .unwrap();
    }
    let after = attention.weights(&STATE).unwrap();
    assert!(
        after[0] > after[1] + 0.2,
        "good source's weight {} against the bad's {} (before: {before:?})",
        after[0],
        after[1]
    );
}

/// A2T's base is a learner of its own: over a run its weights change (the run's network
/// after 600 CartPole steps against after 1, when nothing has learned yet).
#[test]
fn a2ts_base_learns_during_a_run() {
    use sapnet::config::{Budget, Config};
    use sapnet::sapnet::PolicyDescription;
    use sapnet::trainer::{command_channel, train, MethodId, RunSpec, SourcePolicy, StreamOptions};
    let config = Config::default();
    let a2t = sapnet::reuse::Method::A2t(Default::default());
    let base_after = |steps: u64| {
        let sources: Vec<SourcePolicy> = (0..3)
            .map(|i| {
                let net = QNet::new(Architecture::new(4, &[8], 2), &mut StdRng::seed_from_u64(i))
                    .unwrap();
                let description = PolicyDescription::new(vec![8], "cartpole");
                SourcePolicy::new(format!("source-{i}"), net, description, Some(10.0)).unwrap()
            })
            .collect();
        let mut dqn = config.dqn.clone();
        dqn.replay_start_size = 10;
        let spec = RunSpec {
            run: 0,
            method: MethodId::new(0, &a2t),
            reuse: a2t.clone(),
            env: config.env.clone(),
            dqn,
            sapnet: config.sapnet.clone(),
            sources: std::sync::Arc::new(sources),
            budget: Budget::Steps(steps),
            test_episodes: 0,
            seed: 3,
            stream: StreamOptions::episodes(),
        };
        let (events, _received) = std::sync::mpsc::channel();
        let (_commands, receiver) = command_channel();
        let outcome = train(&spec, &events, &receiver).unwrap();
        (
            outcome.record.updates,
            outcome.net.q_values(&[0.01, 0.02, 0.03, 0.04]).unwrap(),
        )
    };
    let (none, before) = base_after(1);
    let (updates, after) = base_after(600);
    assert_eq!(none, 0);
    // The base's and the attention's: two updates a step once learning starts.
    assert_eq!(updates, 2 * (600 - 9));
    assert_ne!(before, after, "the base learned");
}

/// SFQL's bootstrap: on the bandit's two-step variant, a learner that knows nothing
/// bootstraps, with GPI's action, on the action a source values most at `s′`, valued by
/// the learner's own target network; with DQN's, on its own maximum. Here the source
/// prefers action 1 at `s′`, where the learner's target values (5, 2): GPI's target is
/// γ·2 = 1, DQN's γ·5 = 2.5.
#[test]
fn gpis_sfql_bootstrap_takes_the_gpi_action_at_the_next_state() {
    let source = net_with([0.0, 9.0]);
    let train = |joined: &[&QNet]| {
        let mut learner = DqnAgent::new(
            net_with([5.0, 2.0]),
            &DqnConfig {
                learning_rate: 0.05,
                gamma: 0.5,
                target_update_interval: 1_000_000,
                ..config()
            },
        )
        .unwrap();
        let mut replay = ReplayBuffer::new(10, 1);
        replay.push(Transition {
            obs: &STATE,
            action: 0,
            reward: 0.0,
            next_obs: &STATE,
            terminated: false,
            truncated: false,
        });
        let mut rng = StdRng::seed_from_u64(1);
        for _ in 0..600 {
            learner.observe_joined(&replay, &mut rng, joined).unwrap();
        }
        learner.online().q_values(&STATE).unwrap()[0]
    };
    let gpi = train(&[&source]);
    let dqn = train(&[]);
    assert!(
        (gpi - 1.0).abs() < 0.05,
        "GPI's bootstrap: Q(s, 0) = {gpi}, expected ½·2"
    );
    assert!(
        (dqn - 2.5).abs() < 0.05,
        "DQN's: Q(s, 0) = {dqn}, expected ½·5"
    );
}
