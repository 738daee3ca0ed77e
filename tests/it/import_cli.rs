//! `sapnet sources import`: Q-networks trained by Stable-Baselines3, CleanRL and plain
//! PyTorch join a library bit for bit, act as their framework does, are reused as every
//! source; what is malformed or cannot be represented is refused by name, and changes
//! nothing. The fixtures are made by tests/fixtures/import/make_fixtures.py.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use sapnet::policy_store::{self, Format};
use sapnet::sources::manifest;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn fixture(name: &str) -> PathBuf {
    root().join("tests/fixtures/import").join(name)
}

fn tiny_config() -> String {
    root()
        .join("tests/configs/tiny_sources.ron")
        .display()
        .to_string()
}

fn sapnet(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// A library of the three tiny sources of tiny_sources.ron, trained in `dir`.
fn tiny_library(dir: &Path) -> PathBuf {
    let trained = sapnet(&[
        "sources",
        "--config",
        &tiny_config(),
        "--library",
        dir.to_str().unwrap(),
    ]);
    assert!(trained.status.success(), "{}", stderr(&trained));
    dir.join("cartpole")
}

/// `sapnet sources import FILE --name NAME` into the tiny library under `library`.
fn import(library: &Path, file: &Path, name: &str, extra: &[&str]) -> Output {
    import_for(&tiny_config(), library, file, name, extra)
}

/// The same into the library of `config`.
fn import_for(config: &str, library: &Path, file: &Path, name: &str, extra: &[&str]) -> Output {
    let file = file.to_str().unwrap();
    let library = library.to_str().unwrap();
    let mut args = vec![
        "sources", "import", file, "--name", name, "--config", config,
    ];
    args.extend(["--library", library]);
    args.extend(extra);
    sapnet(&args)
}

/// What the framework holds: every parameter in order, the observations and its greedy
/// actions on them.
struct Expected {
    parameters: Vec<(String, Vec<usize>, Vec<f32>)>,
    observations: Vec<[f32; 4]>,
    actions: Vec<usize>,
}

fn expected(name: &str) -> Expected {
    let text = std::fs::read_to_string(fixture(&format!("{name}.expected.json"))).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let mut parameters = json["parameters"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| {
            let shape = v["shape"]
                .as_array()
                .unwrap()
                .iter()
                .map(|d| d.as_u64().unwrap() as usize)
                .collect();
            // Each value is an f32 written as the exact decimal of its f64 widening.
            let values = v["values"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap() as f32)
                .collect();
            (k.clone(), shape, values)
        })
        .collect::<Vec<_>>();
    // JSON objects come back sorted by key: put the layers in their order, weight first.
    parameters.sort_by_key(|(k, _, _): &(String, Vec<usize>, Vec<f32>)| {
        let mut parts = k.rsplit('.');
        let bias = parts.next().unwrap() == "bias";
        let index: u64 = parts.next().unwrap().parse().unwrap();
        (index, bias)
    });
    let bytes = std::fs::read(fixture(json["observations"].as_str().unwrap())).unwrap();
    let observations = bytes
        .chunks_exact(16)
        .map(|o| {
            std::array::from_fn(|i| f32::from_le_bytes(o[4 * i..4 * i + 4].try_into().unwrap()))
        })
        .collect();
    let actions = json["actions"]
        .as_str()
        .unwrap()
        .bytes()
        .map(|b| usize::from(b - b'0'))
        .collect();
    Expected {
        parameters,
        observations,
        actions,
    }
}

/// Imports fixture `file` and checks the policy against the framework's parameters (to the
/// bit) and greedy actions (every one of 1,200 observations).
fn imports_exactly(file: &str, expected_name: &str, format: Format, prefix: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tiny_library(tmp.path());
    let output = import(tmp.path(), &fixture(file), "foreign", &[]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(
        stderr(&output).contains("greedy return"),
        "{}",
        stderr(&output)
    );

    let policy = policy_store::load_for_task(&dir, "foreign", 4, 2).unwrap();
    let expected = expected(expected_name);
    let ours = policy.net.named_parameters();
    assert_eq!(ours.len(), expected.parameters.len());
    for ((name, tensor), (their_name, shape, values)) in ours.iter().zip(&expected.parameters) {
        assert_eq!(tensor.dims(), shape.as_slice(), "{name} vs {their_name}");
        let mine = tensor.flatten_all().unwrap().to_vec1::<f32>().unwrap();
        let same_bits = mine
            .iter()
            .zip(values)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same_bits, "{name} differs from {their_name}");
    }
    assert!(expected.observations.len() >= 1000);
    let disagreements: Vec<usize> = expected
        .observations
        .iter()
        .zip(&expected.actions)
        .enumerate()
        .filter(|(_, (obs, action))| policy.net.greedy_action(obs.as_slice()).unwrap() != **action)
        .map(|(i, _)| i)
        .collect();
    assert!(
        disagreements.is_empty(),
        "actions differ at {disagreements:?}"
    );

    let origin = policy
        .metadata
        .origin
        .expect("an imported policy records its origin");
    assert_eq!(origin.format, format);
    assert_eq!(origin.prefix, prefix);
    assert_eq!(origin.file, file);
    assert_eq!(
        origin.sha256,
        policy_store::sha256_hex(&std::fs::read(fixture(file)).unwrap())
    );
    assert!(policy.metadata.final_score.is_some_and(f64::is_finite));
    let listed = manifest::read(&dir).unwrap().unwrap();
    assert_eq!(listed.policies.len(), 3);
    assert_eq!(listed.imported.len(), 1);
    assert_eq!(listed.imported[0].name, "foreign");
}

#[test]
fn a_stable_baselines3_dqn_imports_bit_for_bit_and_acts_as_its_predict() {
    imports_exactly(
        "sb3_cartpole.zip",
        "sb3_cartpole",
        Format::Sb3Zip,
        "q_net.q_net",
    );
    let tmp = tempfile::tempdir().unwrap();
    tiny_library(tmp.path());
    let output = import(tmp.path(), &fixture("sb3_cartpole.zip"), "sb3", &[]);
    let said = stderr(&output);
    assert!(said.contains("Stable-Baselines3 2."), "{said}");
    let policy = policy_store::load(&tmp.path().join("cartpole"), "sb3").unwrap();
    assert_eq!(policy.metadata.origin.unwrap().steps, Some(6000));
    assert_eq!(policy.metadata.architecture.hidden, [32, 32]);
}

#[test]
fn a_cleanrl_state_dict_imports_bit_for_bit_and_acts_as_its_argmax() {
    imports_exactly(
        "cleanrl_cartpole.cleanrl_model",
        "cleanrl_cartpole",
        Format::TorchStateDict,
        "network",
    );
}

#[test]
fn a_bare_sequential_state_dict_imports_without_options() {
    imports_exactly(
        "sequential_cartpole.pt",
        "sequential_cartpole",
        Format::TorchStateDict,
        "",
    );
}

#[test]
fn a_safetensors_file_named_as_nn_linear_stores_it_imports() {
    let tmp = tempfile::tempdir().unwrap();
    tiny_library(tmp.path());
    let expected = expected("cleanrl_cartpole");
    let tensors: Vec<(String, safetensors::tensor::TensorView)> = expected
        .parameters
        .iter()
        .map(|(name, shape, values)| {
            let bytes: &[u8] = bytemuck_f32(values);
            (
                format!("network.{name}"),
                safetensors::tensor::TensorView::new(safetensors::Dtype::F32, shape.clone(), bytes)
                    .unwrap(),
            )
        })
        .collect();
    let file = tmp.path().join("cleanrl.safetensors");
    std::fs::write(&file, safetensors::serialize(tensors, None).unwrap()).unwrap();
    let output = import(tmp.path(), &file, "st", &[]);
    assert!(output.status.success(), "{}", stderr(&output));
    let policy = policy_store::load(&tmp.path().join("cartpole"), "st").unwrap();
    let hit = expected
        .observations
        .iter()
        .zip(&expected.actions)
        .all(|(o, a)| policy.net.greedy_action(o).unwrap() == *a);
    assert!(hit);
    assert_eq!(policy.metadata.origin.unwrap().format, Format::Safetensors);
}

fn bytemuck_f32(values: &[f32]) -> &[u8] {
    // SAFETY: f32 has no padding and any byte is a valid u8; little-endian on every target
    // these tests run on (x86-64, aarch64).
    unsafe { std::slice::from_raw_parts(values.as_ptr().cast(), std::mem::size_of_val(values)) }
}

/// Every file of the library folder and its bytes: what a refused import must leave as it
/// was.
fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file() && !p.ends_with(".sapnet.lock"))
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect()
}

