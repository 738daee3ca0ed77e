//! A results directory's plots' data read back from its CSV files (`episodes.csv`,
//! `tests.csv`, `activations.csv`): what `sapnet plot` and a protocol's end draw, and what
//! the dashboard's `--compare` shows.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Context, Result};
use serde::Deserialize;

use super::summary::read_header;
use crate::report::plots::{Curve, PlotData, SelectionHistory};
use crate::report::TrainingEpisodes;

#[derive(Deserialize)]
struct EpisodeRow {
    run: u32,
    method: String,
    episode: u32,
    reward: f64,
    steps: u32,
}

#[derive(Deserialize)]
struct TestRow {
    run: u32,
    method: String,
    test: u32,
    #[serde(rename = "return")]
    test_return: f64,
}

/// The plots' data, from the files of a results directory.
pub fn read(dir: &Path) -> Result<PlotData> {
    let config = read_header(dir)?.config;
    let episodes = training_episodes(&dir.join("episodes.csv"))?;
    let tests = by_run(
        rows::<TestRow>(&dir.join("tests.csv"))?
            .into_iter()
            .map(|r| (r.method, r.run, r.test, r.test_return)),
    );
    let methods = crate::trainer::MethodId::all(&config.protocol.methods);
    let curves = methods
        .iter()
        .filter_map(|method| {
            let label = method.label().to_string();
            let of = |map: &ByRun| -> Vec<Vec<f64>> {
                map.iter()
                    .filter(|((method, _), _)| *method == label)
                    .map(|(_, values)| values.clone())
                    .collect()
            };
            let runs: Vec<TrainingEpisodes> = episodes
                .iter()
                .filter(|((method, _), _)| *method == label)
                .map(|(_, run)| run.clone())
                .collect();
            let tested = of(&tests);
            (!runs.is_empty()).then_some(Curve {
                label,
                kind: method.kind,
                runs,
                tests: tested,
            })
        })
        .collect();
    let read = read_activations(&dir.join("activations.csv"))?;
    let of_method = |label: &str| -> Vec<&SelectionHistory> {
        read.runs
            .iter()
            .filter(|((m, _), _)| m == label)
            .map(|(_, history)| history)
            .collect()
    };
    let activations = methods
        .iter()
        .filter(|m| m.kind.spreads)
        .map(|m| {
            let runs: Vec<Vec<Vec<f64>>> = of_method(m.label())
                .into_iter()
                .map(|h| h.scores.clone())
                .collect();
            (m.label().to_string(), runs)
        })
        .filter(|(_, runs)| !runs.is_empty())
        .collect();
    let acted = methods
        .iter()
        .filter(|m| m.kind.reuses)
        .map(|m| {
            let runs: Vec<Vec<Vec<u64>>> = of_method(m.label())
                .into_iter()
                .map(|h| h.acted.clone())
                .collect();
            (m.label().to_string(), runs)
        })
        .filter(|(_, runs)| !runs.is_empty())
        .collect();
    Ok(PlotData {
        task: crate::report::plots::task_title(&config.env),
        subject: None,
        return_range: crate::report::plots::return_bounds(&config.env),
        window: config.protocol.moving_average,
        budget: config.protocol.budget,
        curves,
        policy_names: read.names,
        activations,
        acted,
    })
}

/// (method, run) → that run's values in order.
pub(super) type ByRun = BTreeMap<(String, u32), Vec<f64>>;

/// Each run's training episodes from a results folder's `episodes.csv`, in episode order.
pub(super) fn training_episodes(path: &Path) -> Result<BTreeMap<(String, u32), TrainingEpisodes>> {
    let mut keyed: BTreeMap<(String, u32), Vec<EpisodeRow>> = BTreeMap::new();
    for r in rows::<EpisodeRow>(path)? {
        keyed.entry((r.method.clone(), r.run)).or_default().push(r);
    }
    // Runs side by side interleave their rows.
    Ok(keyed
        .into_iter()
        .map(|(key, mut rows)| {
            rows.sort_by_key(|r| r.episode);
            let mut run = TrainingEpisodes::default();
            for r in rows {
                run.push(r.reward, r.steps);
            }
            (key, run)
        })
        .collect())
}

