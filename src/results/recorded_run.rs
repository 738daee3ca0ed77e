//! A run that ended, read back from its files as the events it sent while it trained:
//! `RunStarted` (with the library and the graph its selector drew on), each episode's
//! selector state (`Activations`) and end (`EpisodeEnded`), then `RunEnded`. So that the
//! workbench shows a run finished before the session (Enter in the Runs view) on the same
//! dashboard as a run followed live.
//!
//! Read from the run's record (`runs/<run>/`: `run.json`, `episodes.csv`,
//! `activations.csv`) or, in a folder shipped without records, from the run's rows of the
//! top-level files. What no file keeps is not made up: no step is streamed, the
//! judgments are the run's totals (`run.json`), not each episode's, and which sources an
//! exclusion left out (`SapNetWith(exclusion: …)`) is not shown. A folder shipped
//! without `activations.csv` has no selector state to show ([`Recorded::activations`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde::Deserialize;

use super::folder_state::FolderState;
use super::plot_data;
use super::records::{run_name, RUNS};
use crate::reuse::{self, Library, ScoreColumn};
use crate::safe_io;
use crate::sapnet::SapNet;
use crate::trainer::{
    ActivationSnapshot, EpisodeRecord, Event, LibraryStart, LockIn, MethodId, SourceSummary,
};

/// What a finished run's files kept of its events (the events themselves go to the sink
/// [`read`] is given, as they are read).
pub struct Recorded {
    /// Whether `activations.csv` held the run's scores and probabilities: without them a
    /// reusing run's dashboard shows its library's scores as they started, with the steps
    /// each source acted and its judgments from the run's record.
    pub activations: bool,
    /// Whether `episodes.csv` held each episode's ε and losses (`docs/` ships it without):
    /// without them they read 0.
    pub learner: bool,
}

/// The events of run `run` of `method` in `folder`, which must have finished (or been
/// stopped) there, handed to `sink` in order as they are read: a run of millions of
/// episodes costs what the sink keeps of them (a dashboard keeps its curve thinned), not
/// an event per episode.
pub fn read(
    folder: &FolderState,
    method: &MethodId,
    run: u32,
    sink: &mut dyn FnMut(Event),
) -> Result<Recorded> {
    let Some(summary) = folder.finished(method, run) else {
        bail!(
            "{}: {} run {run} has no record: it has not finished",
            folder.dir.display(),
            method.label()
        );
    };
    let config = &folder.config;
    let names: Vec<String> = folder.library.iter().map(|e| e.name.clone()).collect();
    // Its record's counts, one per source, before a view indexes them.
    let own = folder.dir.join(RUNS).join(run_name(method.label(), run));
    let record_path = if own.is_dir() {
        own.join("run.json")
    } else {
        folder.dir.join("summary.json")
    };
    super::summary::check_per_source(&record_path, &summary.record, names.len())?;
    let files = RunFiles::of(&folder.dir, method.label(), run);
    let library = if method.kind.reuses && !folder.library.is_empty() {
        Some(library_start(folder, method)?)
    } else {
        None
    };
    let rows = match &library {
        Some(start) => run_activations(&files.activations, method.label(), run, start.net.len())?,
        None => Vec::new(),
    };
    let activations = !rows.is_empty();
    let score = library.as_ref().map_or(ScoreColumn::NONE, |l| l.score);
    // What the record keeps of the selector, when no activations were on file: the
    // scores the run started from.
    let started = match (&library, activations) {
        (Some(start), false) => Some((start.net.activations().to_vec(), start.net.probabilities())),
        _ => None,
    };
    sink(Event::RunStarted {
        run,
        method: method.clone(),
        budget: config.protocol.budget,
        library: library.map(Box::new),
    });
    let by_episode: BTreeMap<u32, &ActivationRow> = rows.iter().map(|r| (r.episode, r)).collect();
    let record = &summary.record;
    let n = names.len();
    let (mut step, mut selections) = (0_u64, vec![0_u64; n]);
    let learner = each_episode(&files.episodes, method, run, &names, &mut |episode| {
        step += u64::from(episode.steps);
        if let Some(row) = by_episode.get(&episode.episode) {
            for (total, acted) in selections.iter_mut().zip(&row.selected) {
                *total += acted;
            }
            // The source lock-in is of: the one then above `LOCK_IN`, if one is.
            let top = reuse::argmax(&row.probabilities);
            sink(Event::Activations(ActivationSnapshot {
                run,
                method: method.clone(),
                step,
                episode: episode.episode,
                score,
                activations: row.scores.clone(),
                probabilities: row.probabilities.clone(),
                selections: selections.clone(),
                positive: record.positive.clone(),
                negative: record.negative.clone(),
                lock_in: record
                    .lock_in_step
                    .filter(|&at| at <= step)
                    .map(|at| LockIn {
                        source: top,
                        step: at,
                    }),
                excluded: Vec::new(),
            }));
        }
        sink(Event::EpisodeEnded(episode));
    })?;
    if let Some((scores, probabilities)) = started {
        // What the record keeps of the selector: the steps each source acted and its
        // judgments, beside the scores the run started from.
        let snapshot = ActivationSnapshot {
            run,
            method: method.clone(),
            step: record.steps,
            episode: record.episodes,
            score,
            activations: scores,
            probabilities,
            selections: record.source_steps.clone(),
            positive: record.positive.clone(),
            negative: record.negative.clone(),
            lock_in: None,
            excluded: Vec::new(),
        };
        sink(Event::Activations(snapshot));
    }
    sink(Event::RunEnded(record.clone()));
    Ok(Recorded {
        activations,
        learner,
    })
}

