//! The result files of a headless run.

use std::fs::File;
use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

use crate::config::Config;
use crate::trainer::{EpisodeRecord, MethodId, RunRecord, TraceRecord};

/// The columns of `episodes.csv`, as [`EpisodeRecord`] serialises.
pub const EPISODES_HEADER: [&str; 10] = [
    "run",
    "method",
    "episode",
    "reward",
    "steps",
    "loss",
    "statistic_loss",
    "epsilon",
    "policy",
    "wall_s",
];

/// `episodes.csv`, one row per episode, flushed row by row so that an interrupted run
/// keeps every finished episode.
pub struct EpisodeWriter {
    csv: csv::Writer<File>,
    path: String,
}

impl EpisodeWriter {
    pub fn create(path: &Path) -> Result<Self> {
        Ok(Self {
            csv: with_header(path, &EPISODES_HEADER)?,
            path: path.display().to_string(),
        })
    }

    /// Writes `record`, its `policy` by name among the sources `names` (as tests.csv
    /// names the chosen one).
    pub fn write(&mut self, record: &EpisodeRecord, names: &[String]) -> Result<()> {
        let row = EpisodeRow {
            run: record.run,
            method: record.method.label(),
            episode: record.episode,
            reward: record.reward,
            steps: record.steps,
            loss: record.loss,
            statistic_loss: record.statistic_loss,
            epsilon: record.epsilon,
            policy: record
                .policy
                .and_then(|i| names.get(i as usize))
                .map(String::as_str),
            wall_s: record.wall_s,
        };
        self.csv
            .serialize(row)
            .and_then(|()| Ok(self.csv.flush()?))
            .with_context(|| format!("writing {}", self.path))
    }
}

/// A row of `episodes.csv`, in [`EPISODES_HEADER`]'s order.
#[derive(Serialize)]
struct EpisodeRow<'a> {
    run: u32,
    method: &'a str,
    episode: u32,
    reward: f64,
    steps: u32,
    loss: Option<f64>,
    statistic_loss: f64,
    epsilon: f64,
    policy: Option<&'a str>,
    wall_s: f64,
}

/// `tests.csv`: the greedy test returns of every run, one row per test episode.
pub struct TestsWriter {
    csv: csv::Writer<File>,
    path: String,
}

#[derive(Serialize)]
struct TestRow<'a> {
    run: u32,
    method: &'a str,
    /// 1-based.
    test: usize,
    #[serde(rename = "return")]
    test_return: f64,
    /// SAP-Net: the chosen policy that was tested.
    policy: Option<&'a str>,
}

impl TestsWriter {
    pub fn create(path: &Path) -> Result<Self> {
        // The header is written at once so that it is there even if no run gets to its tests.
        let csv = with_header(path, &["run", "method", "test", "return", "policy"])?;
        Ok(Self {
            csv,
            path: path.display().to_string(),
        })
    }

    pub fn write(&mut self, record: &RunRecord) -> Result<()> {
        let policy = record.chosen.as_ref().map(|c| c.name.as_str());
        for (i, &test_return) in record.test_returns.iter().enumerate() {
            let row = TestRow {
                run: record.run,
                method: record.method.label(),
                test: i + 1,
                test_return,
                policy,
            };
            self.csv
                .serialize(row)
                .with_context(|| format!("writing {}", self.path))?;
        }
        self.csv
            .flush()
            .with_context(|| format!("writing {}", self.path))
    }
}

/// `activations.csv`: the selector's state at the end of every episode of every run that
/// reuses the library: `run, method, episode, A_<name>…, P_<name>…, selected_<name>…`.
/// `A` is SAP-Net's activation (another selector's own score: UCB's mean, PRQ-learning's
/// W…), `P` the probability of picking the source next, `selected` the steps it acted in
/// that episode.
pub struct ActivationsWriter {
    csv: csv::Writer<File>,
    path: String,
    policies: usize,
    row: Vec<String>,
}

impl ActivationsWriter {
    pub fn create(path: &Path, names: &[String]) -> Result<Self> {
        let mut header = vec![
            "run".to_string(),
            "method".to_string(),
            "episode".to_string(),
        ];
        for prefix in ["A", "P", "selected"] {
            header.extend(names.iter().map(|n| format!("{prefix}_{n}")));
        }
        let csv = with_header(path, &header)?;
        Ok(Self {
            csv,
            path: path.display().to_string(),
            policies: names.len(),
            row: Vec::with_capacity(header.len()),
        })
    }

    pub fn write(
        &mut self,
        run: u32,
        method: &MethodId,
        episode: u32,
        activations: &[f64],
        probabilities: &[f64],
        selected: &[u64],
    ) -> Result<()> {
        debug_assert_eq!(activations.len(), self.policies);
        self.row.clear();
        self.row.push(run.to_string());
        self.row.push(method.label().to_string());
        self.row.push(episode.to_string());
        self.row.extend(activations.iter().map(number));
        self.row.extend(probabilities.iter().map(number));
        self.row.extend(selected.iter().map(ToString::to_string));
        self.csv
            .write_record(&self.row)
            .and_then(|()| self.csv.flush().map_err(Into::into))
            .with_context(|| format!("writing {}", self.path))
    }
}

