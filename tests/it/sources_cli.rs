//! `sapnet sources`: a library of random architectures, written once with its manifest,
//! replaced only when asked, resumed after a kill; a run refuses a library that is not
//! whole.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

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
    // Asked again, the finished library is said to be there: a notice, exit 0 (issue 27:
    // it printed "error:" and exited 2), and nothing is trained or written.
    let again = train(tmp.path(), &[]);
    assert_eq!(again.status.code(), Some(0));
    let message = String::from_utf8_lossy(&again.stderr);
    assert!(
        message.contains("already holds the 3 policies this config describes: nothing to train"),
        "{message}"
    );
    assert!(!message.contains("error"), "{message}");
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

/// A config whose three sources each take a moment to train, so a kill can land between
/// two of them.
fn slow_config(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("slow.ron");
    let text = std::fs::read_to_string(tiny_config())
        .unwrap()
        .replace("training_episodes: 3", "training_episodes: 1500");
    std::fs::write(&path, text).unwrap();
    path
}

fn sources(config: &Path, library: &Path, extra: &[&str]) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_sapnet"));
    command
        .args(["sources", "--config"])
        .arg(config)
        .arg("--library")
        .arg(library)
        .args(extra);
    command
}

/// Starts `command` and kills it (SIGKILL: nothing can be cleaned up) once the library's
/// manifest lists a first policy.
fn kill_after_first_policy(mut command: Command, manifest: &Path) {
    let mut child = command
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let started = Instant::now();
    loop {
        let text = std::fs::read_to_string(manifest).unwrap_or_default();
        if text.contains("complete: false") && text.contains("source-0") {
            break;
        }
        assert!(
            child.try_wait().unwrap().is_none(),
            "training ended before the kill"
        );
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "no first policy"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
}

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut found: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        // The trainer's lock file says who trained last, not what was trained.
        .filter(|p| p.is_file() && !p.ends_with(sapnet::folder_lock::LOCK_FILE))
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    found.sort();
    found
}

fn refusal(config: &Path, library: &Path) -> String {
    let config = Config::from_file(config).unwrap();
    let err = sources::load_library(&config, library).unwrap_err();
    format!("{err:#}")
}

#[test]
fn a_killed_training_is_refused_then_resumed_to_the_same_library() {
    let tmp = tempfile::tempdir().unwrap();
    let config = slow_config(tmp.path());
    let whole = tmp.path().join("whole");
    let output = sources(&config, &whole, &[]).output().unwrap();
    assert!(output.status.success());

    let library = tmp.path().join("lib");
    let dir = library.join("cartpole");
    kill_after_first_policy(sources(&config, &library, &[]), &dir.join("library.ron"));
    let message = refusal(&config, &library);
    assert!(message.contains("is unfinished"), "{message}");
    assert!(message.contains("missing: "), "{message}");
    assert!(message.contains("source-2"), "{message}");

    // Without --retrain: the policies on disk are kept, the rest trained.
    let resumed = sources(&config, &library, &[]).output().unwrap();
    let said = String::from_utf8_lossy(&resumed.stderr);
    assert!(resumed.status.success(), "{said}");
    assert!(
        said.contains("policies already trained and checked"),
        "{said}"
    );
    assert_eq!(files(&dir), files(&whole.join("cartpole")));
    sources::load_library(&Config::from_file(&config).unwrap(), &library).unwrap();
}

#[test]
fn a_killed_retrain_leaves_a_library_runs_refuse_and_no_leftovers_after_it_resumes() {
    let tmp = tempfile::tempdir().unwrap();
    let config = slow_config(tmp.path());
    let library = tmp.path().join("lib");
    let dir = library.join("cartpole");
    assert!(sources(&config, &library, &[]).status().unwrap().success());
    let before = files(&dir);
    // A stray temporary, as a kill in the middle of a save leaves.
    std::fs::write(dir.join(".source-1.ron.999.tmp"), "half").unwrap();

    kill_after_first_policy(
        sources(&config, &library, &["--retrain"]),
        &dir.join("library.ron"),
    );
    assert!(refusal(&config, &library).contains("is unfinished"));
    assert!(sources(&config, &library, &[])
        .stderr(Stdio::null())
        .status()
        .unwrap()
        .success());
    // Same config and seed: the retrained library is the old one, and nothing is left over.
    assert_eq!(files(&dir), before);
}

#[test]
fn a_library_missing_a_file_or_holding_an_unlisted_policy_is_refused_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    let dir = library.join("cartpole");
    assert!(train(&library, &[]).status.success());
    let config = Path::new(&tiny_config()).to_path_buf();

    // The weights are there, their metadata is not.
    let metadata = dir.join("source-1.ron");
    let kept = std::fs::read(&metadata).unwrap();
    std::fs::remove_file(&metadata).unwrap();
    let message = refusal(&config, &library);
    assert!(message.contains("source-1.ron"), "{message}");
    assert!(message.contains("does not exist"), "{message}");
    std::fs::write(&metadata, kept).unwrap();
    sources::load_library(&Config::from_file(&config).unwrap(), &library).unwrap();

    // A policy copied in by hand beside the library's own.
    for ext in ["ron", "safetensors"] {
        std::fs::copy(
            dir.join(format!("source-0.{ext}")),
            dir.join(format!("extra.{ext}")),
        )
        .unwrap();
    }
    let message = refusal(&config, &library);
    assert!(message.contains("holds policy extra"), "{message}");
    assert!(message.contains("does not list"), "{message}");
    std::fs::remove_file(dir.join("extra.ron")).unwrap();
    // Its weights alone are refused too.
    assert!(refusal(&config, &library).contains("holds policy extra"));
}

#[test]
fn a_library_without_a_manifest_is_refused_then_checked_and_adopted_by_sources() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    let dir = library.join("cartpole");
    assert!(train(&library, &[]).status.success());
    let manifest = std::fs::read(dir.join("library.ron")).unwrap();
    std::fs::remove_file(dir.join("library.ron")).unwrap();
    let config = Path::new(&tiny_config()).to_path_buf();
    let message = refusal(&config, &library);
    assert!(message.contains("no manifest"), "{message}");
    assert!(message.contains("sapnet sources"), "{message}");

    let adopted = train(&library, &[]);
    let said = String::from_utf8_lossy(&adopted.stderr);
    assert!(adopted.status.success(), "{said}");
    assert!(said.contains("3 of 3 policies already trained"), "{said}");
    assert_eq!(std::fs::read(dir.join("library.ron")).unwrap(), manifest);
}

#[test]
fn the_manifest_lists_every_policy_with_the_hashes_of_its_files() {
    let tmp = tempfile::tempdir().unwrap();
    assert!(train(tmp.path(), &[]).status.success());
    let dir = tmp.path().join("cartpole");
    let manifest = sources::manifest::read(&dir).unwrap().unwrap();
    assert!(manifest.complete);
    let config = Config::from_file(Path::new(&tiny_config())).unwrap();
    assert_eq!(manifest.training, sources::LibraryTraining::of(&config));
    let names: Vec<&str> = manifest.policies.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["source-0", "source-1", "source-2"]);
    for entry in &manifest.policies {
        let (weights, metadata) = policy_store::paths(&dir, &entry.name);
        let sha = |p: &Path| policy_store::sha256_hex(&std::fs::read(p).unwrap());
        assert_eq!(entry.weights_sha256, sha(&weights));
        assert_eq!(entry.metadata_sha256, sha(&metadata));
    }
}
