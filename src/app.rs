//! Dispatches a parsed command line to the part of the crate that does the work.

use std::io::Write;
use std::path::Path;
use std::sync::mpsc;

use anyhow::{Context, Result};

use crate::cli::{Cli, Command, EnvArgs, SourcesArgs, SourcesCommand, SweepCommand, TeachArgs};
use crate::config::{Budget, Config};
use crate::experiment;
use crate::experiment::{OutputOptions, RunOptions};
use crate::headless;
use crate::results;
use crate::ron_file::{parse_ron, ConfigError};
use crate::teach::lesson::TeachConfig;
use crate::teach::Teach;
use crate::tui;
use crate::{assets, env, env_command, trainer};

pub fn run(cli: Cli) -> Result<()> {
    if let Some(command) = &cli.command {
        refuse_unread_flags(&cli, command)?;
    }
    refuse_non_utf8_paths(&cli)?;
    match &cli.command {
        Some(Command::Env(args)) => run_env(&cli, args),
        Some(Command::Teach(args)) => run_teach(&cli, args),
        Some(Command::Sources(args)) => run_sources(&cli, args),
        Some(Command::Sweep(args)) => run_sweep(&cli, &args.command),
        Some(Command::Pool(args)) => {
            let report = results::pool::pool(&args.dirs, &args.out)?;
            eprintln!(
                "pooled {} tasks into {}: comparison.csv, improvement.csv, scores.csv, intervals.png, profiles.png, improvement.png",
                report.tasks.len(),
                args.out.display()
            );
            if !report.left_out.is_empty() {
                eprintln!(
                    "left out, not run on every task: {}",
                    report.left_out.join(", ")
                );
            }
            print_stdout(&report.table())
        }
        Some(Command::Compare(args)) => {
            let report = crate::compare::compare(args)?;
            eprintln!(
                "compared {0} methods into {1}: comparison.csv, improvement.csv, scores.csv, runs.csv, sample_efficiency.csv and the plots, with run_episodes.csv and compare.json (what `sapnet open {1}` shows them from); `test` is each run's final score, the mean return of its last {2} episodes",
                report.comparison.len(),
                args.out.display(),
                args.last
            );
            print_stdout(&report.table())
        }
        Some(Command::Open(args)) => {
            // SIGINT, SIGTERM or SIGHUP leave as `q` does, the terminal restored.
            let _stop = crate::signals::stop_on_signals()?;
            // `R` resumes a stopped folder where it is shown, as `sapnet --resume` would.
            let load = |path: &Path| load_picked(&cli, path);
            let settings = session_settings(&cli, &load, Vec::new());
            // A results folder opens in the workbench's views, a sweep folder in the Sweep
            // view, a compare folder in its Comparison and Curves, any other lists the
            // folders sapnet wrote under it.
            match results::found::kind(&args.dir) {
                Some(results::found::Kind::Protocol) => {
                    print_ended(tui::workbench::screens::opened::run(&args.dir, &settings)?)
                }
                Some(results::found::Kind::Sweep) => tui::workbench::screens::sweep::run(&args.dir),
                Some(results::found::Kind::Compare) => {
                    tui::workbench::screens::compared::run(&args.dir)
                }
                None => print_ended(tui::workbench::screens::folders::run(&args.dir, &settings)?),
            }
        }
        Some(Command::Plot(args)) => {
            let summary = results::replot(&args.dir)?;
            eprintln!(
                "{} made again: comparison.csv, improvement.csv, scores.csv, sample_efficiency.csv, summary.json and the plots of what the folder holds (activations.png and selections.png only from an activations.csv)",
                args.dir.display()
            );
            headless::print_comparison(&summary)
        }
        None => run_experiment(&cli),
    }
}

