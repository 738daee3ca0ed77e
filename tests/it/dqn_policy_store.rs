//! The policy library on disk: round trips and every refusal.

use std::collections::HashMap;
use std::fs;
use std::path::Path;

use candle_core::{Device, Tensor};
use rand::{rngs::StdRng, SeedableRng};
use sapnet::dqn::{Architecture, QNet};
use sapnet::env::{CartPoleParams, EnvConfig};
use sapnet::policy_store::{self, PolicyInfo, StoreError, TrainingBudget};

fn net(hidden: &[usize], seed: u64) -> QNet {
    QNet::new(
        Architecture::new(4, hidden, 2),
        &mut StdRng::seed_from_u64(seed),
    )
    .unwrap()
}

fn info() -> PolicyInfo {
    PolicyInfo {
        source_task: EnvConfig::CartPole(CartPoleParams {
            masspole: 0.3,
            ..CartPoleParams::default()
        }),
        training: TrainingBudget {
            episodes: 300,
            steps: 41_234,
        },
        seed: 17,
        final_score: Some(187.4),
        reused: None,
        origin: None,
    }
}

fn bits(net: &QNet) -> Vec<Vec<u32>> {
    net.parameters()
        .iter()
        .map(|v| {
            let values = v
                .as_tensor()
                .flatten_all()
                .unwrap()
                .to_vec1::<f32>()
                .unwrap();
            values.into_iter().map(f32::to_bits).collect()
        })
        .collect()
}

/// Rewrites policy `name`'s weights and fixes the digest in its metadata, as a careless
/// hand edit would: only the shape checks stand between these weights and a network.
fn replace_weights(dir: &Path, name: &str, tensors: HashMap<String, Tensor>) {
    let (weights, metadata) = policy_store::paths(dir, name);
    candle_core::safetensors::save(&tensors, &weights).unwrap();
    let digest = policy_store::sha256_hex(&fs::read(&weights).unwrap());
    let text = fs::read_to_string(&metadata).unwrap();
    let old = text.lines().find(|l| l.contains("weights_sha256")).unwrap();
    let text = text.replace(old, &format!("    weights_sha256: \"{digest}\","));
    fs::write(&metadata, text).unwrap();
}

#[test]
fn round_trip_is_bit_exact_with_metadata() {
    let dir = tempfile::tempdir().unwrap();
    for hidden in [&[100][..], &[87, 113], &[60, 40, 90]] {
        let original = net(hidden, 3);
        let name = format!("p{}", hidden.len());
        let written = policy_store::save(dir.path(), &name, &original, &info()).unwrap();
        let loaded = policy_store::load(dir.path(), &name).unwrap();
        assert_eq!(bits(&loaded.net), bits(&original));
        assert_eq!(loaded.metadata, written);
        assert_eq!(loaded.net.architecture(), original.architecture());
        let obs = [0.1, 0.2, -0.3, 0.4];
        assert_eq!(
            loaded.net.q_values(&obs).unwrap(),
            original.q_values(&obs).unwrap()
        );
    }
    let m = policy_store::load(dir.path(), "p2").unwrap().metadata;
    assert_eq!(m.activation, "relu");
    assert_eq!(m.architecture.hidden, vec![87, 113]);
    assert_eq!(m.source_task_name, "cartpole");
    assert_eq!(m.source_task, info().source_task);
    assert_eq!(m.training.steps, 41_234);
    assert_eq!(m.seed, 17);
    assert_eq!(m.final_score, Some(187.4));
    assert_eq!(m.crate_version, env!("CARGO_PKG_VERSION"));
    assert_eq!(policy_store::list(dir.path()).unwrap(), ["p1", "p2", "p3"]);
    // No temporary files are left behind.
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 6);
}

#[test]
fn weights_use_pytorch_names_and_shapes() {
    let dir = tempfile::tempdir().unwrap();
    policy_store::save(dir.path(), "p", &net(&[7, 5], 0), &info()).unwrap();
    let (weights, _) = policy_store::paths(dir.path(), "p");
    let tensors = candle_core::safetensors::load(&weights, &Device::Cpu).unwrap();
    let mut shapes: Vec<(String, Vec<usize>)> = tensors
        .iter()
        .map(|(k, v)| (k.clone(), v.dims().to_vec()))
        .collect();
    shapes.sort();
    let expected = [
        ("layers.0.bias", vec![7]),
        ("layers.0.weight", vec![7, 4]),
        ("layers.1.bias", vec![5]),
        ("layers.1.weight", vec![5, 7]),
        ("layers.2.bias", vec![2]),
        ("layers.2.weight", vec![2, 5]),
    ];
    let expected: Vec<(String, Vec<usize>)> = expected
        .into_iter()
        .map(|(k, s)| (k.to_string(), s))
        .collect();
    assert_eq!(shapes, expected);
}

#[test]
fn saving_again_replaces_the_policy() {
    let dir = tempfile::tempdir().unwrap();
    policy_store::save(dir.path(), "p", &net(&[10], 1), &info()).unwrap();
    policy_store::save(dir.path(), "p", &net(&[20, 20], 2), &info()).unwrap();
    let loaded = policy_store::load(dir.path(), "p").unwrap();
    assert_eq!(bits(&loaded.net), bits(&net(&[20, 20], 2)));
}

