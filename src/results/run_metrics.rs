//! Each run's per-episode metrics as its files record them, for the Curves view
//! ([`crate::report::metric`]): `episodes.csv`'s `reward`, `steps`, `loss`,
//! `statistic_loss`, `epsilon` and `wall_s`, and for a run that reuses the library
//! `activations.csv`'s `A_<name>` and `P_<name>`. A finished run's files are in
//! `runs/<run>/`, a running or stopped one's in its partial folder; a folder shipped with
//! its top-level files only (`docs/`'s) has its returns and lengths, nothing more.
//!
//! Only what is on file is offered ([`on_file`]), and an episode without a value reads as
//! none: a loss before learning, the statistic loss of a method that does not spread
//! activation, a row of a file cut while it was written.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, Result};

use super::folder_state::FolderState;
use super::records::{self, run_name};
use crate::report::metric::{Metric, RunMetric};
use crate::report::TrainingEpisodes;

/// Where one run's metrics are read from.
#[derive(Debug, Clone)]
pub struct RunFiles {
    /// The run's method, by its place in the protocol.
    pub method: usize,
    /// Its record's folder (finished or partial); `None` in a shipped folder.
    pub dir: Option<PathBuf>,
    /// Whether its method spreads activation (has a statistic loss E of its own).
    pub spreads: bool,
    /// Its returns and lengths, as the folder was read.
    pub training: Arc<TrainingEpisodes>,
}

/// Every run of `folder` with episodes, in the protocol's order.
pub fn run_files(folder: &FolderState) -> Vec<RunFiles> {
    let shipped = !folder.dir.join(records::RUNS).is_dir();
    folder
        .runs
        .iter()
        .filter(|r| !r.training.is_empty())
        .map(|r| {
            let name = run_name(r.method.label(), r.run);
            let finished = folder.dir.join(records::RUNS).join(&name);
            let dir = if shipped {
                None
            } else if finished.join("episodes.csv").is_file()
                || crate::safe_io::csv_exists(&finished.join("episodes.csv"))
            {
                Some(finished)
            } else {
                Some(records::partial_dir(&folder.dir, &name))
            };
            RunFiles {
                method: r.method.index,
                dir,
                spreads: r.method.kind.spreads,
                training: r.training.clone(),
            }
        })
        .collect()
}

/// What the runs' files hold: the metrics to offer, in order, and whether the episodes'
/// wall times are there.
#[derive(Debug, Clone, PartialEq)]
pub struct OnFile {
    pub metrics: Vec<Metric>,
    pub wall: bool,
}

/// What `runs`' files hold, from their headers: returns always; lengths where every run
/// has them (a run from elsewhere may give its returns alone); the columns of
/// `episodes.csv` present in the first run's; a source's activation and probability where
/// some run has `activations.csv` (`sources` in the library).
pub fn on_file(runs: &[RunFiles], sources: usize) -> OnFile {
    let mut metrics = vec![Metric::Return];
    if runs
        .iter()
        .all(|r| r.training.lengths.iter().any(|&l| l > 0))
    {
        metrics.push(Metric::Length);
    }
    let mut wall = false;
    let first = runs.iter().find_map(|r| r.dir.as_ref());
    if let Some(dir) = first {
        let header = header(&dir.join("episodes.csv")).unwrap_or_default();
        let has = |column: &str| header.iter().any(|h| h == column);
        if has("loss") {
            metrics.push(Metric::Loss);
        }
        if has("statistic_loss") && runs.iter().any(|r| r.spreads) {
            metrics.push(Metric::StatisticLoss);
        }
        if has("epsilon") {
            metrics.push(Metric::Epsilon);
        }
        if has("wall_s") {
            wall = true;
            metrics.push(Metric::StepsPerSecond);
        }
    }
    let activations = runs.iter().any(|r| {
        r.dir
            .as_ref()
            .is_some_and(|d| crate::safe_io::csv_exists(&d.join("activations.csv")))
    });
    if activations {
        metrics.extend((0..sources).map(Metric::Activation));
        metrics.extend((0..sources).map(Metric::Probability));
    }
    OnFile { metrics, wall }
}

/// A CSV file's header, if it can be read.
fn header(path: &Path) -> Option<Vec<String>> {
    let mut reader = crate::safe_io::csv_reader(path).ok()?;
    let header = reader.headers().ok()?;
    Some(header.iter().map(String::from).collect())
}

