//! The README's front door, run as written (issue 51, item 7): the set-up's test command is
//! the one `.ci/run` runs, the quick start fits the first screen, and every command of the
//! quick start's `sh` block runs, in order, in a fresh folder laid out as the checkout is
//! (`assets/` and the shipped CartPole library), with what it says checked.
//!
//! The commands that open the terminal UI (`sapnet` without `--headless`, `open`, `teach`)
//! run in a tmux pane driven by keys, as `tui_tmux.rs` drives the dashboard; without tmux
//! they are skipped, saying so, and the others still run. A command of the block that this
//! file has no check for fails the test: the README cannot change without it.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common::cli::{ok, sapnet, stderr};
use crate::common::library::copy_library;
use crate::common::tmux::{self, Session};

fn readme() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap()
}

/// The lines of the first fenced block (```` ```LANG ````) after the heading `heading`, and
/// the README's line number of its closing fence.
fn block_after(readme: &str, heading: &str, lang: &str) -> (Vec<String>, usize) {
    let lines: Vec<&str> = readme.lines().collect();
    let at = lines
        .iter()
        .position(|l| *l == heading)
        .unwrap_or_else(|| panic!("README.md has no heading `{heading}`"));
    let open = at
        + lines[at..]
            .iter()
            .position(|l| *l == format!("```{lang}"))
            .unwrap_or_else(|| panic!("no ```{lang} block under `{heading}`"));
    let close = open + 1 + lines[open + 1..].iter().position(|l| *l == "```").unwrap();
    let block = lines[open + 1..close]
        .iter()
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.to_string())
        .collect();
    (block, close + 1)
}

/// One line of a shell block as the shell splits it: words (single quotes kept together and
/// dropped), a `#` at a word's start ending the line, `&&` between commands.
fn commands(line: &str) -> Vec<Vec<String>> {
    let (mut words, mut word) = (vec![], String::new());
    let (mut quoted, mut in_word) = (false, false);
    for c in line.chars() {
        match c {
            '\'' => (quoted, in_word) = (!quoted, true),
            c if c.is_whitespace() && !quoted => {
                if in_word {
                    words.push(std::mem::take(&mut word));
                }
                in_word = false;
            }
            '#' if !quoted && !in_word => break,
            c => (word, in_word) = (word + &c.to_string(), true),
        }
    }
    assert!(!quoted, "an unclosed quote in `{line}`");
    if in_word {
        words.push(word);
    }
    let mut commands = vec![vec![]];
    for word in words {
        if word == "&&" {
            commands.push(vec![]);
        } else {
            commands.last_mut().unwrap().push(word);
        }
    }
    commands.retain(|c: &Vec<String>| !c.is_empty());
    commands
}

#[test]
fn the_shell_splitter_reads_quotes_comments_and_and() {
    assert_eq!(
        commands("sapnet a 'b#c[1]' --x && sapnet y  # a comment, 'quoted'"),
        [vec!["sapnet", "a", "b#c[1]", "--x"], vec!["sapnet", "y"]]
    );
}

/// The value after `flag` in `words`.
fn value<'a>(words: &'a [String], flag: &str) -> &'a str {
    let at = words.iter().position(|w| w == flag).unwrap();
    &words[at + 1]
}

/// What a command of the quick start is, by which its output is checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Kind {
    ProtocolUi,
    ProtocolHeadless,
    Open,
    Compare,
    TeachUi,
    TeachHeadless,
    SweepPlan,
    SweepRun,
    SweepMerge,
}

fn kind(words: &[String]) -> Kind {
    assert_eq!(
        words[0], "sapnet",
        "a quick-start command runs sapnet: {words:?}"
    );
    let headless = words.iter().any(|w| w == "--headless");
    let sub: Vec<&str> = words[1..]
        .iter()
        .take_while(|w| !w.starts_with('-'))
        .take(2)
        .map(String::as_str)
        .collect();
    match (sub.as_slice(), headless) {
        ([], false) => Kind::ProtocolUi,
        ([], true) => Kind::ProtocolHeadless,
        (["open", _], _) => Kind::Open,
        (["compare", ..], _) => Kind::Compare,
        (["teach", ..], false) => Kind::TeachUi,
        (["teach", ..], true) => Kind::TeachHeadless,
        (["sweep", "plan"], _) => Kind::SweepPlan,
        (["sweep", "run"], _) => Kind::SweepRun,
        (["sweep", "merge"], _) => Kind::SweepMerge,
        _ => panic!(
            "the quick start's `{}` has no check in tests/it/quick_start.rs: add one",
            words.join(" ")
        ),
    }
}