/// A `torch.save` archive of an ordered dict of float32 tensors, pickled as torch does
/// (protocol 2), with `extra` as an additional global called in the dict.
fn torch_file(tensors: &[(&str, &[usize], Vec<f32>)], extra: Option<&str>) -> Vec<u8> {
    let mut p = vec![0x80, 2];
    p.extend(b"ccollections\nOrderedDict\n)R(");
    let unicode = |p: &mut Vec<u8>, s: &str| {
        p.push(b'X');
        p.extend((s.len() as u32).to_le_bytes());
        p.extend(s.as_bytes());
    };
    for (i, (name, shape, values)) in tensors.iter().enumerate() {
        unicode(&mut p, name);
        p.extend(b"ctorch._utils\n_rebuild_tensor_v2\n((");
        unicode(&mut p, "storage");
        p.extend(b"ctorch\nFloatStorage\n");
        unicode(&mut p, &i.to_string());
        unicode(&mut p, "cpu");
        p.push(b'J');
        p.extend((values.len() as i32).to_le_bytes());
        p.extend(b"tQK\x00(");
        let mut stride = 1;
        let mut strides = vec![0; shape.len()];
        for d in (0..shape.len()).rev() {
            strides[d] = stride;
            stride *= shape[d];
        }
        for d in shape.iter() {
            p.push(b'J');
            p.extend((*d as i32).to_le_bytes());
        }
        p.extend(b"t(");
        for s in strides {
            p.push(b'J');
            p.extend((s as i32).to_le_bytes());
        }
        p.extend(b"t\x89ccollections\nOrderedDict\n)RtR");
    }
    if let Some(global) = extra {
        unicode(&mut p, "hook");
        let (module, name) = global.rsplit_once('.').unwrap();
        p.extend(format!("c{module}\n{name}\n").as_bytes());
        unicode(&mut p, "echo pwned");
        p.extend(b"\x85R");
    }
    p.extend(b"u.");
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let stored =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    zip.start_file("archive/data.pkl", stored).unwrap();
    zip.write_all(&p).unwrap();
    zip.start_file("archive/byteorder", stored).unwrap();
    zip.write_all(b"little").unwrap();
    for (i, (_, _, values)) in tensors.iter().enumerate() {
        zip.start_file(format!("archive/data/{i}"), stored).unwrap();
        for v in values {
            zip.write_all(&v.to_le_bytes()).unwrap();
        }
    }
    zip.finish().unwrap().into_inner()
}

