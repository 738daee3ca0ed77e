//! `<library>/<task>/library.ron`: what a source library holds and how it was trained.
//!
//! `sapnet sources` writes the manifest before it trains anything (`complete: false`), adds
//! each policy's hashes as soon as the policy is on disk and sets `complete: true` last, so
//! a library is usable only once whole, an interrupted training resumes where it stopped,
//! and a run can tell a finished library from a half-written or hand-edited one. Policies
//! imported into a finished library are listed apart from the planned ones.

use std::fs;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::SourceTask;
use crate::config::Config;
use crate::dqn::DqnConfig;
use crate::policy_store::{self, PolicyMetadata, StoreError};
use crate::ron_file::{parse_ron_as, ron_options};

/// The manifest's file name inside `<library>/<task>/`.
pub const FILE: &str = "library.ron";

/// The contents of `library.ron`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// False while `sapnet sources` is still training: runs refuse the library.
    pub complete: bool,
    /// The part of the config that decides the library's contents.
    pub training: LibraryTraining,
    /// The policies on disk, in the plan's order.
    pub policies: Vec<ManifestEntry>,
    /// Policies trained elsewhere and added by `sapnet sources import`, in the order they
    /// came; kept when the library is trained again. Their seed is 0: sapnet drew none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub imported: Vec<ManifestEntry>,
    /// The version of sapnet that wrote the manifest.
    pub crate_version: String,
}

/// What `sapnet sources` reads from a config: equal trainings give equal libraries.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LibraryTraining {
    /// The source tasks, each with how many policies train on it, in the plan's order.
    pub tasks: Vec<SourceTask>,
    pub hidden_layers: (usize, usize),
    pub units: (usize, usize),
    pub training_episodes: u32,
    pub dqn: DqnConfig,
    /// Greedy episodes that measure each policy's `final_score`.
    pub test_episodes: u32,
    pub seed: u64,
}

/// One policy of the library and the hashes of its two files.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ManifestEntry {
    pub name: String,
    pub hidden: Vec<usize>,
    pub seed: u64,
    pub weights_sha256: String,
    pub metadata_sha256: String,
}

impl LibraryTraining {
    /// The library `config` describes.
    pub fn of(config: &Config) -> Self {
        let s = &config.sources;
        Self {
            tasks: super::tasks(config)
                .into_iter()
                .map(|t| SourceTask {
                    env: t.env.as_recorded(),
                    ..t
                })
                .collect(),
            hidden_layers: s.hidden_layers,
            units: s.units,
            training_episodes: s.training_episodes,
            dqn: s.dqn.clone().unwrap_or_else(|| config.dqn.clone()),
            test_episodes: config.protocol.test_episodes,
            seed: config.seed,
        }
    }

    /// N, the policies of every task.
    pub fn count(&self) -> usize {
        self.tasks.iter().map(|t| t.count).sum()
    }

    /// The settings in which `library` (a library's record) trained its sources otherwise
    /// than this config describes, as `field: the config's X, the library's Y`, the DQN's
    /// settings field by field. The seed, the test episodes, the count and the task are
    /// left out: a run with another `--seed` reuses the same library on purpose, tests only
    /// measure, and a run checks the count and the task itself.
    pub fn differences(&self, library: &Self) -> Vec<String> {
        self.compare(library, false)
    }

    /// Every setting in which `library` differs, the seed and the count included.
    pub fn all_differences(&self, library: &Self) -> Vec<String> {
        self.compare(library, true)
    }

    fn compare(&self, library: &Self, all: bool) -> Vec<String> {
        let mut found = Vec::new();
        let mut compare = |field: &str, config: String, library: String| {
            if config != library {
                found.push(format!(
                    "{field}: the config's {config}, the library's {library}"
                ));
            }
        };
        if all {
            compare("source tasks", tasks(&self.tasks), tasks(&library.tasks));
        }
        compare(
            "sources.hidden_layers",
            format!("{:?}", self.hidden_layers),
            format!("{:?}", library.hidden_layers),
        );
        compare(
            "sources.units",
            format!("{:?}", self.units),
            format!("{:?}", library.units),
        );
        compare(
            "sources.training_episodes",
            self.training_episodes.to_string(),
            library.training_episodes.to_string(),
        );
        for (field, config, library) in dqn_differences(&self.dqn, &library.dqn) {
            compare(&format!("the sources' dqn.{field}"), config, library);
        }
        if all {
            compare(
                "protocol.test_episodes",
                self.test_episodes.to_string(),
                library.test_episodes.to_string(),
            );
            compare("seed", self.seed.to_string(), library.seed.to_string());
        }
        found
    }
}

/// The DQN settings that differ, as (field, ours, theirs) in RON: one line per field rather
/// than the whole section twice.
fn dqn_differences(ours: &DqnConfig, theirs: &DqnConfig) -> Vec<(String, String, String)> {
    let fields = |dqn: &DqnConfig| match serde_json::to_value(dqn) {
        Ok(serde_json::Value::Object(fields)) => fields,
        _ => serde_json::Map::new(),
    };
    let (ours_fields, theirs_fields) = (fields(ours), fields(theirs));
    if ours_fields.is_empty() || theirs_fields.is_empty() {
        // Not a map (cannot happen for a struct): say the whole section.
        return vec![("(all)".into(), ron(ours), ron(theirs))];
    }
    ours_fields
        .iter()
        .filter(|(name, value)| theirs_fields.get(*name) != Some(value))
        .map(|(name, value)| {
            let text = |v: Option<&serde_json::Value>| match v {
                Some(serde_json::Value::String(s)) => s.clone(),
                Some(v) => v.to_string(),
                None => "-".into(),
            };
            (
                name.clone(),
                text(Some(value)),
                text(theirs_fields.get(name)),
            )
        })
        .collect()
}

