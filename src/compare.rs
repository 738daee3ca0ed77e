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

use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use crate::cli::CompareArgs;
use crate::config::Budget;
use crate::outside_runs::{self, results_folder, OutsideRun, PositionColumn, ReadOptions};
use crate::report::plots::{Curve, PlotData};
use crate::report::scored::{ScoredMethod, ScoredRun};
use crate::report::{self, sample_efficiency, step_axis, Report, TrainingEpisodes};
use crate::reuse::{MethodKind, Tested};

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

    let kinds = kinds(methods.len());
    let (budget, episodes) = alignment(args, &methods)?;
    let window = args.window as usize;
    let scored: Vec<ScoredMethod> = methods
        .iter()
        .zip(&kinds)
        .zip(&episodes)
        .map(|((m, &kind), episodes)| ScoredMethod {
            label: m.name.clone(),
            kind,
            runs: m
                .runs
                .iter()
                .zip(episodes)
                .map(|(r, episodes)| score(r, episodes, budget, window, last))
                .collect(),
        })
        .collect();
    let report = Report::of_scored(&task, range, last.get(), &scored);
    report.write(out)?;
    let data = PlotData {
        task: task.clone(),
        subject: None,
        return_range: Some(range),
        window,
        budget,
        curves: methods
            .iter()
            .zip(&kinds)
            .zip(episodes)
            .map(|((m, &kind), runs)| Curve {
                label: m.name.clone(),
                kind,
                runs,
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

/// How the runs are put side by side, and each method's runs as sapnet's own: by step up to
/// `--steps` or the steps every run reached, when every run says where its episodes ended
/// (and `--by-episode` does not ask otherwise); else by episode.
fn alignment(
    args: &CompareArgs,
    methods: &[Method],
) -> Result<(Budget, Vec<Vec<TrainingEpisodes>>)> {
    let by_step: Option<Vec<Vec<TrainingEpisodes>>> = methods
        .iter()
        .map(|m| m.runs.iter().map(training_episodes).collect())
        .collect();
    let most_episodes = methods
        .iter()
        .flat_map(|m| &m.runs)
        .map(|r| r.episodes.len())
        .max()
        .unwrap_or(1);
    let by_episode = || {
        let runs = methods
            .iter()
            .map(|m| {
                m.runs
                    .iter()
                    .map(|r| TrainingEpisodes {
                        returns: r.returns().collect(),
                        lengths: r
                            .episodes
                            .iter()
                            .map(|e| e.length.unwrap_or(0) as u32)
                            .collect(),
                    })
                    .collect()
            })
            .collect();
        (Budget::Episodes(most_episodes as u32), runs)
    };
    match (by_step, args.by_episode, args.steps) {
        (_, true, _) => Ok(by_episode()),
        (Some(runs), false, given) => {
            let reached = runs
                .iter()
                .flatten()
                .map(|r| r.ends().last().copied().unwrap_or(0))
                .min()
                .unwrap_or(0);
            match given.unwrap_or(reached) {
                0 => Ok(by_episode()),
                budget => Ok((Budget::Steps(budget), runs)),
            }
        }
        (None, false, Some(_)) => {
            let run = methods
                .iter()
                .flat_map(|m| &m.runs)
                .find(|r| training_episodes(r).is_none())
                .map_or_else(String::new, |r| r.path.display().to_string());
            bail!(
                "--steps: expected every run to say where its episodes ended (a step column, \
                 episode lengths, event files' steps); {run} gives neither"
            )
        }
        (None, false, None) => Ok(by_episode()),
    }
}

/// `run`'s episodes as sapnet's own are kept, each with its length in steps, when its
/// file places every episode by step (lengths are the steps between two ends) or
/// gives every length; `None` otherwise.
fn training_episodes(run: &OutsideRun) -> Option<TrainingEpisodes> {
    let lengths: Vec<u32> = match run.axis {
        outside_runs::Axis::Steps => {
            let mut previous = 0i64;
            run.episodes
                .iter()
                .map(|e| {
                    let length = e.at.saturating_sub(previous).max(0);
                    previous = previous.max(e.at);
                    u32::try_from(length).unwrap_or(u32::MAX)
                })
                .collect()
        }
        outside_runs::Axis::Episodes => run
            .episodes
            .iter()
            .map(|e| e.length.map(|l| u32::try_from(l).unwrap_or(u32::MAX)))
            .collect::<Option<_>>()?,
    };
    Some(TrainingEpisodes {
        returns: run.returns().collect(),
        lengths,
    })
}

/// What run `run` scored, read as `episodes` under `budget` (`window` the step curve's
/// moving average, `last` the episodes of the final score).
fn score(
    run: &OutsideRun,
    episodes: &TrainingEpisodes,
    budget: Budget,
    window: usize,
    last: NonZeroUsize,
) -> ScoredRun {
    match budget {
        Budget::Episodes(_) => ScoredRun {
            training_return: run.training_return(),
            final_score: run.final_score(last),
            episodes: run.episodes.len(),
            steps: run.steps(),
        },
        Budget::Steps(budget) => {
            let points = step_axis::points(budget, sample_efficiency::POINTS);
            let curve = step_axis::curve(episodes, window, &points);
            let ended = episodes.ends().partition_point(|&end| end <= budget);
            ScoredRun {
                // Every run has an episode ended by the steps every run reached.
                training_return: step_axis::area(&curve).unwrap_or(f64::NAN),
                final_score: step_axis::curve(episodes, last.get(), &[budget])[0]
                    .unwrap_or(f64::NAN),
                episodes: ended,
                steps: Some(budget),
            }
        }
    }
}

/// The longest method name: a legend's line.
const LONGEST_NAME: usize = 120;

/// Whether `name` may name a method: the characters of sapnet's own labels (a results
/// folder's are matched against it), none that a terminal or a plot would take otherwise.
fn is_method_name(name: &str) -> bool {
    (1..=LONGEST_NAME).contains(&name.len())
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "._-[],+".contains(c))
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
        method.runs.push(outside_runs::read_run(path, options)?);
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

/// Each method a family of its own, its hue a golden angle from the last: methods from
/// elsewhere are not variants of one another.
fn kinds(count: usize) -> Vec<MethodKind> {
    (0..count)
        .map(|i| MethodKind {
            family: "Outside",
            hue: ((i as f64 * 137.508 + 210.0) % 360.0) as u16,
            saturation: 65,
            reuses: false,
            tested: Tested::LastEpisodes,
            picks_by_probability: false,
            spreads: false,
        })
        .collect()
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
    use super::*;
    use crate::outside_runs::{Episode, Format};

    fn run(returns: &[f64]) -> OutsideRun {
        OutsideRun {
            path: "run.csv".into(),
            format: Format::Csv,
            series: "return".into(),
            axis: outside_runs::Axis::Episodes,
            episodes: returns
                .iter()
                .enumerate()
                .map(|(i, &r)| Episode {
                    at: i as i64 + 1,
                    episode_return: r,
                    length: None,
                })
                .collect(),
        }
    }

    #[test]
    fn episodes_placed_by_step_give_their_lengths() {
        let mut r = run(&[1.0, 2.0, 3.0]);
        assert_eq!(training_episodes(&r), None, "no lengths, no steps");
        r.axis = outside_runs::Axis::Steps;
        for (e, at) in r.episodes.iter_mut().zip([10, 30, 60]) {
            e.at = at;
        }
        let episodes = training_episodes(&r).unwrap();
        assert_eq!(episodes.lengths, [10, 20, 30]);
        assert_eq!(episodes.ends(), [10, 30, 60]);
        assert_eq!(r.steps(), Some(60));
    }
}
