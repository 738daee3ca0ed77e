//! The policy library on disk: `<dir>/<name>.safetensors` holds a Q-network's weights,
//! `<dir>/<name>.ron` what they are.
//!
//! The weights file holds one `f32` tensor per parameter, named as PyTorch's `nn.Linear`
//! stores them: `layers.{i}.weight` `[out, in]` and `layers.{i}.bias` `[out]`, input side
//! first, with ReLU between layers. From Python:
//! `safetensors.torch.load_file("p.safetensors")["layers.0.weight"]`.
//!
//! Saving is atomic: both files are written to temporary names in the same directory, the
//! weights are renamed into place first and the metadata last. The metadata carries the
//! SHA-256 of its weights, so an interrupted save (new weights, old metadata) is refused on
//! load rather than read as a mismatched pair.

use std::collections::HashMap;
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use candle_core::{DType, Device};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::dqn::{Architecture, DqnError, QNet};
use crate::env::EnvConfig;
use crate::ron_file::{parse_ron_as, ron_options, ConfigError};

/// Not a policy name: `library.ron` is a source library's manifest.
pub const RESERVED_NAME: &str = "library";

/// The only activation the Q-networks use.
pub const ACTIVATION: &str = "relu";

/// How much training produced a policy.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainingBudget {
    pub episodes: u64,
    pub steps: u64,
}

/// What a caller knows about a policy it saves; the store adds the rest.
#[derive(Debug, Clone, PartialEq)]
pub struct PolicyInfo {
    /// The task it was trained on, with its physics.
    pub source_task: EnvConfig,
    pub training: TrainingBudget,
    pub seed: u64,
    /// Mean return of the greedy test episodes after training, if it was tested.
    pub final_score: Option<f64>,
    /// The library policy this one went on learning from (SAP-Net's chosen policy), as
    /// `<task>/<name>`.
    pub reused: Option<String>,
    /// The file it was imported from, for a policy trained elsewhere.
    pub origin: Option<Origin>,
}

/// What an imported policy's file was.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Format {
    /// `model.save` of a Stable-Baselines3 DQN.
    Sb3Zip,
    /// `torch.save(state_dict)`, torch's zip format.
    TorchStateDict,
    Safetensors,
}

impl Format {
    /// What the format is, for messages.
    pub fn describe(self) -> &'static str {
        match self {
            Format::Sb3Zip => "a Stable-Baselines3 DQN",
            Format::TorchStateDict => "a PyTorch state dict",
            Format::Safetensors => "a safetensors file",
        }
    }
}

/// Where an imported policy came from, recorded in its metadata.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Origin {
    /// The file's name as it was imported (its folder left out).
    pub file: String,
    /// SHA-256 of the file, lowercase hex.
    pub sha256: String,
    pub format: Format,
    /// `Stable-Baselines3 2.9.2`, `PyTorch`, `safetensors`.
    pub framework: String,
    /// The prefix of the layers' keys (`q_net.q_net`, `network`, or empty).
    pub prefix: String,
    /// The environment steps it trained for, where the file says (SB3's `num_timesteps`).
    pub steps: Option<u64>,
}

/// The contents of `<name>.ron`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolicyMetadata {
    pub architecture: Architecture,
    /// Always [`ACTIVATION`]; recorded so the file describes the network on its own.
    pub activation: String,
    /// `EnvConfig::task_name` of the source task.
    pub source_task_name: String,
    pub source_task: EnvConfig,
    pub training: TrainingBudget,
    pub seed: u64,
    pub final_score: Option<f64>,
    /// See [`PolicyInfo::reused`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reused: Option<String>,
    /// See [`PolicyInfo::origin`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub origin: Option<Origin>,
    /// The version of sapnet that wrote the files.
    pub crate_version: String,
    /// SHA-256 of the weights file, lowercase hex: ties the pair together.
    pub weights_sha256: String,
}

