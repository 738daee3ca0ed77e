//! A `sapnet compare` folder's own record of the runs it compared, so that `sapnet open`
//! scores them again from the folder alone: the files the runs came from (`runs.csv`
//! names them) may be elsewhere, gone, or — in a folder received — anywhere, and are
//! never followed. Two files beside the report:
//!
//! - [`EPISODES`], `run_episodes.csv`: `method,run,episode,return,step`, one row per
//!   episode of every run as compare read it, in [`SCORING`]'s order of runs. The return
//!   is written so that it reads back to the same number; the step is where the episode
//!   ended as sapnet placed it (the sum of the episodes' lengths so far), empty for every
//!   episode of a run whose file does not give each one's length.
//! - [`SCORING`], `compare.json`: how the runs were scored ([`Scoring`]: the task, the
//!   range, what they were put side by side by and how far, the window, `--last`) and each
//!   run with its episodes and the steps its file said it took, which no sum of lengths
//!   gives back (a file's steps may go back, or a length pass `u32::MAX`).
//!
//! Both are read as any folder from elsewhere is: regular files only, no link followed,
//! bounded in size and rows, every field checked, a bad one refused naming the file, the
//! line or field and what was expected.

use std::num::NonZeroUsize;
use std::path::Path;

use anyhow::{bail, ensure, Context, Result};
use serde::{Deserialize, Serialize};

use super::table::{Comments, Table};
use super::{Axis, Format, Gathered, OutsideRun};
use crate::limits;
use crate::safe_io::{self, Links};

/// Each run's episodes, one row each.
pub const EPISODES: &str = "run_episodes.csv";

/// How the runs were scored, and each run's episodes and steps.
pub const SCORING: &str = "compare.json";

/// The version of [`SCORING`]'s format this sapnet writes and reads.
const VERSION: u32 = 1;

/// The largest [`SCORING`] read: a run is a line of about 80 bytes.
const MAX_SCORING_BYTES: u64 = 16 << 20;

/// The longest task name read back (compare takes any `--task`; titles cut it).
const LONGEST_TASK: usize = 1_000;

/// The longest method name: a legend's line.
pub const LONGEST_NAME: usize = 120;

/// Whether `name` may name a method: the characters of sapnet's own labels (a results
/// folder's are matched against it), none that a terminal, a plot or a CSV cell would
/// take otherwise.
pub fn is_method_name(name: &str) -> bool {
    (1..=LONGEST_NAME).contains(&name.len())
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "._-[],+".contains(c))
}

/// What the runs were put side by side by, and how far.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Alignment {
    /// By environment step, up to this step.
    Steps(u64),
    /// By episode, up to the most episodes a run has.
    Episodes(u64),
}

/// How compare scored its runs: what the report is made again from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scoring {
    /// The task's name, as the report's files give it.
    pub task: String,
    /// The lowest and highest return, which normalise the scores.
    pub range: (f64, f64),
    pub alignment: Alignment,
    /// The step curves' moving average, in episodes.
    pub window: usize,
    /// The episodes a run's final score is the mean of.
    pub last: NonZeroUsize,
}

/// A run as [`SCORING`] lists it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ListedRun {
    method: String,
    /// Its place among its method's runs, from 0.
    run: u32,
    episodes: usize,
    /// The environment steps its file said it took; `null` where the file gives no steps.
    steps: Option<u64>,
}

/// [`SCORING`] as written.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ScoringFile {
    version: u32,
    scoring: Scoring,
    runs: Vec<ListedRun>,
}

/// A compare folder's runs read back, and how they were scored.
#[derive(Debug)]
pub struct Recorded {
    pub scoring: Scoring,
    /// Each method's name and runs, in compare's order.
    pub methods: Vec<(String, Vec<OutsideRun>)>,
}

