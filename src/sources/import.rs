//! `sapnet sources import`: a policy trained elsewhere ([`crate::checkpoints`]) added to a
//! finished library, written as every library policy is and listed in the manifest's
//! `imported`, so that every run, comparison, screen and sweep reuses it as a source.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use super::manifest::{self, ManifestEntry};
use super::{library_dir, policy_files, source_task};
use crate::checkpoints::{self, Origin, Spaces};
use crate::config::Config;
use crate::dqn::Architecture;
use crate::policy_store::{self, PolicyInfo, TrainingBudget};
use crate::seeds;

/// A policy added to a library.
#[derive(Debug)]
pub struct Imported {
    /// The library's folder.
    pub dir: PathBuf,
    pub architecture: Architecture,
    pub origin: Origin,
    /// The task it was imported for, as labelled in results.
    pub task: String,
    /// Mean return of its greedy test episodes on that task.
    pub score: f64,
    pub test_episodes: u32,
}

/// Imports `file` as policy `name` into the library of `config` under `library`: a finished
/// library (imported policies join a whole one, never one in training) with no policy of that
/// name. The policy is tested greedily on the config's source task for
/// `protocol.test_episodes` episodes, which gives its `final_score`.
pub fn import(
    config: &Config,
    library: &Path,
    file: &Path,
    name: &str,
    prefix: Option<&str>,
) -> Result<Imported> {
    let dir = library_dir(library, config);
    if !crate::safe_io::is_portable_name(name) || name == policy_store::RESERVED_NAME {
        bail!(
            "--name {name:?}: expected a policy name of {} (not {:?})",
            crate::safe_io::PORTABLE_NAME,
            policy_store::RESERVED_NAME
        );
    }
    // `source-<i>` is what a (re)trained library of more sources would plan next.
    let planned_name = name
        .strip_prefix("source-")
        .is_some_and(|i| !i.is_empty() && i.bytes().all(|b| b.is_ascii_digit()));
    if planned_name {
        bail!(
            "--name {name}: names source-<i> belong to the sources a config plans; choose another"
        );
    }
    // Read and checked before the library is touched: a refused file changes nothing.
    let task = source_task(config).clone();
    let (observation_size, action_count) = crate::env::spaces(&task)?;
    let spaces = Spaces {
        observation_size,
        action_count,
    };
    let foreign = checkpoints::read(file, spaces, prefix)
        .map_err(|reason| anyhow::anyhow!("cannot import {}: {reason}", file.display()))?;

    if manifest::read(&dir)?.is_none() {
        bail!(
            "{} holds no finished library to import into: train it first with `sapnet sources \
             --config <FILE> --library {}` (an imported policy joins the sources a config \
             describes)",
            dir.display(),
            library.display()
        );
    }
    // Read again under the lock: a training or another import may have written it since.
    let _lock = crate::folder_lock::FolderLock::acquire(&dir, "library import")?;
    recover_locked(&dir)?;
    let mut found = manifest::read(&dir)?
        .ok_or_else(|| anyhow::anyhow!("{}'s manifest went away", dir.display()))?;
    if !found.complete {
        bail!(
            "the library {} is still being trained ({} of {} policies): finish it with `sapnet \
             sources --config <FILE>` before importing",
            dir.display(),
            found.policies.len(),
            found.training.count()
        );
    }
    if policy_files(&dir)?.iter().any(|n| n == name)
        || found
            .policies
            .iter()
            .chain(&found.imported)
            .any(|e| e.name == name)
    {
        bail!(
            "{} already holds a policy named {name}: choose another --name",
            dir.display()
        );
    }

    let episodes = config.protocol.test_episodes.max(1);
    let seed = seeds::derive(
        config.seed,
        &[seeds::Part::Name("import"), seeds::Part::Name(name)],
    );
    let mut env = crate::env::make(&task)?;
    let returns = crate::trainer::test_greedy(&foreign.net, env.as_mut(), episodes, seed)?;
    let score = returns.iter().sum::<f64>() / returns.len() as f64;
    let info = PolicyInfo {
        source_task: task.as_recorded(),
        // sapnet trained it for nothing; the file's own budget is in `origin`.
        training: TrainingBudget {
            episodes: 0,
            steps: 0,
        },
        seed: 0,
        final_score: Some(score),
        reused: None,
        origin: Some(foreign.origin.clone()),
    };
    // The journal first: from here until the manifest lists the policy, a kill leaves a
    // record of what to take back (`recover`).
    let journal = dir.join(JOURNAL);
    crate::safe_io::write_atomically(&journal, |out| out.write_all(name.as_bytes()))
        .with_context(|| format!("writing {}", journal.display()))?;
    crate::failpoint::point("import-journal-written");
    policy_store::save(&dir, name, &foreign.net, &info)
        .with_context(|| format!("writing {name} to {}", dir.display()))?;
    crate::failpoint::point("import-policy-written");
    let listed = ManifestEntry::of_policy(&dir, name)
        .map_err(anyhow::Error::from)
        .and_then(|(entry, _)| {
            found.imported.push(entry);
            manifest::write(&dir, &found).map_err(anyhow::Error::from)
        });
    if let Err(err) = listed {
        // Not listed, the files would make the library refuse itself: take them back.
        let (weights, metadata) = policy_store::paths(&dir, name);
        let _ = std::fs::remove_file(metadata);
        let _ = std::fs::remove_file(weights);
        return Err(err.context(format!(
            "adding {name} to {}",
            manifest::path(&dir).display()
        )));
    }
    crate::failpoint::point("import-listed");
    std::fs::remove_file(&journal).with_context(|| format!("removing {}", journal.display()))?;
    Ok(Imported {
        dir,
        architecture: foreign.net.architecture().clone(),
        origin: foreign.origin,
        task: task.label().trim_end().to_string(),
        score,
        test_episodes: episodes,
    })
}

