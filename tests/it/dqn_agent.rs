//! The DQN learner end to end: updates, target copies, the statistic loss, determinism,
//! and learning a small task.

use rand::{rngs::StdRng, Rng, SeedableRng};
use sapnet::dqn::{huber, Architecture, Batch, DqnAgent, DqnError, QNet, ReplayBuffer, Transition};
use sapnet::dqn::{DqnConfig, Exploration};
use sapnet::env::{self, EnvConfig, EnvError, Environment, Step};

fn agent(hidden: &[usize], seed: u64, config: &DqnConfig) -> DqnAgent {
    let net = QNet::new(
        Architecture::new(2, hidden, 3),
        &mut StdRng::seed_from_u64(seed),
    )
    .unwrap();
    DqnAgent::new(net, config).unwrap()
}

fn flat(net: &QNet) -> Vec<f32> {
    net.parameters()
        .iter()
        .flat_map(|v| {
            v.as_tensor()
                .flatten_all()
                .unwrap()
                .to_vec1::<f32>()
                .unwrap()
        })
        .collect()
}

/// A replay buffer of random transitions.
fn random_replay(n: usize, rng: &mut StdRng) -> ReplayBuffer {
    let mut replay = ReplayBuffer::new(1000, 2);
    for _ in 0..n {
        push_random(&mut replay, rng, false);
    }
    replay
}

/// Pushes a random transition (2 observation values, 3 actions), terminated one time in
/// ten, and truncated one time in ten if `truncations` (drawn only then).
fn push_random(replay: &mut ReplayBuffer, rng: &mut StdRng, truncations: bool) {
    let obs = [rng.random::<f32>(), rng.random::<f32>()];
    let next_obs = [rng.random::<f32>(), rng.random::<f32>()];
    replay.push(Transition {
        obs: &obs,
        action: rng.random_range(0..3),
        reward: rng.random_range(-1.0..1.0),
        next_obs: &next_obs,
        terminated: rng.random::<f64>() < 0.1,
        truncated: truncations && rng.random::<f64>() < 0.1,
    });
}

fn fixed_batch() -> Batch {
    let mut rng = StdRng::seed_from_u64(42);
    let replay = random_replay(64, &mut rng);
    let mut batch = Batch::new();
    replay.sample_into(32, &mut batch, &mut rng);
    batch
}

#[test]
fn updates_reduce_the_loss_on_a_fixed_batch() {
    let config = DqnConfig::default();
    let mut agent = agent(&[16], 0, &config);
    let batch = fixed_batch();
    let first = agent.update(&batch).unwrap();
    let second = agent.update(&batch).unwrap();
    assert!(second < first, "{second} !< {first}");
    let mut last = second;
    for _ in 0..200 {
        last = agent.update(&batch).unwrap();
    }
    assert!(last < 0.5 * first, "{last} vs {first}");
}

#[test]
fn the_loss_is_the_huber_td_error_and_truncation_bootstraps() {
    let (obs, next_obs) = ([0.3f32, -0.2], [0.5f32, 0.1]);
    let loss_for = |terminated, truncated, truncation_as_terminal| {
        let config = DqnConfig {
            truncation_as_terminal,
            ..DqnConfig::default()
        };
        let mut agent = agent(&[8], 5, &config);
        let mut batch = Batch::new();
        batch.push(Transition {
            obs: &obs,
            action: 1,
            reward: 0.7,
            next_obs: &next_obs,
            terminated,
            truncated,
        });
        let q = agent.online().q_values(&obs).unwrap()[1] as f64;
        let next_max = agent
            .target()
            .q_values(&next_obs)
            .unwrap()
            .into_iter()
            .fold(f32::MIN, f32::max);
        let bootstrapped = huber(q - (0.7 + 0.99 * next_max as f64), 1.0);
        let cut = huber(q - 0.7, 1.0);
        (agent.update(&batch).unwrap(), bootstrapped, cut)
    };
    let close = |a: f64, b: f64| (a - b).abs() < 1e-5;
    let (loss, bootstrapped, cut) = loss_for(false, false, false);
    assert!(close(loss, bootstrapped) && !close(bootstrapped, cut));
    let (loss, _, cut) = loss_for(true, false, false);
    assert!(close(loss, cut));
    // Gymnasium semantics: a time limit does not end the value of the next state.
    let (loss, bootstrapped, _) = loss_for(false, true, false);
    assert!(close(loss, bootstrapped));
    // Old Gym / ChainerRL semantics, on request.
    let (loss, _, cut) = loss_for(false, true, true);
    assert!(close(loss, cut));
}