#[test]
fn a_missing_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let err = policy_store::load(dir.path(), "absent").unwrap_err();
    assert!(
        matches!(&err, StoreError::Missing { path } if path.ends_with("absent.ron")),
        "{err}"
    );

    policy_store::save(dir.path(), "p", &net(&[10], 1), &info()).unwrap();
    let (weights, _) = policy_store::paths(dir.path(), "p");
    fs::remove_file(&weights).unwrap();
    let err = policy_store::load(dir.path(), "p").unwrap_err();
    assert!(
        matches!(&err, StoreError::Missing { path } if *path == weights),
        "{err}"
    );
    assert!(err.to_string().contains("p.safetensors"), "{err}");
}

#[test]
fn an_interrupted_save_is_refused() {
    // The crash window: new weights renamed into place, the old metadata still there.
    let dir = tempfile::tempdir().unwrap();
    let other = tempfile::tempdir().unwrap();
    policy_store::save(dir.path(), "p", &net(&[10], 1), &info()).unwrap();
    policy_store::save(other.path(), "p", &net(&[10], 2), &info()).unwrap();
    let (weights, _) = policy_store::paths(dir.path(), "p");
    fs::copy(policy_store::paths(other.path(), "p").0, &weights).unwrap();
    let err = policy_store::load(dir.path(), "p").unwrap_err();
    assert!(matches!(err, StoreError::Mismatch { .. }), "{err}");
    let message = err.to_string();
    assert!(
        message.contains("p.safetensors")
            && message.contains("p.ron")
            && message.contains("SHA-256")
    );
}

#[test]
fn weights_of_the_wrong_shape_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    policy_store::save(dir.path(), "p", &net(&[10], 1), &info()).unwrap();
    let mut tensors: HashMap<String, Tensor> =
        net(&[11], 1).named_parameters().into_iter().collect();
    replace_weights(dir.path(), "p", tensors.clone());
    let err = policy_store::load(dir.path(), "p").unwrap_err();
    assert!(matches!(err, StoreError::Mismatch { .. }), "{err}");
    let message = err.to_string();
    assert!(
        message.contains("layers.0.weight")
            && message.contains("[11, 4]")
            && message.contains("[10, 4]"),
        "{message}"
    );

    tensors = net(&[10], 1).named_parameters().into_iter().collect();
    tensors.remove("layers.1.bias");
    replace_weights(dir.path(), "p", tensors.clone());
    let err = policy_store::load(dir.path(), "p").unwrap_err().to_string();
    assert!(
        err.contains("tensor layers.1.bias of 4-10-2 is missing"),
        "{err}"
    );

    tensors = net(&[10], 1).named_parameters().into_iter().collect();
    tensors.insert(
        "layers.9.weight".into(),
        Tensor::zeros(3, candle_core::DType::F32, &Device::Cpu).unwrap(),
    );
    replace_weights(dir.path(), "p", tensors);
    let err = policy_store::load(dir.path(), "p").unwrap_err().to_string();
    assert!(
        err.contains("layers.9.weight is not part of 4-10-2"),
        "{err}"
    );
}

#[test]
fn a_policy_that_does_not_fit_the_task_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    policy_store::save(dir.path(), "p", &net(&[10], 1), &info()).unwrap();
    assert!(policy_store::load_for_task(dir.path(), "p", 4, 2).is_ok());
    let err = policy_store::load_for_task(dir.path(), "p", 2, 3).unwrap_err();
    assert!(matches!(err, StoreError::DoesNotFit { .. }), "{err}");
    let message = err.to_string();
    assert!(
        message.contains("p.ron") && message.contains("4 observation values, the task gives 2"),
        "{message}"
    );
    assert!(message.contains("2 actions, the task has 3"), "{message}");
}

#[test]
fn bad_metadata_is_located() {
    let dir = tempfile::tempdir().unwrap();
    policy_store::save(dir.path(), "p", &net(&[10], 1), &info()).unwrap();
    let (_, metadata) = policy_store::paths(dir.path(), "p");
    let text = fs::read_to_string(&metadata)
        .unwrap()
        .replace("seed: 17", "seed: \"x\"");
    fs::write(&metadata, text).unwrap();
    let err = policy_store::load(dir.path(), "p").unwrap_err().to_string();
    assert!(
        err.contains("p.ron") && err.contains("line") && err.contains("seed"),
        "{err}"
    );

    policy_store::save(dir.path(), "p", &net(&[10], 1), &info()).unwrap();
    let text = fs::read_to_string(&metadata)
        .unwrap()
        .replace("\"relu\"", "\"tanh\"");
    fs::write(&metadata, text).unwrap();
    let err = policy_store::load(dir.path(), "p").unwrap_err().to_string();
    assert!(err.contains("tanh"), "{err}");
}

#[test]
fn an_absent_library_lists_no_policies() {
    let dir = tempfile::tempdir().unwrap();
    assert!(policy_store::list(&dir.path().join("none"))
        .unwrap()
        .is_empty());
}

#[test]
fn names_must_be_plain_file_names() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["", "../p", "a/b", ".hidden"] {
        let err = policy_store::save(dir.path(), name, &net(&[3], 0), &info()).unwrap_err();
        assert!(
            matches!(err, StoreError::InvalidName { .. }),
            "{name}: {err}"
        );
    }
}
