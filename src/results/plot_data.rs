//! A results directory's plots' data read back from its CSV files (`episodes.csv`,
//! `tests.csv`, `activations.csv`): what `sapnet plot` and a protocol's end draw, and what
//! the dashboard's `--compare` shows.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Context, Result};
use serde::Deserialize;

use super::summary::read_header;
use crate::limits::MAX_VALUES_KEPT;
use crate::report::plots::{Curve, PlotData, SelectionHistory};
use crate::report::{RunSummary, TrainingEpisodes};

#[derive(Deserialize)]
struct EpisodeRow<'a> {
    run: u32,
    method: &'a str,
    episode: u32,
    reward: f64,
    steps: u32,
}

#[derive(Deserialize)]
struct TestRow<'a> {
    run: u32,
    method: &'a str,
    test: u32,
    #[serde(rename = "return")]
    test_return: f64,
}

/// The plots' data, from the files of a results directory.
pub fn read(dir: &Path) -> Result<PlotData> {
    read_expecting(dir, &EpisodeCounts::default())
}

/// [`read`], each run's returns kept in a block of the episodes `counts` gives it.
pub(super) fn read_expecting(dir: &Path, counts: &EpisodeCounts) -> Result<PlotData> {
    let config = read_header(dir)?.config;
    let mut episodes = training_episodes(&dir.join("episodes.csv"), counts)?;
    let path = dir.join("tests.csv");
    let mut tests = ByRunReader::new(&path, "return", "test");
    each_row(&path, |record, headers, at| {
        let row: TestRow = parse(record, headers, &path, at)?;
        tests.push(row.method, row.run, row.test, row.test_return, at)
    })?;
    let mut tests = tests.finish();
    let methods = crate::trainer::MethodId::all(&config.protocol.methods);
    let curves = methods
        .iter()
        .filter_map(|method| {
            let label = method.label().to_string();
            // Moved, not copied: a folder's returns are its largest data.
            let runs = take_method(&mut episodes, &label);
            let tested = take_method(&mut tests, &label);
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

/// The runs of method `label` taken out of `map`, in run order.
fn take_method<T>(map: &mut BTreeMap<(String, u32), T>, label: &str) -> Vec<T> {
    let keys: Vec<_> = map
        .range((label.to_string(), 0)..=(label.to_string(), u32::MAX))
        .map(|(key, _)| key.clone())
        .collect();
    keys.iter().filter_map(|key| map.remove(key)).collect()
}

/// Each run's training episodes (return and length) from a results folder's
/// `episodes.csv`, in episode order; a return that is not finite, or more values than
/// [`MAX_VALUES_KEPT`], refused naming the file and the row. Each run's are kept in a
/// block of the episodes `counts` gives it.
pub(super) fn training_episodes(
    path: &Path,
    counts: &EpisodeCounts,
) -> Result<BTreeMap<(String, u32), TrainingEpisodes>> {
    let mut returns = ByRunReader::new(path, "reward", "episode").expecting(counts);
    // Kept as they are read (a u32 each), not as a return is: 12 bytes an episode.
    let mut lengths = ByRunReader::<u32>::new(path, "steps", "episode").expecting(counts);
    each_row(path, |record, headers, at| {
        let row: EpisodeRow = parse(record, headers, path, at)?;
        returns.push(row.method, row.run, row.episode, row.reward, at)?;
        lengths.push(row.method, row.run, row.episode, row.steps, at)
    })?;
    let mut lengths = lengths.finish();
    Ok(returns
        .finish()
        .into_iter()
        .map(|(key, returns)| {
            let lengths = lengths.remove(&key).unwrap_or_default();
            (key, TrainingEpisodes { returns, lengths })
        })
        .collect())
}

/// Refuses row `at` of `path` when keeping `more` values beside the `kept` ones would pass
/// [`MAX_VALUES_KEPT`].
pub(super) fn check_kept(path: &Path, kept: usize, more: usize, at: usize) -> Result<()> {
    if kept.saturating_add(more) > MAX_VALUES_KEPT {
        bail!(
            "{}: row {at}: more than the {MAX_VALUES_KEPT} values sapnet keeps from one file \
             (a return per episode, 3 per source per row of activations.csv)",
            path.display()
        );
    }
    Ok(())
}

/// Return `i` (row `i + 2`) of `path`, a run's own `episodes.csv`: finite, and within
/// [`MAX_VALUES_KEPT`].
pub(super) fn a_kept_return(path: &Path, i: usize, reward: f64) -> Result<f64> {
    if !reward.is_finite() {
        bail!(
            "{}: row {}, column reward: the return {reward} is not finite",
            path.display(),
            i + 2
        );
    }
    check_kept(path, i, 1, i + 2)?;
    Ok(reward)
}

/// A run that ended (not stopped) has episodes: a record without any would make its
/// scores NaN.
pub(super) fn some_returns(
    path: &Path,
    record: &crate::trainer::RunRecord,
    returns: usize,
) -> Result<()> {
    if returns == 0 && !record.stopped {
        bail!(
            "{}: no episode of {} run {}, which its record says ended (after {} episodes)",
            path.display(),
            record.method.label(),
            record.run,
            record.episodes
        );
    }
    Ok(())
}

/// Refuses row `at` of `path` unless its index (`what`: episode or test) comes after the
/// `last` one of its run: a run's rows are numbered in order, as sapnet writes them, so a
/// reader keeps their values in the order read, never an index to sort them by.
pub(super) fn in_order(
    path: &Path,
    at: usize,
    what: &str,
    (method, run): (&str, u32),
    last: u32,
    index: u32,
) -> Result<()> {
    if index <= last {
        bail!(
            "{}: row {at}: {what} {index} of {method:?} run {run} comes after its {what} \
             {last}: a run's rows are read in the order of their {what}, each once, as sapnet \
             writes them",
            path.display()
        );
    }
    Ok(())
}

/// How many episodes each run has, as its record says (none when not given): the room a
/// reader makes for its values, so that they are read where they will stay.
#[derive(Default)]
pub(super) struct EpisodeCounts<'a>(BTreeMap<(&'a str, u32), usize>);

impl<'a> EpisodeCounts<'a> {
    pub(super) fn of(runs: &'a [RunSummary]) -> Self {
        let count = |r: &'a RunSummary| {
            let record = &r.record;
            (
                (record.method.label(), record.run),
                record.episodes as usize,
            )
        };
        Self(runs.iter().map(count).collect())
    }

    fn of_run(&self, method: &str, run: u32) -> usize {
        self.0.get(&(method, run)).copied().unwrap_or(0)
    }
}

