//! Q-networks trained elsewhere, read as sapnet's: a Stable-Baselines3 DQN `.zip`, a PyTorch
//! state dict (`.pt`, `.pth`, CleanRL's `.cleanrl_model`) or a safetensors file of a plain
//! MLP of linear layers with ReLU between them. The format is told from the bytes, not the
//! name; nothing in a file is run; what sapnet's Q-network cannot represent is refused with
//! the reason.
//!
//! - [`pickle`]: a pickle reader that runs nothing;
//! - [`torch_zip`]: `torch.save`'s archive;
//! - [`sb3`]: an SB3 DQN's zip;
//! - [`mlp`]: named tensors read as linear layers.
//!
//! [`crate::sources::import`] adds what is read here to a library.

use std::path::Path;

use crate::dqn::{Architecture, QNet};
pub use crate::policy_store::{Format, Origin};
use candle_core::{Device, Tensor};

pub mod mlp;
pub mod pickle;
pub mod sb3;
pub mod torch_zip;

/// The largest file an import reads: policies are kilobytes to a few megabytes.
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// A parameter as a framework stored it, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedTensor {
    pub name: String,
    pub shape: Vec<usize>,
    pub values: Vec<f32>,
}

/// The sizes of the task a policy must fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Spaces {
    pub observation_size: usize,
    pub action_count: usize,
}

/// A network read from a foreign file.
#[derive(Debug)]
pub struct Foreign {
    pub net: QNet,
    pub origin: Origin,
}

/// Reads the policy in `path`, which must fit `task`: its weights copied bit for bit into
/// sapnet's Q-network. `prefix` picks one network of a state dict holding several.
pub fn read(path: &Path, task: Spaces, prefix: Option<&str>) -> Result<Foreign, String> {
    let bytes =
        crate::safe_io::read(path, crate::safe_io::Links::Follow, MAX_FILE_BYTES).map_err(|e| {
            match e.kind() {
                std::io::ErrorKind::NotFound => "no such file".to_string(),
                _ => format!("cannot be read ({e})"),
            }
        })?;
    let (format, tensors, framework, steps) = if bytes.starts_with(b"PK\x03\x04") {
        let mut zip = torch_zip::archive(&bytes)?;
        if sb3::is_sb3(&zip) {
            refuse_normalisation(path)?;
            let model = sb3::read(&mut zip, task)?;
            (Format::Sb3Zip, model.tensors, model.framework, model.steps)
        } else {
            let tensors = torch_zip::state_dict_in(&mut zip)?;
            (Format::TorchStateDict, tensors, "PyTorch".into(), None)
        }
    } else if bytes.starts_with(b"\x80") {
        return Err(
            "a pickle outside a zip archive: PyTorch's legacy format (torch < 1.6, or \
                    _use_new_zipfile_serialization=False); load and save it again with a newer \
                    torch"
                .into(),
        );
    } else if let Some(tensors) = safetensors(&bytes)? {
        (Format::Safetensors, tensors, "safetensors".into(), None)
    } else {
        return Err(
            "neither a zip archive (an SB3 model, a torch.save file) nor a safetensors \
                    file"
                .into(),
        );
    };
    let prefix = match (format, prefix) {
        (_, Some(p)) => Some(p),
        (Format::Sb3Zip, None) => Some(sb3::PREFIX),
        _ => None,
    };
    let chosen: Vec<NamedTensor> = match (format, prefix) {
        // The target network and the optimiser are not the policy SB3's `predict` uses.
        (Format::Sb3Zip, Some(sb3::PREFIX)) => tensors
            .into_iter()
            .filter(|t| !t.name.starts_with("q_net_target."))
            .collect(),
        _ => tensors,
    };
    let network = mlp::network(&chosen, prefix, task)?;
    let used_prefix = network.prefix.clone();
    let net = build(network.architecture, network.parameters)?;
    Ok(Foreign {
        net,
        origin: Origin {
            file: path.file_name().map_or_else(
                || path.display().to_string(),
                |f| f.to_string_lossy().into(),
            ),
            sha256: crate::policy_store::sha256_hex(&bytes),
            format,
            framework,
            prefix: used_prefix,
            steps,
        },
    })
}

/// The RL Baselines3 Zoo saves the running statistics of `VecNormalize` beside the model
/// (`vecnormalize.pkl`, in the model's folder or one named after it): the agent acted on
/// normalised observations, which sapnet's sources do not see.
fn refuse_normalisation(path: &Path) -> Result<(), String> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let stem = path.file_stem().unwrap_or_default();
    for candidate in [
        dir.join("vecnormalize.pkl"),
        dir.join(stem).join("vecnormalize.pkl"),
    ] {
        if candidate.exists() {
            return Err(format!(
                "{} lies beside it: the agent was trained on observations normalised by \
                 VecNormalize, which sapnet's Q-networks do not apply",
                candidate.display()
            ));
        }
    }
    Ok(())
}

/// The tensors of a safetensors file, or `None` if `bytes` is not one.
fn safetensors(bytes: &[u8]) -> Result<Option<Vec<NamedTensor>>, String> {
    let header_len = bytes
        .get(..8)
        .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")));
    let looks_like = header_len
        .and_then(|n| usize::try_from(n).ok())
        .and_then(|n| bytes.get(8..8usize.checked_add(n)?))
        .is_some_and(|header| header.first() == Some(&b'{'));
    if !looks_like {
        return Ok(None);
    }
    let file = safetensors::SafeTensors::deserialize(bytes)
        .map_err(|e| format!("a damaged safetensors file ({e})"))?;
    let mut names: Vec<String> = file.names().into_iter().map(String::from).collect();
    names.sort();
    names
        .into_iter()
        .map(|name| {
            let view = file
                .tensor(&name)
                .map_err(|e| format!("tensor `{name}`: {e}"))?;
            if view.dtype() != safetensors::Dtype::F32 {
                return Err(format!(
                    "tensor `{name}` is {:?}; sapnet's Q-networks are float32",
                    view.dtype()
                ));
            }
            let values = view
                .data()
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect();
            Ok(NamedTensor {
                shape: view.shape().to_vec(),
                name,
                values,
            })
        })
        .collect::<Result<_, _>>()
        .map(Some)
}

fn build(architecture: Architecture, parameters: Vec<Vec<f32>>) -> Result<QNet, String> {
    let tensors = architecture
        .parameter_shapes()
        .into_iter()
        .zip(parameters)
        .map(|((_, shape), values)| Tensor::from_vec(values, shape, &Device::Cpu))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    QNet::from_parameters(architecture, tensors).map_err(|e| e.to_string())
}