/// Paths that results record (in summary.json, run.json and policy metadata, which are
/// text) must be text: a `--library` or `--out` that is not UTF-8 is refused before any
/// run trains, not after, when the first record is written.
fn refuse_non_utf8_paths(cli: &Cli) -> Result<()> {
    let mut paths: Vec<(&str, &Path)> = Vec::new();
    if let Some(library) = &cli.run.library {
        paths.push(("--library", library));
    }
    if let Some(out) = &cli.run.out {
        paths.push(("--out", out));
    }
    match &cli.command {
        Some(Command::Pool(args)) => paths.push(("--out", &args.out)),
        Some(Command::Compare(args)) => paths.push(("--out", &args.out)),
        Some(Command::Sweep(args)) => {
            if let SweepCommand::Plan { out, .. } = &args.command {
                paths.push(("--out", out));
            }
        }
        _ => {}
    }
    for (flag, path) in paths {
        if path.to_str().is_none() {
            anyhow::bail!(
                "{flag} {}: expected a UTF-8 path (results record their paths as text)",
                path.display()
            );
        }
    }
    Ok(())
}

/// A flag the subcommand would ignore is refused: `sapnet env --library DIR` reads no
/// library, and saying nothing would let the user believe it did.
fn refuse_unread_flags(cli: &Cli, command: &Command) -> Result<()> {
    let name = match command {
        Command::Env(_) => "env",
        Command::Teach(_) => "teach",
        Command::Sources(args) => match args.command {
            Some(SourcesCommand::Import(_)) => "sources import",
            None => "sources",
        },
        Command::Plot(_) => "plot",
        Command::Open(_) => "open",
        Command::Pool(_) => "pool",
        Command::Compare(_) => "compare",
        Command::Sweep(args) => match args.command {
            SweepCommand::Plan { .. } => "sweep plan",
            SweepCommand::Run { .. } => "sweep run",
            SweepCommand::Prepare { .. } => "sweep prepare",
            SweepCommand::Status { .. } => "sweep status",
            SweepCommand::Merge { .. } => "sweep merge",
        },
    };
    let reads = crate::cli::SubcommandFlags::of(name).reads;
    let unread: Vec<&str> = cli
        .run
        .given()
        .into_iter()
        .filter(|flag| !reads.contains(flag))
        .collect();
    if unread.is_empty() {
        return Ok(());
    }
    let what = if reads.is_empty() {
        "none of the run's flags".to_string()
    } else {
        reads.join(", ")
    };
    let them = if unread.len() == 1 { "it" } else { "them" };
    anyhow::bail!(
        "`sapnet {name}` does not read {}: leave {them} out (it reads {what})",
        unread.join(", ")
    )
}

/// The config the user named, or `embedded` (with `label` for messages), with `--quick`,
/// then `--seed`, `--episodes` and `--runs` applied (an explicit `--episodes` or `--runs`
/// wins over `--quick`'s).
fn load_config(cli: &Cli, embedded: &str, label: &str) -> Result<Config> {
    let mut config = match &cli.run.config {
        Some(path) => training_config(path)?,
        None => Config::from_ron(embedded, label)?,
    };
    apply_flags(cli, &mut config);
    // A Gymnasium id that does not exist (or a Python without Gymnasium) is said first,
    // before a library or a folder is looked for under its name.
    for (field, task) in config.tasks() {
        env::spaces(task)
            .with_context(|| format!("{label}: {field}", label = origin(cli, label)))?;
    }
    Ok(config)
}

/// The command line's `--quick`, then `--seed`, `--episodes` and `--runs`, applied to
/// `config` (its warnings said first).
fn apply_flags(cli: &Cli, config: &mut Config) {
    for warning in config.warnings() {
        eprintln!("warning: {warning}");
    }
    if cli.run.quick {
        config.quick();
    }
    if let Some(seed) = cli.run.seed {
        config.seed = seed;
    }
    if let Some(episodes) = cli.run.episodes {
        config.protocol.budget = Budget::Episodes(episodes);
    }
    if let Some(steps) = cli.run.steps {
        config.protocol.budget = Budget::Steps(steps);
    }
    if let Some(runs) = cli.run.runs {
        config.protocol.runs = runs;
    }
    config.run_with(&cli.run.python_settings());
}

