//! Command-line interface: the run's own flags here, each subcommand's arguments in
//! [`commands`].

mod commands;

use std::path::PathBuf;

pub use commands::*;

use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand};

/// SAP-Net: reuse a library of DQN policies by spreading activation over a policy graph.
///
/// With no subcommand, runs the whole protocol of `--config` (default: the embedded
/// `assets/cartpole.ron`, the paper's CartPole-v1 experiment: SAP-Net and three DQN
/// baselines) in the terminal UI, one run followed live, results written to --out as
/// `--headless` writes them; with `--headless`, the same protocol without the UI.
#[derive(Debug, Parser)]
#[command(name = "sapnet", version, about, long_about = None)]
pub struct Cli {
    #[command(flatten)]
    pub run: RunArgs,

    #[command(subcommand)]
    pub command: Option<Command>,
}

/// Options of a training run.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// RON config file (see assets/). Without it, the embedded CartPole config (paper
    /// values).
    #[arg(long, short, value_name = "FILE", global = true)]
    pub config: Option<PathBuf>,

    /// Run without the terminal UI: progress on stderr, results in --out (the same files
    /// the UI's protocol writes).
    #[arg(long)]
    pub headless: bool,

    /// Also add each run's chosen policy, fine-tuned, to the library as
    /// <LIBRARY>/<task>/chosen/<out dir>-<method>-run<r> (Algorithm 3's last step). Without
    /// it a run writes only under --out (its policies/ holds the same files).
    #[arg(long)]
    pub add_to_library: bool,

    /// Run seed, overriding the config's `seed`: the same seed and config give the same
    /// numbers on the same machine.
    #[arg(long, value_name = "N", global = true)]
    pub seed: Option<u64>,

    /// Directory for results (CSV, JSON, trained policies). Default: a new directory
    /// `out/<config>-<unix time>`.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,

    /// Replace results already in --out.
    #[arg(long)]
    pub force: bool,

    /// With --headless --out DIR: continue the stopped, failed or killed protocol in DIR,
    /// with the config it began with. Finished runs are kept; the others run again from
    /// their seeds, giving the numbers an uninterrupted protocol gives.
    #[arg(
        long,
        requires = "out",
        conflicts_with_all = ["config", "seed", "quick", "episodes", "steps", "force", "trace"]
    )]
    pub resume: bool,

    /// With --resume: add to DIR's protocol the methods CONFIG lists after DIR's own (CONFIG
    /// must equal the config DIR began with in all else, its methods first and in order).
    /// Finished runs are kept: a run's seeds come from its method's label, never from the
    /// list, so the result is the protocol that had every method from the start.
    #[arg(long, value_name = "CONFIG", requires = "resume")]
    pub add_methods: Option<PathBuf>,

    /// A smoke run (seconds for the paper's protocol, about ten for the comparison of
    /// assets/reuse_cartpole.ron, on 2 cores): the protocol cut to 1/20 of its budget
    /// (episodes or steps) and at most 2 runs per method (on the same source library). With
    /// --episodes or --steps, that budget.
    #[arg(long)]
    pub quick: bool,

    /// The UI follows run 0 of this method (its label in results, e.g. `ucb1`,
    /// `sapnet-episode`, `dqn[100]`) in its Run view: pause, step and speed act on it, the
    /// other runs train at full speed. Default: the first SAP-Net method, else the first
    /// that reuses the library, else the first.
    #[arg(long, value_name = "METHOD")]
    pub follow: Option<String>,

    /// The UI follows run N of the followed method instead of run 0 (the seeds a headless
    /// protocol gives run N): to watch a run the results single out. Runs are numbered
    /// from 0, as in the results' files (`sapnet-run2`).
    #[arg(long, value_name = "N")]
    pub follow_run: Option<u32>,

    /// The Run view draws a finished protocol's results (a `--headless` output folder)
    /// under the live curves: for each method on screen, the mean of its runs' moving
    /// averages and its 95% bootstrap interval.
    #[arg(long, value_name = "DIR")]
    pub compare: Option<PathBuf>,

    /// Training episodes per run, overriding the config's `protocol.budget` with
    /// `Episodes(N)`: the first N episodes of every run are exactly those of the full
    /// protocol (the same seeds).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=crate::limits::MAX_EPISODES as i64))]
    pub episodes: Option<u32>,

    /// Environment steps per run, overriding the config's `protocol.budget` with
    /// `Steps(N)`: every method is given the same experience, scored on the step axis.
    #[arg(long, value_name = "N", conflicts_with = "episodes", value_parser = clap::value_parser!(u64).range(1..=crate::limits::MAX_STEPS))]
    pub steps: Option<u64>,

    /// Runs per method, overriding the config's `protocol.runs`. Run r's seeds do not
    /// depend on how many runs there are, so the first N runs of a longer protocol are
    /// exactly these. With --resume: extend a finished protocol to N runs (its runs kept).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=crate::limits::MAX_RUNS as i64))]
    pub runs: Option<u32>,

    /// Also write trace.csv, every spread call (eq. 9-11) of every
    /// positive activation of SAP-Net's runs, as teach mode shows them. One row per call:
    /// millions over a full protocol, so best with --quick or a small config.
    #[arg(long)]
    pub trace: bool,

    /// Also write each run's TensorBoard event file, live, under
    /// <out>/tensorboard/<method>-run<r>/ (CleanRL's tag names, SAP-Net's activations and
    /// probabilities, the run's hyper-parameters): `tensorboard --logdir <out>/tensorboard`.
    #[arg(long)]
    pub tensorboard: bool,

    /// Runs trained at the same time. Default: one per core.
    #[arg(long, value_name = "N", global = true, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=4096))]
    pub jobs: Option<usize>,

    /// The policy library's root directory: SAP-Net reuses <LIBRARY>/<source task>/.
    /// Default: ./saved_policies (trained on first use if missing), or where there is none
    /// the library shipped beside the source sapnet was built from. A library given here
    /// must exist, unless --train-library.
    #[arg(long, value_name = "DIR", global = true)]
    pub library: Option<PathBuf>,

    /// The Python that runs Gymnasium tasks, instead of the config's `python` (without
    /// either: the active virtualenv's, else python3). A results or sweep folder never
    /// chooses it: resuming one, say it here.
    #[arg(long, value_name = "PATH", global = true)]
    pub python: Option<PathBuf>,

    /// The folder of your own Gymnasium environment modules (a task id `my_envs:Maze-v0`
    /// imports `my_envs` from it), instead of the config's `module_dir`. Nothing is ever
    /// imported from the folder sapnet is started in.
    #[arg(long, value_name = "DIR", global = true)]
    pub module_dir: Option<PathBuf>,

    /// A Python module that the task of a folder from elsewhere (a resumed protocol, a
    /// sweep's cells) may import through its id `MODULE:Env-v0`: none may unless named
    /// here. Repeat for several.
    #[arg(long, value_name = "MODULE", global = true)]
    pub allow_module: Vec<String>,

    /// Train the source library first if --library holds none (or finish one whose
    /// training was interrupted), as the default library is.
    #[arg(long)]
    pub train_library: bool,
}