#[test]
fn the_target_network_is_copied_exactly_every_interval() {
    let config = DqnConfig {
        target_update_interval: 5,
        replay_start_size: 1,
        ..DqnConfig::default()
    };
    let mut rng = StdRng::seed_from_u64(1);
    let replay = random_replay(100, &mut rng);
    let mut agent = agent(&[8], 1, &config);
    let mut previous_target = flat(agent.target());
    for step in 1..=12u64 {
        let online_before = flat(agent.online());
        agent
            .observe(&replay, &mut rng)
            .unwrap()
            .expect("an update every step");
        let target = flat(agent.target());
        if step % 5 == 0 {
            // ChainerRL's order: the copy comes before this step's update.
            assert_eq!(target, online_before, "step {step}");
            assert_ne!(target, previous_target, "step {step}");
        } else {
            assert_eq!(target, previous_target, "step {step}");
        }
        previous_target = target;
    }
}

#[test]
fn the_statistic_loss_is_chainerrls_average_loss() {
    let config = DqnConfig {
        replay_start_size: 10,
        ..DqnConfig::default()
    };
    let mut rng = StdRng::seed_from_u64(2);
    let replay = random_replay(40, &mut rng);
    let mut agent = agent(&[8], 2, &config);
    assert_eq!(agent.statistic_loss(), 0.0);
    let mut expected = 0.0;
    for _ in 0..50 {
        let report = agent.observe(&replay, &mut rng).unwrap().unwrap();
        assert_eq!(report.previous_statistic_loss, expected);
        // ChainerRL, statement for statement (`1 − 0.99` is not the double nearest 0.01).
        let by_hand = 0.99 * expected + 0.01 * report.loss;
        expected *= 0.99;
        expected += (1.0 - 0.99) * report.loss;
        assert_eq!(report.statistic_loss, expected);
        assert!((expected - by_hand).abs() <= 1e-15 * by_hand.abs());
        assert_eq!(agent.statistic_loss(), expected);
        assert_eq!(agent.last_loss(), Some(report.loss));
        assert!(
            (report.transition() - 0.01 * (report.loss - report.previous_statistic_loss)).abs()
                < 1e-12
        );
    }
    assert_eq!(agent.updates(), 50);
}

#[test]
fn no_update_before_the_replay_start_size_or_between_intervals() {
    let config = DqnConfig {
        replay_start_size: 20,
        update_interval: 3,
        gradient_steps: 2,
        ..DqnConfig::default()
    };
    let mut rng = StdRng::seed_from_u64(3);
    let mut agent = agent(&[8], 3, &config);
    assert!(agent
        .observe(&random_replay(19, &mut rng), &mut rng)
        .unwrap()
        .is_none());
    let replay = random_replay(20, &mut rng);
    assert!(agent.observe(&replay, &mut rng).unwrap().is_none()); // step 2
    assert!(agent.observe(&replay, &mut rng).unwrap().is_some()); // step 3
    assert_eq!(agent.updates(), 2);
}

#[test]
fn same_seed_same_weights_and_losses() {
    let run = |seed: u64| {
        let config = DqnConfig {
            replay_start_size: 8,
            target_update_interval: 7,
            ..DqnConfig::default()
        };
        let mut rng = StdRng::seed_from_u64(seed);
        let replay = random_replay(64, &mut rng);
        let mut agent = agent(&[12, 9], seed, &config);
        let losses: Vec<f64> = (0..30)
            .map(|_| agent.observe(&replay, &mut rng).unwrap().unwrap().loss)
            .collect();
        (flat(agent.online()), losses)
    };
    assert_eq!(run(11), run(11));
    assert_ne!(run(11).1, run(12).1);
}

