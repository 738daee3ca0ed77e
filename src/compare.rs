//! `sapnet compare`: runs that already exist — Stable-Baselines3 monitor files, CSV exports
//! of CleanRL or openrlbenchmark, TensorBoard event files, sapnet results folders — put
//! through the report a protocol writes: each method's training return and final score
//! with their 95% intervals, every pair by the separation rule, the sample-efficiency
//! curves and the plots (issue 38, item 4).
//!
//! Runs are put side by side **by environment step** whenever every run's file says where
//! its episodes ended (a monitor file's lengths, a step column, an event file's steps, a
//! results folder's episode lengths), up to `--steps N` or else the steps every run
//! reached: methods that finish episodes at different rates are read on the same
//! experience, as sapnet scores a step-budget protocol ([`crate::report::step_axis`]). A
//! run's **training return** is then its step curve's area, its **final score** the mean
//! of its last `--last` episodes ended by the budget. Without steps for every run (or with
//! `--by-episode`) they are put side by side by episode: the training return is the mean
//! return of all a run's episodes, the final score the mean of its last `--last`; runs of
//! unequal length are each scored over their own episodes. Either way the final score
//! stands in the report's `test` columns (`tested` = `last-episodes`). The bounds that
//! normalise scores (the optimality gap, the profiles) are fixed by `--range`, else taken
//! from the results folders' task, else from the data, with a warning: then adding a run
//! can move every normalised score.
//!
//! Beside the report, the folder records the runs as read and how they were scored
//! ([`compare_folder`]): `sapnet open` shows the comparison from those, through the same
//! scoring ([`scored::compare_report`]), wherever the runs' own files have gone.

use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use crate::cli::CompareArgs;
use crate::config::Budget;
use crate::outside_runs::compare_folder::{self, is_method_name, Scoring, LONGEST_NAME};
use crate::outside_runs::{self, results_folder, OutsideRun, PositionColumn, ReadOptions};
use crate::report::plots::{Curve, PlotData};
use crate::report::scored::{self, RunEpisodes, ScoredMethod};
use crate::report::{self, Report, TrainingEpisodes};

/// One `--method`: its name and the runs read for it.
struct Method {
    name: String,
    runs: Vec<OutsideRun>,
    /// The task of each results folder its runs came from (its return range and name).
    tasks: Vec<(String, (f64, f64))>,
}

