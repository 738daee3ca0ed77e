//! A policy's category in a lesson built from `descriptions` (eq. 3–5): the first
//! prototype's key, as a teacher types it (`2` for two hidden layers under `HiddenLayers`),
//! and a description changed so that the prototype gives it another key.

use crate::sapnet::{PolicyDescription, Prototype};

/// The most hidden layers a typed category may ask for: a lesson's policies are drawn on
/// one screen, and a key of a million layers would allocate a million widths.
pub const MAX_HIDDEN_LAYERS: usize = 64;

/// Units per layer of a policy made for a category that no policy has yet (Table II's).
const DEFAULT_UNITS: usize = 100;

/// What a category key means under `prototype`, for prompts and messages.
pub fn meaning(prototype: &Prototype) -> &'static str {
    match prototype {
        Prototype::HiddenLayers => "its number of hidden layers",
        Prototype::UnitsBucket { .. } => "its bucket of mean units per layer",
        Prototype::SourceTask => "its source task",
        Prototype::Activation => "its activation function",
    }
}

/// The key `prototype` gives `policy`, as typed.
pub fn key(prototype: &Prototype, policy: &PolicyDescription) -> String {
    match prototype {
        Prototype::HiddenLayers => policy.hidden.len().to_string(),
        Prototype::UnitsBucket { width } => {
            let layers = policy.hidden.len().max(1);
            (policy.hidden.iter().sum::<usize>() / layers / (*width).max(1)).to_string()
        }
        Prototype::SourceTask => policy.source_task.clone(),
        Prototype::Activation => policy.activation.clone(),
    }
}

/// `policy` changed as little as it takes for `prototype` to give it the key `typed`:
/// hidden layers cut or repeated, widths set to the bucket, the task or activation
/// renamed. Refused, saying what the key is, where `typed` cannot be one.
pub fn with_key(
    prototype: &Prototype,
    policy: &PolicyDescription,
    typed: &str,
) -> Result<PolicyDescription, String> {
    let typed = typed.trim();
    let number = |what: &str| -> Result<usize, String> {
        typed.parse::<usize>().map_err(|_| {
            format!("a category under {prototype:?} is {what} (0, 1, 2, …), got {typed:?}")
        })
    };
    let mut changed = policy.clone();
    match prototype {
        Prototype::HiddenLayers => {
            let layers = number("a number of hidden layers")?;
            if layers > MAX_HIDDEN_LAYERS {
                return Err(format!(
                    "a category under HiddenLayers is at most {MAX_HIDDEN_LAYERS} hidden \
                     layers, got {layers}"
                ));
            }
            let width = policy.hidden.last().copied().unwrap_or(DEFAULT_UNITS);
            changed.hidden.resize(layers, width);
        }
        Prototype::UnitsBucket { width } => {
            let bucket = number("a bucket of mean units per layer")?;
            let units = bucket
                .checked_mul((*width).max(1))
                .filter(|&u| u <= 1_000_000)
                .ok_or_else(|| format!("bucket {bucket} of width {width} is too many units"))?;
            let layers = policy.hidden.len().max(1);
            changed.hidden = vec![units; layers];
        }
        Prototype::SourceTask | Prototype::Activation if typed.is_empty() || typed == "-" => {
            return Err(format!(
                "a category under {prototype:?} is {}, got nothing",
                meaning(prototype)
            ));
        }
        Prototype::SourceTask => changed.source_task = typed.to_string(),
        Prototype::Activation => changed.activation = typed.to_string(),
    }
    Ok(changed)
}

/// A new policy in the category `typed`: a copy of the first policy already in it (so
/// it joins that category's edges as its members do), else Table II's one layer of 100
/// ReLU units changed to the key.
pub fn new_policy(
    prototype: &Prototype,
    policies: &[PolicyDescription],
    typed: &str,
) -> Result<PolicyDescription, String> {
    let template = PolicyDescription::new(vec![DEFAULT_UNITS], "");
    let wanted = key(prototype, &with_key(prototype, &template, typed)?);
    match policies.iter().find(|p| key(prototype, p) == wanted) {
        Some(member) => Ok(member.clone()),
        None => with_key(prototype, &template, typed),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hidden_layers_are_cut_or_repeated_to_the_key() {
        let p = PolicyDescription::new(vec![64, 128], "");
        let three = with_key(&Prototype::HiddenLayers, &p, "3").unwrap();
        assert_eq!(three.hidden, [64, 128, 128]);
        assert_eq!(key(&Prototype::HiddenLayers, &three), "3");
        let one = with_key(&Prototype::HiddenLayers, &p, " 1 ").unwrap();
        assert_eq!(one.hidden, [64]);
        let e = with_key(&Prototype::HiddenLayers, &p, "two").unwrap_err();
        assert!(e.contains("a number of hidden layers"), "{e}");
        let e = with_key(&Prototype::HiddenLayers, &p, "1000").unwrap_err();
        assert!(e.contains("at most 64"), "{e}");
    }

    #[test]
    fn other_prototypes_change_their_own_feature() {
        let p = PolicyDescription::new(vec![100], "CartPole-v1");
        let bucket = Prototype::UnitsBucket { width: 50 };
        assert_eq!(with_key(&bucket, &p, "3").unwrap().hidden, [150]);
        assert_eq!(key(&bucket, &with_key(&bucket, &p, "3").unwrap()), "3");
        let task = with_key(&Prototype::SourceTask, &p, "Acrobot-v1").unwrap();
        assert_eq!(task.source_task, "Acrobot-v1");
        assert!(with_key(&Prototype::Activation, &p, "").is_err());
    }

    #[test]
    fn a_new_policy_copies_a_member_of_its_category() {
        let policies = [
            PolicyDescription::new(vec![100], ""),
            PolicyDescription::new(vec![64, 128], ""),
        ];
        let two = new_policy(&Prototype::HiddenLayers, &policies, "2").unwrap();
        assert_eq!(two.hidden, [64, 128]);
        let three = new_policy(&Prototype::HiddenLayers, &policies, "3").unwrap();
        assert_eq!(three.hidden, [100, 100, 100]);
    }
}
