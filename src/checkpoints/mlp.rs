//! A state dict read as a plain MLP of linear layers: keys `<prefix>.<i>.weight` `[out, in]`
//! and `<prefix>.<i>.bias` `[out]` under one prefix (CleanRL's `network`, SB3's
//! `q_net.q_net`, a bare `nn.Sequential`'s empty one), layers in the order of `i` (the gaps
//! are the parameter-free activations between them), each taking what the previous gives.

use std::collections::BTreeMap;

use super::{NamedTensor, Spaces};
use crate::dqn::Architecture;

/// A network read from named tensors.
#[derive(Debug)]
pub struct Network {
    pub architecture: Architecture,
    /// In [`Architecture::parameter_shapes`] order.
    pub parameters: Vec<Vec<f32>>,
    /// The prefix of the keys it was read from (`network`, or empty for bare keys).
    pub prefix: String,
}

/// The layers of the network in `tensors` under `prefix` (`None`: the one prefix they have).
pub fn network(
    tensors: &[NamedTensor],
    prefix: Option<&str>,
    task: Spaces,
) -> Result<Network, String> {
    if tensors.is_empty() {
        return Err("it holds no tensors".into());
    }
    let mut layers: BTreeMap<String, BTreeMap<u64, [Option<&NamedTensor>; 2]>> = BTreeMap::new();
    for t in tensors {
        if t.shape.len() > 2 {
            return Err(format!(
                "tensor `{}` has shape {:?}: a convolution (a CNN policy); sapnet's Q-networks \
                 are plain MLPs of linear layers",
                t.name, t.shape
            ));
        }
        let Some((owner, index, part)) = linear_key(&t.name) else {
            return Err(not_linear(&t.name));
        };
        layers
            .entry(owner.to_string())
            .or_default()
            .entry(index)
            .or_default()[usize::from(part == "bias")] = Some(t);
    }
    let (prefix, chosen) = match prefix {
        Some(p) => layers.remove_entry(p).ok_or_else(|| {
            format!(
                "no layers under the prefix `{p}`; it has {}",
                prefixes(layers.keys())
            )
        })?,
        None if layers.len() == 1 => layers.pop_first().expect("one prefix"),
        None => {
            return Err(format!(
                "it holds more than one network ({}): name the one to import with --prefix",
                prefixes(layers.keys())
            ))
        }
    };
    let mut sizes = vec![task.observation_size];
    let mut parameters = Vec::new();
    for (index, [weight, bias]) in &chosen {
        let (weight, bias) = match (weight, bias) {
            (Some(w), Some(b)) => (w, b),
            (Some(w), None) => {
                return Err(format!(
                    "layer {index} has a weight (`{}`) and no bias: sapnet's linear layers \
                     have both",
                    w.name
                ))
            }
            (None, Some(b)) => {
                return Err(format!(
                    "layer {index} has a bias (`{}`) and no weight",
                    b.name
                ))
            }
            (None, None) => unreachable!("a layer is recorded by one of its tensors"),
        };
        let inputs = *sizes.last().expect("the observation starts the sizes");
        let [out, inp] = weight.shape[..] else {
            return Err(format!(
                "tensor `{}` has shape {:?}, a linear layer's weight is [out, in]",
                weight.name, weight.shape
            ));
        };
        if inp != inputs {
            let what = if sizes.len() == 1 {
                format!("the task observes {inputs} values")
            } else {
                format!("the layer before gives {inputs}")
            };
            return Err(format!(
                "tensor `{}` has shape {:?}: it takes {inp} inputs, {what}",
                weight.name, weight.shape
            ));
        }
        if bias.shape != [out] {
            return Err(format!(
                "tensor `{}` has shape {:?}, its layer's weight needs [{out}]",
                bias.name, bias.shape
            ));
        }
        for t in [weight, bias] {
            if let Some(v) = t.values.iter().find(|v| !v.is_finite()) {
                return Err(format!(
                    "tensor `{}` holds a non-finite weight ({v}): not a policy to reuse",
                    t.name
                ));
            }
        }
        sizes.push(out);
        parameters.push(weight.values.clone());
        parameters.push(bias.values.clone());
    }
    let actions = sizes.pop().expect("at least one layer");
    if actions != task.action_count {
        return Err(format!(
            "its last layer scores {actions} actions, the task has {}",
            task.action_count
        ));
    }
    let architecture = Architecture::new(task.observation_size, &sizes[1..], actions);
    architecture.validate().map_err(|e| e.to_string())?;
    Ok(Network {
        architecture,
        parameters,
        prefix,
    })
}

/// `(prefix, index, "weight" | "bias")` of a linear layer's key.
fn linear_key(key: &str) -> Option<(&str, u64, &str)> {
    let (rest, part) = key.rsplit_once('.')?;
    if part != "weight" && part != "bias" {
        return None;
    }
    let (prefix, index) = match rest.rsplit_once('.') {
        Some((prefix, index)) => (prefix, index),
        None => ("", rest),
    };
    Some((prefix, index.parse().ok()?, part))
}

