//! Adding a run's chosen policy to the policy library (Algorithm 3's last step), beside
//! the sources and never over them.

use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::config::Config;
use crate::dqn::QNet;
use crate::policy_store::{self, PolicyInfo, TrainingBudget};
use crate::sources;
use crate::trainer::RunRecord;

/// The library directory that receives SAP-Net's chosen policies, and the prefix that tells
/// one experiment's from another's.
pub struct LibraryCopies {
    pub dir: PathBuf,
    prefix: String,
}

impl LibraryCopies {
    pub fn new(config: &Config, out_dir: &Path, library: &Path) -> Self {
        // A policy's name is portable (`crate::safe_io::is_portable_name`): the folder's
        // name with anything else as `-`, and no leading dot (hidden files are the store's
        // temporaries).
        let prefix = out_dir
            .file_name()
            .map(|n| {
                n.to_string_lossy()
                    .chars()
                    .map(|c| match c {
                        'a'..='z' | 'A'..='Z' | '0'..='9' | '.' | '-' | '_' => c,
                        _ => '-',
                    })
                    .collect::<String>()
                    .trim_start_matches('.')
                    .chars()
                    .take(200)
                    .collect::<String>()
            })
            .filter(|n| !n.is_empty())
            .unwrap_or_else(|| "results".into());
        Self {
            dir: library.join(config.env.task_name()).join("chosen"),
            prefix,
        }
    }

    /// Writes `net` under a name no policy in the directory has yet (`…-2`, `…-3` after
    /// the first), and returns the path of its metadata file.
    pub fn add(&self, file_name: &str, net: &QNet, info: &PolicyInfo) -> Result<PathBuf> {
        // A library from elsewhere may hold a link where `<task>/` or `chosen/` belongs:
        // the copy goes into real directories or nowhere.
        if let Some(task) = self.dir.parent() {
            crate::safe_io::real_dir(task).with_context(|| format!("{}", task.display()))?;
        }
        crate::safe_io::real_dir(&self.dir).with_context(|| format!("{}", self.dir.display()))?;
        let base = format!("{}-{file_name}", self.prefix);
        let mut k = 1;
        let (name, metadata) = loop {
            let name = match k {
                1 => base.clone(),
                k => format!("{base}-{k}"),
            };
            let (weights, metadata) = policy_store::paths(&self.dir, &name);
            // The metadata file is claimed by creating it, so that another sapnet writing
            // to the same library at the same time cannot take the same name; the store's
            // save then renames the real metadata over this placeholder.
            if !weights.exists() {
                match std::fs::OpenOptions::new()
                    .write(true)
                    .create_new(true)
                    .custom_flags(libc::O_NOFOLLOW)
                    .open(&metadata)
                {
                    Ok(_) => break (name, metadata),
                    Err(err) if err.kind() == std::io::ErrorKind::AlreadyExists => {}
                    Err(err) => {
                        return Err(err).with_context(|| format!("creating {}", metadata.display()))
                    }
                }
            }
            k += 1;
        };
        if let Err(err) = policy_store::save(&self.dir, &name, net, info) {
            let _ = std::fs::remove_file(&metadata);
            return Err(err.into());
        }
        Ok(metadata)
    }
}

/// The metadata of a run's trained network: its task, budget, seed, greedy score and, for
/// a reusing run, the source it fine-tuned.
pub fn policy_info(config: &Config, record: &RunRecord) -> PolicyInfo {
    let final_score = (!record.test_returns.is_empty())
        .then(|| record.test_returns.iter().sum::<f64>() / record.test_returns.len() as f64);
    let reused = record
        .chosen
        .as_ref()
        .map(|chosen| format!("{}/{}", sources::library_name(config), chosen.name));
    PolicyInfo {
        source_task: config.env.as_recorded(),
        training: TrainingBudget {
            episodes: u64::from(record.episodes),
            steps: record.steps,
        },
        seed: record.seed,
        final_score,
        reused,
        origin: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chosen_copy_skips_names_taken_or_being_written() {
        use rand::SeedableRng;
        let tmp = tempfile::tempdir().unwrap();
        let copies = LibraryCopies::new(
            &Config::default(),
            &tmp.path().join(".hidden-out"),
            &tmp.path().join("lib"),
        );
        let net = QNet::new(
            crate::dqn::Architecture::new(4, &[3], 2),
            &mut rand::rngs::StdRng::seed_from_u64(0),
        )
        .unwrap();
        let info = PolicyInfo {
            source_task: Config::default().env,
            training: TrainingBudget {
                episodes: 1,
                steps: 1,
            },
            seed: 0,
            final_score: None,
            reused: None,
            origin: None,
        };
        // A leading dot would make a hidden name, which the store refuses.
        let first = copies.add("sapnet-run0", &net, &info).unwrap();
        assert!(first.ends_with("lib/cartpole/chosen/hidden-out-sapnet-run0.ron"));
        // Another process has claimed "-2" but not written it yet.
        std::fs::write(copies.dir.join("hidden-out-sapnet-run0-2.ron"), "").unwrap();
        let third = copies.add("sapnet-run0", &net, &info).unwrap();
        assert!(third.ends_with("hidden-out-sapnet-run0-3.ron"));
        assert!(policy_store::load(&copies.dir, "hidden-out-sapnet-run0-3").is_ok());
        assert_eq!(
            std::fs::read(copies.dir.join("hidden-out-sapnet-run0-2.ron")).unwrap(),
            b""
        );
    }
}
