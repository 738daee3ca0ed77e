//! Runs a list of runs, at most `jobs` at a time, each on a thread of its own, and hands
//! their events and outcomes to a front end's [`Observer`] on the calling thread.

use std::collections::VecDeque;
use std::sync::mpsc::{self, Receiver};
use std::thread;
use std::time::Duration;

use anyhow::{Context, Result};

use crate::env::EnvError;
use crate::trainer::{
    self, Command, Commands, Event, RunHandle, RunOutcome, RunSpec, TrainerError,
};

/// How often the scheduler drains the runs' events and checks for a stop.
const POLL_INTERVAL: Duration = Duration::from_millis(10);

/// What a front end does with the runs' results, on the scheduler's thread.
pub trait Observer {
    fn on_event(&mut self, event: Event) -> Result<()>;

    /// A run ended (finished or stopped); `order` is its place in the list.
    fn on_finished(&mut self, order: usize, spec: &RunSpec, outcome: RunOutcome) -> Result<()>;

    /// A run failed; returns the error the schedule ends with.
    fn on_failed(&mut self, spec: &RunSpec, err: TrainerError) -> anyhow::Error;

    /// A run started on its thread: a front end that steers one run (the workbench's
    /// followed run: pause, step, speed) keeps its commands. Headless steers none.
    fn on_started(&mut self, _spec: &RunSpec, _commands: &Commands) {}
}

/// A run in progress.
struct Active {
    order: usize,
    spec: RunSpec,
    handle: RunHandle,
}

/// Runs `specs` in order, at most `jobs` at a time. A [`Command::Stop`] on `stop` (from
/// Ctrl-C) ends the runs in progress early and starts no more. Returns whether the runs
/// were stopped; a run that fails stops the others and is returned as the error (the
/// observer has seen everything the others did).
pub fn schedule(
    specs: Vec<RunSpec>,
    jobs: usize,
    stop: &Receiver<Command>,
    observer: &mut impl Observer,
) -> Result<bool> {
    let (events_tx, events) = mpsc::channel();
    let mut queue: VecDeque<(usize, RunSpec)> = specs.into_iter().enumerate().collect();
    let mut active: Vec<Active> = Vec::new();
    let mut stopping = false;
    let mut failure: Option<anyhow::Error> = None;
    loop {
        while !stopping && active.len() < jobs.max(1) {
            let Some((order, spec)) = queue.pop_front() else {
                break;
            };
            let handle = trainer::spawn(spec.clone(), events_tx.clone())
                .context("starting a trainer thread")?;
            observer.on_started(&spec, &handle.commands);
            active.push(Active {
                order,
                spec,
                handle,
            });
        }
        if active.is_empty() {
            break;
        }
        // Poll rather than wait on the channel: a send that finds its receiver parked
        // must wake it (in a profile of the transfer loop, the kernel's task switching
        // took 11% of the samples), while a receiver that drains every few milliseconds
        // costs the trainer nothing but the enqueue.
        thread::sleep(POLL_INTERVAL);
        for event in events.try_iter() {
            observer.on_event(event)?;
        }
        if !stopping && matches!(stop.try_recv(), Ok(Command::Stop)) {
            stopping = true;
            for run in &active {
                let _ = run.handle.commands.send(Command::Stop);
            }
        }
        let mut i = 0;
        while i < active.len() {
            if !active[i].handle.thread.is_finished() {
                i += 1;
                continue;
            }
            let run = active.swap_remove(i);
            // A finished thread has sent all its events: take them before its outcome.
            while let Ok(event) = events.try_recv() {
                observer.on_event(event)?;
            }
            let outcome = run.handle.thread.join().map_err(|_| {
                anyhow::anyhow!(
                    "the trainer thread of {} run {} panicked",
                    run.spec.method,
                    run.spec.run
                )
            })?;
            match outcome {
                // A signal ended its wait for a Gymnasium worker: stopped, not failed (it
                // runs again from its seeds on a resume, as any stopped run).
                Err(TrainerError::Env(EnvError::Interrupted)) => {
                    stopping = true;
                    for other in &active {
                        let _ = other.handle.commands.send(Command::Stop);
                    }
                }
                Ok(outcome) => {
                    stopping |= outcome.record.stopped;
                    observer.on_finished(run.order, &run.spec, outcome)?;
                }
                Err(err) => {
                    let err = observer.on_failed(&run.spec, err);
                    failure.get_or_insert(err);
                    stopping = true;
                    for other in &active {
                        let _ = other.handle.commands.send(Command::Stop);
                    }
                }
            }
        }
    }
    while let Ok(event) = events.try_recv() {
        observer.on_event(event)?;
    }
    match failure {
        Some(err) => Err(err),
        None => Ok(stopping),
    }
}
