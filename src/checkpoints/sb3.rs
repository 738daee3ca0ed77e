//! A Stable-Baselines3 DQN saved by `model.save` (`.zip`): `data` (the model's settings as
//! JSON, with each space's and class's repr beside its cloudpickle, which is never read),
//! `policy.pth` (the policy's state dict: `q_net.q_net.{i}` the online network,
//! `q_net_target.q_net.{i}` its target copy), `system_info.txt` (the versions).

use super::{torch_zip, NamedTensor, Spaces};

/// The online Q-network's keys in an SB3 DQN's state dict: what `predict` uses.
pub const PREFIX: &str = "q_net.q_net";

/// The only activation sapnet's Q-networks have, as SB3 writes the class.
const RELU: &str = "<class 'torch.nn.modules.activation.ReLU'>";

/// What an SB3 zip holds that an import uses.
pub struct Sb3Model {
    pub tensors: Vec<NamedTensor>,
    /// `Stable-Baselines3 2.9.2`, from system_info.txt.
    pub framework: String,
    /// `num_timesteps`: how long it trained.
    pub steps: Option<u64>,
}

/// Reads the SB3 DQN in `zip` (with `data` and `policy.pth`), refusing what a
/// plain ReLU Q-network cannot be: another algorithm's policy, another activation, a
/// feature extractor with weights, other spaces than a flat box and a discrete set.
pub fn read(zip: &mut torch_zip::Archive, task: Spaces) -> Result<Sb3Model, String> {
    let data = torch_zip::entry(zip, "data", 16 << 20)?;
    let data: serde_json::Value = serde_json::from_slice(&data)
        .map_err(|e| format!("its `data` entry is not the JSON SB3 writes ({e})"))?;
    check_policy(&data)?;
    check_spaces(&data, task)?;
    let policy = torch_zip::entry(zip, "policy.pth", super::MAX_FILE_BYTES)?;
    let tensors = torch_zip::state_dict(&policy).map_err(|e| format!("policy.pth: {e}"))?;
    if let Some(extractor) = tensors
        .iter()
        .find(|t| t.name.starts_with("q_net.features_extractor."))
    {
        return Err(format!(
            "its Q-network has a feature extractor with weights (`{}`: a CNN policy?); sapnet's \
             Q-networks are plain MLPs on the observation",
            extractor.name
        ));
    }
    let framework = torch_zip::entry(zip, "system_info.txt", 64 << 10)
        .ok()
        .and_then(|text| {
            String::from_utf8_lossy(&text)
                .lines()
                .find_map(|l| l.strip_prefix("- Stable-Baselines3: ").map(str::to_string))
        })
        .map_or("Stable-Baselines3".into(), |v| {
            format!("Stable-Baselines3 {}", v.trim())
        });
    Ok(Sb3Model {
        tensors,
        framework,
        steps: data["num_timesteps"].as_u64(),
    })
}

/// A DQN policy (not QR-DQN's quantiles, nor another algorithm's), with ReLU.
fn check_policy(data: &serde_json::Value) -> Result<(), String> {
    let module = data["policy_class"]["__module__"].as_str().unwrap_or("");
    if module != "stable_baselines3.dqn.policies" {
        let what = if module.is_empty() {
            "no policy class".to_string()
        } else {
            format!("a policy of `{module}`")
        };
        return Err(format!(
            "it holds {what}, not Stable-Baselines3's DQN policy (stable_baselines3.dqn.policies): \
             only DQN's Q-networks can be reused as sapnet's sources"
        ));
    }
    let kwargs = &data["policy_kwargs"];
    if let Some(activation) = kwargs.get("activation_fn") {
        let activation = activation.as_str().unwrap_or("");
        if activation != RELU {
            return Err(format!(
                "its policy_kwargs.activation_fn is {activation}: sapnet's Q-networks use ReLU \
                 between layers, so this network cannot be represented"
            ));
        }
    }
    if kwargs.get("dueling").is_some() {
        return Err(
            "its policy has a dueling head (policy_kwargs.dueling): sapnet's \
                    Q-networks have one linear output layer"
                .into(),
        );
    }
    Ok(())
}

/// A flat float box of the task's size and `Discrete(n)` from 0 with the task's `n`.
fn check_spaces(data: &serde_json::Value, task: Spaces) -> Result<(), String> {
    let observation = &data["observation_space"];
    let kind = observation[":type:"].as_str().unwrap_or("");
    if !kind.contains("spaces.box.Box") {
        return Err(format!(
            "its observation_space is {kind}: sapnet's tasks observe a Box of floats"
        ));
    }
    let shape: Vec<u64> = observation["_shape"]
        .as_array()
        .map(|s| s.iter().filter_map(serde_json::Value::as_u64).collect())
        .unwrap_or_default();
    if shape != [task.observation_size as u64] {
        return Err(format!(
            "its observation_space has shape {shape:?}, the task observes [{}]",
            task.observation_size
        ));
    }
    let actions = &data["action_space"];
    let kind = actions[":type:"].as_str().unwrap_or("");
    if !kind.contains("spaces.discrete.Discrete") {
        return Err(format!(
            "its action_space is {kind}: DQN's sources choose among discrete actions"
        ));
    }
    // SB3 writes the attributes' reprs: "2", "0".
    let number = |field: &str| {
        let v = &actions[field];
        v.as_u64()
            .or_else(|| v.as_str().and_then(|s| s.trim().parse().ok()))
    };
    if number("start").unwrap_or(0) != 0 {
        return Err(format!(
            "its action_space starts at {}: sapnet numbers a task's actions from 0",
            actions["start"]
        ));
    }
    match number("n") {
        Some(n) if n == task.action_count as u64 => Ok(()),
        Some(n) => Err(format!(
            "its action_space is Discrete({n}), the task has {} actions",
            task.action_count
        )),
        None => Err("its action_space does not say how many actions (n)".into()),
    }
}

/// Whether `zip` is an SB3 model: it holds `data` and `policy.pth`.
pub fn is_sb3(zip: &torch_zip::Archive) -> bool {
    let names: Vec<String> = zip
        .file_names()
        .filter_map(|n| n.ok().map(|n| n.into_owned()))
        .collect();
    names.iter().any(|n| n == "data") && names.iter().any(|n| n == "policy.pth")
}