/// The run's flags that each subcommand reads (a subcommand refuses the others), and what
/// its `--config` is. `--config`, `--seed`, `--jobs` and `--library` are clap globals so that
/// they may come before or after the subcommand; each subcommand's `--help` lists only the
/// ones it reads.
pub struct SubcommandFlags {
    /// As the user types it: `teach`, `sweep plan`.
    pub name: &'static str,
    pub reads: &'static [&'static str],
    /// `--config`'s help for this subcommand, when it reads one.
    pub config: Option<&'static str>,
    /// `--library`'s, where the run's text does not fit.
    pub library: Option<&'static str>,
}

/// `--library` for the commands that train or read one library.
const SOURCES_LIBRARY: &str = "The policy library's root directory: the library is <LIBRARY>/<source task>/. Default: ./saved_policies, or where there is none the one shipped with sapnet";

/// Every subcommand's flags, as [`SubcommandFlags`] says.
pub const SUBCOMMANDS: &[SubcommandFlags] = &[
    SubcommandFlags {
        name: "env",
        reads: &["--config", "--seed", "--python", "--module-dir"],
        config: Some("RON config whose target task (`env`) is run. Default: the embedded CartPole config"),
        library: None,
    },
    SubcommandFlags {
        name: "teach",
        reads: &["--config"],
        config: Some("A lesson file (assets/teach_*.ron). Default: the paper's Fig. 2"),
        library: None,
    },
    SubcommandFlags {
        name: "sources",
        reads: &["--config", "--seed", "--library", "--python", "--module-dir"],
        config: Some("RON config whose `sources` section describes the library. Default: the embedded CartPole config"),
        library: Some(SOURCES_LIBRARY),
    },
    SubcommandFlags {
        name: "sources import",
        reads: &["--config", "--seed", "--library", "--python", "--module-dir"],
        config: Some("RON config of the library the policy joins (its `sources` section and source task). Default: the embedded CartPole config"),
        library: Some(SOURCES_LIBRARY),
    },
    SubcommandFlags {
        name: "plot",
        reads: &[],
        config: None,
        library: None,
    },
    SubcommandFlags {
        name: "open",
        reads: &["--jobs", "--library", "--python", "--module-dir", "--allow-module"],
        config: None,
        library: Some("With R (resuming a stopped folder): the library root its protocol began with, as `sapnet --resume` reads it. Default: ./saved_policies, or where there is none the one shipped with sapnet"),
    },
    SubcommandFlags {
        name: "compare",
        reads: &[],
        config: None,
        library: None,
    },
    SubcommandFlags {
        name: "pool",
        reads: &[],
        config: None,
        library: None,
    },
    SubcommandFlags {
        name: "sweep",
        reads: &[],
        config: None,
        library: None,
    },
    SubcommandFlags {
        name: "sweep plan",
        reads: &["--config", "--library", "--python", "--module-dir", "--allow-module"],
        config: Some("A RON config that replaces the grid's base config"),
        library: Some("The library root the cells reuse, read-only (`sweep prepare` trains what is missing). Default: ./saved_policies, or where there is none the one shipped with sapnet"),
    },
    SubcommandFlags {
        name: "sweep prepare",
        reads: &["--library", "--python", "--module-dir", "--allow-module"],
        config: None,
        library: Some("The library root the cells reuse, as sweep.ron names it: a library that needs training is trained only when named here (a sweep folder may come from elsewhere)"),
    },
    SubcommandFlags {
        name: "sweep run",
        reads: &["--jobs", "--python", "--module-dir", "--allow-module"],
        config: None,
        library: None,
    },
    SubcommandFlags {
        name: "sweep status",
        reads: &[],
        config: None,
        library: None,
    },
    SubcommandFlags {
        name: "sweep merge",
        reads: &[],
        config: None,
        library: None,
    },
];