/// Reads every method's runs, writes the report into `--out` and returns it.
pub fn compare(args: &CompareArgs) -> Result<Report> {
    let last = NonZeroUsize::new(args.last).context("--last: expected at least 1 episode")?;
    let options = read_options(args);
    let mut methods: Vec<Method> = Vec::new();
    for given in &args.methods {
        let (name, paths) = parse_method(given)?;
        let index = match methods.iter().position(|m| m.name == name) {
            Some(index) => index,
            None => {
                methods.push(Method {
                    name: name.clone(),
                    runs: Vec::new(),
                    tasks: Vec::new(),
                });
                methods.len() - 1
            }
        };
        for path in paths {
            read_path(&mut methods[index], &path, &options)?;
        }
    }
    if methods.len() < 2 {
        bail!("--method: expected at least two methods to compare (each `--method NAME=PATH`)");
    }
    if methods.len() > crate::limits::MAX_METHODS {
        bail!(
            "--method: {} methods, more than the {} a comparison sets side by side (every \
             pair is bootstrapped)",
            methods.len(),
            crate::limits::MAX_METHODS
        );
    }
    let (task, range) = task_and_range(args, &methods)?;
    let out = &args.out;
    match std::fs::metadata(out) {
        Ok(m) if !m.is_dir() => bail!(
            "--out {}: a file is there, expected a new or empty directory (the report is \
             several files)",
            out.display()
        ),
        Ok(_) => {
            let mut entries =
                std::fs::read_dir(out).with_context(|| format!("--out {}", out.display()))?;
            if entries.next().is_some() {
                bail!("--out {}: expected a new or empty directory", out.display());
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(e).with_context(|| format!("--out {}", out.display())),
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;

    let budget = alignment(args, &methods)?;
    let scoring = Scoring {
        task: task.clone(),
        range,
        alignment: scored::alignment(budget),
        window: args.window as usize,
        last,
    };
    let runs: Vec<(&str, &[OutsideRun])> = methods
        .iter()
        .map(|m| (m.name.as_str(), m.runs.as_slice()))
        .collect();
    let episodes: Vec<(&str, Vec<RunEpisodes>)> = runs
        .iter()
        .map(|&(name, runs)| (name, runs.iter().map(RunEpisodes::of).collect()))
        .collect();
    let (scored, report) = scored::compare_report(&scoring, &episodes);
    report.write(out)?;
    // What `sapnet open` scores the runs again from, the files they came from aside.
    compare_folder::write(out, &scoring, &runs)?;
    // The plots take the runs' episodes, which are not copied: what is left of each run
    // is where it came from, for runs.csv.
    let data = PlotData {
        task: task.clone(),
        subject: None,
        return_range: Some(range),
        window: scoring.window,
        budget,
        curves: methods
            .iter_mut()
            .zip(&scored)
            .map(|(m, scored)| Curve {
                label: m.name.clone(),
                kind: scored.kind,
                runs: m
                    .runs
                    .iter_mut()
                    .map(|r| std::mem::take(&mut r.episodes))
                    .collect(),
                tests: Vec::new(),
            })
            .collect(),
        policy_names: Vec::new(),
        activations: Vec::new(),
        acted: Vec::new(),
    };
    report::write_plots(out, &data)?;
    write_runs(&out.join("runs.csv"), &methods, &scored)?;
    Ok(report)
}

/// How the runs are put side by side: by step up to `--steps` or the steps every run
/// reached, when every run says where its episodes ended (and `--by-episode` does not ask
/// otherwise); else by episode.
fn alignment(args: &CompareArgs, methods: &[Method]) -> Result<Budget> {
    let runs = || methods.iter().flat_map(|m| &m.runs);
    let by_step = runs().all(|r| r.placed().is_some());
    let most_episodes = runs().map(|r| r.episodes.len()).max().unwrap_or(1);
    let by_episode = Budget::Episodes(most_episodes as u32);
    match (by_step, args.by_episode, args.steps) {
        (_, true, _) => Ok(by_episode),
        (true, false, given) => {
            let reached = runs()
                .filter_map(OutsideRun::placed)
                .map(TrainingEpisodes::steps)
                .min()
                .unwrap_or(0);
            let budget = match given.unwrap_or(reached) {
                0 => return Ok(by_episode),
                budget => budget,
            };
            let named = methods.iter().map(|m| (m.name.as_str(), m.runs.as_slice()));
            if let Some((name, r, first)) = compare_folder::unended_by(named, budget) {
                let chosen = match given {
                    Some(_) => format!("--steps {budget}"),
                    None => format!("the steps every run reached ({budget})"),
                };
                bail!(
                    "{chosen}: {name} run {r}'s first episode ends at step {first}, later: a \
                     run scored by step needs an episode ended by then (give --steps N of at \
                     least {first}, or --by-episode)"
                );
            }
            Ok(Budget::Steps(budget))
        }
        (false, false, Some(_)) => {
            let run = runs()
                .find(|r| r.placed().is_none())
                .map_or_else(String::new, |r| r.path.display().to_string());
            bail!(
                "--steps: expected every run to say where its episodes ended (a step column, \
                 episode lengths, event files' steps); {run} gives neither"
            )
        }
        (false, false, None) => Ok(by_episode),
    }
}

/// `NAME=PATH[,PATH…]`: the method's name and its paths.
fn parse_method(given: &str) -> Result<(String, Vec<PathBuf>)> {
    let Some((name, paths)) = given.split_once('=') else {
        bail!("--method {given:?}: expected NAME=PATH[,PATH…]");
    };
    if !is_method_name(name) {
        bail!(
            "--method {given:?}: expected NAME=PATH[,PATH…] with NAME of 1 to {LONGEST_NAME} \
             ASCII letters, digits and `._-[],+` (as sapnet's own labels: `dqn[100,100]`)"
        );
    }
    let paths: Vec<PathBuf> = paths
        .split(',')
        .filter(|p| !p.is_empty())
        .map(PathBuf::from)
        .collect();
    if paths.is_empty() {
        bail!("--method {given:?}: expected at least one PATH after `{name}=`");
    }
    Ok((name.to_string(), paths))
}

/// A run's file, or a folder of event files (one run), or a results folder: the runs of
/// the method named as this one, or of `LABEL` for `DIR#LABEL`.
fn read_path(method: &mut Method, path: &Path, options: &ReadOptions) -> Result<()> {
    let text = path.to_string_lossy();
    let (dir, label) = match text.rsplit_once('#') {
        Some((dir, label)) if results_folder::is_results_folder(Path::new(dir)) => {
            (PathBuf::from(dir), label.to_string())
        }
        _ => (path.to_path_buf(), method.name.clone()),
    };
    if results_folder::is_results_folder(&dir) {
        let header = crate::results::read_header(&dir)?;
        let env = &header.config.env;
        method.tasks.push((env.gym_id(), env.return_range()));
        method
            .runs
            .extend(results_folder::read_method(&dir, &label)?);
    } else {
        method.runs.extend(outside_runs::read_runs(path, options)?);
    }
    Ok(())
}

fn read_options(args: &CompareArgs) -> ReadOptions {
    ReadOptions {
        return_column: args.return_column.clone(),
        position_column: match (&args.step_column, &args.episode_column) {
            (Some(step), _) => Some(PositionColumn::Step(step.clone())),
            (None, Some(episode)) => Some(PositionColumn::Episode(episode.clone())),
            (None, None) => None,
        },
        length_column: args.length_column.clone(),
        tag: args.tag.clone(),
        rollout_mean: args.rollout_mean,
    }
}

/// The task's name and the bounds that normalise its returns: `--task` and `--range` when
/// given, else the results folders' own when every run came from folders of one task, else
/// `runs` and the lowest and highest return read, said in a warning.
fn task_and_range(args: &CompareArgs, methods: &[Method]) -> Result<(String, (f64, f64))> {
    let folders: Vec<&(String, (f64, f64))> = methods.iter().flat_map(|m| &m.tasks).collect();
    let every_run_from_a_folder = methods
        .iter()
        .flat_map(|m| &m.runs)
        .all(|r| r.format == outside_runs::Format::ResultsFolder);
    let from_folders =
        every_run_from_a_folder && !folders.is_empty() && folders.windows(2).all(|w| w[0] == w[1]);
    let folder_task = from_folders.then(|| folders[0].clone());
    let task = args
        .task
        .clone()
        .or_else(|| folder_task.as_ref().map(|(t, _)| t.clone()))
        .unwrap_or_else(|| "runs".to_string());
    let range = match (&args.range, &folder_task) {
        (Some(range), _) => (range[0], range[1]),
        (None, Some((_, range))) => *range,
        (None, None) => {
            let returns = methods
                .iter()
                .flat_map(|m| &m.runs)
                .flat_map(|r| r.returns());
            let (lo, hi) = returns.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            });
            eprintln!(
                "warning: no --range: scores are normalised by the lowest and highest return \
                 read ({lo} to {hi}), so adding a run can move every normalised score (the \
                 optimality gap, the profiles); fix the bounds with --range LO HI"
            );
            (lo, hi)
        }
    };
    if !(range.0.is_finite() && range.1.is_finite() && range.0 < range.1) {
        bail!(
            "--range {} {}: expected two finite returns, the lowest below the highest",
            range.0,
            range.1
        );
    }
    Ok((task, range))
}

/// `runs.csv`: where each run came from and what it scored (as the report does: on the step
/// axis when the runs were aligned by step), one row per run.
fn write_runs(path: &Path, methods: &[Method], scored: &[ScoredMethod]) -> Result<()> {
    let header: Vec<String> = [
        "method", "run", "path", "format", "series", "axis", "episodes", "steps", "return", "final",
    ]
    .map(String::from)
    .to_vec();
    let records: Vec<Vec<String>> = methods
        .iter()
        .zip(scored)
        .flat_map(|(m, scored)| {
            m.runs
                .iter()
                .zip(&scored.runs)
                .enumerate()
                .map(move |(r, (run, score))| {
                    vec![
                        m.name.clone(),
                        r.to_string(),
                        run.path.to_string_lossy().into_owned(),
                        format!("{:?}", run.format),
                        run.series.clone(),
                        format!("{:?}", run.axis),
                        score.episodes.to_string(),
                        score.steps.map_or(String::new(), |s| s.to_string()),
                        format!("{:?}", score.training_return),
                        format!("{:?}", score.final_score),
                    ]
                })
        })
        .collect();
    report::write_rows(path, &header, &records)
}

#[cfg(test)]
mod tests {
    use crate::outside_runs::{Axis, Format, Gathered};

    #[test]
    fn episodes_placed_by_step_give_their_lengths() {
        let mut by_episode = Gathered::new(Axis::Episodes);
        let mut by_step = Gathered::new(Axis::Steps);
        for (at, r) in [(10, 1.0), (30, 2.0), (60, 3.0)] {
            by_episode.push(at, r, None);
            by_step.push(at, r, None);
        }
        let r = by_episode.into_run("run.csv".as_ref(), Format::Csv, "return".into());
        assert_eq!(r.placed(), None, "no lengths, no steps");
        assert_eq!(r.steps(), None);
        let r = by_step.into_run("run.csv".as_ref(), Format::Csv, "return".into());
        let episodes = r.placed().unwrap();
        assert_eq!(episodes.lengths, [10, 20, 30]);
        assert_eq!(episodes.ends(), [10, 30, 60]);
        assert_eq!(r.steps(), Some(60));
    }

    #[test]
    fn a_step_behind_the_furthest_is_a_length_of_0_and_a_gap_past_u32_is_cut() {
        let mut by_step = Gathered::new(Axis::Steps);
        for (at, r) in [(50, 1.0), (20, 2.0), (70, 3.0), (70 + (1 << 33), 4.0)] {
            by_step.push(at, r, None);
        }
        let r = by_step.into_run("run.csv".as_ref(), Format::Csv, "return".into());
        assert_eq!(r.episodes.lengths, [50, 0, 20, u32::MAX]);
        assert_eq!(r.steps(), Some(70 + (1 << 33)));
        // Lengths given on the episode axis: their sum, each cut at u32::MAX.
        let mut by_episode = Gathered::new(Axis::Episodes);
        by_episode.push(1, 1.0, Some(5));
        by_episode.push(2, 1.0, Some(1 << 40));
        let r = by_episode.into_run("run.csv".as_ref(), Format::Csv, "return".into());
        assert_eq!(r.placed().unwrap().lengths, [5, u32::MAX]);
        assert_eq!(r.steps(), Some(5 + (1 << 40)));
    }
}