/// An import in progress, in the library's folder: the name of the policy being added.
/// Written before the policy's files, removed once the manifest lists them.
const JOURNAL: &str = ".import-in-progress";

/// What a killed import or save left in the library `dir`, finished by the next command
/// that reads it: taken back if the manifest does not list its policy (the library as it
/// was), its journal dropped if it does (the import had finished), a save's hidden
/// temporaries removed. Takes the library's lock if there is anything to do; returns what
/// was done, one sentence each, also said on stderr.
pub fn recover(dir: &Path) -> Result<Vec<String>> {
    let temporaries = policy_store::temporaries(dir).unwrap_or_default();
    if !dir.join(JOURNAL).exists() && temporaries.is_empty() {
        return Ok(Vec::new());
    }
    let _lock = crate::folder_lock::FolderLock::acquire(dir, "a library repair")?;
    recover_locked(dir)
}

/// [`recover`], the lock held by the caller.
pub fn recover_locked(dir: &Path) -> Result<Vec<String>> {
    let mut done = Vec::new();
    let journal = dir.join(JOURNAL);
    if std::fs::symlink_metadata(&journal).is_ok() {
        let name = crate::safe_io::read_text(&journal, crate::safe_io::Links::Refuse, 1024)
            .with_context(|| format!("reading {}", journal.display()))?;
        if !crate::safe_io::is_portable_name(&name) {
            bail!(
                "{}: names the policy {name:?}, expected {}; remove the file",
                journal.display(),
                crate::safe_io::PORTABLE_NAME
            );
        }
        let listed =
            manifest::read(dir)?.is_some_and(|m| m.imported.iter().any(|e| e.name == name));
        if listed {
            done.push(format!(
                "the import of {name} had finished: its journal is removed"
            ));
        } else {
            let (weights, metadata) = policy_store::paths(dir, &name);
            for file in [metadata, weights] {
                match std::fs::remove_file(&file) {
                    Ok(()) => {}
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                    Err(e) => {
                        return Err(e).with_context(|| format!("removing {}", file.display()))
                    }
                }
            }
            done.push(format!(
                "the import of {name} was stopped before the manifest listed it: its files are \
                 removed, the library is as before"
            ));
        }
        std::fs::remove_file(&journal)
            .with_context(|| format!("removing {}", journal.display()))?;
    }
    let temporaries =
        policy_store::temporaries(dir).with_context(|| format!("listing {}", dir.display()))?;
    if !temporaries.is_empty() {
        policy_store::remove_temporaries(dir).with_context(|| {
            format!("removing a killed save's leftovers from {}", dir.display())
        })?;
        done.push(format!(
            "{} leftover temporary {} of a killed save removed",
            temporaries.len(),
            if temporaries.len() == 1 {
                "file"
            } else {
                "files"
            }
        ));
    }
    for said in &done {
        eprintln!("{}: {said}", dir.display());
    }
    Ok(done)
}