/// `run`'s values of `metric`, one per episode it has (as the folder was read: a running
/// run's files may have grown since, and a row cut while written ends the reading), with
/// the episodes' wall times when `wall` and on file. `sources` names the library's sources,
/// as `activations.csv`'s columns do.
pub fn read(run: &RunFiles, metric: Metric, wall: bool, sources: &[String]) -> Result<RunMetric> {
    let training = &run.training;
    let episodes = training.len();
    let mut out = RunMetric {
        values: Vec::new(),
        lengths: training.lengths.clone(),
        wall_s: None,
    };
    let column = match metric {
        Metric::Return => {
            out.values = training.returns.iter().map(|&r| Some(r)).collect();
            None
        }
        Metric::Length => {
            out.values = training
                .lengths
                .iter()
                .map(|&l| Some(f64::from(l)))
                .collect();
            None
        }
        Metric::Loss => Some("loss"),
        Metric::StatisticLoss if !run.spreads => {
            out.values = vec![None; episodes];
            None
        }
        Metric::StatisticLoss => Some("statistic_loss"),
        Metric::Epsilon => Some("epsilon"),
        Metric::StepsPerSecond => Some("wall_s"),
        Metric::Activation(_) | Metric::Probability(_) => None,
    };
    let Some(dir) = &run.dir else {
        out.values.resize(episodes, None);
        return Ok(out);
    };
    let needs_wall = wall || metric == Metric::StepsPerSecond;
    if column.is_some() || needs_wall {
        let path = dir.join("episodes.csv");
        let mut columns: Vec<&str> = column.into_iter().chain(["wall_s"]).collect();
        columns.dedup();
        let read = read_columns(&path, &columns, episodes)?;
        if let Some(values) = read.get("wall_s").filter(|_| needs_wall) {
            if values.iter().all(Option::is_some) && values.len() == episodes {
                out.wall_s = Some(values.iter().flatten().copied().collect());
            }
        }
        match (metric, column) {
            (Metric::StepsPerSecond, _) => {
                let wall = read.get("wall_s").cloned().unwrap_or_default();
                out.values = (0..episodes)
                    .map(|i| {
                        let end = (*wall.get(i)?)?;
                        let start = if i == 0 { Some(0.0) } else { *wall.get(i - 1)? }?;
                        let seconds = end - start;
                        (seconds > 0.0).then(|| f64::from(training.lengths[i]) / seconds)
                    })
                    .collect();
            }
            (_, Some(column)) => out.values = read.get(column).cloned().unwrap_or_default(),
            _ => {}
        }
    }
    if let Metric::Activation(i) | Metric::Probability(i) = metric {
        let prefix = if matches!(metric, Metric::Activation(_)) {
            "A"
        } else {
            "P"
        };
        let name = sources
            .get(i)
            .map_or(String::new(), |s| format!("{prefix}_{s}"));
        out.values = read_by_episode(&dir.join("activations.csv"), &name, episodes)?;
    }
    out.values.resize(episodes, None);
    Ok(out)
}

/// `columns` of the first `rows` rows of `path` (missing or empty cells, and rows past a
/// row cut while written, are none); a file not there reads as empty.
fn read_columns(
    path: &Path,
    columns: &[&str],
    rows: usize,
) -> Result<HashMap<String, Vec<Option<f64>>>> {
    let mut out: HashMap<String, Vec<Option<f64>>> = HashMap::new();
    let Some((mut reader, header)) = open_with_header(path)? else {
        return Ok(out);
    };
    let at: Vec<(&str, Option<usize>)> = columns
        .iter()
        .map(|&c| (c, header.iter().position(|h| h == c)))
        .collect();
    let mut record = csv::StringRecord::new();
    for _ in 0..rows {
        // A row being written, or a bad one, ends what is read: the rest has no value.
        if !matches!(reader.read_record(&mut record), Ok(true)) {
            break;
        }
        for &(column, index) in &at {
            let value = index
                .and_then(|i| record.get(i))
                .and_then(|cell| cell.parse::<f64>().ok())
                .filter(|v| v.is_finite());
            out.entry(column.to_string()).or_default().push(value);
        }
    }
    Ok(out)
}

