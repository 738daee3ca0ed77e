//! A scripted SAP-Net run for the TUI's tests and render bench: the shipped CartPole
//! library's ten architectures, with made-up but plausible numbers, so that what is drawn
//! does not depend on timing.

use sapnet::config::Config;
use sapnet::dqn::UpdateReport;
use sapnet::reuse::Method;
use sapnet::sapnet::{PolicyDescription, SapNet};
use sapnet::trainer::{
    ActivationSnapshot, ChosenPolicy, Deposit, EpisodeRecord, Event, LibraryStart, MethodId,
    RunRecord, SourceSummary, StepRecord,
};

/// The id of the scripted methods: `sapnet` first, then `dqn[100]`, as the embedded
/// config lists them.
pub fn method(label: &str) -> MethodId {
    match label {
        "sapnet" => MethodId::new(0, &Method::SapNet),
        "dqn[100]" => MethodId::new(1, &Method::Dqn { hidden: vec![100] }),
        other => panic!("the script has no method {other}"),
    }
}

/// The shipped CartPole library's hidden layers.
pub const HIDDEN: [&[usize]; 10] = [
    &[113],
    &[64, 114, 149],
    &[144, 54],
    &[97, 142],
    &[142],
    &[58, 129],
    &[82, 82, 55],
    &[105, 67],
    &[139, 103, 58],
    &[144],
];

pub fn sapnet_start() -> Event {
    let descriptions: Vec<PolicyDescription> = HIDDEN
        .iter()
        .map(|h| PolicyDescription::new(h.to_vec(), "cartpole"))
        .collect();
    let net = SapNet::from_policies(&descriptions, Config::default().sapnet).expect("Table II net");
    Event::RunStarted {
        run: 0,
        method: method("sapnet"),
        budget: sapnet::config::Budget::Episodes(5000),
        library: Some(Box::new(LibraryStart {
            policies: descriptions
                .into_iter()
                .enumerate()
                .map(|(i, description)| SourceSummary {
                    name: format!("source-{i}"),
                    description,
                    final_score: Some(100.0 + 40.0 * i as f64),
                })
                .collect(),
            net,
            score: sapnet::reuse::sapnet::SCORE,
        })),
    }
}

pub fn baseline_start() -> Event {
    Event::RunStarted {
        run: 0,
        method: method("dqn[100]"),
        budget: sapnet::config::Budget::Episodes(5000),
        library: None,
    }
}

/// `episodes` episodes of SAP-Net and three times as many of the baseline, SAP-Net settling on source-6 as it did in the
/// measured runs, with a step and a snapshot before each SAP-Net episode's end.
pub fn episodes(episodes: u32) -> Vec<Event> {
    let mut events = Vec::new();
    let mut step = 0u64;
    let mut activations = vec![0.0; 10];
    let mut selections = vec![0u64; 10];
    let mut positive = vec![0u64; 10];
    let mut negative = vec![0u64; 10];
    for episode in 1..=episodes {
        let length = 20 + (episode * 37 % 180);
        step += u64::from(length);
        let policy = if episode < 4 {
            (episode as usize * 3) % 10
        } else {
            6
        };
        selections[policy] += u64::from(length);
        positive[policy] += u64::from(length / 2);
        negative[policy] += u64::from(length - length / 2);
        activations[policy] += f64::from(length / 2);
        for neighbour in [1, 8] {
            if policy == 6 {
                activations[neighbour] += f64::from(length / 2) * 0.526;
            }
        }
        let top = activations.iter().copied().fold(f64::MIN, f64::max);
        let terms: Vec<f64> = activations.iter().map(|a: &f64| (a - top).exp()).collect();
        let total: f64 = terms.iter().sum();
        events.push(Event::Step(StepRecord {
            method: 0,
            run: 0,
            step,
            episode,
            policy: Some(policy),
            action: 1,
            reward: 1.0,
            update: Some(UpdateReport {
                loss: 0.05,
                previous_statistic_loss: 0.0421,
                statistic_loss: 0.0417,
                td: None,
            }),
            judgment: Some(true),
            deposit: Some(Deposit {
                own: 1.0,
                others: 0.526_315_789_473_684_2,
            }),
            warm_up: false,
        }));
        events.push(Event::Activations(ActivationSnapshot {
            run: 0,
            method: method("sapnet"),
            step,
            score: sapnet::reuse::sapnet::SCORE,
            episode,
            activations: activations.clone(),
            probabilities: terms.iter().map(|t| t / total).collect(),
            selections: selections.clone(),
            positive: positive.clone(),
            negative: negative.clone(),
            lock_in: None,
            excluded: Vec::new(),
        }));
        events.push(episode_end("sapnet", episode, f64::from(length)));
        // The baseline's ~10-step episodes run ahead of SAP-Net's, as they do live.
        for b in 3 * episode - 2..=3 * episode {
            events.push(episode_end("dqn[100]", b, f64::from(9 + b % 3)));
        }
    }
    events
}

fn episode_end(label: &str, episode: u32, reward: f64) -> Event {
    Event::EpisodeEnded(EpisodeRecord {
        run: 0,
        method: self::method(label),
        episode,
        reward,
        steps: reward as u32,
        loss: Some(0.05),
        statistic_loss: 0.02 + 0.1 / f64::from(episode),
        epsilon: 0.03,
        policy: Some(6),
        wall_s: f64::from(episode) * 0.01,
    })
}

/// The end of SAP-Net's run after `episodes` episodes: source-6 chosen and tested.
pub fn sapnet_end(episodes: u32) -> Event {
    let mut record = RunRecord::new(0, method("sapnet"), 1);
    record.episodes = episodes;
    record.steps = 6450;
    record.updates = 5950;
    record.chosen = Some(ChosenPolicy {
        index: 6,
        name: "source-6".into(),
        hidden: HIDDEN[6].to_vec(),
        score: 3117.0,
        score_name: "A".into(),
    });
    record.test_returns = vec![500.0, 500.0, 487.0, 500.0, 500.0];
    record.wall_s = 12.5;
    Event::RunEnded(record)
}

/// A selector's snapshot of `method` at `step` with these probabilities, and nothing else
/// to show: for tests of what the probabilities alone decide (the lock-in).
pub fn probabilities_at(method: MethodId, step: u64, probabilities: Vec<f64>) -> Event {
    let n = probabilities.len();
    Event::Activations(ActivationSnapshot {
        run: 0,
        method,
        step,
        episode: 1,
        score: sapnet::reuse::sapnet::SCORE,
        activations: vec![0.0; n],
        probabilities,
        selections: vec![0; n],
        positive: vec![0; n],
        negative: vec![0; n],
        lock_in: None,
        excluded: Vec::new(),
    })
}