/// `trace.csv` (`--trace`): every `spread` call of every positive activation of SAP-Net's
/// runs, as teach mode shows them: `run, method, step, policy, call, from, to, h, omega, eta, delta,
/// stopped` (`policy` the activated one, `call` numbering the calls of one activation from
/// 1, `delta` = η/(h·Ω) or 0 when `Ω ≥ T_ω` stopped the call).
pub struct TraceWriter {
    csv: csv::Writer<File>,
    path: String,
    names: Vec<String>,
}

impl TraceWriter {
    pub fn create(path: &Path, names: &[String]) -> Result<Self> {
        let csv = with_header(
            path,
            &[
                "run", "method", "step", "policy", "call", "from", "to", "h", "omega", "eta",
                "delta", "stopped",
            ],
        )?;
        Ok(Self {
            csv,
            path: path.display().to_string(),
            names: names.to_vec(),
        })
    }

    /// One activation's calls; buffered (a long run makes millions), see [`Self::flush`].
    pub fn write(&mut self, record: &TraceRecord) -> Result<()> {
        let Self { csv, path, names } = self;
        let name = |i: usize| names.get(i).map_or("?", String::as_str);
        for (k, call) in record.calls.iter().enumerate() {
            csv.write_record([
                record.run.to_string().as_str(),
                record.method.label(),
                &record.step.to_string(),
                name(record.policy),
                &(k + 1).to_string(),
                name(call.from),
                name(call.to),
                &call.h.to_string(),
                &number(&call.omega),
                &number(&call.eta),
                &number(&call.delta),
                if call.stopped { "true" } else { "false" },
            ])
            .with_context(|| format!("writing {path}"))?;
        }
        Ok(())
    }

    /// Puts what is buffered on disk: at every episode's end, so a stopped run keeps it.
    pub fn flush(&mut self) -> Result<()> {
        self.csv
            .flush()
            .with_context(|| format!("writing {}", self.path))
    }
}

/// A new CSV file at `path` with its header already on disk; rows are written by hand.
fn with_header(path: &Path, header: &[impl AsRef<[u8]>]) -> Result<csv::Writer<File>> {
    let file = File::create(path).with_context(|| format!("creating {}", path.display()))?;
    let mut csv = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(file);
    csv.write_record(header)
        .and_then(|()| csv.flush().map_err(Into::into))
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(csv)
}

/// The shortest text that reads back as `x`, with an exponent where that is shorter (a
/// selection probability of 1.8e-184 would otherwise take 200 digits).
fn number(x: &f64) -> String {
    format!("{x:?}")
}

/// A source policy as `summary.json` lists it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LibraryEntry {
    pub name: String,
    pub hidden: Vec<usize>,
    /// The task it was trained on, with what differs from the task's defaults.
    #[serde(default)]
    pub task: String,
    pub final_score: Option<f64>,
}

/// Where a protocol stands, the first field of `summary.json`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// A process is running it (or was killed: `sapnet plot` and `--resume` then say
    /// `interrupted`).
    Running,
    /// Every planned run finished.
    Complete,
    /// Stopped by the user or a signal; `--resume` finishes it.
    Stopped,
    /// A run failed (`error` says why); `--resume` retries the unfinished runs.
    Failed,
    /// The process died without saying so (SIGKILL, power loss); `--resume` finishes it.
    Interrupted,
}

/// A run of the protocol, by method label and 0-based index.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct RunKey {
    pub method: String,
    pub run: u32,
}

/// `summary.json`.
#[derive(Debug, Serialize)]
pub struct Summary {
    pub status: Status,
    /// Planned runs without a finished record: not started, stopped or killed.
    pub unfinished: Vec<RunKey>,
    pub crate_version: &'static str,
    pub config: Config,
    /// Whether SAP-Net's spread calls are traced (`--trace`): a resumed protocol goes on
    /// as it began.
    pub trace: bool,
    /// The source library the reusing methods drew on (absent without one).
    pub library: Option<Vec<LibraryEntry>>,
    /// Finished (and stopped) runs, ordered by method as the protocol lists them, then run.
    pub runs: Vec<RunSummary>,
    /// The methods side by side (`comparison.csv`).
    pub comparison: Vec<super::comparison::MethodComparison>,
    /// Seconds this process spent (a resumed protocol: since the resume).
    pub wall_s: f64,
    /// Why the experiment ended early, if it failed (the runs above finished before).
    pub error: Option<String>,
}

/// What `--resume` and `sapnet plot` read back from `summary.json`.
#[derive(Debug, Deserialize)]
pub struct SummaryHeader {
    /// Absent in results written before the field existed: complete or stopped, never
    /// resumable.
    pub status: Option<Status>,
    pub config: Config,
    #[serde(default)]
    pub trace: bool,
    pub library: Option<Vec<LibraryEntry>>,
}