/// Groups `(method, run, index, value)` rows by run, each run's values in order of their
/// index (episode or test): runs side by side interleave their rows.
fn by_run(rows: impl IntoIterator<Item = (String, u32, u32, f64)>) -> ByRun {
    let mut keyed: BTreeMap<(String, u32), Vec<(u32, f64)>> = BTreeMap::new();
    for (method, run, index, value) in rows {
        keyed.entry((method, run)).or_default().push((index, value));
    }
    keyed
        .into_iter()
        .map(|(key, mut values)| {
            values.sort_by_key(|&(index, _)| index);
            (key, values.into_iter().map(|(_, v)| v).collect())
        })
        .collect()
}

fn rows<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<Vec<T>> {
    let mut reader =
        crate::safe_io::csv_reader(path).with_context(|| format!("reading {}", path.display()))?;
    reader
        .deserialize()
        .enumerate()
        .map(|(i, row)| row.with_context(|| format!("{}: row {}", path.display(), i + 2)))
        .collect()
}

/// What `activations.csv` holds: for the plots, and for a finished run's dashboard
/// ([`super::recorded_run`]).
#[derive(Default)]
pub(super) struct Activations {
    /// The sources' names (the `A_<name>` columns).
    pub names: Vec<String>,
    /// Per (method, run), each episode's scores, probabilities and steps acted.
    pub runs: BTreeMap<(String, u32), SelectionHistory>,
}

/// No file (a config without a reusing method) is no activations. A file without the
/// `method` column (before the comparison of methods) is SAP-Net's; one without the
/// `episode` column numbers each run's rows from 1.
pub(super) fn read_activations(path: &Path) -> Result<Activations> {
    if !crate::safe_io::csv_exists(path) {
        return Ok(Activations::default());
    }
    let mut reader =
        crate::safe_io::csv_reader(path).with_context(|| format!("reading {}", path.display()))?;
    let headers = reader
        .headers()
        .with_context(|| format!("reading {}", path.display()))?
        .clone();
    let prefixed = |prefix: &str| -> Vec<(usize, String)> {
        headers
            .iter()
            .enumerate()
            .filter_map(|(i, h)| Some((i, h.strip_prefix(prefix)?.to_string())))
            .collect()
    };
    let (scores, acted) = (prefixed("A_"), prefixed("selected_"));
    let probabilities = prefixed("P_");
    let method_column = headers.iter().position(|h| h == "method");
    let episode_column = headers.iter().position(|h| h == "episode");
    if headers.get(0) != Some("run")
        || scores.is_empty()
        || acted.len() != scores.len()
        || !(probabilities.is_empty() || probabilities.len() == scores.len())
    {
        bail!(
            "{}: expected the columns run, method, episode, A_<policy>…, P_<policy>…, \
             selected_<policy>…, found {:?}",
            path.display(),
            headers.iter().collect::<Vec<_>>()
        );
    }
    let mut runs: BTreeMap<(String, u32), SelectionHistory> = BTreeMap::new();
    for (i, record) in reader.records().enumerate() {
        let at = || format!("{}: row {}", path.display(), i + 2);
        let record = record.with_context(at)?;
        let number = |column: usize| -> Result<f64> {
            let field = record.get(column).unwrap_or("");
            field.parse().with_context(|| {
                format!("{}, column {}: {field:?} is not a number", at(), column + 1)
            })
        };
        let run = number(0)? as u32;
        let method = method_column
            .and_then(|c| record.get(c))
            .unwrap_or("sapnet")
            .to_string();
        let values = scores
            .iter()
            .map(|&(c, _)| number(c))
            .collect::<Result<Vec<f64>>>()?;
        let steps = acted
            .iter()
            .map(|&(c, _)| number(c).map(|v| v as u64))
            .collect::<Result<Vec<u64>>>()?;
        let chances = probabilities
            .iter()
            .map(|&(c, _)| number(c))
            .collect::<Result<Vec<f64>>>()?;
        let entry = runs.entry((method, run)).or_default();
        let episode = match episode_column {
            Some(c) => number(c)? as u32,
            None => entry.episodes.len() as u32 + 1,
        };
        entry.scores.push(values);
        entry.acted.push(steps);
        if !chances.is_empty() {
            entry.probabilities.push(chances);
        }
        entry.episodes.push(episode);
    }
    Ok(Activations {
        names: scores.into_iter().map(|(_, name)| name).collect(),
        runs,
    })
}