/// A network 4-3-2 of small weights, as tensors named under `network`.
fn small_network() -> Vec<(&'static str, &'static [usize], Vec<f32>)> {
    vec![
        (
            "network.0.weight",
            &[3, 4],
            (0..12).map(|i| i as f32 * 0.1).collect(),
        ),
        ("network.0.bias", &[3], vec![0.0, 0.1, -0.1]),
        (
            "network.2.weight",
            &[2, 3],
            vec![1.0, -1.0, 0.5, -0.5, 0.25, 2.0],
        ),
        ("network.2.bias", &[2], vec![0.0, 0.0]),
    ]
}

/// An SB3 zip of the fixture with its `data` JSON changed by `edit`.
fn sb3_with(edit: impl Fn(&mut serde_json::Value)) -> Vec<u8> {
    let bytes = std::fs::read(fixture("sb3_cartpole.zip")).unwrap();
    let mut archive = zip::ZipArchive::new(std::io::Cursor::new(bytes)).unwrap();
    let mut out = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let stored =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    for i in 0..archive.len() {
        let mut entry = archive.by_index(i).unwrap();
        let name = entry.name().unwrap().to_string();
        let mut content = Vec::new();
        std::io::Read::read_to_end(&mut entry, &mut content).unwrap();
        if name == "data" {
            let mut data: serde_json::Value = serde_json::from_slice(&content).unwrap();
            edit(&mut data);
            content = serde_json::to_vec(&data).unwrap();
        }
        out.start_file(name, stored).unwrap();
        out.write_all(&content).unwrap();
    }
    out.finish().unwrap().into_inner()
}

