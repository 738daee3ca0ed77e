//! `sapnet plot DIR`: draws a results directory's plots again from its files —
//! `summary.json` (the config: task, methods, moving-average window), `episodes.csv`,
//! `tests.csv` and `activations.csv` — exactly as the run that wrote them drew them.
//! For a run stopped before its plots, or plots of an older version.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Context, Result};
use serde::Deserialize;

use super::plots::{self, Curve, PlotData};
use crate::config::Config;

#[derive(Deserialize)]
struct EpisodeRow {
    run: u32,
    method: String,
    episode: u32,
    reward: f64,
}

#[derive(Deserialize)]
struct TestRow {
    run: u32,
    method: String,
    test: u32,
    #[serde(rename = "return")]
    test_return: f64,
}

/// Reads `dir`'s results and writes its plots (replacing those there).
pub fn replot(dir: &Path) -> Result<()> {
    let data = read(dir)?;
    plots::write_all(dir, &data).with_context(|| format!("drawing the plots in {}", dir.display()))
}

/// The plots' data, from the files of a results directory.
pub fn read(dir: &Path) -> Result<PlotData> {
    let config = read_config(&dir.join("summary.json"))?;
    let returns = by_run(
        rows::<EpisodeRow>(&dir.join("episodes.csv"))?
            .into_iter()
            .map(|r| (r.method, r.run, r.episode, r.reward)),
    );
    let tests = by_run(
        rows::<TestRow>(&dir.join("tests.csv"))?
            .into_iter()
            .map(|r| (r.method, r.run, r.test, r.test_return)),
    );
    let curves = super::method_labels(&config)
        .into_iter()
        .filter_map(|label| {
            let of = |map: &ByRun| -> Vec<Vec<f64>> {
                map.iter()
                    .filter(|((method, _), _)| *method == label)
                    .map(|(_, values)| values.clone())
                    .collect()
            };
            let (runs, tested) = (of(&returns), of(&tests));
            (!runs.is_empty()).then_some(Curve {
                label,
                returns: runs,
                tests: tested,
            })
        })
        .collect();
    let activations = read_activations(&dir.join("activations.csv"))?;
    Ok(PlotData {
        task: crate::env::make(&config.env).id().to_string(),
        window: config.protocol.moving_average,
        curves,
        policy_names: activations.names,
        activations: activations.runs,
    })
}

/// (method, run) → that run's values in order.
type ByRun = BTreeMap<(String, u32), Vec<f64>>;

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

fn read_config(path: &Path) -> Result<Config> {
    #[derive(Deserialize)]
    struct Summary {
        config: Config,
    }
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading {} (is this a results directory?)", path.display()))?;
    let summary: Summary = serde_json::from_str(&text)
        .with_context(|| format!("reading {}: field `config`", path.display()))?;
    Ok(summary.config)
}

fn rows<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<Vec<T>> {
    let mut reader =
        csv::Reader::from_path(path).with_context(|| format!("reading {}", path.display()))?;
    reader
        .deserialize()
        .enumerate()
        .map(|(i, row)| row.with_context(|| format!("{}: row {}", path.display(), i + 2)))
        .collect()
}

/// What `activations.csv` holds for the plots.
#[derive(Default)]
struct Activations {
    /// The sources' names (the `A_<name>` columns).
    names: Vec<String>,
    /// Per run, each episode's activations.
    runs: Vec<Vec<Vec<f64>>>,
}

/// No file (a config without SAP-Net) is no activations.
fn read_activations(path: &Path) -> Result<Activations> {
    if !path.exists() {
        return Ok(Activations::default());
    }
    let mut reader =
        csv::Reader::from_path(path).with_context(|| format!("reading {}", path.display()))?;
    let headers = reader
        .headers()
        .with_context(|| format!("reading {}", path.display()))?
        .clone();
    let columns: Vec<(usize, String)> = headers
        .iter()
        .enumerate()
        .filter_map(|(i, h)| Some((i, h.strip_prefix("A_")?.to_string())))
        .collect();
    if headers.get(0) != Some("run") || columns.is_empty() {
        bail!(
            "{}: expected the columns run, episode, A_<policy>…, found {:?}",
            path.display(),
            headers.iter().collect::<Vec<_>>()
        );
    }
    let mut runs: BTreeMap<u32, Vec<Vec<f64>>> = BTreeMap::new();
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
        let values = columns
            .iter()
            .map(|&(c, _)| number(c))
            .collect::<Result<Vec<f64>>>()?;
        runs.entry(run).or_default().push(values);
    }
    Ok(Activations {
        names: columns.into_iter().map(|(_, name)| name).collect(),
        runs: runs.into_values().collect(),
    })
}