/// Records `methods`' runs and `scoring` in `dir`, each file written atomically, the
/// episodes row by row: a run of millions of episodes costs no more memory than its
/// numbers already do.
pub fn write(dir: &Path, scoring: &Scoring, methods: &[(&str, &[OutsideRun])]) -> Result<()> {
    let path = dir.join(EPISODES);
    safe_io::write_atomically(&path, |out| {
        let mut csv = csv::Writer::from_writer(out);
        csv.write_record(["method", "run", "episode", "return", "step"])?;
        for (name, runs) in methods {
            for (r, run) in runs.iter().enumerate() {
                let placed = run.placed();
                let mut end = 0u64;
                for (e, episode_return) in run.returns().enumerate() {
                    let step = match placed {
                        Some(p) => {
                            end += u64::from(p.lengths[e]);
                            end.to_string()
                        }
                        None => String::new(),
                    };
                    csv.write_record([
                        *name,
                        &r.to_string(),
                        &(e + 1).to_string(),
                        // Debug prints the shortest text that reads back to the same f64.
                        &format!("{episode_return:?}"),
                        &step,
                    ])?;
                }
            }
        }
        csv.flush()
    })
    .with_context(|| format!("writing {}", path.display()))?;
    let runs = methods
        .iter()
        .flat_map(|(name, runs)| {
            runs.iter().enumerate().map(move |(r, run)| ListedRun {
                method: name.to_string(),
                run: r as u32,
                episodes: run.episodes.len(),
                steps: run.steps(),
            })
        })
        .collect();
    let file = ScoringFile {
        version: VERSION,
        scoring: scoring.clone(),
        runs,
    };
    let path = dir.join(SCORING);
    let text = serde_json::to_string_pretty(&file).context("writing compare.json")?;
    safe_io::write_bytes(&path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}

/// The first run of `methods` none of whose episodes ended by step `step` — its method,
/// its place, the step its first episode ended at —: set side by side by step to there it
/// would have no score.
pub fn unended_by<'a>(
    methods: impl IntoIterator<Item = (&'a str, &'a [OutsideRun])>,
    step: u64,
) -> Option<(&'a str, usize, u64)> {
    methods.into_iter().find_map(|(name, runs)| {
        runs.iter().enumerate().find_map(|(r, run)| {
            let first = u64::from(*run.episodes.lengths.first()?);
            (first > step).then_some((name, r, first))
        })
    })
}

/// Whether `dir` holds the record [`write()`] makes: compare folders written before it did
/// hold only their report.
pub fn is_recorded(dir: &Path) -> bool {
    std::fs::symlink_metadata(dir.join(SCORING)).is_ok()
}

/// The runs recorded in `dir` and how they were scored, every field checked.
pub fn read(dir: &Path) -> Result<Recorded> {
    let path = dir.join(SCORING);
    let text = safe_io::read_text(&path, Links::Refuse, MAX_SCORING_BYTES)
        .with_context(|| format!("reading {}", path.display()))?;
    let mut de = serde_json::Deserializer::from_str(&text);
    let file: ScoringFile = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        anyhow::anyhow!(
            "{}: {}: {}",
            path.display(),
            e.path(),
            crate::shown_text::cut(&e.inner().to_string(), 200)
        )
    })?;
    check(&path, &file)?;
    let methods = read_episodes(&dir.join(EPISODES), &file)?;
    if let Alignment::Steps(budget) = file.scoring.alignment {
        for (name, runs) in &methods {
            if let Some(r) = runs.iter().position(|run| run.placed().is_none()) {
                bail!(
                    "{}: {name} run {r} has no steps, but compare.json's alignment is by \
                     step: every run must give its episodes' steps",
                    dir.join(EPISODES).display()
                );
            }
        }
        let runs = methods
            .iter()
            .map(|(n, runs)| (n.as_str(), runs.as_slice()));
        if let Some((name, r, first)) = unended_by(runs, budget) {
            bail!(
                "{}: scoring.alignment.steps: {budget} comes before {name} run {r}'s first \
                 episode ends (step {first}): expected a step every run has an episode ended by",
                path.display()
            );
        }
    }
    Ok(Recorded {
        scoring: file.scoring,
        methods,
    })
}