/// Where a run's episodes and selector states are: its record's own files, else the
/// folder's top-level ones (a folder shipped without `runs/`).
struct RunFiles {
    episodes: PathBuf,
    activations: PathBuf,
}

impl RunFiles {
    fn of(dir: &Path, method: &str, run: u32) -> Self {
        let own = dir.join(RUNS).join(run_name(method, run));
        let at = if safe_io::csv_exists(&own.join("episodes.csv")) {
            own
        } else {
            dir.to_path_buf()
        };
        Self {
            episodes: at.join("episodes.csv"),
            activations: at.join("activations.csv"),
        }
    }
}

/// The most sources whose graph a finished run's dashboard builds again: 1,000 (the paper's
/// library has 10), a million edges.
pub const MAX_DRAWN_SOURCES: usize = 1_000;

/// The library and the graph the run's selector drew on, made as the run made them: the
/// selector built again from the library's descriptions and scores (SAP-Net's own net; for
/// another selector the library's graph under the config's SAP-Net section).
fn library_start(folder: &FolderState, method: &MethodId) -> Result<LibraryStart> {
    let config = &folder.config;
    // The graph is n × n: 10,000 sources (a library's bound) take gigabytes and minutes to
    // build again, for a screen that shows a few dozen of them.
    if folder.library.len() > MAX_DRAWN_SOURCES {
        bail!(
            "{}: a library of {} sources: a finished run's dashboard builds the graph of at \
             most {MAX_DRAWN_SOURCES} (its comparison and curves are in the other views)",
            folder.dir.display(),
            folder.library.len()
        );
    }
    let descriptions: Vec<_> = folder.library.iter().map(|e| e.description()).collect();
    let scores: Vec<Option<f64>> = folder.library.iter().map(|e| e.final_score).collect();
    let library = Library {
        descriptions: &descriptions,
        scores: &scores,
        gamma: config.dqn.gamma,
        return_range: config.env.return_range(),
        discounted_return_range: config.env.discounted_return_range(config.dqn.gamma),
    };
    let definition = &config.protocol.methods[method.index];
    let selector = reuse::build(definition, library, &config.sapnet)
        .with_context(|| format!("{}: the library of summary.json", folder.dir.display()))?;
    let net = match selector.graph() {
        Some(net) => net.clone(),
        None => SapNet::from_policies(&descriptions, config.sapnet.clone())
            .with_context(|| format!("{}: the library of summary.json", folder.dir.display()))?,
    };
    Ok(LibraryStart {
        policies: folder
            .library
            .iter()
            .zip(descriptions)
            .map(|(entry, description)| SourceSummary {
                name: entry.name.clone(),
                description,
                final_score: entry.final_score,
            })
            .collect(),
        net,
        score: selector.view().score,
    })
}