/// Why a key is not a linear layer's, in the words of what it likely is.
fn not_linear(key: &str) -> String {
    let lower = key.to_ascii_lowercase();
    let what = if ["value", "advantage"].iter().any(|w| lower.contains(w)) {
        "a dueling head's stream"
    } else if ["running_mean", "running_var", "obs_rms", "norm"]
        .iter()
        .any(|w| lower.contains(w))
    {
        "normalisation statistics"
    } else if lower.contains("conv") || lower.contains("cnn") {
        "a convolution"
    } else {
        "not a numbered linear layer's weight or bias"
    };
    format!(
        "key `{key}` is {what}: sapnet's Q-networks are plain MLPs of linear layers with ReLU \
         between them (keys <prefix>.<i>.weight and <prefix>.<i>.bias)"
    )
}

fn prefixes<'a>(keys: impl Iterator<Item = &'a String>) -> String {
    // A state dict may hold thousands: the refusal stays a line.
    crate::shown_text::cut_list(
        keys.map(|k| {
            if k.is_empty() {
                "the bare layers `0.weight`, ...".to_string()
            } else {
                format!("`{}`", crate::shown_text::escaped(k))
            }
        }),
        20,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(name: &str, shape: &[usize]) -> NamedTensor {
        NamedTensor {
            name: name.into(),
            shape: shape.to_vec(),
            values: vec![0.5; shape.iter().product()],
        }
    }

    const CARTPOLE: Spaces = Spaces {
        observation_size: 4,
        action_count: 2,
    };

    #[test]
    fn cleanrl_keys_with_gaps_read_as_layers_in_order() {
        let tensors = [
            t("network.4.weight", &[2, 16]),
            t("network.0.weight", &[24, 4]),
            t("network.0.bias", &[24]),
            t("network.2.weight", &[16, 24]),
            t("network.2.bias", &[16]),
            t("network.4.bias", &[2]),
        ];
        let read = network(&tensors, None, CARTPOLE).unwrap();
        assert_eq!(read.architecture, Architecture::new(4, &[24, 16], 2));
        assert_eq!(read.prefix, "network");
        let lengths: Vec<usize> = read.parameters.iter().map(Vec::len).collect();
        assert_eq!(lengths, [96, 24, 384, 16, 32, 2]);
    }

    #[test]
    fn bare_sequential_keys_and_a_chosen_prefix() {
        let bare = [t("0.weight", &[2, 4]), t("0.bias", &[2])];
        assert_eq!(
            network(&bare, None, CARTPOLE).unwrap().architecture,
            Architecture::new(4, &[], 2)
        );
        let two = [
            t("a.0.weight", &[2, 4]),
            t("a.0.bias", &[2]),
            t("b.0.weight", &[2, 4]),
            t("b.0.bias", &[2]),
        ];
        let err = network(&two, None, CARTPOLE).unwrap_err();
        assert!(
            err.contains("`a`, `b`") && err.contains("--prefix"),
            "{err}"
        );
        assert!(network(&two, Some("b"), CARTPOLE).is_ok());
        assert!(network(&two, Some("c"), CARTPOLE)
            .unwrap_err()
            .contains("`c`"));
    }

    #[test]
    fn what_a_plain_relu_mlp_cannot_be_is_refused_by_name() {
        let case = |tensors: &[NamedTensor]| network(tensors, None, CARTPOLE).unwrap_err();
        let err = case(&[t("cnn.0.weight", &[8, 4, 3, 3])]);
        assert!(err.contains("convolution"), "{err}");
        let err = case(&[t("value_stream.weight", &[1, 4])]);
        assert!(err.contains("dueling"), "{err}");
        let err = case(&[t("obs_rms.mean", &[4])]);
        assert!(err.contains("normalisation"), "{err}");
        let err = case(&[t("0.weight", &[2, 5]), t("0.bias", &[2])]);
        assert!(err.contains("takes 5 inputs, the task observes 4"), "{err}");
        let err = case(&[t("0.weight", &[3, 4]), t("0.bias", &[3])]);
        assert!(err.contains("scores 3 actions, the task has 2"), "{err}");
        let err = case(&[t("0.weight", &[2, 4])]);
        assert!(err.contains("no bias"), "{err}");
        let err = case(&[t("0.weight", &[2, 4]), t("0.bias", &[3])]);
        assert!(err.contains("`0.bias` has shape [3]"), "{err}");
        let mut nan = t("0.bias", &[2]);
        nan.values[1] = f32::NAN;
        let err = case(&[t("0.weight", &[2, 4]), nan]);
        assert!(err.contains("non-finite"), "{err}");
    }
}
