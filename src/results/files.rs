//! The CSV files of a results directory, written row by row as runs train: `episodes.csv`,
//! `tests.csv`, `activations.csv` and `trace.csv`.

use std::fs::File;
use std::path::Path;

use anyhow::{Context, Result};
use serde::Serialize;

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
    let file =
        crate::safe_io::create(path).with_context(|| format!("creating {}", path.display()))?;
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