/// A row of `episodes.csv`; the columns after `steps` default where an older file lacks
/// them.
#[derive(Deserialize)]
struct EpisodeRow {
    run: u32,
    method: String,
    episode: u32,
    reward: f64,
    steps: u32,
    #[serde(default)]
    loss: Option<f64>,
    #[serde(default)]
    statistic_loss: f64,
    #[serde(default)]
    epsilon: f64,
    #[serde(default)]
    policy: Option<String>,
    #[serde(default)]
    wall_s: f64,
}

/// Hands the run's episodes to `each` in order as they are read (sapnet writes a run's
/// rows in episode order; another order is refused), its acting policy known again by its
/// name among `names`; says whether the file kept each episode's ε and statistic loss.
fn each_episode(
    path: &Path,
    method: &MethodId,
    run: u32,
    names: &[String],
    each: &mut dyn FnMut(EpisodeRecord),
) -> Result<bool> {
    let mut reader =
        safe_io::csv_reader(path).with_context(|| format!("reading {}", path.display()))?;
    let headers = reader
        .headers()
        .with_context(|| format!("reading {}", path.display()))?
        .clone();
    let learner = ["epsilon", "statistic_loss"]
        .iter()
        .all(|column| headers.iter().any(|h| h == *column));
    // A name to its index, looked up per row: a library of thousands stays linear.
    let index: std::collections::HashMap<&str, u32> = names
        .iter()
        .enumerate()
        .map(|(i, n)| (n.as_str(), i as u32))
        .collect();
    let mut record = csv::StringRecord::new();
    let mut last: Option<u32> = None;
    for at in 2.. {
        let row = || format!("{}: row {at}", path.display());
        if !reader.read_record(&mut record).with_context(row)? {
            break;
        }
        let row: EpisodeRow = record.deserialize(Some(&headers)).with_context(row)?;
        if row.method != method.label() || row.run != run {
            continue;
        }
        if !row.reward.is_finite() {
            bail!(
                "{}: row {at}, column reward: the return {} is not finite",
                path.display(),
                row.reward
            );
        }
        if last.is_some_and(|last| row.episode <= last) {
            bail!(
                "{}: row {at}: episode {} of {} run {run} after episode {}: expected a \
                 run's episodes in order, as sapnet writes them",
                path.display(),
                row.episode,
                method.label(),
                last.unwrap_or(0)
            );
        }
        last = Some(row.episode);
        each(EpisodeRecord {
            run,
            method: method.clone(),
            episode: row.episode,
            reward: row.reward,
            steps: row.steps,
            loss: row.loss,
            statistic_loss: row.statistic_loss,
            epsilon: row.epsilon,
            policy: row
                .policy
                .and_then(|name| index.get(name.as_str()).copied()),
            wall_s: row.wall_s,
        });
    }
    Ok(learner)
}

/// One episode's end in `activations.csv`: each source's score, probability and steps
/// acted in that episode.
struct ActivationRow {
    episode: u32,
    scores: Vec<f64>,
    probabilities: Vec<f64>,
    selected: Vec<u64>,
}

/// The run's rows of `activations.csv`, read as the plots read it
/// ([`plot_data::read_activations`]), each with a value per source of `sources`; none if the
/// file is absent (a folder shipped without it).
fn run_activations(
    path: &Path,
    method: &str,
    run: u32,
    sources: usize,
) -> Result<Vec<ActivationRow>> {
    let read = plot_data::read_activations_of(path, Some((method, run)))?;
    let Some(history) = read.runs.get(&(method.to_string(), run)) else {
        return Ok(Vec::new());
    };
    if read.names.len() != sources || history.probabilities.len() != history.scores.len() {
        bail!(
            "{}: expected {sources} columns each of A_<policy>, P_<policy> and \
             selected_<policy> (one per source of summary.json's library), found {} sources{}",
            path.display(),
            read.names.len(),
            if history.probabilities.is_empty() {
                " and no P_ columns"
            } else {
                ""
            }
        );
    }
    Ok(history
        .episodes
        .iter()
        .zip(&history.scores)
        .zip(&history.probabilities)
        .zip(&history.acted)
        .map(
            |(((&episode, scores), probabilities), selected)| ActivationRow {
                episode,
                scores: scores.clone(),
                probabilities: probabilities.clone(),
                selected: selected.clone(),
            },
        )
        .collect())
}
