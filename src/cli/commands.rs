//! The arguments of each subcommand: `sweep`, `plot`, `open`, `compare`, `pool`,
//! `sources`, `env`, `teach`.

use std::path::PathBuf;

use clap::{Args, Subcommand};

#[derive(Debug, Args)]
pub struct SweepArgs {
    #[command(subcommand)]
    pub command: SweepCommand,
}

#[derive(Debug, Subcommand)]
pub enum SweepCommand {
    /// Expand a grid (a base config and axes over its fields) into SWEEP/cells/NNNN.ron,
    /// a manifest, SWEEP/slurm.sbatch and SWEEP/parallel.txt. `--config` overrides the
    /// grid's base; `--library` is the library the cells reuse, read-only.
    Plan {
        /// The grid file (see assets/sweep_example.ron).
        #[arg(long, value_name = "FILE")]
        grid: PathBuf,
        /// The sweep's folder.
        #[arg(long, value_name = "SWEEP")]
        out: PathBuf,
    },
    /// Train the source libraries the cells reuse, once, before the cells run.
    Prepare {
        /// The sweep's folder (`sweep plan --out`).
        #[arg(value_name = "SWEEP")]
        sweep: PathBuf,
    },
    /// Run one cell (`--cell K`, else $SLURM_ARRAY_TASK_ID or $JOB_COMPLETION_INDEX) into
    /// SWEEP/results/NNNN, or with `--all` every cell not done, `--jobs` cells at a time.
    Run {
        /// The sweep's folder (`sweep plan --out`).
        #[arg(value_name = "SWEEP")]
        sweep: PathBuf,
        /// The cell to run (its number, as in SWEEP/cells/NNNN.ron).
        #[arg(long, value_name = "K", conflicts_with = "all")]
        cell: Option<usize>,
        /// Every cell not done yet, --jobs at a time, on this machine.
        #[arg(long)]
        all: bool,
    },
    /// Which cells are done, running, failed (with the error's last line) or missing.
    Status {
        /// The sweep's folder (`sweep plan --out`).
        #[arg(value_name = "SWEEP")]
        sweep: PathBuf,
    },
    /// Merge the finished cells into SWEEP/merged/: a comparison per axis value,
    /// episodes.csv in long format, plots.
    Merge {
        /// The sweep's folder (`sweep plan --out`).
        #[arg(value_name = "SWEEP")]
        sweep: PathBuf,
    },
}

#[derive(Debug, Args)]
pub struct PlotArgs {
    /// The results directory (a headless run's --out).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
}

#[derive(Debug, Args)]
pub struct OpenArgs {
    /// The results directory (a headless run's --out), finished or still being written; a
    /// folder shipped with its top-level files (summary.json, episodes.csv); or a sweep
    /// folder (sapnet sweep plan's --out).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
}

#[derive(Debug, Args)]
pub struct CompareArgs {
    /// A method and its runs, each PATH one run: an SB3 monitor.csv, a CSV with a header
    /// (an episodic-return column beside a step or episode column), a TensorBoard event
    /// file or a folder of them; or a sapnet results folder, whose runs of the method NAME
    /// (or LABEL, written DIR#LABEL) are taken. Repeat the flag for each method, or for
    /// more runs of one.
    #[arg(long = "method", value_name = "NAME=PATH[,PATH…]", required = true)]
    pub methods: Vec<String>,
    /// Where the report goes (a new or empty directory).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// The lowest and highest return of the task, which normalise the scores (the
    /// optimality gap, the profiles). Default: when every run comes from results folders
    /// of one task, that task's range; else the lowest and highest return read (with a
    /// warning: adding a run would move every score).
    #[arg(long, num_args = 2, value_names = ["LO", "HI"], allow_negative_numbers = true)]
    pub range: Option<Vec<f64>>,
    /// The final score is the mean return of each run's last K episodes.
    #[arg(long, value_name = "K", default_value_t = 100)]
    pub last: usize,
    /// The moving average's window, in episodes, for the curves.
    #[arg(long, value_name = "N", default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..))]
    pub window: u32,
    /// Put the runs side by side by environment step up to N (each run's curve there the
    /// mean return of its last episodes ended by it; a run shorter than N holds its last
    /// value). Default, when every run says where its episodes ended: the steps every run
    /// reached.
    #[arg(long, value_name = "N", conflicts_with = "by_episode", value_parser = clap::value_parser!(u64).range(1..=crate::limits::MAX_STEPS))]
    pub steps: Option<u64>,
    /// Put the runs side by side by episode even when their files give steps.
    #[arg(long)]
    pub by_episode: bool,
    /// The task's name in titles. Default: the task of the results folders when every run
    /// comes from folders of one task, else `runs`.
    #[arg(long, value_name = "NAME")]
    pub task: Option<String>,
    /// A CSV's episodic-return column. Default: the first of charts/episodic_return,
    /// episodic_return, return, r.
    #[arg(long, value_name = "COLUMN")]
    pub return_column: Option<String>,
    /// A CSV's step column. Default: the first of global_step, step, _step.
    #[arg(long, value_name = "COLUMN", conflicts_with = "episode_column")]
    pub step_column: Option<String>,
    /// A CSV's episode column, for files without a step column. Default: episode.
    #[arg(long, value_name = "COLUMN")]
    pub episode_column: Option<String>,
    /// A CSV's episode-length column. Default: the first of charts/episodic_length,
    /// episodic_length, length, l, if any.
    #[arg(long, value_name = "COLUMN")]
    pub length_column: Option<String>,
    /// The tag of episodic returns in event files. Default: charts/episodic_return.
    #[arg(long, value_name = "TAG")]
    pub tag: Option<String>,
    /// Event files without the return tag are read from SB3's rollout/ep_rew_mean (a
    /// moving mean of 100 episodes, not each episode's return).
    #[arg(long)]
    pub rollout_mean: bool,
}