/// One run in `summary.json` (and in `runs/<run>/run.json`); `M` as in [`RunRecord`].
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunSummary<M = MethodId> {
    #[serde(flatten)]
    pub record: RunRecord<M>,
    /// Mean of the greedy test returns (absent when the run was stopped before testing).
    pub mean_test_return: Option<f64>,
    /// Moving average of the last `window` training returns.
    pub final_moving_average: Option<f64>,
    /// Best moving average over the run.
    pub best_moving_average: Option<f64>,
    /// First episode (1-based) whose moving average reached the best value.
    pub best_moving_average_episode: Option<u32>,
    /// Where the chosen source, fine-tuned, was added to the policy library (its metadata
    /// file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub library_copy: Option<std::path::PathBuf>,
}

impl Summary {
    pub fn new(config: &Config, trace: bool) -> Self {
        Self {
            status: Status::Running,
            unfinished: Vec::new(),
            crate_version: env!("CARGO_PKG_VERSION"),
            config: config.clone(),
            trace,
            library: None,
            runs: Vec::new(),
            comparison: Vec::new(),
            wall_s: 0.0,
            error: None,
        }
    }

    /// Some run was stopped by the user.
    pub fn stopped(&self) -> bool {
        self.status == Status::Stopped
    }
}

impl RunSummary<String> {
    /// The summary read back from disk, its method known again by its id.
    pub fn with_method(self, method: MethodId) -> RunSummary {
        RunSummary {
            record: self.record.with_method(method),
            mean_test_return: self.mean_test_return,
            final_moving_average: self.final_moving_average,
            best_moving_average: self.best_moving_average,
            best_moving_average_episode: self.best_moving_average_episode,
            library_copy: self.library_copy,
        }
    }
}

impl RunSummary {
    pub fn new(record: RunRecord, rewards: &[f64], window: usize) -> Self {
        let averages = moving_average(rewards, window);
        let best = averages
            .iter()
            .enumerate()
            .fold(None, |best: Option<(usize, f64)>, (i, &a)| match best {
                Some((_, b)) if b >= a => best,
                _ => Some((i, a)),
            });
        let mean_test_return = (!record.test_returns.is_empty())
            .then(|| record.test_returns.iter().sum::<f64>() / record.test_returns.len() as f64);
        Self {
            record,
            mean_test_return,
            final_moving_average: averages.last().copied(),
            best_moving_average: best.map(|(_, a)| a),
            best_moving_average_episode: best.map(|(i, _)| (i + window) as u32),
            library_copy: None,
        }
    }
}

/// Means of every full window of `window` consecutive values (the paper's learning curves
/// average 10 episodes). Element `i` covers values `i ..= i + window - 1`.
pub fn moving_average(values: &[f64], window: usize) -> Vec<f64> {
    if window == 0 || values.len() < window {
        return Vec::new();
    }
    values
        .windows(window)
        .map(|w| w.iter().sum::<f64>() / window as f64)
        .collect()
}

/// Writes `summary` (or a run's `run.json`) atomically: a reader never sees half a file.
pub fn write_json(path: &Path, summary: &impl Serialize) -> Result<()> {
    let tmp = path.with_extension("json.tmp");
    let write = || -> std::io::Result<()> {
        let mut file = File::create(&tmp)?;
        serde_json::to_writer_pretty(&mut file, summary)?;
        file.write_all(b"\n")?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    };
    write().map_err(|err| {
        let _ = std::fs::remove_file(&tmp);
        anyhow::Error::new(err).context(format!("writing {}", path.display()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moving_average_covers_full_windows_only() {
        // (1+2+3)/3 = 2, (2+3+4)/3 = 3, (3+4+5)/3 = 4
        assert_eq!(
            moving_average(&[1.0, 2.0, 3.0, 4.0, 5.0], 3),
            vec![2.0, 3.0, 4.0]
        );
        assert!(moving_average(&[1.0, 2.0], 3).is_empty());
    }

    #[test]
    fn the_best_window_is_dated_by_its_last_episode() {
        let record = RunRecord {
            run: 0,
            method: MethodId::new(0, &crate::config::Method::Dqn { hidden: vec![4] }),
            seed: 0,
            episodes: 5,
            steps: 0,
            updates: 0,
            chosen: None,
            source_steps: Vec::new(),
            lock_in_step: None,
            test_returns: vec![10.0, 20.0],
            stopped: false,
            wall_s: 0.0,
        };
        let s = RunSummary::new(record, &[1.0, 5.0, 3.0, 9.0, 1.0], 2);
        // windows: 3, 4, 6, 5 → best 6 over episodes 3–4.
        assert_eq!(s.best_moving_average, Some(6.0));
        assert_eq!(s.best_moving_average_episode, Some(4));
        assert_eq!(s.final_moving_average, Some(5.0));
        assert_eq!(s.mean_test_return, Some(15.0));
    }
}