/// A policy read from the library.
#[derive(Debug)]
pub struct StoredPolicy {
    pub net: QNet,
    pub metadata: PolicyMetadata,
}

/// Why a policy could not be saved or loaded. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    #[error("policy file {} does not exist", path.display())]
    Missing { path: PathBuf },
    // The OS error is part of the message, not a `source`, so that a chain of errors
    // prints it once.
    #[error("reading policy file {}: {cause}", path.display())]
    Read {
        path: PathBuf,
        cause: std::io::Error,
    },
    #[error("writing policy file {}: {cause}", path.display())]
    Write {
        path: PathBuf,
        cause: std::io::Error,
    },
    #[error(
        "policy name {name:?}: expected {} (and not {RESERVED_NAME:?})",
        crate::safe_io::PORTABLE_NAME
    )]
    InvalidName { name: String },
    /// Reading or parsing a RON file of the store (its message names the file and what it is).
    #[error("{0}")]
    Metadata(ConfigError),
    #[error("policy file {}: {message}", path.display())]
    Invalid { path: PathBuf, message: String },
    #[error("policy weights {} do not match their metadata {}: {mismatch}", weights.display(), metadata.display())]
    Mismatch {
        weights: PathBuf,
        metadata: PathBuf,
        mismatch: String,
    },
    #[error("policy {} does not fit the task: {mismatch}", path.display())]
    DoesNotFit { path: PathBuf, mismatch: String },
}

impl From<ConfigError> for StoreError {
    fn from(error: ConfigError) -> Self {
        StoreError::Metadata(error)
    }
}

/// The two files of policy `name` in `dir`: `(weights, metadata)`.
pub fn paths(dir: &Path, name: &str) -> (PathBuf, PathBuf) {
    (
        dir.join(format!("{name}.safetensors")),
        dir.join(format!("{name}.ron")),
    )
}

/// Writes `net` as policy `name` in `dir` (created if needed), replacing any policy of that
/// name. Returns the metadata written.
pub fn save(
    dir: &Path,
    name: &str,
    net: &QNet,
    info: &PolicyInfo,
) -> Result<PolicyMetadata, StoreError> {
    check_name(name)?;
    crate::safe_io::real_dir(dir).map_err(|source| StoreError::Write {
        path: dir.to_path_buf(),
        cause: source,
    })?;
    let (weights_path, metadata_path) = paths(dir, name);
    let weights_tmp = temporary(&weights_path);
    let metadata_tmp = temporary(&metadata_path);
    let written = write_pair(
        net,
        info,
        [&weights_tmp, &metadata_tmp],
        [&weights_path, &metadata_path],
    );
    if written.is_err() {
        // Best effort: leftovers are hidden `*.tmp` files that load never reads.
        let _ = fs::remove_file(&weights_tmp);
        let _ = fs::remove_file(&metadata_tmp);
    }
    // Make the renames themselves durable; not every platform can open a directory.
    if let Ok(d) = fs::File::open(dir) {
        let _ = d.sync_all();
    }
    written
}