/// The training config at `path`; a lesson given instead is said to be one, with what
/// each reads.
fn training_config(path: &Path) -> Result<Config> {
    Config::from_file(path).map_err(|err| {
        let lesson = matches!(err, ConfigError::Parse(_))
            && crate::ron_file::read_text(path)
                .is_ok_and(|text| parse_ron::<TeachConfig>(&text, "").is_ok());
        if lesson {
            anyhow::anyhow!(
                "config {}: this is a lesson, for `sapnet teach --config`; runs, `env` and \
                 `sources` read a training config (e.g. assets/cartpole.ron, \
                 assets/mountain_car.ron)",
                path.display()
            )
        } else {
            err.into()
        }
    })
}

/// The config's file as the user named it, or the embedded one's `label`.
fn origin(cli: &Cli, label: &str) -> String {
    cli.run
        .config
        .as_ref()
        .map_or(label.to_string(), |path| path.display().to_string())
}

fn run_env(cli: &Cli, args: &EnvArgs) -> Result<()> {
    let config = load_config(cli, assets::CARTPOLE, "embedded assets/cartpole.ron")?;
    let mut env = env::make(&config.env)?;
    let episodes = env_command::run(env.as_mut(), args.episodes, config.seed)?;
    let mut out = std::io::stdout().lock();
    env_command::print(&mut out, env.id(), &episodes)
        .and_then(|()| out.flush())
        .context("writing to stdout")
}

fn run_teach(cli: &Cli, args: &TeachArgs) -> Result<()> {
    let (lesson, origin) = edited_lesson(cli, args)?;
    if let Some(path) = &args.save {
        lesson.save(path)?;
        eprintln!(
            "wrote {} ({}): `sapnet teach --config {}` opens it",
            path.display(),
            edited_origin(&origin, args),
            path.display()
        );
        return Ok(());
    }
    let source = lesson;
    let lesson = source.lesson().map_err(|message| ConfigError::Invalid {
        origin: edited_origin(&origin, args),
        message,
    })?;
    if !args.headless {
        let n = lesson.net.len();
        if let Some(&i) = args.activate.iter().find(|&&i| i >= n) {
            anyhow::bail!(
                "--activate {i}: there is no policy {i}; the lesson has {n}, numbered 0 to {}",
                n.saturating_sub(1)
            );
        }
        // SIGTERM or SIGHUP end teach mode as `q` does, the terminal restored.
        let _stop = crate::signals::stop_on_signals()?;
        let mut teach = Teach::new(lesson.names, lesson.net).with_source(source);
        if let Some(groups) = lesson.groups {
            teach = teach.with_groups(groups);
        }
        // Each activation finishes the walk before it; the last is left to step, unless
        // --run. Without --activate, a lesson saved mid-walk reopens where it was.
        for &i in &args.activate {
            teach.move_cursor(i as isize - teach.cursor() as isize);
            teach.activate();
        }
        if let (true, Some(position)) = (args.activate.is_empty(), lesson.walk) {
            teach.resume_walk(position);
        }
        if args.run {
            teach.run_to_end();
        }
        if args.exercise {
            teach.toggle_exercise();
        }
        return tui::run_teach(teach);
    }
    crate::teach::headless::run_lesson(lesson, &origin, args, &mut std::io::stdout().lock())
}

