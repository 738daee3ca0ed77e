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
use crate::reuse::{self, Library};
use crate::safe_io;
use crate::sapnet::SapNet;
use crate::trainer::{
    ActivationSnapshot, EpisodeRecord, Event, LibraryStart, LockIn, MethodId, SourceSummary,
};

/// A finished run's events, and what of them its files kept.
pub struct Recorded {
    pub events: Vec<Event>,
    /// Whether `activations.csv` held the run's scores and probabilities: without them a
    /// reusing run's dashboard shows its library's scores as they started, with the steps
    /// each source acted and its judgments from the run's record.
    pub activations: bool,
    /// Whether `episodes.csv` held each episode's ε and losses (`docs/` ships it without):
    /// without them they read 0.
    pub learner: bool,
}

/// The events of run `run` of `method` in `folder`, which must have finished (or been
/// stopped) there.
pub fn read(folder: &FolderState, method: &MethodId, run: u32) -> Result<Recorded> {
    let Some(summary) = folder.finished(method, run) else {
        bail!(
            "{}: {} run {run} has no record: it has not finished",
            folder.dir.display(),
            method.label()
        );
    };
    let config = &folder.config;
    let names: Vec<String> = folder.library.iter().map(|e| e.name.clone()).collect();
    let files = RunFiles::of(&folder.dir, method.label(), run);
    let (episodes, learner) = read_episodes(&files.episodes, method, run, &names)?;
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
    let score_name = library.as_ref().map_or("", |l| l.score_name);
    let mut events = vec![Event::RunStarted {
        run,
        method: method.clone(),
        budget: config.protocol.budget,
        library: library.map(Box::new),
    }];
    let by_episode: BTreeMap<u32, &ActivationRow> = rows.iter().map(|r| (r.episode, r)).collect();
    let record = &summary.record;
    let n = names.len();
    let (mut step, mut selections) = (0_u64, vec![0_u64; n]);
    for episode in episodes {
        step += u64::from(episode.steps);
        if let Some(row) = by_episode.get(&episode.episode) {
            for (total, acted) in selections.iter_mut().zip(&row.selected) {
                *total += acted;
            }
            // The source lock-in is of: the one then above `LOCK_IN`, if one is.
            let top = reuse::argmax(&row.probabilities);
            events.push(Event::Activations(ActivationSnapshot {
                run,
                method: method.clone(),
                step,
                episode: episode.episode,
                score_name,
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
        events.push(Event::EpisodeEnded(episode));
    }
    if let (
        false,
        Some(Event::RunStarted {
            library: Some(start),
            ..
        }),
    ) = (activations, events.first())
    {
        // What the record keeps of the selector: the steps each source acted and its
        // judgments, beside the scores the run started from.
        let snapshot = ActivationSnapshot {
            run,
            method: method.clone(),
            step: record.steps,
            episode: record.episodes,
            score_name,
            activations: start.net.activations().to_vec(),
            probabilities: start.net.probabilities(),
            selections: record.source_steps.clone(),
            positive: record.positive.clone(),
            negative: record.negative.clone(),
            lock_in: None,
            excluded: Vec::new(),
        };
        events.push(Event::Activations(snapshot));
    }
    events.push(Event::RunEnded(record.clone()));
    Ok(Recorded {
        events,
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

/// The library and the graph the run's selector drew on, made as the run made them: the
/// selector built again from the library's descriptions and scores (SAP-Net's own net; for
/// another selector the library's graph under the config's SAP-Net section).
fn library_start(folder: &FolderState, method: &MethodId) -> Result<LibraryStart> {
    let config = &folder.config;
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
        score_name: selector.view().score_name,
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

/// The run's episodes in order, its acting policy known again by its name among `names`;
/// and whether the file kept each episode's ε and statistic loss.
fn read_episodes(
    path: &Path,
    method: &MethodId,
    run: u32,
    names: &[String],
) -> Result<(Vec<EpisodeRecord>, bool)> {
    let mut reader =
        safe_io::csv_reader(path).with_context(|| format!("reading {}", path.display()))?;
    let headers = reader
        .headers()
        .with_context(|| format!("reading {}", path.display()))?;
    let learner = ["epsilon", "statistic_loss"]
        .iter()
        .all(|column| headers.iter().any(|h| h == *column));
    let mut episodes = Vec::new();
    for (i, row) in reader.deserialize::<EpisodeRow>().enumerate() {
        let row = row.with_context(|| format!("{}: row {}", path.display(), i + 2))?;
        if row.method != method.label() || row.run != run {
            continue;
        }
        episodes.push(EpisodeRecord {
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
                .and_then(|name| names.iter().position(|n| *n == name))
                .map(|i| i as u32),
            wall_s: row.wall_s,
        });
    }
    episodes.sort_by_key(|e| e.episode);
    Ok((episodes, learner))
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
    let read = plot_data::read_activations(path)?;
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
