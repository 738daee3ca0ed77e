//! The numbers of the paper's default runs, pinned: a restructure must not move them.
//!
//! The embedded `--quick` protocol (SAP-Net and the three DQN baselines on CartPole, two
//! runs each) and a cut of the shipped MountainCar config run on the shipped libraries;
//! every number of `episodes.csv` (but the wall time), `tests.csv` and SAP-Net's
//! activations and probabilities is reduced to one digest per file, with the rows sorted,
//! so that neither `--jobs` nor a new column moves it. Only a deliberate numerical change,
//! said in its commit, may update a pin (the last: the seed derivation of 2026-12, which
//! hashes the base seed and each part apart and names a run by its method's label, with
//! PRQ-learning's W on [0, 1] and the random selectors' handover; before it, issue 16's
//! kernels, which sum in their own order). The pins are the same on the AVX-512, AVX2 and
//! portable paths, checked with `SAPNET_KERNELS=avx2` and `=portable cargo test --release
//! --test it pinned_numbers`.

use crate::common::library::copy_library;

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use sapnet::config::Config;
use sapnet::dqn::kernels::{Isa, KERNELS_VARIABLE};
use sha2::{Digest, Sha256};

/// The columns each file's digest covers, read by name.
const EPISODE_KEY: [&str; 3] = ["method", "run", "episode"];
const EPISODE_NUMBERS: [&str; 5] = ["reward", "steps", "loss", "statistic_loss", "epsilon"];

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut reader = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    let header = reader.headers().unwrap().iter().map(String::from).collect();
    let rows = reader
        .records()
        .map(|r| r.unwrap().iter().map(String::from).collect())
        .collect();
    (header, rows)
}

/// The named columns of every row (a row without one of them is skipped, e.g. the
/// activations of a method that has none), sorted by `key` and hashed.
fn digest(path: &Path, key: &[&str], numbers: &dyn Fn(&str) -> bool) -> String {
    let (header, rows) = read_csv(path);
    let col = |name: &str| header.iter().position(|h| h == name);
    let key_cols: Vec<usize> = key
        .iter()
        .map(|k| col(k).unwrap_or_else(|| panic!("{path:?} has no column {k}")))
        .collect();
    let number_cols: Vec<usize> = (0..header.len()).filter(|&i| numbers(&header[i])).collect();
    // activations.csv lists every reusing method; the pinned numbers are SAP-Net's.
    let method = col("method").filter(|_| !key.contains(&"method"));
    let mut lines = BTreeMap::new();
    for row in rows {
        if method.is_some_and(|m| row[m] != "sapnet") {
            continue;
        }
        let k: Vec<String> = key_cols.iter().map(|&i| row[i].clone()).collect();
        let v: Vec<String> = number_cols.iter().map(|&i| row[i].clone()).collect();
        if v.iter().all(String::is_empty) {
            continue;
        }
        // Sort numerically where the key is a number (run 10 after run 9).
        let sortable: Vec<(u64, String)> = k
            .iter()
            .map(|s| (s.parse().unwrap_or(0), s.clone()))
            .collect();
        lines.insert(sortable, format!("{}|{}", k.join(","), v.join(",")));
    }
    let mut hasher = Sha256::new();
    for line in lines.values() {
        hasher.update(line.as_bytes());
        hasher.update(b"\n");
    }
    format!("{:x}", hasher.finalize())[..16].to_string()
}

/// One digest per result file of the run in `out`.
fn digests(out: &Path) -> [String; 3] {
    let episodes = digest(&out.join("episodes.csv"), &EPISODE_KEY, &|h| {
        EPISODE_NUMBERS.contains(&h)
    });
    let tests = digest(&out.join("tests.csv"), &["method", "run", "test"], &|h| {
        h == "return"
    });
    let activations = digest(
        &out.join("activations.csv"),
        &["run", "episode"],
        &|h: &str| h.starts_with("A_") || h.starts_with("P_"),
    );
    [episodes, tests, activations]
}

fn run_headless(config: &Path, library: &Path, out: &Path, quick: bool, kernels: Option<Isa>) {
    let mut command = Command::new(env!("CARGO_BIN_EXE_sapnet"));
    if let Some(isa) = kernels {
        command.env(KERNELS_VARIABLE, isa.name());
    }
    command
        .args(["--headless", "--jobs", "2", "--config"])
        .arg(config)
        .arg("--library")
        .arg(library)
        .arg("--out")
        .arg(out);
    if quick {
        command.arg("--quick");
    }
    let output = command.output().unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

#[test]
fn the_embedded_quick_protocol_gives_the_pinned_numbers() {
    let tmp = tempfile::tempdir().unwrap();
    copy_library("cartpole", &tmp.path().join("lib"));
    let out = tmp.path().join("out");
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cartpole.ron");
    run_headless(&config, &tmp.path().join("lib"), &out, true, None);
    let pinned = [
        "4396d728c375a743".to_string(),
        "881fe427eb1cd3d5".to_string(),
        "f6f59ada9b64b547".to_string(),
    ];
    assert_eq!(digests(&out), pinned);
    // The same bits on this CPU's other vector path (the portable one takes minutes on x86,
    // where `mul_add` is a library call: checked by hand, see the top of this file).
    if Isa::Avx2.supported() && Isa::best() != Isa::Avx2 {
        let out = tmp.path().join("out-avx2");
        run_headless(
            &config,
            &tmp.path().join("lib"),
            &out,
            true,
            Some(Isa::Avx2),
        );
        assert_eq!(digests(&out), pinned, "on the AVX2 path");
    }
}

#[test]
fn the_shipped_mountain_car_config_gives_the_pinned_numbers() {
    let tmp = tempfile::tempdir().unwrap();
    copy_library("mountain_car", &tmp.path().join("lib"));
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/mountain_car.ron");
    let mut config = Config::from_file(&shipped).unwrap();
    // Past the warm-up (10 × 100 steps) and into selection, in seconds.
    config.protocol.budget = sapnet::config::Budget::Episodes(12);
    config.protocol.runs = 1;
    let cut = tmp.path().join("mountain_car_cut.ron");
    let text = sapnet::ron_file::ron_options().to_string(&config).unwrap();
    std::fs::write(&cut, text).unwrap();
    let out = tmp.path().join("out");
    run_headless(&cut, &tmp.path().join("lib"), &out, false, None);
    assert_eq!(
        digests(&out),
        [
            "fe43b3419aa743a2".to_string(),
            "65cdc7330c0c705e".to_string(),
            "71d1d612b0652e44".to_string()
        ]
    );
}
