//! The results directory before a protocol writes to it: created, and refused if it
//! holds results, unless they are to be replaced (`--force`: moved aside, deleted last).

use std::path::PathBuf;

use anyhow::{bail, Context, Result};

use super::OutputOptions;
use crate::report;
use crate::results::records;

/// Entries that mark a directory as holding results already.
const RESULT_FILES: [&str; 7] = [
    "episodes.csv",
    "tests.csv",
    "activations.csv",
    "trace.csv",
    "summary.json",
    "policies",
    records::RUNS,
];

/// Where `--force` moves the results it replaces until the new ones are written.
const REPLACED: &str = ".replaced";

/// Creates the output directory and refuses to mix new results with old ones. With
/// `force`, the old results are moved into `<dir>/.replaced/` (returned), to be deleted
/// once the new ones are written: a directory where nothing can be written loses nothing.
pub(super) fn prepare_output(output: &OutputOptions) -> Result<Option<PathBuf>> {
    let dir = &output.dir;
    if dir.exists() && !dir.is_dir() {
        bail!(
            "--out {}: expected a directory for the results, and it is a file",
            dir.display()
        );
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("creating the output directory {}", dir.display()))?;
    let existing: Vec<&str> = RESULT_FILES
        .into_iter()
        .chain(["comparison.csv"])
        .filter(|f| dir.join(f).exists())
        .collect();
    if existing.is_empty() {
        return Ok(None);
    }
    if !output.force {
        bail!(
            "the output directory {} already holds results ({}); choose another --out, pass \
             --force to replace them, or --resume to finish them",
            dir.display(),
            existing.join(", ")
        );
    }
    let replaced = dir.join(REPLACED);
    if replaced.exists() {
        // A replacement that never finished: its results were replaced already.
        std::fs::remove_dir_all(&replaced)
            .with_context(|| format!("removing {}", replaced.display()))?;
    }
    std::fs::create_dir(&replaced).with_context(|| {
        format!(
            "cannot replace the results in {}: creating {}",
            dir.display(),
            replaced.display()
        )
    })?;
    let mut moved = Vec::new();
    for name in RESULT_FILES.iter().chain(report::FILES.iter()) {
        let (from, to) = (dir.join(name), replaced.join(name));
        if !from.exists() {
            continue;
        }
        if let Err(err) = std::fs::rename(&from, &to) {
            // Put back what moved: the old results stay as they were.
            for (from, to) in moved.iter().rev() {
                let _ = std::fs::rename(to, from);
            }
            let _ = std::fs::remove_dir(&replaced);
            return Err(err).with_context(|| {
                format!(
                    "cannot replace the results in {}: moving {} aside; nothing was changed",
                    dir.display(),
                    from.display()
                )
            });
        }
        moved.push((from, to));
    }
    Ok(Some(replaced))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forced_results_move_aside_until_the_new_ones_are_written() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        std::fs::write(dir.join("episodes.csv"), "old").unwrap();
        std::fs::create_dir(dir.join("policies")).unwrap();
        std::fs::write(dir.join("policies/p.ron"), "old").unwrap();
        let refused = prepare_output(&OutputOptions {
            dir: dir.clone(),
            force: false,
        });
        assert!(format!("{:#}", refused.unwrap_err()).contains("--resume"));

        let replaced = prepare_output(&OutputOptions {
            dir: dir.clone(),
            force: true,
        })
        .unwrap()
        .unwrap();
        assert!(!dir.join("episodes.csv").exists());
        assert_eq!(
            std::fs::read_to_string(replaced.join("policies/p.ron")).unwrap(),
            "old"
        );
    }
}