/// The lesson `--config` names (Fig. 2 without one) with its graph edits (`--add-edge`,
/// `--cut-edge`, `--add-policy`, `--remove-policy`, `--set-category`) applied in order, each refused naming itself; a lesson to save is built first, so that
/// one the net refuses is never written.
fn edited_lesson(cli: &Cli, args: &TeachArgs) -> Result<(TeachConfig, String)> {
    let (mut lesson, origin) = TeachConfig::read(cli.run.config.as_deref())?;
    for (flag, values) in &args.edits {
        let edit = crate::teach::edit::GraphEdit::parse(flag, values)
            .map_err(|why| anyhow::anyhow!("{flag} {}: {why}", values.join(" ")))?;
        lesson
            .apply(&edit)
            .map_err(|why| anyhow::anyhow!("{}: {why} ({origin})", edit.flag()))?;
    }
    if let Some(decay) = args.decay {
        crate::teach::lesson::check_decay(decay)
            .map_err(|why| anyhow::anyhow!("--decay {decay}: {why}"))?;
        lesson.decay = decay;
    }
    if args.save.is_some() {
        lesson.lesson().map_err(|message| ConfigError::Invalid {
            origin: edited_origin(&origin, args),
            message,
        })?;
    }
    Ok((lesson, origin))
}

/// The lesson's origin with the edits made to it, as given, for messages.
fn edited_origin(origin: &str, args: &TeachArgs) -> String {
    if args.edits.is_empty() {
        return origin.to_string();
    }
    let said: Vec<String> = args
        .edits
        .iter()
        .map(|(flag, values)| format!("{flag} {}", values.join(" ")))
        .collect();
    format!("{origin} with {}", said.join(" "))
}

fn run_experiment(cli: &Cli) -> Result<()> {
    if cli.run.resume {
        return resume_experiment(cli);
    }
    let config = load_config(cli, assets::CARTPOLE, "embedded assets/cartpole.ron")?;
    if !cli.run.headless {
        return run_in_ui(cli, config);
    }
    if cli.run.compare.is_some() {
        anyhow::bail!(
            "--compare is for the dashboard (the UI's Run view): with --headless, `sapnet plot DIR` redraws a \
             results folder's plots"
        );
    }
    if cli.run.follow.is_some() {
        anyhow::bail!("--follow is for the UI: --headless follows no run");
    }
    if cli.run.follow_run.is_some() {
        anyhow::bail!("--follow-run is for the UI: --headless follows no run");
    }
    let dir = match &cli.run.out {
        Some(dir) => dir.clone(),
        None => experiment::default_out_dir(cli.run.config.as_deref()),
    };
    let output = OutputOptions {
        dir,
        force: cli.run.force,
    };

    let options = run_options(cli);
    let summary = experiment::run(&config, &output, &options, &on_interrupt()?)
        .map_err(|error| in_config_file(error, cli))?;
    headless::print_summary(&summary, &output.dir, headless::RanIn::Headless)
}

/// Names the config's file in an error one of its fields caused (a field only the library
/// can check: [`experiment::ConfigField`]).
fn in_config_file(error: anyhow::Error, cli: &Cli) -> anyhow::Error {
    if error.downcast_ref::<experiment::ConfigField>().is_none() {
        return error;
    }
    let origin = match &cli.run.config {
        Some(path) => path.display().to_string(),
        None => "embedded assets/cartpole.ron".to_string(),
    };
    error.context(format!("config {origin}"))
}

/// `--resume --out DIR`: in the UI, or with `--headless` without it.
fn resume_experiment(cli: &Cli) -> Result<()> {
    let dir = cli
        .run
        .out
        .as_deref()
        .context("--resume needs --out DIR, the results to continue")?;
    let added = match &cli.run.add_methods {
        Some(path) => {
            let mut config = training_config(path)?;
            config.run_with(&cli.run.python_settings());
            Some(experiment::AddedMethods {
                config,
                origin: path.clone(),
            })
        }
        None => None,
    };
    if !cli.run.headless {
        return resume_in_ui(cli, dir, added.as_ref());
    }
    let summary = experiment::resume(
        dir,
        cli.run.runs,
        added.as_ref(),
        &cli.run.python_settings(),
        &run_options(cli),
        &on_interrupt()?,
    )?;
    headless::print_summary(&summary, dir, headless::RanIn::Headless)
}

fn run_options(cli: &Cli) -> RunOptions {
    RunOptions {
        jobs: cli.run.jobs.unwrap_or_else(|| {
            std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
        }),
        library: cli.run.library_root(),
        trace: cli.run.trace,
        copy_chosen: cli.run.add_to_library,
        tensorboard: cli.run.tensorboard,
    }
}

