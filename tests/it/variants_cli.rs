//! Libraries over several source tasks: trained task by task, each policy recording its
//! task, reused on a target that is none of them, refused when the tasks or the sizes do
//! not fit.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use sapnet::config::Config;
use sapnet::{policy_store, sources};

fn config(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/configs")
        .join(name)
}

fn sapnet(args: &[&str], library: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args(args)
        .arg("--library")
        .arg(library)
        .output()
        .expect("the binary runs")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn train(config: &Path, library: &Path) -> Output {
    sapnet(&["sources", "--config", config.to_str().unwrap()], library)
}

#[test]
fn a_library_over_two_tasks_records_each_policys_task_and_is_reused() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    let file = config("tiny_variants.ron");
    let output = train(&file, &library);
    assert!(output.status.success(), "{}", stderr(&output));

    let dir = library.join("tiny-variants");
    let parsed = Config::from_file(&file).unwrap();
    let tasks = sources::tasks(&parsed);
    assert_eq!(tasks[0].label, "cartpole(length=1.0)");
    assert_eq!(tasks[1].label, "mirrored");
    for (plan, task) in sources::plan(&parsed).iter().zip([0, 0, 1]) {
        assert_eq!(plan.task, task);
        let policy = policy_store::load(&dir, &plan.name).unwrap();
        assert_eq!(policy.metadata.source_task, tasks[task].env);
    }
    let manifest = sources::manifest::read(&dir).unwrap().unwrap();
    assert_eq!(manifest.training.tasks, tasks);

    // Each source tested on the target, beside its score on its own task.
    let evaluated = sapnet(
        &["sources", "--config", file.to_str().unwrap(), "--evaluate"],
        &library,
    );
    assert!(evaluated.status.success(), "{}", stderr(&evaluated));
    let table = String::from_utf8(evaluated.stdout).unwrap();
    let rows: Vec<&str> = table.lines().collect();
    assert!(
        rows[0].contains("own task") && rows[0].ends_with("CartPole-v1"),
        "{table}"
    );
    assert_eq!(rows.len(), 4, "{table}");
    assert!(
        rows[3].starts_with("source-2") && rows[3].contains("mirrored"),
        "{table}"
    );
    let evaluations = sources::evaluate(&parsed, &library).unwrap();
    assert!(evaluations.iter().all(|e| e.target_score >= 1.0));

    let out = tmp.path().join("out");
    let output = sapnet(
        &[
            "--headless",
            "--config",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &library,
    );
    assert!(output.status.success(), "{}", stderr(&output));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let named: Vec<&str> = summary["library"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["task"].as_str().unwrap())
        .collect();
    assert_eq!(
        named,
        ["cartpole(length=1.0)", "cartpole(length=1.0)", "mirrored"]
    );
    // The chosen policy's copy names the library it came from.
    let chosen = policy_store::load(&out.join("policies"), "sapnet-run0").unwrap();
    assert!(chosen
        .metadata
        .reused
        .unwrap()
        .starts_with("tiny-variants/source-"));
}

#[test]
fn a_library_of_other_tasks_or_sizes_is_refused_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    let file = config("tiny_variants.ron");
    assert!(train(&file, &library).status.success());
    let text = std::fs::read_to_string(&file).unwrap();

    // The same library name over other physics.
    let other = tmp.path().join("other.ron");
    std::fs::write(&other, text.replace("length: 1.0", "length: 2.0")).unwrap();
    let refused = sapnet(
        &[
            "--headless",
            "--config",
            other.to_str().unwrap(),
            "--out",
            tmp.path().join("out").to_str().unwrap(),
        ],
        &library,
    );
    assert_eq!(refused.status.code(), Some(2));
    let message = stderr(&refused);
    assert!(
        message.contains("was trained on cartpole(length=1.0) ×2, mirrored ×1"),
        "{message}"
    );
    assert!(message.contains("cartpole(length=2.0) ×2"), "{message}");

    // Two families in one library: a task of other sizes than the target's, without a
    // mapping, is refused at its field before anything trains.
    let mixed = tmp.path().join("mixed.ron");
    std::fs::write(
        &mixed,
        text.replace("tiny-variants", "mixed").replace(
            "(env: CartPole(force_mag: -10.0), count: 1, label: Some(\"mirrored\"))",
            "(env: MountainCar(), count: 1)",
        ),
    )
    .unwrap();
    let refused = train(&mixed, &library);
    assert_eq!(refused.status.code(), Some(2));
    let message = stderr(&refused);
    assert!(
        message.contains(
            "field `sources.tasks[1]`: its agent has 2 observation values and 3 actions, the \
             target's 4 observation values and 2 actions: give its `mapping"
        ),
        "{message}"
    );
    assert!(!library.join("mixed").exists());
}

#[test]
fn source_tasks_that_cannot_work_are_refused_at_their_field() {
    let base = std::fs::read_to_string(config("tiny_variants.ron")).unwrap();
    for (change, field) in [
        (("count: 3,", "count: 4,"), "sources.count"),
        (("name: Some(\"tiny-variants\"),", ""), "sources.name"),
        (
            ("name: Some(\"tiny-variants\")", "name: Some(\"../up\")"),
            "sources.name",
        ),
        (("count: 2)", "count: 0)"), "sources.tasks[0].count"),
        (
            ("length: 1.0", "length: -1.0"),
            "sources.tasks[0].env.length",
        ),
        (
            (
                "label: Some(\"mirrored\")",
                "label: Some(\"cartpole(length=1.0)\")",
            ),
            "sources.tasks[1]",
        ),
        (
            (
                "training_episodes: 3,",
                "training_episodes: 3, env: Some(CartPole()),",
            ),
            "sources.env",
        ),
    ] {
        let text = base.replace(change.0, change.1);
        assert_ne!(text, base, "{change:?}");
        let err = Config::from_ron(&text, "v.ron").unwrap_err().to_string();
        assert!(
            err.contains(&format!("field `{field}`")),
            "{change:?}: {err}"
        );
    }
}