/// A run file's CSV reader, bounded by the safe reader.
type CsvReader = csv::Reader<Box<dyn std::io::Read>>;

/// The CSV file at `path` opened by the safe reader, with its header; none if the run
/// did not write it.
fn open_with_header(path: &Path) -> Result<Option<(CsvReader, csv::StringRecord)>> {
    if !crate::safe_io::csv_exists(path) {
        return Ok(None);
    }
    let mut reader =
        crate::safe_io::csv_reader(path).with_context(|| format!("reading {}", path.display()))?;
    let header = reader
        .headers()
        .with_context(|| format!("reading {}", path.display()))?
        .clone();
    Ok(Some((reader, header)))
}

/// Column `name` of `activations.csv` at `path`, placed by each row's `episode` (from 1)
/// among a run's `episodes`.
fn read_by_episode(path: &Path, name: &str, episodes: usize) -> Result<Vec<Option<f64>>> {
    let mut values = vec![None; episodes];
    let Some((mut reader, header)) = open_with_header(path)? else {
        return Ok(values);
    };
    let (Some(episode_at), Some(value_at)) = (
        header.iter().position(|h| h == "episode"),
        header.iter().position(|h| h == name),
    ) else {
        return Ok(values);
    };
    let mut record = csv::StringRecord::new();
    while let Ok(true) = reader.read_record(&mut record) {
        let episode = record.get(episode_at).and_then(|e| e.parse::<usize>().ok());
        let value = record
            .get(value_at)
            .and_then(|v| v.parse::<f64>().ok())
            .filter(|v| v.is_finite());
        if let Some(slot) = episode
            .and_then(|e| e.checked_sub(1))
            .and_then(|i| values.get_mut(i))
        {
            *slot = value;
        }
    }
    Ok(values)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_runs_columns_are_read_missing_cells_as_none() {
        let tmp = tempfile::tempdir().unwrap();
        std::fs::write(
            tmp.path().join("episodes.csv"),
            "run,method,episode,reward,steps,loss,statistic_loss,epsilon,policy,wall_s\n\
             0,sapnet,1,12.0,12,,0.0,0.5,,1.0\n\
             0,sapnet,2,20.0,20,0.25,0.01,0.25,source-3,2.0\n\
             0,sapnet,3,31.0,40,0.5,0.01,0.125,source-1,4.0\n",
        )
        .unwrap();
        std::fs::write(
            tmp.path().join("activations.csv"),
            "run,method,episode,A_a,A_b,P_a,P_b,selected_a,selected_b\n\
             0,sapnet,2,0.5,0.25,0.75,0.25,3,0\n",
        )
        .unwrap();
        let mut training = TrainingEpisodes::default();
        for (r, l) in [(12.0, 12), (20.0, 20), (31.0, 40)] {
            training.push(r, l);
        }
        let run = RunFiles {
            method: 0,
            dir: Some(tmp.path().to_path_buf()),
            spreads: true,
            training: Arc::new(training),
        };
        let sources = ["a".to_string(), "b".to_string()];
        let offered = on_file(std::slice::from_ref(&run), 2);
        assert!(offered.wall);
        assert_eq!(offered.metrics.len(), 6 + 4, "{offered:?}");
        let loss = read(&run, Metric::Loss, true, &sources).unwrap();
        assert_eq!(
            loss.values,
            [None, Some(0.25), Some(0.5)],
            "no loss is none, not 0"
        );
        assert_eq!(loss.wall_s, Some(vec![1.0, 2.0, 4.0]));
        // 12 steps in 1 s, 20 in 1 s, 40 in 2 s.
        let sps = read(&run, Metric::StepsPerSecond, false, &sources).unwrap();
        assert_eq!(sps.values, [Some(12.0), Some(20.0), Some(20.0)]);
        let p = read(&run, Metric::Probability(0), false, &sources).unwrap();
        assert_eq!(p.values, [None, Some(0.75), None]);
        let dqn = RunFiles {
            spreads: false,
            ..run.clone()
        };
        let e = read(&dqn, Metric::StatisticLoss, false, &sources).unwrap();
        assert_eq!(e.values, [None, None, None]);
        let shipped = RunFiles { dir: None, ..run };
        assert_eq!(
            on_file(&[shipped], 2),
            OnFile {
                metrics: vec![Metric::Return, Metric::Length],
                wall: false
            }
        );
    }
}