/// A global flag's help where a subcommand reads it otherwise than the run does: the
/// subcommand, the flag's id, its help there.
const OWN_HELP: &[(&str, &str, &str)] = &[
    ("env", "python", CONFIG_PYTHON),
    ("sources", "python", CONFIG_PYTHON),
    ("sources import", "python", CONFIG_PYTHON),
    ("sweep run", "jobs", "Cells run at the same time with --all. Default: one per core"),
    ("sweep run", "python", "The Python that runs the cells' Gymnasium tasks (without it: the active virtualenv's, else python3): a sweep folder never chooses it"),
];

/// `--python` for the commands that read a config and no folder.
const CONFIG_PYTHON: &str = "The Python that runs a Gymnasium task, instead of the config's `python` (without either: the active virtualenv's, else python3)";

impl SubcommandFlags {
    /// The entry of the subcommand named `name` (`sweep run`).
    pub fn of(name: &str) -> &'static Self {
        SUBCOMMANDS
            .iter()
            .find(|s| s.name == name)
            .expect("every subcommand has an entry")
    }
}

/// The command line's parser: [`Cli`], with each subcommand's help showing only the global
/// flags it reads, and its own words for `--config`.
pub fn command() -> clap::Command {
    let command = Cli::command();
    let globals: Vec<clap::Arg> = command
        .get_arguments()
        .filter(|a| a.is_global_set())
        .cloned()
        .collect();
    // A subcommand that has an argument of a global's id keeps it (clap copies the globals
    // into subcommands only where they are absent), and its value still reaches the
    // top-level `Cli`: each subcommand gets its own copy, hidden where it is not read.
    SUBCOMMANDS.iter().fold(command, |command, flags| {
        let path: Vec<&str> = flags.name.split(' ').collect();
        mut_path(command, &path, &|sub| {
            globals.iter().fold(sub, |sub, global| {
                let id = global.get_id().as_str();
                let mut arg = global.clone();
                if !flags.reads.contains(&format!("--{id}").as_str()) {
                    arg = arg.hide(true);
                } else if let Some(help) = match id {
                    "config" => flags.config,
                    "library" => flags.library,
                    _ => OWN_HELP
                        .iter()
                        .find(|(name, flag, _)| *name == flags.name && *flag == id)
                        .map(|(_, _, help)| *help),
                } {
                    arg = arg.help(help);
                }
                sub.arg(arg)
            })
        })
    })
}