#[test]
fn malformed_and_unrepresentable_files_are_refused_by_name_and_change_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tiny_library(tmp.path());
    let before = snapshot(&dir);

    let sb3 = std::fs::read(fixture("sb3_cartpole.zip")).unwrap();
    let mut missing_bias = small_network();
    missing_bias.remove(3);
    let mut wrong_shape = small_network();
    wrong_shape[2] = ("network.2.weight", &[2, 4], vec![0.0; 8]);
    let mut nan = small_network();
    nan[1].2[1] = f32::NAN;
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "truncated.zip",
            sb3[..sb3.len() / 2].to_vec(),
            "not a readable zip archive",
        ),
        (
            "missing_key.pt",
            torch_file(&missing_bias, None),
            "`network.2.weight`) and no bias",
        ),
        (
            "wrong_shape.pt",
            torch_file(&wrong_shape, None),
            "takes 4 inputs, the layer before gives 3",
        ),
        ("nan.pt", torch_file(&nan, None), "non-finite"),
        (
            "evil.pt",
            torch_file(&small_network(), Some("posix.system")),
            "the global `posix.system`",
        ),
        (
            "module.pt",
            torch_file(&small_network(), Some("__main__.QNetwork")),
            "`__main__.QNetwork`",
        ),
        (
            "tanh.zip",
            sb3_with(|d| {
                d["policy_kwargs"]["activation_fn"] =
                    "<class 'torch.nn.modules.activation.Tanh'>".into()
            }),
            "activation_fn is <class 'torch.nn.modules.activation.Tanh'>",
        ),
        (
            "other_obs.zip",
            sb3_with(|d| d["observation_space"]["_shape"] = serde_json::json!([6])),
            "shape [6], the task observes [4]",
        ),
        (
            "three_actions.zip",
            sb3_with(|d| d["action_space"]["n"] = "3".into()),
            "Discrete(3), the task has 2 actions",
        ),
        (
            "qrdqn.zip",
            sb3_with(|d| d["policy_class"]["__module__"] = "sb3_contrib.qrdqn.policies".into()),
            "`sb3_contrib.qrdqn.policies`",
        ),
        (
            "legacy.pt",
            b"\x80\x02\x8a\x0al\xfc\x9cF\xf9 j\xa8P\x19.".to_vec(),
            "legacy format",
        ),
        ("text.pt", b"hello".to_vec(), "neither a zip archive"),
    ];
    for (name, bytes, reason) in cases {
        let file = tmp.path().join(name);
        std::fs::write(&file, bytes).unwrap();
        let output = import(tmp.path(), &file, "x", &[]);
        let said = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{name}: {said}");
        assert!(said.contains(&file.display().to_string()), "{name}: {said}");
        assert!(said.contains(reason), "{name}: {said}");
        assert!(!said.contains("panicked"), "{name}: {said}");
        assert_eq!(snapshot(&dir), before, "{name} changed the library");
    }

    // The zoo's normalised agent: its statistics beside the model.
    let zoo = tmp.path().join("zoo");
    std::fs::create_dir(&zoo).unwrap();
    std::fs::copy(fixture("sb3_cartpole.zip"), zoo.join("CartPole-v1.zip")).unwrap();
    std::fs::write(zoo.join("vecnormalize.pkl"), b"").unwrap();
    let output = import(tmp.path(), &zoo.join("CartPole-v1.zip"), "x", &[]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("VecNormalize"),
        "{}",
        stderr(&output)
    );

    // A name already taken, and a name that is a path.
    let good = tmp.path().join("small.pt");
    std::fs::write(&good, torch_file(&small_network(), None)).unwrap();
    for (name, reason) in [
        ("source-0", "belong to the sources a config plans"),
        ("source-77", "belong to the sources a config plans"),
        ("library", "expected a policy name of letters, digits"),
        ("../x", "expected a policy name of letters, digits"),
    ] {
        let output = import(tmp.path(), &good, name, &[]);
        assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
        assert!(stderr(&output).contains(reason), "{}", stderr(&output));
    }
    assert_eq!(snapshot(&dir), before);

    // Two networks in one state dict: the prefix chooses.
    let mut two = small_network();
    two.extend(small_network().into_iter().map(|(n, s, v)| {
        let renamed: &'static str = Box::leak(n.replace("network", "target").into_boxed_str());
        (renamed, s, v)
    }));
    let both = tmp.path().join("both.pt");
    std::fs::write(&both, torch_file(&two, None)).unwrap();
    let output = import(tmp.path(), &both, "x", &[]);
    assert!(stderr(&output).contains("--prefix"), "{}", stderr(&output));
    let output = import(tmp.path(), &both, "x", &["--prefix", "target"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let again = import(tmp.path(), &good, "x", &[]);
    assert_eq!(again.status.code(), Some(2));
    assert!(
        stderr(&again).contains("already holds a policy named x"),
        "{}",
        stderr(&again)
    );
}

#[test]
fn an_import_needs_a_finished_library() {
    let tmp = tempfile::tempdir().unwrap();
    let output = import(tmp.path(), &fixture("sequential_cartpole.pt"), "x", &[]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("holds no finished library to import into"),
        "{}",
        stderr(&output)
    );
    assert!(!tmp.path().join("cartpole").exists());
}

/// A copy of the shipped CartPole library under `dir`.
fn shipped_library(dir: &Path) -> PathBuf {
    let to = dir.join("cartpole");
    std::fs::create_dir(&to).unwrap();
    for entry in std::fs::read_dir(root().join("saved_policies/cartpole")).unwrap() {
        let path = entry.unwrap().path();
        if path.is_file() {
            std::fs::copy(&path, to.join(path.file_name().unwrap())).unwrap();
        }
    }
    to
}

#[test]
fn a_shipped_library_with_two_imported_sources_runs_quick_and_lists_them() {
    let tmp = tempfile::tempdir().unwrap();
    shipped_library(tmp.path());
    let library = tmp.path().to_str().unwrap();
    let config = root().join("assets/reuse_cartpole.ron");
    let config = config.to_str().unwrap();
    for (file, name) in [
        ("sb3_cartpole.zip", "sb3"),
        ("cleanrl_cartpole.cleanrl_model", "cleanrl"),
    ] {
        let output = import_for(config, tmp.path(), &fixture(file), name, &[]);
        assert!(output.status.success(), "{}", stderr(&output));
    }

    let evaluated = sapnet(&[
        "sources",
        "--evaluate",
        "--config",
        config,
        "--library",
        library,
    ]);
    assert!(evaluated.status.success(), "{}", stderr(&evaluated));
    let table = String::from_utf8_lossy(&evaluated.stdout);
    assert_eq!(table.lines().count(), 1 + 12, "{table}");
    assert!(
        table.contains("\nsb3 ") && table.contains("\ncleanrl "),
        "{table}"
    );

    // A run's results go under --out only: the library it read is left as it was.
    let before = tree(tmp.path());
    let out = tmp.path().join("out");
    let run = sapnet(&[
        "--headless",
        "--quick",
        "--config",
        config,
        "--library",
        library,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let names: Vec<&str> = summary["library"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["name"].as_str().unwrap())
        .collect();
    let mut expected: Vec<String> = (0..10).map(|i| format!("source-{i}")).collect();
    expected.extend(["sb3".into(), "cleanrl".into()]);
    assert_eq!(names, expected);
    let activations = std::fs::read_to_string(out.join("activations.csv")).unwrap();
    let header = activations.lines().next().unwrap();
    assert!(header.contains("A_sb3,A_cleanrl,P_source-0"), "{header}");
    let mut after = tree(tmp.path());
    after.retain(|path, _| !path.starts_with("out"));
    assert_eq!(after, before, "the run changed its input library");
}

/// Every file under `dir` (a lock file left out), by relative path, with its bytes.
fn tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(folder) = todo.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                todo.push(path);
            } else if !path.ends_with(".sapnet.lock") {
                let bytes = std::fs::read(&path).unwrap();
                files.insert(path.strip_prefix(dir).unwrap().to_path_buf(), bytes);
            }
        }
    }
    files
}

#[test]
fn imported_sources_survive_a_retrain_of_their_library() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tiny_library(tmp.path());
    for (file, name) in [
        ("sb3_cartpole.zip", "sb3"),
        ("sequential_cartpole.pt", "seq"),
    ] {
        let output = import(tmp.path(), &fixture(file), name, &[]);
        assert!(output.status.success(), "{}", stderr(&output));
    }
    let retrained = sapnet(&[
        "sources",
        "--retrain",
        "--config",
        &tiny_config(),
        "--library",
        tmp.path().to_str().unwrap(),
    ]);
    assert!(retrained.status.success(), "{}", stderr(&retrained));
    let listed = manifest::read(&dir).unwrap().unwrap();
    let kept: Vec<&str> = listed.imported.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(kept, ["sb3", "seq"]);
    assert_eq!(listed.policies.len(), 3);
    let reuse = root().join("tests/configs/tiny_reuse.ron");
    let out = tmp.path().join("out");
    let run = sapnet(&[
        "--headless",
        "--config",
        reuse.to_str().unwrap(),
        "--library",
        tmp.path().to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
}