/// Refuses a [`SCORING`] whose fields are out of their bounds, naming the field.
fn check(path: &Path, file: &ScoringFile) -> Result<()> {
    let at = path.display();
    ensure!(
        file.version == VERSION,
        "{at}: version: {} is not {VERSION}, the version this sapnet reads",
        file.version
    );
    let scoring = &file.scoring;
    ensure!(
        scoring.task.len() <= LONGEST_TASK,
        "{at}: scoring.task: expected at most {LONGEST_TASK} bytes"
    );
    let (lo, hi) = scoring.range;
    ensure!(
        lo.is_finite() && hi.is_finite() && lo < hi,
        "{at}: scoring.range: expected two finite returns, the lowest below the highest"
    );
    match scoring.alignment {
        Alignment::Steps(n) => ensure!(
            (1..=limits::MAX_STEPS).contains(&n),
            "{at}: scoring.alignment.steps: expected 1 to {} steps",
            limits::MAX_STEPS
        ),
        Alignment::Episodes(n) => ensure!(
            (1..=u64::from(limits::MAX_EPISODES)).contains(&n),
            "{at}: scoring.alignment.episodes: expected 1 to {} episodes",
            limits::MAX_EPISODES
        ),
    }
    ensure!(
        (1..=limits::MAX_EPISODES as usize).contains(&scoring.window),
        "{at}: scoring.window: expected 1 to {} episodes",
        limits::MAX_EPISODES
    );
    ensure!(
        scoring.last.get() <= limits::MAX_VALUES_KEPT,
        "{at}: scoring.last: expected at most {} episodes",
        limits::MAX_VALUES_KEPT
    );
    let mut methods: Vec<&str> = Vec::new();
    let mut episodes = 0usize;
    for (i, run) in file.runs.iter().enumerate() {
        let field = format!("{at}: runs[{i}]");
        ensure!(
            is_method_name(&run.method),
            "{field}.method: expected 1 to {LONGEST_NAME} ASCII letters, digits and `._-[],+`"
        );
        let new = methods.last() != Some(&run.method.as_str());
        if new {
            ensure!(
                !methods.contains(&run.method.as_str()),
                "{field}.method: {} again after other methods: a method's runs are listed \
                 together",
                run.method
            );
            methods.push(&run.method);
        }
        let expected = if new { 0 } else { file.runs[i - 1].run + 1 };
        ensure!(
            run.run == expected,
            "{field}.run: expected {expected}, {}'s runs being listed from 0 in order",
            run.method
        );
        ensure!(
            run.run < limits::MAX_RUNS,
            "{field}.run: a method may have at most {} runs",
            limits::MAX_RUNS
        );
        ensure!(
            run.episodes >= 1,
            "{field}.episodes: expected at least 1 episode"
        );
        ensure!(
            run.steps.is_none_or(|s| s <= limits::MAX_STEPS),
            "{field}.steps: expected at most {} steps",
            limits::MAX_STEPS
        );
        episodes = episodes.saturating_add(run.episodes);
    }
    ensure!(
        (2..=limits::MAX_METHODS).contains(&methods.len()),
        "{at}: runs: expected the runs of 2 to {} methods, found {}",
        limits::MAX_METHODS,
        methods.len()
    );
    ensure!(
        episodes <= limits::MAX_VALUES_KEPT,
        "{at}: runs: {episodes} episodes in all, more than the {} sapnet reads from one file",
        limits::MAX_VALUES_KEPT
    );
    Ok(())
}