/// Groups `(method, run, index, value)` rows by run as they are read: runs side by side
/// interleave their rows. Within a run a row that repeats or goes back is refused where it
/// is read ([`in_order`]): it kept every index to sort by, which a file of 2^25 rows all
/// numbered 1 made cost 128 MiB more per column (issue 52's xz bomb, 804 MB in all).
struct ByRunReader<'p, T = f64> {
    path: &'p Path,
    /// What the value is, for messages (`reward`).
    column: &'static str,
    /// What the index counts, for messages (`episode`).
    index: &'static str,
    runs: BTreeMap<String, BTreeMap<u32, Series<T>>>,
    kept: usize,
    /// The rows each run is expected to have.
    counts: Option<&'p EpisodeCounts<'p>>,
    /// Room made for expected rows so far: at most [`MAX_VALUES_KEPT`], whatever the
    /// counts say.
    reserved: usize,
}

/// A value a [`ByRunReader`] keeps: a return (refused unless finite) or a length.
trait Kept: Copy + std::fmt::Display {
    fn is_finite(self) -> bool;
}

impl Kept for f64 {
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

impl Kept for u32 {
    fn is_finite(self) -> bool {
        true
    }
}

struct Series<T> {
    values: Chunked<T>,
    /// The last row's index: the next one's is greater.
    last: u32,
}

impl<'p, T: Kept> ByRunReader<'p, T> {
    fn new(path: &'p Path, column: &'static str, index: &'static str) -> Self {
        Self {
            path,
            column,
            index,
            runs: BTreeMap::new(),
            kept: 0,
            counts: None,
            reserved: 0,
        }
    }

    /// Each run's values kept in one block made for its expected rows, as many as the
    /// reader keeps at most: read into chunks, a folder's runs would be copied into their
    /// blocks at the end, and the chunks left to the allocator would cost as much again
    /// (a folder of 24 M episodes peaked at 557 MB for 288 MB of values).
    fn expecting(mut self, counts: &'p EpisodeCounts<'p>) -> Self {
        self.counts = Some(counts);
        self
    }

    fn push(&mut self, method: &str, run: u32, index: u32, value: T, at: usize) -> Result<()> {
        if !value.is_finite() {
            bail!(
                "{}: row {at}, column {}: the return {value} is not finite",
                self.path.display(),
                self.column
            );
        }
        check_kept(self.path, self.kept, 1, at)?;
        self.kept += 1;
        let runs = match self.runs.get_mut(method) {
            Some(runs) => runs,
            None => self.runs.entry(method.to_string()).or_default(),
        };
        let series = runs.entry(run).or_insert_with(|| {
            let expected = self.counts.map_or(0, |counts| counts.of_run(method, run));
            let room = expected.min(MAX_VALUES_KEPT - self.reserved);
            self.reserved += room;
            Series {
                values: Chunked::with_capacity(room),
                last: 0,
            }
        });
        if !series.values.is_empty() {
            in_order(self.path, at, self.index, (method, run), series.last, index)?;
        }
        series.last = index;
        series.values.push(value);
        Ok(())
    }

