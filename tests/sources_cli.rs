//! `sapnet sources`: a library of random architectures, written once, replaced only when
//! asked.

use std::path::Path;
use std::process::{Command, Output};

use sapnet::config::Config;
use sapnet::{policy_store, sources};

fn tiny_config() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/configs/tiny_sources.ron")
        .display()
        .to_string()
}

fn train(library: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args(["sources", "--config", &tiny_config(), "--library"])
        .arg(library)
        .args(extra)
        .output()
        .expect("the binary runs")
}

#[test]
fn the_library_holds_the_planned_policies_and_is_not_overwritten_unasked() {
    let tmp = tempfile::tempdir().unwrap();
    let output = train(tmp.path(), &[]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );

    let config = Config::from_file(Path::new(&tiny_config())).unwrap();
    let dir = tmp.path().join("cartpole");
    let mut names = policy_store::list(&dir).unwrap();
    names.sort();
    assert_eq!(names, ["source-0", "source-1", "source-2"]);
    for plan in sources::plan(&config) {
        let policy = policy_store::load_for_task(&dir, &plan.name, 4, 2).unwrap();
        assert_eq!(policy.net.architecture().hidden, plan.hidden);
        assert_eq!(policy.metadata.training.episodes, 3);
        assert_eq!(policy.metadata.seed, plan.seed);
        assert!(policy.metadata.final_score.is_some());
    }

    let before = std::fs::read(dir.join("source-0.safetensors")).unwrap();
    let refused = train(tmp.path(), &[]);
    assert_eq!(refused.status.code(), Some(2));
    let message = String::from_utf8_lossy(&refused.stderr);
    assert!(message.contains("already holds 3 policies"), "{message}");
    assert!(message.contains("--retrain"), "{message}");
    assert_eq!(
        std::fs::read(dir.join("source-0.safetensors")).unwrap(),
        before
    );

    let retrained = train(tmp.path(), &["--retrain"]);
    assert!(retrained.status.success());
    // Same seed, same config: the same library, to the bit.
    assert_eq!(
        std::fs::read(dir.join("source-0.safetensors")).unwrap(),
        before
    );
}
