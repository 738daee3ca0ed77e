//! DQN learns CartPole-v1: a `[100]` network reaches a moving average of 10 returns of at
//! least 195 within a fixed budget and seed.

use std::path::Path;
use std::sync::mpsc;

use sapnet::config::Config;
use sapnet::reuse::Method;
use sapnet::trainer::{self, Event, RunSpec};

#[test]
fn a_100_unit_dqn_learns_cartpole() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/configs/learn_cartpole.ron");
    let config = Config::from_file(&path).unwrap();
    let Method::Dqn { hidden } = &config.protocol.methods[0] else {
        panic!("the learning config runs a DQN");
    };
    let spec = RunSpec::scratch(
        0,
        "dqn[100]",
        config.env.clone(),
        config.dqn.clone(),
        hidden.clone(),
        config.protocol.budget.episodes(),
        config.protocol.test_episodes,
        config.seed,
    );
    let (events, received) = mpsc::channel();
    let (_commands, commands) = sapnet::trainer::command_channel();
    let outcome = trainer::train(&spec, &events, &commands).unwrap();
    drop(events);

    let rewards: Vec<f64> = received
        .iter()
        .filter_map(|e| match e {
            Event::EpisodeEnded(r) => Some(r.reward),
            _ => None,
        })
        .collect();
    assert_eq!(rewards.len() as u32, config.protocol.budget.episodes());
    let best = rewards
        .windows(10)
        .map(|w| w.iter().sum::<f64>() / 10.0)
        .fold(f64::MIN, f64::max);
    assert!(
        best >= 195.0,
        "best MA(10) {best:.1} < 195 in {} episodes",
        rewards.len()
    );
    assert_eq!(outcome.record.test_returns.len(), 5);
}
