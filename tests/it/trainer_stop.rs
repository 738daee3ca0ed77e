//! A `Command::Stop` ends a run early, reported as stopped and untested, with every
//! finished episode already sent.

use std::sync::mpsc;
use std::thread;

use sapnet::dqn::DqnConfig;
use sapnet::env::{CartPoleParams, EnvConfig};
use sapnet::trainer::{self, Command, Event, RunSpec};

fn spec() -> RunSpec {
    RunSpec::scratch(
        0,
        "dqn[8]",
        EnvConfig::CartPole(CartPoleParams::default()),
        DqnConfig::default(),
        vec![8],
        1_000_000,
        5,
        3,
    )
}

#[test]
fn a_stop_before_the_first_step_trains_nothing() {
    let (events, received) = mpsc::channel();
    let (commands_tx, commands) = trainer::command_channel();
    commands_tx.send(Command::Stop).unwrap();
    let outcome = trainer::train(&spec(), &events, &commands).unwrap();
    assert!(outcome.record.stopped);
    assert_eq!((outcome.record.episodes, outcome.record.steps), (0, 0));
    assert!(outcome.record.test_returns.is_empty());
    drop(events);
    let last = received.iter().last().unwrap();
    assert!(matches!(last, Event::RunEnded(r) if r.stopped));
}

#[test]
fn a_stop_mid_run_keeps_the_episodes_so_far() {
    let (events, received) = mpsc::channel();
    let (commands_tx, commands) = trainer::command_channel();
    let worker = thread::spawn(move || trainer::train(&spec(), &events, &commands));
    let mut episodes_seen = 0;
    for event in &received {
        if let Event::EpisodeEnded(record) = event {
            episodes_seen += 1;
            assert_eq!(record.episode, episodes_seen);
            if episodes_seen == 3 {
                commands_tx.send(Command::Stop).unwrap();
            }
        }
    }
    let outcome = worker.join().unwrap().unwrap();
    assert!(outcome.record.stopped);
    assert_eq!(outcome.record.episodes, episodes_seen);
    assert!((3..1_000_000).contains(&episodes_seen));
    assert!(outcome.record.test_returns.is_empty());
}
