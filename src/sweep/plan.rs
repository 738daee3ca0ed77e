//! `sapnet sweep plan`: a grid expanded into `SWEEP/cells/NNNN.ron`, the manifest, and the
//! command lines that fan the cells out (a Slurm array job, GNU parallel).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use super::grid::Grid;
use crate::results::sweep::{cell_config, describe, CellEntry, Manifest};

use crate::env::PythonSettings;
use crate::policy_store::{sha256_hex, write_atomically};
use crate::ron_file::ron_options;

/// What to plan.
pub struct PlanOptions {
    pub grid: PathBuf,
    /// `--config`: the base, instead of the grid's `base`.
    pub config: Option<PathBuf>,
    pub out: PathBuf,
    /// The library root the cells reuse.
    pub library: PathBuf,
    /// `--python`, `--module-dir`, `--allow-module`: how the cells' Gymnasium tasks run.
    pub python: PythonSettings,
}

/// Writes the sweep and returns its manifest. Planning the same grid again into the same
/// folder changes nothing; a folder that holds another sweep is refused.
pub fn plan(options: &PlanOptions) -> Result<Manifest> {
    let grid = Grid::read(&options.grid)?;
    let origin = options.grid.display().to_string();
    let grid_name = options
        .grid
        .file_name()
        .map_or(origin.clone(), |n| n.to_string_lossy().into_owned());
    let base = grid.base_config(&options.grid, options.config.as_deref())?;
    let cells = grid.cells(&base, &origin)?;
    let sweep = absolute(&options.out)?;
    let library = absolute(&options.library)?;

    // The cells record their tasks only; how this machine runs them goes on the command
    // lines, which are the user's to read and run.
    let python = worker_flags(&cells, &options.python);
    for word in [&sweep, &library].into_iter().chain(&python.paths) {
        refuse_control_characters(word)?;
    }
    let texts: Vec<String> = cells
        .iter()
        .enumerate()
        .map(|(id, cell)| {
            let pretty = ron::ser::PrettyConfig::default().compact_arrays(true);
            let config = ron_options()
                .to_string_pretty(&cell.config.as_recorded(), pretty)
                .context("a cell's config")?;
            // The grid by its file name only: the same grid planned from another working
            // directory gives the same cells, to the byte.
            Ok(format!(
                "// Cell {id} of the sweep planned from {grid_name}: {}\n{config}\n",
                describe(&cell.axes)
            ))
        })
        .collect::<Result<_>>()?;
    let manifest = Manifest {
        grid: absolute(&options.grid)?,
        library,
        cells: cells
            .iter()
            .zip(&texts)
            .enumerate()
            .map(|(id, (cell, text))| CellEntry {
                id,
                axes: cell.axes.clone(),
                config_sha256: sha256_hex(text.as_bytes()),
            })
            .collect(),
    };
    if sweep.join("sweep.ron").exists() {
        let found = Manifest::read(&sweep)?;
        if found.cells != manifest.cells || found.library != manifest.library {
            bail!(
                "{} holds another sweep (its cells or library differ); plan into another --out",
                sweep.display()
            );
        }
        // The same sweep planned again: a cell file edited since is written back as planned
        // (a cell runs only the config its manifest hashes).
        for (entry, text) in found.cells.iter().zip(&texts) {
            let path = cell_config(&sweep, entry.id);
            let now = std::fs::read(&path).ok().map(|bytes| sha256_hex(&bytes));
            if now.as_deref() != Some(entry.config_sha256.as_str()) {
                write_atomically(&path, text.as_bytes())?;
            }
        }
        return Ok(found);
    }
    for dir in ["cells", "results", "failed", "logs"] {
        crate::safe_io::real_dir(&sweep.join(dir))
            .with_context(|| format!("{}", sweep.join(dir).display()))?;
    }
    for (id, text) in texts.iter().enumerate() {
        write_atomically(&cell_config(&sweep, id), text.as_bytes())?;
    }
    let exe = std::env::current_exe().context("finding the sapnet binary")?;
    refuse_control_characters(&exe)?;
    let n = manifest.cells.len();
    write_atomically(
        &sweep.join("slurm.sbatch"),
        slurm_script(&exe, &sweep, n, &python.words).as_bytes(),
    )?;
    write_atomically(
        &sweep.join("parallel.txt"),
        parallel_lines(&exe, &sweep, n, &python.words).as_bytes(),
    )?;
    // The manifest last: a folder with one is a whole plan.
    manifest.write(&sweep)?;
    Ok(manifest)
}