    fn finish(self) -> BTreeMap<(String, u32), Vec<T>> {
        let mut by_run = BTreeMap::new();
        for (method, runs) in self.runs {
            for (run, series) in runs {
                by_run.insert((method.clone(), run), series.values.into_vec());
            }
        }
        by_run
    }
}

/// Values kept in the block made for those expected, then in chunks of about a mebibyte:
/// grown a chunk at a time, never copied into a larger block as a `Vec` grows (which
/// would hold the old block and the new, twice the data, and leave the old ones to the
/// allocator), so what a file's rows cost is the values themselves.
pub(super) struct Chunked<T> {
    /// The values expected, in the block they are handed over in.
    block: Vec<T>,
    /// The values past the block's room.
    chunks: Vec<Vec<T>>,
    len: usize,
}

impl<T> Default for Chunked<T> {
    fn default() -> Self {
        Self::with_capacity(0)
    }
}

impl<T> Chunked<T> {
    pub(super) fn with_capacity(expected: usize) -> Self {
        Self {
            block: Vec::with_capacity(expected),
            chunks: Vec::new(),
            len: 0,
        }
    }
}

impl<T: Copy> Chunked<T> {
    /// A chunk's values: a mebibyte, less room for the allocator's own bookkeeping.
    const CHUNK: usize = ((1 << 20) - 512) / std::mem::size_of::<T>();

    pub(super) fn push(&mut self, value: T) {
        self.len += 1;
        if self.block.len() < self.block.capacity() {
            self.block.push(value);
            return;
        }
        match self.chunks.last_mut() {
            Some(chunk) if chunk.len() < Self::CHUNK => chunk.push(value),
            _ => {
                let mut chunk = Vec::with_capacity(Self::CHUNK);
                chunk.push(value);
                self.chunks.push(chunk);
            }
        }
    }

    fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The values in one block: the block made for them when they were as many as
    /// expected; room expected and not used is given back.
    pub(super) fn into_vec(self) -> Vec<T> {
        let mut values = self.block;
        if self.chunks.is_empty() {
            values.shrink_to_fit();
            return values;
        }
        values.reserve_exact(self.len - values.len());
        for chunk in self.chunks {
            values.extend_from_slice(&chunk);
        }
        values
    }
}

/// Hands each row of `path` (a CSV file of a folder, or its xz twin) to `each` with the
/// header and its row number (the header is row 1), one at a time: nothing but the row
/// read is held.
fn each_row(
    path: &Path,
    mut each: impl FnMut(&csv::ByteRecord, &csv::ByteRecord, usize) -> Result<()>,
) -> Result<()> {
    let mut reader =
        crate::safe_io::csv_reader(path).with_context(|| format!("reading {}", path.display()))?;
    let headers = reader
        .byte_headers()
        .with_context(|| format!("reading {}", path.display()))?
        .clone();
    let mut record = csv::ByteRecord::new();
    for at in 2.. {
        let more = reader
            .read_byte_record(&mut record)
            .with_context(|| format!("{}: row {at}", path.display()))?;
        if !more {
            break;
        }
        each(&record, &headers, at)?;
    }
    Ok(())
}

/// Row `at` of `path` as a `T`.
fn parse<'r, T: Deserialize<'r>>(
    record: &'r csv::ByteRecord,
    headers: &'r csv::ByteRecord,
    path: &Path,
    at: usize,
) -> Result<T> {
    record
        .deserialize(Some(headers))
        .with_context(|| format!("{}: row {at}", path.display()))
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
    read_activations_of(path, None)
}

/// [`read_activations`], keeping only the rows of `only` (a method's label and a run)
/// where it is named: a finished run's dashboard reads its own rows of a folder's file.
/// Every value is finite, and at most [`MAX_VALUES_KEPT`] are kept.
pub(super) fn read_activations_of(path: &Path, only: Option<(&str, u32)>) -> Result<Activations> {
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
    let per_row = scores.len() + acted.len() + probabilities.len();
    let mut kept = 0;
    let mut record = csv::StringRecord::new();
    for i in 0.. {
        let at = || format!("{}: row {}", path.display(), i + 2);
        if !reader.read_record(&mut record).with_context(at)? {
            break;
        }
        let number = |column: usize| -> Result<f64> {
            let field = record.get(column).unwrap_or("");
            let value: f64 = field.parse().with_context(|| {
                format!("{}, column {}: {field:?} is not a number", at(), column + 1)
            })?;
            if !value.is_finite() {
                bail!("{}, column {}: {value} is not finite", at(), column + 1);
            }
            Ok(value)
        };
        let run = number(0)? as u32;
        let method = method_column
            .and_then(|c| record.get(c))
            .unwrap_or("sapnet");
        if only.is_some_and(|only| only != (method, run)) {
            continue;
        }
        check_kept(path, kept, per_row, i + 2)?;
        kept += per_row;
        let method = method.to_string();
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