/// The config's whole protocol in the UI: headless's runs, seeds and files into the same
/// `--out` folder (taken here, so that a folder refused is said on the command line), with
/// one run followed live (`--follow`, `--follow-run`, else SAP-Net's run 0). Prints what
/// `--headless` prints once the screen has closed on a protocol that ended.
fn run_in_ui(cli: &Cli, config: Config) -> Result<()> {
    let ids = crate::trainer::MethodId::all(&config.protocol.methods);
    let followed = tui::follow::followed_run(
        &ids,
        cli.run.follow.as_deref(),
        cli.run.follow_run,
        config.protocol.runs,
    )?;
    // Read before training starts, so that a wrong folder is said at once.
    let reference = match &cli.run.compare {
        Some(dir) => tui::reference::bands_of_folder(dir, &config.env.gym_id())?,
        None => Vec::new(),
    };
    // Said before the folder is taken or a run starts.
    if !std::io::IsTerminal::is_terminal(&std::io::stdout()) {
        anyhow::bail!(
            "the protocol runs in the terminal UI, and stdout is not a terminal: use \
             --headless (the same protocol and files, progress on stderr)"
        );
    }
    let output = OutputOptions {
        dir: match &cli.run.out {
            Some(dir) => dir.clone(),
            None => experiment::default_out_dir(cli.run.config.as_deref()),
        },
        force: cli.run.force,
    };
    let opened = experiment::OpenedOutput::open(&output)?;
    // SIGTERM and SIGHUP stop the protocol as `q` does, the terminal restored.
    let _signals = on_interrupt()?;
    let load = |path: &Path| load_picked(cli, path);
    let settings = session_settings(cli, &load, reference);
    let start = tui::workbench::screens::session::live::Start::New {
        config,
        output,
        opened,
        followed,
    };
    print_ended(tui::workbench::screens::session::live::run(
        start, &settings,
    )?)
}

/// `--resume --out DIR` without `--headless`: the stopped protocol in the workbench, as
/// `sapnet` runs a new one, its folder taken (and a folder that cannot be resumed said)
/// before the screen opens.
fn resume_in_ui(cli: &Cli, dir: &Path, added: Option<&experiment::AddedMethods>) -> Result<()> {
    if !std::io::IsTerminal::is_terminal(&std::io::stdout()) {
        anyhow::bail!(
            "the protocol resumes in the terminal UI, and stdout is not a terminal: \
             `sapnet --headless --resume --out {}` resumes it without the UI (progress on \
             stderr)",
            dir.display()
        );
    }
    let python = cli.run.python_settings();
    let stopped = experiment::StoppedProtocol::take(dir, cli.run.runs, added, &python)?;
    let config = stopped.config();
    let followed = match (&cli.run.follow, cli.run.follow_run) {
        (None, None) => None,
        (follow, run) => tui::follow::followed_run(
            &crate::trainer::MethodId::all(&config.protocol.methods),
            follow.as_deref(),
            run,
            config.protocol.runs,
        )?,
    };
    let reference = match &cli.run.compare {
        Some(compare) => tui::reference::bands_of_folder(compare, &config.env.gym_id())?,
        None => Vec::new(),
    };
    let _signals = on_interrupt()?;
    let load = |path: &Path| load_picked(cli, path);
    let settings = session_settings(cli, &load, reference);
    let start = tui::workbench::screens::session::live::Start::Resume { stopped, followed };
    print_ended(tui::workbench::screens::session::live::run(
        start, &settings,
    )?)
}

/// A config `L` picked, read with this command line's flags applied (`--quick`,
/// `--episodes`, `--runs`, `--seed`), its tasks checked.
fn load_picked(cli: &Cli, path: &Path) -> Result<Config> {
    let mut config = training_config(path)?;
    apply_flags(cli, &mut config);
    for (field, task) in config.tasks() {
        env::spaces(task).with_context(|| format!("{}: {field}", path.display()))?;
    }
    Ok(config)
}

