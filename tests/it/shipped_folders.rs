//! Every results folder shipped in `docs/` reads as `sapnet open` and `sapnet plot` read it
//! (its `summary.json` and its episodes, no run records): a change to a method's knobs or
//! label that would orphan a shipped run (the episode study's `qswitch` once did) fails
//! here, not in a reader's hands.

use std::path::{Path, PathBuf};

use sapnet::results::{read_header, shipped};

fn shipped_folders(dir: &Path, found: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let entry = entry.unwrap();
        if entry.file_type().unwrap().is_dir() {
            let path = entry.path();
            if path.join("summary.json").is_file() && shipped::can_replot(&path) {
                found.push(path.clone());
            }
            shipped_folders(&path, found);
        }
    }
}

#[test]
fn every_folder_shipped_in_docs_reads_with_every_run_its_config_lists() {
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs");
    let mut found = Vec::new();
    shipped_folders(&docs, &mut found);
    assert!(
        found.len() >= 10,
        "docs/ ships its results folders: found {}",
        found.len()
    );
    let failures: Vec<String> = found
        .iter()
        .filter(|dir| !dir.join("runs").exists())
        .filter_map(|dir| {
            let read = read_header(dir).and_then(|header| shipped::runs(dir, &header));
            read.err().map(|e| format!("{}: {e:#}", dir.display()))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