/// Writes both temporary files, then renames weights first and metadata last.
fn write_pair(
    net: &QNet,
    info: &PolicyInfo,
    [weights_tmp, metadata_tmp]: [&Path; 2],
    [weights_path, metadata_path]: [&Path; 2],
) -> Result<PolicyMetadata, StoreError> {
    // "format": "pt" tells Hugging Face tooling the tensors are laid out as PyTorch's.
    let header = HashMap::from([("format".to_string(), "pt".to_string())]);
    let weights = safetensors::serialize(net.named_parameters(), Some(header)).map_err(|e| {
        StoreError::Invalid {
            path: weights_path.to_path_buf(),
            message: format!("cannot serialise weights: {e}"),
        }
    })?;
    write_synced(weights_tmp, &weights)?;

    let metadata = PolicyMetadata {
        architecture: net.architecture().clone(),
        activation: ACTIVATION.to_string(),
        source_task_name: info.source_task.task_name().to_string(),
        source_task: info.source_task.clone(),
        training: info.training.clone(),
        seed: info.seed,
        final_score: info.final_score,
        reused: info.reused.clone(),
        origin: info.origin.clone(),
        crate_version: env!("CARGO_PKG_VERSION").to_string(),
        weights_sha256: sha256_hex(&weights),
    };
    let pretty = ron::ser::PrettyConfig::default().compact_arrays(true);
    let text = ron_options()
        .to_string_pretty(&metadata, pretty)
        .map_err(|e| StoreError::Invalid {
            path: metadata_path.to_path_buf(),
            message: format!("cannot serialise metadata: {e}"),
        })?;
    write_synced(metadata_tmp, format!("{text}\n").as_bytes())?;

    rename(weights_tmp, weights_path)?;
    rename(metadata_tmp, metadata_path)?;
    Ok(metadata)
}

/// Writes `bytes` to `path` through a synced temporary sibling and one rename: a reader
/// sees the old file or the new one, never a part.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), StoreError> {
    let tmp = temporary(path);
    let written = write_synced(&tmp, bytes).and_then(|()| rename(&tmp, path));
    if written.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    if let Some(dir) = path.parent().and_then(|d| fs::File::open(d).ok()) {
        let _ = dir.sync_all();
    }
    written
}

/// Reads policy `name` from `dir`, checking the weights against the metadata.
pub fn load(dir: &Path, name: &str) -> Result<StoredPolicy, StoreError> {
    check_name(name)?;
    let (weights_path, metadata_path) = paths(dir, name);
    if !metadata_path.exists() {
        return Err(StoreError::Missing {
            path: metadata_path,
        });
    }
    let text = crate::ron_file::read_folder_text(&metadata_path)?;
    let metadata: PolicyMetadata = parse_ron_as(
        &text,
        &metadata_path.display().to_string(),
        "policy metadata",
    )?;
    if metadata.activation != ACTIVATION {
        return Err(StoreError::Invalid {
            path: metadata_path,
            message: format!(
                "activation {:?} is not supported (only {ACTIVATION:?})",
                metadata.activation
            ),
        });
    }
    if let Err(e) = metadata.architecture.validate() {
        return Err(StoreError::Invalid {
            path: metadata_path,
            message: e.to_string(),
        });
    }

    if let Some(score) = metadata.final_score.filter(|s| !s.is_finite()) {
        return Err(StoreError::Invalid {
            path: metadata_path,
            message: format!("field `final_score`: expected a finite return, got {score}"),
        });
    }
    // The weights are the parameters' f32s and a JSON header naming them: a file much
    // larger than its architecture needs is not these weights (a link to /dev/zero is
    // refused as a link before that).
    let parameters: usize = metadata
        .architecture
        .parameter_shapes()
        .iter()
        .map(|(_, shape)| shape.iter().product::<usize>())
        .sum();
    let limit = 4 * parameters as u64 + MAX_HEADER_BYTES;
    let weights = read(&weights_path, limit)?;
    let mismatch = |mismatch: String| StoreError::Mismatch {
        weights: weights_path.clone(),
        metadata: metadata_path.clone(),
        mismatch,
    };
    let digest = sha256_hex(&weights);
    if digest != metadata.weights_sha256 {
        return Err(mismatch(format!(
            "the weights' SHA-256 is {digest}, the metadata records {} (an interrupted save, or a file \
             changed by hand)",
            metadata.weights_sha256
        )));
    }
    let mut tensors =
        candle_core::safetensors::load_buffer(&weights, &Device::Cpu).map_err(|e| {
            StoreError::Invalid {
                path: weights_path.clone(),
                message: format!("not a safetensors file: {e}"),
            }
        })?;
    let arch = &metadata.architecture;
    let mut values = Vec::new();
    for (name, shape) in arch.parameter_shapes() {
        let tensor = tensors
            .remove(&name)
            .ok_or_else(|| mismatch(format!("tensor {name} of {arch} is missing")))?;
        if tensor.dims() != shape.as_slice() || tensor.dtype() != DType::F32 {
            return Err(mismatch(format!(
                "tensor {name} is {:?} {:?}, {arch} needs F32 {shape:?}",
                tensor.dtype(),
                tensor.dims()
            )));
        }
        let finite = tensor
            .flatten_all()
            .and_then(|t| t.to_vec1::<f32>())
            .map_err(|e| mismatch(format!("tensor {name}: {e}")))?
            .iter()
            .all(|v| v.is_finite());
        if !finite {
            return Err(StoreError::Invalid {
                path: weights_path.clone(),
                message: format!(
                    "tensor {name} holds a NaN or infinite weight: not a policy to reuse"
                ),
            });
        }
        values.push(tensor);
    }
    if let Some(extra) = tensors.keys().min() {
        return Err(mismatch(format!("tensor {extra} is not part of {arch}")));
    }
    let net = QNet::from_parameters(arch.clone(), values)
        .map_err(|e: DqnError| mismatch(e.to_string()))?;
    Ok(StoredPolicy { net, metadata })
}

