//! What a protocol's event stream writes as it runs: each run's record, progress, and
//! `summary.json` after every run; a reusing run's chosen policy added to the library.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::{Context, Result};

use crate::config::{Budget, Config};
use crate::experiment::{policy_info, LibraryCopies};
use crate::policy_store::{self, PolicyInfo, TrainingBudget};
use crate::progress::Progress;
use crate::report::RunSummary;
use crate::results::records::{run_name, RunWriter};
use crate::results::{self, Summary};
use crate::trainer::Observer;

use super::tensorboard_runs::TensorBoardRuns;
use crate::trainer::{Divergence, Event, MethodId, RunOutcome, RunSpec, TrainerError};

/// What the event stream writes: each run's record, progress, and `summary.json` after
/// every run.
pub(super) struct ResultFiles {
    out: PathBuf,
    config: Config,
    /// The sources' names (none without a library).
    names: Vec<String>,
    /// Progress on stderr; none under a screen that shows it (the workbench).
    progress: Option<Progress>,
    /// The record of every run in progress.
    writers: BTreeMap<(MethodId, u32), RunWriter>,
    /// Runs finished so far, rewritten to `summary.json` as each ends.
    summary: Summary,
    /// Where the chosen policies join the library, if they do.
    copies: Option<LibraryCopies>,
    /// Each run's event file, with `--tensorboard`.
    tensorboard: Option<TensorBoardRuns>,
}

impl ResultFiles {
    /// Records into `out`; `summary` holds the runs finished before (a resumed protocol's).
    pub(super) fn new(
        out: PathBuf,
        config: Config,
        names: Vec<String>,
        progress: Option<Progress>,
        summary: Summary,
        copies: Option<LibraryCopies>,
        tensorboard: Option<TensorBoardRuns>,
    ) -> Self {
        Self {
            out,
            config,
            names,
            progress,
            writers: BTreeMap::new(),
            summary,
            copies,
            tensorboard,
        }
    }

    /// Ends the progress display; `complete` false leaves it where it stopped.
    pub(super) fn finish_progress(&mut self, complete: bool) {
        if let Some(progress) = &mut self.progress {
            progress.finish(complete);
        }
    }

    /// A warning above the bars, or on stderr when there are none.
    fn warn(&self, message: &str) {
        match &self.progress {
            Some(progress) => progress.warn(message),
            None => eprintln!("warning: {message}"),
        }
    }

    fn writer(&mut self, method: &MethodId, run: u32) -> Result<&mut RunWriter> {
        let key = (method.clone(), run);
        if !self.writers.contains_key(&key) {
            let writer = RunWriter::create(&self.out, method, run, &self.names)?;
            self.writers.insert(key.clone(), writer);
        }
        Ok(self.writers.get_mut(&key).expect("inserted above"))
    }
}

impl Observer for ResultFiles {
    fn on_event(&mut self, event: Event) -> Result<()> {
        match event {
            Event::RunStarted {
                run,
                method,
                budget,
                ..
            } => {
                let planned = match budget {
                    Budget::Episodes(n) => u64::from(n),
                    Budget::Steps(n) => n,
                };
                if let Some(progress) = &mut self.progress {
                    progress.run_started(method.label(), run, planned);
                }
                self.writer(&method, run)?;
                if let Some(tensorboard) = &mut self.tensorboard {
                    tensorboard.run_started(&self.config, &method, run)?;
                }
            }
            Event::Activations(snapshot) => {
                if let Some(tensorboard) = &mut self.tensorboard {
                    tensorboard.snapshot(&snapshot)?;
                }
                let (method, run) = (snapshot.method.clone(), snapshot.run);
                self.writer(&method, run)?.snapshot(snapshot);
            }
            Event::EpisodeEnded(record) => {
                self.writer(&record.method, record.run)?.episode(&record)?;
                if let Some(tensorboard) = &mut self.tensorboard {
                    tensorboard.episode(&record)?;
                }
                if let Some(progress) = &mut self.progress {
                    progress.episode(&record);
                }
            }
            Event::Trace(record) => {
                self.writer(&record.method, record.run)?.trace(&record)?;
            }
            // A failure is reported from the run's thread when it is joined.
            Event::Step(_) | Event::RunEnded(_) | Event::RunFailed { .. } => {}
        }
        Ok(())
    }

    fn on_finished(&mut self, _order: usize, _spec: &RunSpec, outcome: RunOutcome) -> Result<()> {
        let record = outcome.record;
        if let Some(progress) = &mut self.progress {
            progress.run_finished(record.method.label(), record.run);
        }
        if let Some(tensorboard) = &mut self.tensorboard {
            tensorboard.run_finished(&record.method, record.run, record.stopped)?;
        }
        let mut library_copy = None;
        // A run stopped before its first step trained nothing worth keeping.
        if record.steps > 0 {
            let name = run_name(record.method.label(), record.run);
            let info = policy_info(&self.config, &record);
            policy_store::save(&self.out.join("policies"), &name, &outcome.net, &info)
                .with_context(|| format!("saving the trained {}", record.method))?;
            // Only a finished reuse's choice, tested, is worth reusing. The results hold
            // it already, so a library that cannot take it costs a warning, not the run.
            if let (Some(copies), true) = (&self.copies, record.chosen.is_some() && !record.stopped)
            {
                match copies.add(&name, &outcome.net, &info) {
                    Ok(path) => library_copy = Some(path),
                    Err(err) => self.warn(&format!(
                        "the chosen policy of {} run {} could not be added to the library in \
                         {}: {err:#}; it is in {}",
                        record.method,
                        record.run,
                        copies.dir.display(),
                        self.out.join("policies").display()
                    )),
                }
            }
        }
        let key = (record.method.clone(), record.run);
        self.writer(&record.method, record.run)?;
        let writer = self.writers.remove(&key).expect("created above");
        let mut summary =
            RunSummary::new(record, &writer.rewards, self.config.protocol.moving_average);
        summary.library_copy = library_copy;
        writer.finish(&self.out, &summary)?;
        crate::failpoint::point("run-recorded");

        let runs = &mut self.summary.runs;
        runs.push(summary);
        runs.sort_by_key(|r| (r.record.method.index, r.record.run));
        self.summary.unfinished.retain(|k| {
            !runs.iter().any(|r| {
                !r.record.stopped && r.record.run == k.run && r.record.method.label() == k.method
            })
        });
        results::write_json(&self.out.join("summary.json"), &self.summary)
    }

    /// Keeps what a failed run left (its last good weights) and says what happened.
    fn on_failed(&mut self, spec: &RunSpec, err: TrainerError) -> anyhow::Error {
        let TrainerError::Diverged(divergence) = err else {
            return anyhow::Error::new(err).context(format!("{} run {}", spec.method, spec.run));
        };
        let Divergence {
            method,
            run,
            source,
            episodes,
            steps,
            last_good,
        } = *divergence;
        let info = PolicyInfo {
            source_task: self.config.env.as_recorded(),
            training: TrainingBudget {
                episodes: u64::from(episodes),
                steps,
            },
            seed: spec.seed,
            final_score: None,
            reused: None,
            origin: None,
        };
        let policies = self.out.join("policies");
        let name = run_name(spec.method.label(), run);
        let kept = match policy_store::save(&policies, &name, &last_good, &info) {
            Ok(_) => format!(
                "its last good weights are in {}",
                policies.join(&name).display()
            ),
            Err(err) => format!("its last good weights could not be saved: {err}"),
        };
        anyhow::anyhow!("policy {method} (run {run}) diverged: {source}; {kept}")
    }
}