/// An array job with one task per cell, one CPU each, a log pair per cell. Every path is
/// shell-quoted: a sweep folder named `a b` or `$(…)` is a name, never a command.
pub fn slurm_script(exe: &Path, sweep: &Path, cells: usize, flags: &str) -> String {
    let (exe, sweep_q) = (quote(exe), quote(sweep));
    // `#SBATCH` lines are read by sbatch, not the shell: a path with a space or a quote
    // cannot be said there, so the logs go to the working directory's default and are
    // named in the script's first lines instead.
    let logs = if plain(sweep) {
        format!(
            "#SBATCH --output={s}/logs/%a.out\n#SBATCH --error={s}/logs/%a.err\n",
            s = sweep.display()
        )
    } else {
        String::new()
    };
    format!(
        "#!/bin/bash\n\
         # The {cells} cells of {sweep_q} as a Slurm array job: `sbatch {sweep_q}/slurm.sbatch`.\n\
         # Throttle with `sbatch --array=0-{last}%8 …`; rerun only some cells by their\n\
         # numbers, e.g. `sbatch --array=0,{last} …` (`sapnet sweep status {sweep_q}` lists\n\
         # what failed).\n\
         #SBATCH --job-name=sapnet-sweep\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --cpus-per-task=1\n\
         {logs}\
         exec {exe} sweep run {sweep_q} --jobs 1{flags}\n",
        last = cells.saturating_sub(1)
    )
}

/// GNU parallel command lines: here, over machines, and rerunning what failed. `-q`
/// (`--quote`) passes the quoted paths to each job as the words they are (without it,
/// parallel joins the command's words and a shell splits them again).
pub fn parallel_lines(exe: &Path, sweep: &Path, cells: usize, flags: &str) -> String {
    let (exe, sweep) = (quote(exe), quote(sweep));
    let last = cells.saturating_sub(1);
    let log = quote_joined(&sweep, "/parallel.log");
    format!(
        "# The {cells} cells of {sweep} with GNU parallel, one core each, on this machine:\n\
         parallel -q --joblog {log} -j 2 {exe} sweep run {sweep} --cell {{}} --jobs 1{flags} ::: $(seq 0 {last})\n\
         # Over machines that share the sweep folder (and have sapnet at the same path):\n\
         parallel -q --joblog {log} --sshloginfile HOSTS {exe} sweep run {sweep} --cell {{}} --jobs 1{flags} ::: $(seq 0 {last})\n\
         # Rerun only the cells that failed (a finished cell is skipped anyway):\n\
         parallel --retry-failed --joblog {log}\n"
    )
}

/// How the cells' Gymnasium tasks run, for their command lines.
struct WorkerFlags {
    /// ` --python '…' --allow-module '…'`, each value one quoted word (empty: none).
    words: String,
    /// The paths among them.
    paths: Vec<PathBuf>,
}

/// The flags the planner gave, else what the cells' own configs (the user's grid and
/// config) name: their interpreter, their module folder, and the modules their ids import.
fn worker_flags(cells: &[super::grid::Cell], given: &PythonSettings) -> WorkerFlags {
    let tasks = || {
        cells
            .iter()
            .flat_map(|c| c.config.tasks())
            .filter_map(|(_, t)| match t {
                crate::env::EnvConfig::Gymnasium(p) => Some((t, p)),
                _ => None,
            })
    };
    let interpreter = given
        .interpreter
        .clone()
        .or_else(|| tasks().find_map(|(_, p)| p.python.clone()));
    let module_dir = given
        .module_dir
        .clone()
        .or_else(|| tasks().find_map(|(_, p)| p.module_dir.clone()));
    let mut modules = given.allowed_modules.clone();
    for (task, _) in tasks() {
        if let Some(module) = task.imported_module() {
            if !modules.iter().any(|m| m == module) {
                modules.push(module.to_string());
            }
        }
    }
    let mut words = String::new();
    let mut paths = Vec::new();
    for (flag, path) in [("--python", interpreter), ("--module-dir", module_dir)] {
        if let Some(path) = path {
            let path = absolute(&path).unwrap_or(path);
            words.push_str(&format!(" {flag} {}", quote(&path)));
            paths.push(path);
        }
    }
    for module in modules {
        words.push_str(&format!(" --allow-module {}", quote(Path::new(&module))));
    }
    WorkerFlags { words, paths }
}

/// A path written into the sweep's scripts must not hold a control character: a newline
/// would end a comment line of `slurm.sbatch` and run the rest as a command.
fn refuse_control_characters(path: &Path) -> Result<()> {
    let text = path.display().to_string();
    if let Some(c) = text.chars().find(|c| c.is_control()) {
        bail!(
            "{text:?}: a path in a sweep's scripts may not hold a control character (found \
             {c:?}); choose another"
        );
    }
    Ok(())
}

/// `path` as one shell word: in single quotes, each `'` written `'\''`.
pub fn quote(path: &Path) -> String {
    format!("'{}'", path.display().to_string().replace('\'', "'\\''"))
}

/// A quoted word with `tail` appended inside its quotes.
fn quote_joined(quoted: &str, tail: &str) -> String {
    format!("{}{tail}'", &quoted[..quoted.len() - 1])
}

/// Whether `path` needs no quoting anywhere (letters, digits and `/._-+,=:@`).
fn plain(path: &Path) -> bool {
    path.display()
        .to_string()
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || "/._-+,=:@".contains(c))
}

pub(super) fn absolute(path: &Path) -> Result<PathBuf> {
    if path.is_absolute() {
        return Ok(path.to_path_buf());
    }
    Ok(std::env::current_dir()
        .context("the working directory")?
        .join(path))
}