/// Reads policy `name` and checks that it fits a task of `observation_size` inputs and
/// `action_count` actions.
pub fn load_for_task(
    dir: &Path,
    name: &str,
    observation_size: usize,
    action_count: usize,
) -> Result<StoredPolicy, StoreError> {
    let policy = load(dir, name)?;
    let arch = &policy.metadata.architecture;
    let mut problems = Vec::new();
    if arch.observation_size != observation_size {
        problems.push(format!(
            "it takes {} observation values, the task gives {observation_size}",
            arch.observation_size
        ));
    }
    if arch.action_count != action_count {
        problems.push(format!(
            "it scores {} actions, the task has {action_count}",
            arch.action_count
        ));
    }
    if problems.is_empty() {
        Ok(policy)
    } else {
        Err(StoreError::DoesNotFit {
            path: paths(dir, name).1,
            mismatch: problems.join("; "),
        })
    }
}

/// Names of the policies in `dir` (those with a metadata file), sorted; none if `dir` does
/// not exist.
pub fn list(dir: &Path) -> Result<Vec<String>, StoreError> {
    names_of(dir, "ron", |_| true)
}

/// Names of the weights files in `dir` that have no metadata beside them (a policy whose
/// `.ron` was lost), sorted.
pub fn orphan_weights(dir: &Path) -> Result<Vec<String>, StoreError> {
    names_of(dir, "safetensors", |path| {
        !path.with_extension("ron").exists()
    })
}

/// The plain names of the files `*.<extension>` in `dir` that `keep` accepts, sorted.
fn names_of(
    dir: &Path,
    extension: &str,
    keep: impl Fn(&Path) -> bool,
) -> Result<Vec<String>, StoreError> {
    let read_error = |cause| StoreError::Read {
        path: dir.to_path_buf(),
        cause,
    };
    let entries = match fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(cause) => return Err(read_error(cause)),
    };
    let mut names = Vec::new();
    for entry in entries {
        let path = entry.map_err(read_error)?.path();
        if path.extension().is_some_and(|e| e == extension) && keep(&path) {
            if let Some(stem) = path.file_stem().and_then(|s| s.to_str()) {
                if check_name(stem).is_ok() {
                    names.push(stem.to_string());
                }
            }
        }
    }
    names.sort();
    Ok(names)
}

/// SHA-256 of `bytes` as lowercase hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

fn check_name(name: &str) -> Result<(), StoreError> {
    if crate::safe_io::is_portable_name(name) && name != RESERVED_NAME {
        Ok(())
    } else {
        Err(StoreError::InvalidName {
            name: name.to_string(),
        })
    }
}