/// `words` run as the README's reader runs them, in `dir`.
fn run(dir: &Path, words: &[String]) -> Output {
    sapnet()
        .args(&words[1..])
        .current_dir(dir)
        .output()
        .expect("the binary runs")
}

/// `words` started in a tmux pane in `dir`, the pane saying `SAPNET-EXITED <code>` when
/// the binary ends.
fn in_tmux(dir: &Path, words: &[String]) -> Session {
    let quote = |w: &str| format!("'{}'", w.replace('\'', r"'\''"));
    let args: Vec<String> = words[1..].iter().map(|w| quote(w)).collect();
    let command = format!(
        "cd {} && {} {}; echo SAPNET-EXITED $?; sleep 60",
        quote(&dir.to_string_lossy()),
        quote(env!("CARGO_BIN_EXE_sapnet")),
        args.join(" ")
    );
    Session::start(120, 40, &command)
}

/// What a command said, on stdout and stderr.
fn both(output: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        stderr(output)
    )
}

fn summary_status(folder: &Path) -> String {
    let text = std::fs::read_to_string(folder.join("summary.json"))
        .unwrap_or_else(|e| panic!("{}: {e}", folder.join("summary.json").display()));
    let summary: serde_json::Value = serde_json::from_str(&text).unwrap();
    summary["status"].as_str().unwrap_or_default().to_string()
}

/// Checks what one command of the quick start said and wrote.
fn check(dir: &Path, words: &[String], kind: Kind) {
    let said = words.join(" ");
    match kind {
        Kind::ProtocolUi => {
            let session = in_tmux(dir, words);
            session.wait_for(&["SAP-Net graph", "policies"]);
            session.wait_for(&["· complete ·"]);
            session.keys("q");
            let screen = session.wait_for(&["SAPNET-EXITED 0"]);
            let out = value(words, "--out");
            assert!(
                screen.contains(&format!("results in {out}")),
                "{said}:\n{screen}"
            );
            assert_eq!(summary_status(&dir.join(out)), "complete", "{said}");
        }
        Kind::ProtocolHeadless => {
            let output = ok(run(dir, words));
            let stdout = String::from_utf8_lossy(&output.stdout);
            let table = stdout
                .lines()
                .find(|l| l.starts_with("method "))
                .unwrap_or_else(|| panic!("{said}: no comparison table on stdout:\n{stdout}"));
            assert!(table.contains("return IQM [95% CI]"), "{said}: {table}");
            assert!(
                stdout.lines().any(|l| l.starts_with("sapnet ")),
                "{said}:\n{stdout}"
            );
            let out = value(words, "--out");
            assert!(
                stderr(&output).contains(&format!("results in {out}")),
                "{said}"
            );
            assert_eq!(summary_status(&dir.join(out)), "complete", "{said}");
        }
        Kind::Open => {
            let session = in_tmux(dir, words);
            session.wait_for(&["Runs ·", "done", "sapnet"]);
            session.keys("c");
            // Each view known by its own keys in the status bar.
            session.wait_for(&["a aggregate", "s score"]);
            session.keys("v");
            session.wait_for(&["y metric", "x axis"]);
            session.keys("q");
            session.wait_for(&["SAPNET-EXITED 0"]);
        }
        Kind::Compare => {
            let output = ok(run(dir, words));
            let stdout = String::from_utf8_lossy(&output.stdout);
            for method in words
                .iter()
                .filter_map(|w| w.split_once('='))
                .map(|(m, _)| m)
            {
                assert!(
                    stdout.lines().any(|l| l.starts_with(&format!("{method} "))),
                    "{said}: no row of {method}:\n{stdout}"
                );
            }
            let out = dir.join(value(words, "--out"));
            for file in [
                "comparison.csv",
                "improvement.csv",
                "runs.csv",
                "intervals.png",
            ] {
                assert!(out.join(file).is_file(), "{said}: no {file}");
            }
        }
        Kind::TeachUi => {
            let session = in_tmux(dir, words);
            session.wait_for(&["SAP-Net · T_ω 1", "activations"]);
            session.keys("a");
            session.wait_for(&["pending spread calls", "▶"]);
            session.keys("s");
            // π0's first call deposits η/(h×Ω) = 0.5/(1×0.4) on π1 (eq. 9-11).
            session.wait_for(&["1.250000"]);
            session.keys("q");
            session.wait_for(&["SAPNET-EXITED 0"]);
        }
        Kind::TeachHeadless => {
            let output = ok(run(dir, words));
            let stdout = String::from_utf8_lossy(&output.stdout);
            for needle in [
                "activate π1: A[π1] += 𝒜 = 1, k = 3, η = 𝒜/k = 0.333333",
                "stopped: Ω ≥ T_ω",
                "policy    activation  probability",
            ] {
                assert!(stdout.contains(needle), "{said}: no `{needle}`:\n{stdout}");
            }
        }
        Kind::SweepPlan => {
            let said_all = both(&ok(run(dir, words)));
            let out = value(words, "--out");
            assert!(
                said_all.contains(&format!("6 cells in {out}")),
                "{said}:\n{said_all}"
            );
            assert!(dir.join(out).join("slurm.sbatch").is_file(), "{said}");
        }
        Kind::SweepRun => {
            let said_all = both(&ok(run(dir, words)));
            assert!(
                said_all.contains("6 cells: 6 done, 0 running, 0 failed, 0 missing"),
                "{said}:\n{said_all}"
            );
        }
        Kind::SweepMerge => {
            let said_all = both(&ok(run(dir, words)));
            let sweep = &words[3];
            assert!(
                said_all.contains(&format!("merged 6 cells into {sweep}/merged")),
                "{said}:\n{said_all}"
            );
        }
    }
}