#[test]
fn a_non_finite_loss_is_an_error_naming_the_step_and_keeps_the_weights() {
    let config = DqnConfig {
        replay_start_size: 1,
        ..DqnConfig::default()
    };
    let mut rng = StdRng::seed_from_u64(4);
    let mut agent = agent(&[8], 4, &config);
    let mut replay = ReplayBuffer::new(10, 2);
    replay.push(Transition {
        obs: &[0.0, 1.0],
        action: 0,
        reward: f64::NAN,
        next_obs: &[1.0, 0.0],
        terminated: false,
        truncated: false,
    });
    let before = flat(agent.online());
    agent.observe(&ReplayBuffer::new(10, 2), &mut rng).unwrap();
    let err = agent.observe(&replay, &mut rng).unwrap_err();
    assert!(
        matches!(
            err,
            DqnError::NonFiniteLoss {
                step: 2,
                update: 1,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("step 2"), "{err}");
    assert_eq!(flat(agent.online()), before);
    assert_eq!(agent.statistic_loss(), 0.0);
}

/// A corridor of `LENGTH` cells: action 2 moves right, 0 left, 1 stays; reaching the last
/// cell pays 1 and ends the episode. One-hot-ish observation: (position, 1 − position).
struct Corridor {
    position: usize,
    steps: u32,
    obs: [f32; 2],
}

impl Corridor {
    fn new() -> Self {
        Self {
            position: 0,
            steps: 0,
            obs: [0.0, 1.0],
        }
    }

    fn observe(&mut self) {
        let x = self.position as f32 / (LENGTH - 1) as f32;
        self.obs = [x, 1.0 - x];
    }
}

const LENGTH: usize = 4;

impl Environment for Corridor {
    fn id(&self) -> &str {
        "Corridor"
    }
    fn observation_size(&self) -> usize {
        2
    }
    fn action_count(&self) -> usize {
        3
    }
    fn reset(&mut self, _seed: Option<u64>) -> Result<&[f32], EnvError> {
        self.position = 0;
        self.steps = 0;
        self.observe();
        Ok(&self.obs)
    }
    fn step(&mut self, action: usize) -> Result<Step<'_>, EnvError> {
        self.steps += 1;
        self.position = match action {
            0 => self.position.saturating_sub(1),
            1 => self.position,
            _ => self.position + 1,
        };
        let terminated = self.position == LENGTH - 1;
        self.observe();
        Ok(Step {
            obs: &self.obs,
            reward: if terminated { 1.0 } else { 0.0 },
            terminated,
            truncated: self.steps >= 20,
        })
    }
    fn observation(&self) -> &[f32] {
        &self.obs
    }
    fn state(&self) -> &[f64] {
        &[]
    }
    fn set_state(&mut self, _state: &[f64]) -> Result<(), EnvError> {
        Ok(())
    }
    fn elapsed_steps(&self) -> u32 {
        self.steps
    }
}

/// The training loop a caller writes: act, store, observe.
fn train(
    env: &mut dyn Environment,
    agent: &mut DqnAgent,
    replay: &mut ReplayBuffer,
    steps: u64,
    seed: u64,
) {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut obs = env.reset(Some(seed)).unwrap().to_vec();
    for _ in 0..steps {
        let action = agent.act(&obs, &mut rng).unwrap();
        let step = env.step(action).unwrap();
        replay.push(Transition {
            obs: &obs,
            action,
            reward: step.reward,
            next_obs: step.obs,
            terminated: step.terminated,
            truncated: step.truncated,
        });
        if step.done() {
            obs.copy_from_slice(env.reset(None).unwrap());
        } else {
            obs.copy_from_slice(step.obs);
        }
        agent.observe(replay, &mut rng).unwrap();
    }
}

#[test]
fn learns_to_walk_down_a_corridor() {
    let config = DqnConfig {
        replay_start_size: 32,
        target_update_interval: 100,
        exploration: Exploration::Linear {
            start: 1.0,
            end: 0.05,
            steps: 1000,
        },
        ..DqnConfig::default()
    };
    let mut env = Corridor::new();
    let mut agent = agent(&[16], 7, &config);
    let mut replay = ReplayBuffer::new(config.replay_capacity, 2);
    train(&mut env, &mut agent, &mut replay, 3000, 7);
    let mut obs = env.reset(None).unwrap().to_vec();
    for _ in 0..LENGTH - 1 {
        let step = env.step(agent.greedy_action(&obs).unwrap()).unwrap();
        obs = step.obs.to_vec();
    }
    assert_eq!(
        env.position,
        LENGTH - 1,
        "greedy policy did not walk straight to the end"
    );
}

#[test]
fn trains_on_cartpole_through_env_make() {
    let mut env = env::make(&EnvConfig::CartPole(Default::default())).unwrap();
    let config = DqnConfig::default();
    let architecture = Architecture::new(env.observation_size(), &[100], env.action_count());
    let net = QNet::new(architecture, &mut StdRng::seed_from_u64(0)).unwrap();
    let mut agent = DqnAgent::new(net, &config).unwrap();
    let mut replay = ReplayBuffer::new(config.replay_capacity, env.observation_size());
    train(env.as_mut(), &mut agent, &mut replay, 2000, 0);
    assert_eq!(agent.steps(), 2000);
    assert!(agent.statistic_loss().is_finite() && agent.statistic_loss() > 0.0);
}

/// The TD error's change (`SapNetWith(judgment: TdChange)`), by hand on a net whose
/// weights are written out: one input, one hidden unit, two actions, every weight 1 but
/// the second head's 2, biases 0, so Q(s) = [relu(s), 2·relu(s)].
#[test]
fn the_td_error_of_the_latest_transition_is_measured_before_and_after_the_round() {
    use candle_core::{Device, Tensor};
    let net = || {
        let t = |v: &[f32], shape: &[usize]| Tensor::from_slice(v, shape, &Device::Cpu).unwrap();
        QNet::from_parameters(
            Architecture::new(1, &[1], 2),
            vec![
                t(&[1.0], &[1, 1]),
                t(&[0.0], &[1]),
                t(&[1.0, 2.0], &[2, 1]),
                t(&[0.0, 0.0], &[2]),
            ],
        )
        .unwrap()
    };
    let config = DqnConfig {
        replay_start_size: 1,
        ..DqnConfig::default()
    };
    let replay_of = |terminated| {
        let mut replay = ReplayBuffer::new(10, 1);
        replay.push(Transition {
            obs: &[1.0],
            action: 0,
            reward: 0.5,
            next_obs: &[2.0],
            terminated,
            truncated: false,
        });
        replay
    };
    let observe = |measure: bool, terminated: bool| {
        let mut agent = DqnAgent::new(net(), &config).unwrap();
        agent.measure_td_error(measure);
        let mut rng = StdRng::seed_from_u64(0);
        let report = agent
            .observe(&replay_of(terminated), &mut rng)
            .unwrap()
            .unwrap();
        (report, flat(agent.online()))
    };
    let (report, weights) = observe(true, false);
    let td = report.td.expect("measured when asked");
    // Before: y = r + γ·max Q_target(s' = 2) = 0.5 + 0.99·4 = 4.46; Q_online(1, 0) = 1.
    assert!((td.before - 3.46).abs() < 1e-6, "{td:?}");
    // The batch is 32 copies of the one transition; |Q − y| > 1, so the Huber loss's
    // gradient on Q(1, 0) is −1 in all, and on W1, b1, W2[0], b2[0] each −1 (W2[1], b2[1]
    // 0). Chainer's Adam, first step: m = 0.1·g, v = 0.001·g², α_t = 1e-3·√0.001/0.1, so
    // each of the four moves by α_t·m/(√v + 1e-3) = 1e-3·0.0316228/0.0326228 = 9.693466e-4.
    // After: Q(1, 0) = 1.000969·(1.000969 + 0.000969) + 0.000969 = 1.003879; the target
    // net is unchanged, δ = 4.46 − 1.003879 = 3.456121.
    assert!((td.after - 3.456_120_7).abs() < 1e-5, "{td:?}");
    // Measuring changes nothing of the update.
    let (unmeasured, same_weights) = observe(false, false);
    assert_eq!(unmeasured.td, None);
    assert_eq!((unmeasured.loss, same_weights), (report.loss, weights));
    // At a terminal state y = r: δ = 0.5 − 1 = −0.5 before the round.
    let (report, _) = observe(true, true);
    assert!((report.td.unwrap().before + 0.5).abs() < 1e-6);
}

/// The learner keeps `max_a Q_target(s′, a)` of the replay's transitions while its target
/// network lasts (`dqn/target_values.rs`). Kept or computed afresh, every target must be the
/// same bits: a learner drawing from a small ring buffer (so slots are overwritten), its
/// target copied every 7 updates, against a twin given the very same minibatches through
/// `update`, which passes the target network over every transition each time.
#[test]
fn kept_target_values_give_the_bits_of_a_full_target_pass() {
    let config = DqnConfig {
        replay_start_size: 1,
        ..DqnConfig::default()
    };
    let (mut kept, mut fresh) = (agent(&[24, 16], 3, &config), agent(&[24, 16], 3, &config));
    let mut rng = StdRng::seed_from_u64(9);
    let mut replay = ReplayBuffer::new(40, 2);
    let (mut kept_rng, mut fresh_rng) = (StdRng::seed_from_u64(1), StdRng::seed_from_u64(1));
    let mut batch = Batch::new();
    for step in 0..300u64 {
        push_random(&mut replay, &mut rng, true);
        let kept_loss = kept.learn_once(&replay, 7, &mut kept_rng).unwrap().unwrap();
        replay.sample_into(config.batch_size, &mut batch, &mut fresh_rng);
        let mut unslotted = Batch::new();
        for b in 0..batch.len() {
            let width = batch.obs_size();
            unslotted.push(Transition {
                obs: &batch.obs()[b * width..(b + 1) * width],
                action: batch.actions()[b] as usize,
                reward: f64::from(batch.rewards()[b]),
                next_obs: &batch.next_obs()[b * width..(b + 1) * width],
                terminated: batch.terminated()[b],
                truncated: batch.truncated()[b],
            });
        }
        let fresh_loss = fresh.update(&unslotted).unwrap();
        if (step + 1).is_multiple_of(7) {
            fresh.sync_target().unwrap();
        }
        assert_eq!(
            kept_loss.to_bits(),
            fresh_loss.to_bits(),
            "loss at step {step}"
        );
    }
    let bits = |net: &QNet| flat(net).iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(kept.online()), bits(fresh.online()));
}