/// What every protocol a session of the UI starts (`L`, `R`) runs with.
fn session_settings<'a>(
    cli: &Cli,
    load: &'a dyn Fn(&Path) -> Result<Config>,
    reference: Vec<tui::reference::Band>,
) -> tui::workbench::screens::session::live::Settings<'a> {
    tui::workbench::screens::session::live::Settings {
        options: run_options(cli),
        python: cli.run.python_settings(),
        load,
        reference,
    }
}

/// What `--headless` prints, for every protocol the screen saw end, in order (`L` starts
/// others into folders of their own: each is named); the first that failed is the error.
fn print_ended(ended: tui::workbench::screens::session::live::Ended) -> Result<()> {
    let mut failed = None;
    for (outcome, dir) in ended {
        match outcome {
            Ok(summary) => headless::print_summary(&summary, &dir, headless::RanIn::Ui)?,
            Err(error) => {
                let error = error.context(format!("the protocol into {}", dir.display()));
                if failed.is_none() {
                    failed = Some(error);
                } else {
                    eprintln!("error: {error:#}");
                }
            }
        }
    }
    failed.map_or(Ok(()), Err)
}

fn run_sources(cli: &Cli, args: &SourcesArgs) -> Result<()> {
    let config = load_config(cli, assets::CARTPOLE, "embedded assets/cartpole.ron")?;
    if let Some(SourcesCommand::Import(import)) = &args.command {
        let done = crate::sources::import(
            &config,
            &cli.run.library_path(),
            &import.file,
            &import.name,
            import.prefix.as_deref(),
        )?;
        let origin = &done.origin;
        eprintln!(
            "imported {} ({}, {}, layers `{}`) into {} as {}: {}, greedy return {:.1} on {}              (mean of {} episodes)",
            import.file.display(),
            origin.format.describe(),
            origin.framework,
            // The state dict's own keys: shown as data.
            crate::shown_text::escaped(&origin.prefix),
            done.dir.display(),
            import.name,
            done.architecture,
            done.score,
            done.task,
            done.test_episodes
        );
        return Ok(());
    }
    if args.evaluate {
        let evaluations = crate::sources::evaluate(&config, &cli.run.library_path())?;
        let target = config.env.gym_id();
        // Columns as wide as their longest entry: a Gymnasium task's label with its
        // keywords runs to 70 characters.
        let hidden: Vec<String> = evaluations
            .iter()
            .map(|e| format!("{:?}", e.hidden))
            .collect();
        let name_width = evaluations
            .iter()
            .map(|e| e.name.len())
            .fold(10, usize::max);
        let task_width = evaluations.iter().map(|e| e.task.len()).fold(4, usize::max);
        let hidden_width = hidden.iter().map(String::len).fold(6, usize::max);
        let target_width = target.len().max(12);
        let mut out = std::io::stdout().lock();
        writeln!(
            out,
            "{:<name_width$} {:<task_width$} {:<hidden_width$} {:>10} {:>target_width$}",
            "source", "task", "hidden", "own task", target,
        )?;
        for (e, hidden) in evaluations.iter().zip(&hidden) {
            writeln!(
                out,
                "{:<name_width$} {:<task_width$} {:<hidden_width$} {:>10} {:>target_width$.1}",
                e.name,
                e.task,
                hidden,
                e.own_score.map_or("-".into(), |s| format!("{s:.1}")),
                e.target_score,
            )?;
        }
        return Ok(());
    }
    let dir = crate::sources::train_library(
        &config,
        &cli.run.library_path(),
        args.retrain,
        &on_interrupt()?,
    )?;
    eprintln!(
        "{} source policies in {}",
        config.sources.count,
        dir.display()
    );
    Ok(())
}