/// [`EPISODES`] at `path`, read run by run in the order `file` lists them: each row its
/// run's next episode, none missing, none more.
fn read_episodes(path: &Path, file: &ScoringFile) -> Result<Vec<(String, Vec<OutsideRun>)>> {
    let at = path.display();
    let csv = safe_io::open_csv(path).with_context(|| format!("reading {at}"))?;
    let total: usize = file.runs.iter().map(|r| r.episodes).sum();
    let mut table =
        Table::read(csv, path, Comments::Data)?.at_most(total, "episodes compare.json lists");
    let [method, run_column, episode, return_column, step] =
        ["method", "run", "episode", "return", "step"].map(|name| table.column(&[name]));
    let (method, run_column, episode, return_column, step) =
        (method?, run_column?, episode?, return_column?, step?);
    let mut methods: Vec<(String, Vec<OutsideRun>)> = Vec::new();
    for listed in &file.runs {
        let mut gathered: Option<Gathered> = None;
        let mut last_end = 0i64;
        for e in 1..=listed.episodes {
            let Some(row) = table.next_row() else {
                bail!(
                    "{at}: ends before {} run {}'s episode {e} of the {} compare.json lists",
                    listed.method,
                    listed.run,
                    listed.episodes
                );
            };
            let row = row?;
            let line = row.line();
            let found = (
                table.cell(&row, method).text(),
                table.cell(&row, run_column).whole()?,
                table.cell(&row, episode).whole()?,
            );
            if found != (listed.method.as_str(), i64::from(listed.run), e as i64) {
                bail!(
                    "{at}: line {line}: expected {} run {} episode {e} (compare.json's order), \
                     found {} run {} episode {}",
                    listed.method,
                    listed.run,
                    crate::shown_text::cut(found.0, 60),
                    found.1,
                    found.2
                );
            }
            let episode_return = table.cell(&row, return_column).episode_return()?;
            let step_cell = table.cell(&row, step);
            let end = (!step_cell.is_empty())
                .then(|| step_cell.length())
                .transpose()?;
            let gathered = gathered.get_or_insert_with(|| {
                Gathered::new(if end.is_some() {
                    Axis::Steps
                } else {
                    Axis::Episodes
                })
            });
            match (gathered.axis, end) {
                (Axis::Episodes, None) => gathered.push(e as i64, episode_return, None),
                (Axis::Steps, Some(end)) => {
                    let end = i64::try_from(end).ok().filter(|&s| {
                        s >= last_end
                            && s - last_end <= i64::from(u32::MAX)
                            && s as u64 <= limits::MAX_STEPS
                    });
                    let Some(end) = end else {
                        bail!(
                            "{at}: line {line}, column {} (step): expected a step from \
                             {last_end} (the episode before's) to {} more, at most {}",
                            step + 1,
                            u32::MAX,
                            limits::MAX_STEPS
                        );
                    };
                    last_end = end;
                    gathered.push(end, episode_return, None);
                }
                _ => bail!(
                    "{at}: line {line}, column {} (step): expected every episode of {} run {} \
                     to give its step, or none",
                    step + 1,
                    listed.method,
                    listed.run
                ),
            }
        }
        let mut run = gathered.expect("a listed run has an episode").into_run(
            path,
            Format::Csv,
            "return".to_string(),
        );
        if run.lengths_known != listed.steps.is_some() {
            bail!(
                "{}: {} run {}: steps {}, but {EPISODES} gives {} steps",
                path.with_file_name(SCORING).display(),
                listed.method,
                listed.run,
                listed.steps.map_or("null".to_string(), |s| s.to_string()),
                if run.lengths_known { "its" } else { "no" }
            );
        }
        run.steps = listed.steps;
        match methods.last_mut() {
            Some((name, runs)) if *name == listed.method => runs.push(run),
            _ => methods.push((listed.method.clone(), vec![run])),
        }
    }
    if let Some(row) = table.next_row() {
        let line = row?.line();
        bail!("{at}: line {line}: a row past the runs compare.json lists");
    }
    Ok(methods)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(at: &[(i64, f64)], axis: Axis) -> OutsideRun {
        let mut gathered = Gathered::new(axis);
        for &(at, r) in at {
            gathered.push(at, r, None);
        }
        gathered.into_run("x.csv".as_ref(), Format::Csv, "r".into())
    }

    fn scoring() -> Scoring {
        Scoring {
            task: "CartPole-v1".into(),
            range: (0.0, 500.0),
            alignment: Alignment::Episodes(3),
            window: 10,
            last: NonZeroUsize::new(2).unwrap(),
        }
    }

    #[test]
    fn runs_read_back_as_they_were_written() {
        let dir = tempfile::tempdir().unwrap();
        // Steps that go back: the run's steps are its last row's, not the sum of lengths.
        let a = [
            run(&[(10, 0.1), (30, 1.0 / 3.0), (20, 2.5)], Axis::Steps),
            run(&[(5, -1e-300)], Axis::Steps),
        ];
        let b = [run(&[(1, 7.0), (2, 8.0), (3, 9.0)], Axis::Episodes)];
        write(dir.path(), &scoring(), &[("a", &a), ("b[2]", &b)]).unwrap();
        let text = std::fs::read_to_string(dir.path().join(EPISODES)).unwrap();
        assert!(
            text.starts_with("method,run,episode,return,step\na,0,1,0.1,10\n"),
            "{text}"
        );
        assert!(
            text.contains("a,0,3,2.5,30\n") && text.contains("b[2],0,3,9.0,\n"),
            "{text}"
        );
        let read = read(dir.path()).unwrap();
        assert_eq!(read.scoring, scoring());
        let names: Vec<&str> = read.methods.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["a", "b[2]"]);
        for (written, (_, runs)) in [&a[..], &b[..]].into_iter().zip(&read.methods) {
            for (w, r) in written.iter().zip(runs) {
                assert_eq!(w.episodes, r.episodes);
                assert_eq!((w.lengths_known, w.steps()), (r.lengths_known, r.steps()));
            }
        }
        assert_eq!(read.methods[0].1[0].steps(), Some(20));
    }

    #[test]
    fn a_step_before_a_runs_first_episode_ends_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let a = [run(&[(10, 1.0), (20, 2.0)], Axis::Steps)];
        let b = [run(&[(4, 1.0), (30, 2.0)], Axis::Steps)];
        let scoring = Scoring {
            alignment: Alignment::Steps(5),
            ..scoring()
        };
        write(dir.path(), &scoring, &[("a", &a), ("b", &b)]).unwrap();
        let error = format!("{:#}", read(dir.path()).unwrap_err());
        assert!(
            error.contains("compare.json: scoring.alignment.steps: 5 comes before a run 0's")
                && error.contains("(step 10)"),
            "{error}"
        );
    }

    #[test]
    fn a_bad_field_is_refused_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let a = [run(&[(1, 1.0)], Axis::Episodes)];
        write(dir.path(), &scoring(), &[("a", &a), ("b", &a)]).unwrap();
        let json = dir.path().join(SCORING);
        let good: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let bad: [(&str, serde_json::Value, &str); 6] = [
            ("/scoring/last", 0.into(), "scoring.last"),
            ("/scoring/window", (-1).into(), "scoring.window"),
            ("/scoring/range/1", (-500.0).into(), "scoring.range"),
            ("/runs/1/run", 1.into(), "runs[1].run"),
            ("/runs/1/method", "a\u{1b}".into(), "runs[1].method"),
            ("/version", 2.into(), "version"),
        ];
        for (pointer, value, said) in bad {
            let mut doctored = good.clone();
            *doctored.pointer_mut(pointer).unwrap() = value;
            std::fs::write(&json, doctored.to_string()).unwrap();
            let error = format!("{:#}", read(dir.path()).unwrap_err());
            assert!(
                error.contains(said) && error.contains("compare.json"),
                "{said}: {error}"
            );
        }
    }
}