/// The hidden `*.tmp` files a save that never finished (a killed process) left in `dir`.
pub fn temporaries(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut found = Vec::new();
    for entry in fs::read_dir(dir)? {
        let entry = entry?;
        let path = entry.path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if name.starts_with('.') && name.ends_with(".tmp") && entry.file_type()?.is_file() {
            found.push(path);
        }
    }
    Ok(found)
}

/// Removes the hidden `*.tmp` files a save that never finished (a killed process) left in
/// `dir`. For a folder no other process is writing to: a resumed run's, a library being
/// trained again.
pub fn remove_temporaries(dir: &Path) -> std::io::Result<()> {
    for path in temporaries(dir)? {
        fs::remove_file(&path)?;
    }
    Ok(())
}

/// Room for a weights file's JSON header beyond the tensors themselves: the names,
/// shapes and offsets of a 64-layer network take a few kilobytes.
const MAX_HEADER_BYTES: u64 = 1 << 20;

/// A hidden sibling of `path`, unique to this process; `*.tmp` is ignored by git. Its name
/// fits a file system's 255 bytes whatever the policy's name: a long one is cut and told
/// apart from others cut the same by a hash of the whole.
fn temporary(path: &Path) -> PathBuf {
    use std::hash::{Hash, Hasher};
    let file = path
        .file_name()
        .and_then(|f| f.to_str())
        .unwrap_or("policy");
    let pid = std::process::id();
    let whole = format!(".{file}.{pid}.tmp");
    if whole.len() <= 255 {
        return path.with_file_name(whole);
    }
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    file.hash(&mut hasher);
    // Portable names are ASCII: any byte is a character's end.
    let cut = &file[..200.min(file.len())];
    path.with_file_name(format!(".{cut}-{:016x}.{pid}.tmp", hasher.finish()))
}

/// The bytes of a weights file, a regular file of at most `limit` bytes read without
/// following a link.
fn read(path: &Path, limit: u64) -> Result<Vec<u8>, StoreError> {
    crate::safe_io::read(path, crate::safe_io::Links::Refuse, limit).map_err(|source| match source
        .kind()
    {
        std::io::ErrorKind::NotFound => StoreError::Missing {
            path: path.to_path_buf(),
        },
        _ => StoreError::Read {
            path: path.to_path_buf(),
            cause: source,
        },
    })
}

fn write_synced(path: &Path, bytes: &[u8]) -> Result<(), StoreError> {
    let write = || {
        let mut file = crate::safe_io::create(path)?;
        file.write_all(bytes)?;
        file.sync_all()
    };
    write().map_err(|source| StoreError::Write {
        path: path.to_path_buf(),
        cause: source,
    })
}

fn rename(from: &Path, to: &Path) -> Result<(), StoreError> {
    fs::rename(from, to).map_err(|source| StoreError::Write {
        path: to.to_path_buf(),
        cause: source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_temporary_name_fits_255_bytes_for_the_longest_policy_name() {
        let tmp = tempfile::tempdir().unwrap();
        let name = "p".repeat(crate::safe_io::MAX_NAME_BYTES);
        assert!(crate::safe_io::is_portable_name(&name));
        for ext in ["safetensors", "ron"] {
            let path = tmp.path().join(format!("{name}.{ext}"));
            let hidden = temporary(&path);
            let file = hidden.file_name().unwrap().to_str().unwrap();
            assert!(file.len() <= 255 && file.starts_with('.') && file.ends_with(".tmp"));
            std::fs::write(&hidden, b"x").unwrap();
            std::fs::rename(&hidden, &path).unwrap();
        }
        // Two long names cut the same are told apart.
        let other = format!("{}q", "p".repeat(crate::safe_io::MAX_NAME_BYTES - 1));
        assert_ne!(
            temporary(&tmp.path().join(format!("{name}.ron"))),
            temporary(&tmp.path().join(format!("{other}.ron")))
        );
    }
}
