use std::path::Path;

/// A copy of the shipped library `saved_policies/<task>` under `library`, so that a test's
/// runs read a library outside the checkout.
pub fn copy_library(task: &str, library: &Path) {
    let from = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("saved_policies")
        .join(task);
    let to = library.join(task);
    std::fs::create_dir_all(&to).unwrap();
    for entry in std::fs::read_dir(&from).unwrap() {
        let path = entry.unwrap().path();
        if path.is_file() {
            std::fs::copy(&path, to.join(path.file_name().unwrap())).unwrap();
        }
    }
}

/// Runs `sapnet --headless --quick --jobs 2` on `config` over a copy of the shipped library
/// `saved_policies/<task>` under `dir`; asserts it succeeded and returns its `--out` folder
/// and parsed `summary.json`.
pub fn quick_protocol(
    config: &Path,
    task: &str,
    dir: &Path,
) -> (std::path::PathBuf, serde_json::Value) {
    let (library, out) = (dir.join("library"), dir.join("out"));
    copy_library(task, &library);
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args(["--headless", "--quick", "--jobs", "2", "--config"])
        .arg(config)
        .arg("--library")
        .arg(&library)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("the binary runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    (out, serde_json::from_str(&summary).unwrap())
}
