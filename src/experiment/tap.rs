//! A front end watching a protocol while it runs (the workbench): every run's events,
//! passed on beside the result files that take them, and each run's command channel when
//! it starts, so that the run the screen follows can be paused, stepped and slowed.

use std::sync::mpsc::Sender;

use anyhow::Result;

use crate::trainer::{
    Commands, Event, MethodId, Observer, RunOutcome, RunSpec, StreamOptions, TrainerError,
};

/// What a watched protocol tells its front end.
// An event is moved as it is: boxing it would cost an allocation per step.
#[allow(clippy::large_enum_variant)]
pub enum Watched {
    /// A run started on its thread: its commands steer it.
    Started {
        method: MethodId,
        run: u32,
        commands: Commands,
    },
    /// One of the runs' events, as the result files receive it.
    Event(Event),
}

/// Where a watched protocol's runs are told, and which run streams its every step.
pub struct Tap {
    pub to: Sender<Watched>,
    /// The run (method label, run index) that streams every step from its start, for the
    /// Run view; the others stream episodes, as headless runs do. Steps and snapshots are
    /// only sent, never used by training, so the files are the same either way.
    pub live: Option<(String, u32)>,
}

impl Tap {
    /// Gives the run to follow step by step the stream a live view needs.
    pub(super) fn stream(&self, specs: &mut [RunSpec]) {
        let Some((label, run)) = &self.live else {
            return;
        };
        for spec in specs
            .iter_mut()
            .filter(|s| s.method.label() == label && s.run == *run)
        {
            spec.stream = StreamOptions {
                trace: spec.stream.trace,
                ..StreamOptions::live()
            };
        }
    }
}

/// The result files' observer with a tap beside it: what the files take, the tap is sent
/// first (a tap whose front end left is ignored: the protocol goes on).
pub(super) struct Tapped<'a, O> {
    pub(super) files: O,
    pub(super) tap: Option<&'a Tap>,
}

impl<O: Observer> Observer for Tapped<'_, O> {
    fn on_event(&mut self, event: Event) -> Result<()> {
        let Some(tap) = self.tap else {
            return self.files.on_event(event);
        };
        // Steps are the files' to ignore: moved, not copied.
        if matches!(event, Event::Step(_)) {
            let _ = tap.to.send(Watched::Event(event));
            return Ok(());
        }
        let _ = tap.to.send(Watched::Event(event.clone()));
        self.files.on_event(event)
    }

    fn on_finished(&mut self, order: usize, spec: &RunSpec, outcome: RunOutcome) -> Result<()> {
        self.files.on_finished(order, spec, outcome)
    }

    fn on_failed(&mut self, spec: &RunSpec, err: TrainerError) -> anyhow::Error {
        self.files.on_failed(spec, err)
    }

    fn on_started(&mut self, spec: &RunSpec, commands: &Commands) {
        if let Some(tap) = self.tap {
            let _ = tap.to.send(Watched::Started {
                method: spec.method.clone(),
                run: spec.run,
                commands: commands.clone(),
            });
        }
    }
}
