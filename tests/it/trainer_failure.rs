//! A run that cannot go on, started on its own thread, says so on the event stream at once
//! (the dashboard shows it), and its thread's result carries the error.

use std::sync::mpsc;

use sapnet::dqn::DqnConfig;
use sapnet::env::{CartPoleParams, EnvConfig};
use sapnet::trainer::{self, Event, RunSpec, TrainerError};

#[test]
fn a_diverging_run_sends_run_failed_and_returns_the_error() {
    let spec = RunSpec::scratch(
        0,
        "dqn[8]",
        EnvConfig::CartPole(CartPoleParams::default()),
        // A learning rate no network survives (as tests/configs/diverging_cartpole.ron).
        DqnConfig {
            learning_rate: 1e30,
            ..DqnConfig::default()
        },
        vec![8],
        200,
        1,
        0,
    );
    let (events, received) = mpsc::channel();
    let handle = trainer::spawn(spec, events).unwrap();
    let last = received.iter().last().expect("events");
    let Event::RunFailed { run, method, error } = last else {
        panic!("the last event is {last:?}");
    };
    assert_eq!((run, method.label()), (0, "dqn[8]"));
    assert!(error.contains("diverged"), "{error}");
    assert!(matches!(
        handle.thread.join().unwrap(),
        Err(TrainerError::Diverged(_))
    ));
}
