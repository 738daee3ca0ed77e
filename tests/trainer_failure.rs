//! A run that cannot go on, started on its own thread, says so on the event stream at once
//! (the dashboard shows it), and its thread's result carries the error.

use std::sync::mpsc;

use sapnet::config::DqnConfig;
use sapnet::env::{CartPoleParams, EnvConfig};
use sapnet::trainer::{self, DqnRunSpec, Event, RunSpec, StreamOptions, TrainerError};

#[test]
fn a_diverging_run_sends_run_failed_and_returns_the_error() {
    let spec = DqnRunSpec {
        run: 0,
        method: trainer::dqn_label(&[8]),
        env: EnvConfig::CartPole(CartPoleParams::default()),
        // A learning rate no network survives (as tests/configs/diverging_cartpole.ron).
        dqn: DqnConfig {
            learning_rate: 1e30,
            ..DqnConfig::default()
        },
        hidden: vec![8],
        episodes: 200,
        max_steps: None,
        test_episodes: 1,
        seed: 0,
        stream: StreamOptions::episodes(),
    };
    let (events, received) = mpsc::channel();
    let handle = trainer::spawn(RunSpec::Dqn(spec), events).unwrap();
    let last = received.iter().last().expect("events");
    let Event::RunFailed { run, method, error } = last else {
        panic!("the last event is {last:?}");
    };
    assert_eq!((run, method.as_str()), (0, "dqn[8]"));
    assert!(error.contains("diverged"), "{error}");
    assert!(matches!(
        handle.thread.join().unwrap(),
        Err(TrainerError::Diverged(_))
    ));
}