#[derive(Debug, Args)]
pub struct PoolArgs {
    /// The results directories (headless runs' --out), one per task.
    #[arg(value_name = "DIR", num_args = 2.., required = true)]
    pub dirs: Vec<PathBuf>,
    /// Where the pooled report goes (a new or empty directory).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct SourcesArgs {
    /// Replace a library already on disk (policies imported into it are kept).
    #[arg(long)]
    pub retrain: bool,

    /// Train nothing: test each source of the library greedily on the config's target task
    /// (`protocol.test_episodes` episodes) beside its score on its own task.
    #[arg(long, conflicts_with = "retrain")]
    pub evaluate: bool,

    #[command(subcommand)]
    pub command: Option<SourcesCommand>,
}

#[derive(Debug, Subcommand)]
pub enum SourcesCommand {
    /// Add a Q-network trained elsewhere to the finished library of --config (default: the
    /// embedded CartPole one) in <LIBRARY>/<task>/: a Stable-Baselines3 DQN .zip, a PyTorch
    /// state dict (.pt, .pth, CleanRL's .cleanrl_model) or a safetensors file of linear
    /// layers with ReLU between them. The format is told from the file; nothing in it is
    /// run. The policy is tested on the config's source task and reused as every source.
    Import(ImportArgs),
}

#[derive(Debug, Args)]
pub struct ImportArgs {
    /// The file to import.
    #[arg(value_name = "FILE")]
    pub file: PathBuf,

    /// The policy's name in the library: letters, digits, `.`, `-` and `_` (e.g. `sb3-64x64`).
    #[arg(long, value_name = "NAME")]
    pub name: String,

    /// Which network of a state dict holding several: the prefix of its keys (`network`
    /// for `network.0.weight`). An SB3 model's is `q_net.q_net`, its online network.
    #[arg(long, value_name = "PREFIX")]
    pub prefix: Option<String>,
}

#[derive(Debug, Args)]
pub struct EnvArgs {
    /// Number of episodes.
    #[arg(long, value_name = "N", default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..))]
    pub episodes: u32,
}

#[derive(Debug, Args)]
pub struct TeachArgs {
    /// Print the trace instead of opening the interactive view.
    #[arg(long)]
    pub headless: bool,

    /// Activate this policy (0-based index); repeat to activate several in order. The
    /// interactive view opens at the start of the last one's walk, to step it.
    #[arg(long = "activate", value_name = "I")]
    pub activate: Vec<usize>,

    /// With --activate: open with the last walk already run to its end (--headless prints
    /// every walk whole anyway).
    #[arg(long, conflicts_with = "headless")]
    pub run: bool,

    /// Between two activations, multiply every activation by (1 − D), 0 ≤ D ≤ 1 (overrides
    /// the lesson's `decay`). The paper has no decay (eq. 8-11 only add): D = 0, the
    /// default, is the paper; D > 0 lets older activations fade, as spreading-activation
    /// models in psychology do.
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    pub decay: Option<f64>,

    /// Open in exercise mode: before each call the student types its ΔA (X ends it).
    #[arg(long, conflicts_with_all = ["headless", "save"])]
    pub exercise: bool,

    /// With --headless: print one JSON object {activations, probabilities, trace,
    /// through_time}.
    #[arg(long, requires = "headless")]
    pub json: bool,

    /// Add an edge of weight W between policies I and J (or set its weight) before the
    /// lesson opens; repeatable, applied in order with --cut-edge.
    #[arg(long = "add-edge", num_args = 3, value_names = ["I", "J", "W"], action = clap::ArgAction::Append, allow_negative_numbers = true)]
    pub add_edge: Vec<String>,

    /// Remove the edge between policies I and J before the lesson opens; repeatable,
    /// applied in order with --add-edge.
    #[arg(long = "cut-edge", num_args = 2, value_names = ["I", "J"], action = clap::ArgAction::Append)]
    pub cut_edge: Vec<String>,

    /// Add a policy, last, before the lesson opens: in CATEGORY (the first prototype's
    /// key, e.g. 2 for two hidden layers) where the lesson gives `descriptions`, or `-`
    /// (joined to nothing; join it with --add-edge) where it gives `edges`; repeatable,
    /// applied in order with the other edits.
    #[arg(long = "add-policy", value_name = "CATEGORY", action = clap::ArgAction::Append, allow_hyphen_values = true)]
    pub add_policy: Vec<String>,

    /// Remove policy I and its edges before the lesson opens (the later policies move
    /// down one number); repeatable, applied in order with the other edits.
    #[arg(long = "remove-policy", value_name = "I", action = clap::ArgAction::Append)]
    pub remove_policy: Vec<String>,

    /// Move policy I to CATEGORY (the first prototype's key) before the lesson opens,
    /// where the lesson gives `descriptions` (M follows, eq. 3-5); repeatable, applied in
    /// order with the other edits.
    #[arg(long = "set-category", num_args = 2, value_names = ["I", "CATEGORY"], action = clap::ArgAction::Append)]
    pub set_category: Vec<String>,

    /// Write the lesson, its edits applied, to FILE in the format --config reads, and exit.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["headless", "activate", "run"])]
    pub save: Option<PathBuf>,

    /// The edits in the order given on the command line: (flag, its values).
    #[arg(skip)]
    pub edits: Vec<(&'static str, Vec<String>)>,
}