#[test]
fn the_readme_sets_up_with_the_command_ci_runs() {
    let readme = readme();
    let ci =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(".ci/run")).unwrap();
    let ci_test = ci
        .lines()
        .rev()
        .find(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .unwrap();
    let set_up: Vec<&str> = readme
        .lines()
        .skip_while(|l| !l.starts_with("## Set-up"))
        .filter(|l| l.starts_with("    cargo "))
        .map(|l| l.split('#').next().unwrap().trim())
        .collect();
    assert_eq!(set_up, ["cargo run --release", ci_test], "README's set-up");
}

#[test]
fn the_readme_quick_start_runs_as_written() {
    let readme = readme();
    let (lines, end) = block_after(&readme, "## Quick start", "sh");
    assert!(
        end <= 60,
        "the quick start ends on line {end}: past the first screen"
    );
    assert!(
        (5..=8).contains(&lines.len()),
        "five to eight commands: {lines:?}"
    );
    let commands: Vec<Vec<String>> = lines.iter().flat_map(|l| commands(l)).collect();
    let kinds: Vec<Kind> = commands.iter().map(|c| kind(c)).collect();
    for wanted in [
        Kind::ProtocolUi,
        Kind::ProtocolHeadless,
        Kind::Open,
        Kind::Compare,
        Kind::TeachUi,
        Kind::SweepPlan,
        Kind::SweepRun,
    ] {
        assert!(
            kinds.contains(&wanted),
            "the quick start has no {wanted:?} command"
        );
    }

    // A folder laid out as the checkout is: the configs, and the shipped library the
    // default protocol reuses (copied, so nothing writes into the checkout).
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::os::unix::fs::symlink(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("assets"),
        dir.join("assets"),
    )
    .unwrap();
    copy_library("cartpole", &dir.join("saved_policies"));

    let tmux = tmux::available();
    if !tmux {
        eprintln!(
            "tmux is not installed: the quick start's commands that open the UI are skipped (.ci/run installs it)"
        );
    }
    // Each protocol's folder, and its flags but --out and --headless.
    let mut protocols: Vec<(PathBuf, Vec<String>)> = vec![];
    for (words, kind) in commands.iter().zip(kinds) {
        let ui = matches!(kind, Kind::ProtocolUi | Kind::Open | Kind::TeachUi);
        if ui && !tmux {
            continue;
        }
        check(dir, words, kind);
        if matches!(kind, Kind::ProtocolUi | Kind::ProtocolHeadless) {
            let out = value(words, "--out");
            let flags = words
                .iter()
                .filter(|w| *w != "--headless" && *w != "--out" && *w != out)
                .cloned()
                .collect();
            protocols.push((dir.join(out), flags));
        }
    }
    // The UI and headless protocols of the same flags leave the same comparison.
    if let [(ui, ui_flags), (headless, headless_flags)] = protocols.as_slice() {
        assert_eq!(
            ui_flags, headless_flags,
            "the quick start's two protocols differ"
        );
        let read = |p: &Path| std::fs::read_to_string(p.join("comparison.csv")).unwrap();
        assert_eq!(
            read(ui),
            read(headless),
            "the UI's comparison.csv and headless's"
        );
    }
}