/// `change` applied to the subcommand at `path` of `command`.
fn mut_path(
    command: clap::Command,
    path: &[&str],
    change: &dyn Fn(clap::Command) -> clap::Command,
) -> clap::Command {
    match path {
        [] => change(command),
        [first, rest @ ..] => command.mut_subcommand(*first, |sub| mut_path(sub, rest, change)),
    }
}

/// The command line of this process, parsed by [`command`]; exits as clap does on bad input
/// or `--help`.
pub fn parse() -> Cli {
    let matches = command().get_matches();
    let mut cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    if let (Some(Command::Teach(args)), Some(teach)) =
        (&mut cli.command, matches.subcommand_matches("teach"))
    {
        args.edits = edits_in_order(teach);
    }
    cli
}

/// `teach`'s graph edits (`--add-edge`, `--cut-edge`, `--add-policy`, `--remove-policy`,
/// `--set-category`), each with its values, in the order given: clap keeps each flag's
/// values apart, and their positions say the order.
fn edits_in_order(teach: &clap::ArgMatches) -> Vec<(&'static str, Vec<String>)> {
    let mut edits: Vec<(usize, &'static str, Vec<String>)> = Vec::new();
    let flags = [
        ("add_edge", "--add-edge", 3),
        ("cut_edge", "--cut-edge", 2),
        ("add_policy", "--add-policy", 1),
        ("remove_policy", "--remove-policy", 1),
        ("set_category", "--set-category", 2),
    ];
    for (id, flag, arity) in flags {
        let (Some(indices), Some(values)) = (teach.indices_of(id), teach.get_many::<String>(id))
        else {
            continue;
        };
        let indices: Vec<usize> = indices.collect();
        let values: Vec<String> = values.cloned().collect();
        for (at, chunk) in indices.chunks(arity).zip(values.chunks(arity)) {
            edits.push((at[0], flag, chunk.to_vec()));
        }
    }
    edits.sort_by_key(|&(at, _, _)| at);
    edits
        .into_iter()
        .map(|(_, flag, values)| (flag, values))
        .collect()
}

/// The library root when `--library` is not given.
pub const DEFAULT_LIBRARY: &str = "saved_policies";

/// The default library: `./saved_policies`, else, where the folder sapnet is started in has
/// none, the one shipped beside the source sapnet was built from (a binary installed with
/// `cargo install --path .` and started elsewhere reuses the shipped library rather than
/// train ten sources for minutes into a new folder), else `./saved_policies`, trained there
/// on first use. Said once when it is the shipped one.
fn default_library() -> PathBuf {
    let here = PathBuf::from(DEFAULT_LIBRARY);
    if here.exists() {
        return here;
    }
    let shipped = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(DEFAULT_LIBRARY);
    if !shipped.is_dir() {
        return here;
    }
    static SAID: std::sync::Once = std::sync::Once::new();
    SAID.call_once(|| {
        eprintln!(
            "the source library: {} (shipped with sapnet; no ./{DEFAULT_LIBRARY} here, \
             --library DIR names another)",
            shipped.display()
        );
    });
    shipped
}

impl RunArgs {
    /// The flags given, as the user spelled them: a subcommand refuses those it does not
    /// read rather than ignore them.
    pub fn given(&self) -> Vec<&'static str> {
        [
            ("--config", self.config.is_some()),
            ("--headless", self.headless),
            ("--add-to-library", self.add_to_library),
            ("--seed", self.seed.is_some()),
            ("--out", self.out.is_some()),
            ("--force", self.force),
            ("--resume", self.resume),
            ("--quick", self.quick),
            ("--follow", self.follow.is_some()),
            ("--follow-run", self.follow_run.is_some()),
            ("--compare", self.compare.is_some()),
            ("--episodes", self.episodes.is_some()),
            ("--steps", self.steps.is_some()),
            ("--runs", self.runs.is_some()),
            ("--trace", self.trace),
            ("--jobs", self.jobs.is_some()),
            ("--library", self.library.is_some()),
            ("--train-library", self.train_library),
            ("--python", self.python.is_some()),
            ("--module-dir", self.module_dir.is_some()),
            ("--allow-module", !self.allow_module.is_empty()),
        ]
        .into_iter()
        .filter_map(|(flag, given)| given.then_some(flag))
        .collect()
    }

    /// `--library`, or the default library.
    pub fn library_path(&self) -> PathBuf {
        self.library.clone().unwrap_or_else(default_library)
    }

    /// How this machine runs Gymnasium tasks, as the flags say.
    pub fn python_settings(&self) -> crate::env::PythonSettings {
        crate::env::PythonSettings {
            interpreter: self.python.clone(),
            module_dir: self.module_dir.clone(),
            allowed_modules: self.allow_module.clone(),
        }
    }

    /// Where runs find their library, and whether they may train a missing one: the
    /// default library is trained on first use; one named by `--library` only with
    /// `--train-library`, so that a typo does not start hours of training.
    pub fn library_root(&self) -> crate::sources::LibraryRoot {
        crate::sources::LibraryRoot {
            path: self.library_path(),
            train_if_missing: self.library.is_none() || self.train_library,
        }
    }
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run episodes with uniformly random actions and print their lengths and returns
    /// (a quick check of an environment and its physics).
    Env(EnvArgs),
    /// Step SAP-Net's activation and spreading by hand on a small graph.
    Teach(TeachArgs),
    /// Train the library of source policies the config describes (`sources`: N random
    /// architectures) and write it to <LIBRARY>/<task>/.
    Sources(SourcesArgs),
    /// Make a results directory's report and plots again from its files (summary.json and
    /// the run records in runs/): for a run stopped before its plots, a killed one, or a
    /// folder of an older version. Prints the comparison.
    Plot(PlotArgs),
    /// Open a results folder in the terminal UI, read only: finished, stopped, or live and
    /// being written by another process (`sapnet --headless --out DIR` running). Views, a
    /// tab each: Runs (r or 1), Comparison (c, 2), Curves (v, 3) and a run's dashboard (f,
    /// 4: Enter on a finished run in Runs); a sweep folder opens in the Sweep view, a compare
    /// folder in its Comparison and Curves, a parent folder as the list of the results
    /// folders under it. `?` lists the keys. Nothing in the folder changes unless R resumes
    /// its stopped protocol there (with --jobs, --library and --python as `sapnet --resume`
    /// reads them).
    Open(OpenArgs),
    /// One comparison of finished protocols on different tasks (e.g. the variants of
    /// CartPole and of MountainCar): each method's scores normalised by each task's range
    /// of returns and resampled within each task; written to --out with its plots.
    Pool(PoolArgs),
    /// Runs that already exist, made by other tools or by sapnet (SB3 monitor.csv files,
    /// CleanRL / openrlbenchmark CSV exports, TensorBoard event files, results folders),
    /// compared with the intervals, the separation rule and the plots of a protocol's
    /// report, written to --out.
    Compare(CompareArgs),
    /// Sweeps: a grid of configs as independent cells, run by Slurm array jobs, GNU
    /// parallel or this machine, then merged (docs/SWEEPS.md).
    Sweep(SweepArgs),
}