fn tasks(tasks: &[SourceTask]) -> String {
    tasks
        .iter()
        .map(|t| format!("{} ×{}", t.label, t.count))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A config value as its RON text, for messages.
fn ron<T: Serialize>(value: &T) -> String {
    ron_options()
        .to_string(value)
        .unwrap_or_else(|e| format!("<{e}>"))
}

impl ManifestEntry {
    /// Hashes policy `name` as it is on disk in `dir`, checking the pair on the way; with
    /// the policy's metadata.
    pub fn of_policy(dir: &Path, name: &str) -> Result<(Self, PolicyMetadata), StoreError> {
        let policy = policy_store::load(dir, name)?;
        let metadata_path = policy_store::paths(dir, name).1;
        let bytes = fs::read(&metadata_path).map_err(|source| StoreError::Read {
            path: metadata_path,
            cause: source,
        })?;
        let entry = Self {
            name: name.to_string(),
            hidden: policy.metadata.architecture.hidden.clone(),
            seed: policy.metadata.seed,
            weights_sha256: policy.metadata.weights_sha256.clone(),
            metadata_sha256: policy_store::sha256_hex(&bytes),
        };
        Ok((entry, policy.metadata))
    }
}

/// The manifest's path in `dir`.
pub fn path(dir: &Path) -> PathBuf {
    dir.join(FILE)
}

/// Reads `dir`'s manifest; `None` when there is none.
pub fn read(dir: &Path) -> Result<Option<Manifest>, StoreError> {
    let path = path(dir);
    if !path.exists() {
        return Ok(None);
    }
    let text = crate::ron_file::read_folder_text(&path)?;
    let manifest: Manifest = parse_ron_as(&text, &path.display().to_string(), "library manifest")?;
    // A library may come from elsewhere: every name it lists becomes a file name and a
    // column of activations.csv.
    let entries = manifest.policies.iter().chain(&manifest.imported);
    if let Some(entry) = entries
        .into_iter()
        .find(|e| !crate::safe_io::is_portable_name(&e.name))
    {
        return Err(StoreError::Invalid {
            path,
            message: format!(
                "the library manifest lists a policy named {:?}: expected {}",
                entry.name,
                crate::safe_io::PORTABLE_NAME
            ),
        });
    }
    Ok(Some(manifest))
}

/// Replaces `dir`'s manifest in one rename, so a reader sees the old one or the new one.
pub fn write(dir: &Path, manifest: &Manifest) -> Result<(), StoreError> {
    let path = path(dir);
    let pretty = ron::ser::PrettyConfig::default().compact_arrays(true);
    let text = ron_options()
        .to_string_pretty(manifest, pretty)
        .map_err(|e| StoreError::Invalid {
            path: path.clone(),
            message: format!("cannot serialise the manifest: {e}"),
        })?;
    policy_store::write_atomically(&path, format!("{text}\n").as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_manifest_reads_back_as_written() {
        let tmp = tempfile::tempdir().unwrap();
        let manifest = Manifest {
            complete: false,
            training: LibraryTraining::of(&Config::default()),
            policies: vec![ManifestEntry {
                name: "source-0".into(),
                hidden: vec![3, 4],
                seed: 9,
                weights_sha256: "ab".into(),
                metadata_sha256: "cd".into(),
            }],
            imported: Vec::new(),
            crate_version: "0".into(),
        };
        assert_eq!(read(tmp.path()).unwrap(), None);
        write(tmp.path(), &manifest).unwrap();
        assert_eq!(read(tmp.path()).unwrap(), Some(manifest));
    }

    #[test]
    fn a_broken_manifest_is_named_as_one() {
        let dir = tempfile::tempdir().unwrap();
        fs::write(path(dir.path()), "(complete: tru").unwrap();
        let err = read(dir.path()).unwrap_err().to_string();
        assert!(
            err.starts_with(&format!(
                "library manifest {}: line 1",
                path(dir.path()).display()
            )),
            "{err}"
        );
    }

    #[test]
    fn differences_name_the_field_and_ignore_the_seed() {
        let ours = LibraryTraining::of(&Config::default());
        let mut theirs = ours.clone();
        theirs.seed += 1;
        theirs.test_episodes += 1;
        assert!(ours.differences(&theirs).is_empty());
        theirs.training_episodes = 3;
        theirs.dqn.learning_rate *= 2.0;
        let found = ours.differences(&theirs);
        assert_eq!(found.len(), 2, "{found:?}");
        assert_eq!(
            found[0],
            "sources.training_episodes: the config's 5000, the library's 3"
        );
        assert_eq!(
            found[1],
            "the sources' dqn.learning_rate: the config's 0.001, the library's 0.002"
        );
    }
}