fn run_sweep(cli: &Cli, command: &SweepCommand) -> Result<()> {
    use crate::sweep;
    match command {
        SweepCommand::Plan { grid, out } => {
            let manifest = sweep::plan::plan(&sweep::plan::PlanOptions {
                grid: grid.clone(),
                config: cli.run.config.clone(),
                out: out.clone(),
                library: cli.run.library_path(),
                python: cli.run.python_settings(),
            })?;
            eprintln!(
                "{} cells in {}: `sapnet sweep run {} --all` runs them here; slurm.sbatch and \
                 parallel.txt fan them out",
                manifest.cells.len(),
                out.display(),
                out.display()
            );
            Ok(())
        }
        SweepCommand::Prepare { sweep } => sweep::run::prepare(
            sweep,
            cli.run.library.as_deref(),
            &cli.run.python_settings(),
            &on_interrupt()?,
        ),
        SweepCommand::Run { sweep, cell, all } => {
            let jobs = cli.run.jobs.unwrap_or_else(|| {
                std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
            });
            if *all {
                let _stop = on_interrupt()?;
                let failed = sweep::run::run_all(sweep, jobs, &cli.run.python_settings())?;
                let states = crate::results::sweep::status::states(sweep)?;
                eprint!("{}", crate::results::sweep::status::report(&states));
                anyhow::ensure!(
                    failed == 0,
                    "{failed} {} failed: `sapnet sweep status {}` says why",
                    if failed == 1 { "cell" } else { "cells" },
                    sweep.display()
                );
                return Ok(());
            }
            let id = match cell {
                Some(id) => *id,
                None => sweep::run::cell_from_environment()?.context(
                    "which cell? --cell K, $SLURM_ARRAY_TASK_ID or $JOB_COMPLETION_INDEX \
                     (or --all)",
                )?,
            };
            match sweep::run::run_cell(
                sweep,
                id,
                jobs,
                &cli.run.python_settings(),
                &on_interrupt()?,
            )? {
                sweep::run::CellRun::AlreadyDone => eprintln!("cell {id}: done already"),
                sweep::run::CellRun::Finished => eprintln!("cell {id}: done"),
                sweep::run::CellRun::Stopped => eprintln!("cell {id}: stopped; run it again"),
            }
            Ok(())
        }
        SweepCommand::Status { sweep } => print_stdout(&crate::results::sweep::status::report(
            &crate::results::sweep::status::states(sweep)?,
        )),
        SweepCommand::Merge { sweep } => {
            let report = crate::results::sweep::merge::merge(sweep)?;
            if !report.missing.is_empty() {
                let names: Vec<String> = report
                    .missing
                    .iter()
                    .map(|&id| crate::results::sweep::cell_name(id))
                    .collect();
                eprintln!(
                    "{} {} left out: {}",
                    names.len(),
                    if names.len() == 1 {
                        "cell is not done and is"
                    } else {
                        "cells are not done and are"
                    },
                    names.join(", ")
                );
            }
            let mut out = std::io::stdout().lock();
            for (title, table) in &report.tables {
                writeln!(out, "{title}\n{table}").context("writing to stdout")?;
            }
            eprintln!(
                "merged {} cells into {}",
                report.merged,
                sweep.join("merged").display()
            );
            Ok(())
        }
    }
}

/// Writes `text` to stdout; a reader that left (`| head`) is an error that `main` ends
/// quietly on, where `print!` would panic.
fn print_stdout(text: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .context("writing to stdout")
}

/// The trainer's command channel, on which SIGINT (Ctrl-C), SIGTERM and SIGHUP ask it to
/// stop.
fn on_interrupt() -> Result<mpsc::Receiver<trainer::Command>> {
    crate::signals::stop_on_signals()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lesson_given_as_a_training_config_is_named_as_such() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("fig2.ron");
        std::fs::write(&path, include_str!("../assets/teach_fig2.ron")).unwrap();
        let err = training_config(&path).unwrap_err().to_string();
        assert!(
            err.contains("fig2.ron: this is a lesson, for `sapnet teach --config`"),
            "{err}"
        );
    }
}
