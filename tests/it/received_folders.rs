//! A folder from elsewhere runs nothing, and a misbehaving environment never hangs sapnet
//! (issue 34). Each test makes the hostile folder, worker script or file itself; the tests
//! that need a Python with Gymnasium say they are skipped without one.

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::common::cli::{configs, ok, sapnet, stderr};
use crate::common::python::python_or_skip;

/// Refused with exit 2 and a message holding each of `says`.
fn refused(output: &Output, says: &[&str]) {
    assert_eq!(output.status.code(), Some(2), "{}", stderr(output));
    for s in says {
        assert!(
            stderr(output).contains(s),
            "expected {s:?}: {}",
            stderr(output)
        );
    }
}

/// A finished DQN protocol in `out`, then its summary doctored by `edit` and marked stopped,
/// as a folder received from someone else would be.
fn received_results(out: &Path, edit: impl FnOnce(&mut serde_json::Value)) {
    ok(sapnet()
        .args(["--headless", "--config"])
        .arg(configs("short_cartpole.ron"))
        .arg("--out")
        .arg(out)
        .output()
        .unwrap());
    let path = out.join("summary.json");
    let mut summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    summary["status"] = "stopped".into();
    edit(&mut summary);
    std::fs::write(&path, serde_json::to_string_pretty(&summary).unwrap()).unwrap();
}

/// `kill -SIGNAL pid`.
fn kill(pid: u32, signal: &str) {
    assert!(Command::new("kill")
        .arg(format!("-{signal}"))
        .arg(pid.to_string())
        .status()
        .unwrap()
        .success());
}

/// A CartPole task through Gymnasium, as a summary.json holds it.
fn gymnasium_task(id: &str, python: Option<&str>) -> serde_json::Value {
    serde_json::json!({"Gymnasium": {"id": id, "kwargs": {}, "attributes": {},
        "max_episode_steps": null, "return_range": null, "python": python}})
}

/// Items 1 and 2: the interpreter and the modules a resumed protocol runs come from the
/// user's invocation, never from the folder's summary.json; the program the folder names
/// never starts.
#[test]
fn a_results_folder_cannot_choose_the_program_or_module_a_resume_runs() {
    let tmp = tempfile::tempdir().unwrap();
    // The program a hostile folder names: it would leave a mark if it ever ran.
    let mark = tmp.path().join("PWNED");
    let evil = tmp.path().join("evilpy");
    std::fs::write(&evil, format!("#!/bin/sh\ntouch '{}'\n", mark.display())).unwrap();
    std::fs::set_permissions(&evil, std::fs::Permissions::from_mode(0o755)).unwrap();
    let evil = evil.display().to_string();

    let out = tmp.path().join("python");
    received_results(&out, |s| {
        s["config"]["env"] = gymnasium_task("CartPole-v1", Some(&evil));
    });
    let resume = |extra: &[&str]| {
        sapnet()
            .args(["--headless", "--resume", "--out"])
            .arg(&out)
            .args(extra)
            .output()
            .unwrap()
    };
    refused(
        &resume(&[]),
        &[
            "summary.json",
            "env.Gymnasium.python",
            &evil,
            "--python PATH",
        ],
    );
    // Another interpreter given: both are shown, and the folder's is still refused.
    refused(
        &resume(&["--python", "/usr/bin/python3"]),
        &[&evil, "you gave --python /usr/bin/python3"],
    );
    assert!(!mark.exists(), "the folder's program ran");

    // A module the id imports: refused unless the user names it.
    let out = tmp.path().join("module");
    received_results(&out, |s| {
        s["config"]["env"] = gymnasium_task("recv.evilmod:Evil-v0", None);
        s["config"]["env"]["Gymnasium"]["return_range"] = serde_json::json!([0.0, 1.0]);
    });
    let output = sapnet()
        .args(["--headless", "--resume", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    refused(
        &output,
        &[
            "imports the Python module recv.evilmod",
            "--allow-module recv.evilmod",
        ],
    );
    // What sapnet writes never names an interpreter or a module folder.
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(!summary.contains("module_dir"), "{summary}");
}

/// Items 1 and 9: a sweep's cell cannot name a program either (its hash recomputed by the
/// folder's author), and a path with a control character never reaches its scripts.
#[test]
fn a_sweep_cell_cannot_choose_the_program_and_scripts_refuse_control_characters() {
    use sapnet::policy_store::sha256_hex;
    let tmp = tempfile::tempdir().unwrap();
    std::fs::copy(configs("short_cartpole.ron"), tmp.path().join("base.ron")).unwrap();
    let grid = tmp.path().join("grid.ron");
    std::fs::write(&grid, "(base: \"base.ron\", episodes: Some(5))").unwrap();
    let plan = |out: &Path| {
        sapnet()
            .args(["sweep", "plan", "--grid"])
            .arg(&grid)
            .arg("--out")
            .arg(out)
            .arg("--library")
            .arg(tmp.path().join("lib"))
            .output()
            .unwrap()
    };
    let newline = tmp.path().join("sw\ntouch PWNED");
    refused(&plan(&newline), &["control character"]);
    assert!(!newline.exists());

    let sweep = tmp.path().join("sweep");
    ok(plan(&sweep));
    // The folder's author replaces the cell's task (the CartPole block up to `dqn`) and
    // recomputes its hash.
    let cell = sweep.join("cells/0000.ron");
    let text = std::fs::read_to_string(&cell).unwrap();
    let (start, end) = (text.find("env: ").unwrap(), text.find("dqn: ").unwrap());
    let text = format!(
        "{}env: Gymnasium(id: \"CartPole-v1\", python: Some(\"/tmp/evilpy\")),\n    {}",
        &text[..start],
        &text[end..]
    );
    let manifest = std::fs::read_to_string(sweep.join("sweep.ron")).unwrap();
    let old = sha256_hex(&std::fs::read(&cell).unwrap());
    std::fs::write(&cell, &text).unwrap();
    std::fs::write(
        sweep.join("sweep.ron"),
        manifest.replace(&old, &sha256_hex(text.as_bytes())),
    )
    .unwrap();
    let output = sapnet()
        .args(["sweep", "run"])
        .arg(&sweep)
        .args(["--cell", "0"])
        .output()
        .unwrap();
    refused(
        &output,
        &["0000.ron", "env.Gymnasium.python", "/tmp/evilpy"],
    );
}

/// The bad-task module of the worker tests: `bad_envs:Bad-v0`, which prints in `step`
/// (`mode: "print"`), sleeps in its third step (`"sleep"`) or while it is made
/// (`make_sleep`).
fn bad_envs(dir: &Path) -> PathBuf {
    let modules = dir.join("modules");
    std::fs::create_dir_all(&modules).unwrap();
    std::fs::write(
        modules.join("bad_envs.py"),
        r#"
import sys, time
import gymnasium as gym
import numpy as np

class Bad(gym.Env):
    def __init__(self, mode="print", make_sleep=0.0):
        time.sleep(make_sleep)
        self.observation_space = gym.spaces.Box(-1.0, 1.0, (4,), np.float32)
        self.action_space = gym.spaces.Discrete(2)
        self.mode = mode
        self.t = 0

    def reset(self, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        return np.zeros(4, np.float32), {}

    def step(self, action):
        self.t += 1
        if self.mode == "print":
            # Bytes that, read as a reply, would declare a 1.7 GB frame.
            print("hello from step", flush=True)
        if self.mode == "sleep" and self.t == 3:
            time.sleep(1000)
        return np.full(4, 0.25, np.float32), 1.0, self.t >= 10, False, {}

gym.register("Bad-v0", entry_point=Bad, max_episode_steps=50)
"#,
    )
    .unwrap();
    modules
}

/// A config of `bad_envs:Bad-v0` with `kwargs` and `timeouts` (RON), in `dir`.
fn bad_config(dir: &Path, name: &str, kwargs: &str, timeouts: &str, protocol: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!(
            "(env: Gymnasium(id: \"bad_envs:Bad-v0\", kwargs: {{{kwargs}}}, \
             return_range: Some([0.0, 10.0]), module_dir: Some(\"modules\"), \
             timeouts: ({timeouts})), {protocol})"
        ),
    )
    .unwrap();
    path
}

/// The worker processes (children of `parent`, or of anyone with `None`) alive now.
fn workers(parent: Option<u32>) -> Vec<String> {
    let mut pgrep = Command::new("pgrep");
    if let Some(parent) = parent {
        pgrep.args(["-P", &parent.to_string()]);
    }
    let found = pgrep
        .args(["-f", sapnet::env::gymnasium::SCRIPT_NAME])
        .output()
        .unwrap();
    String::from_utf8_lossy(&found.stdout)
        .lines()
        .map(str::to_string)
        .collect()
}

/// Item 2: the worker imports nothing from the directory sapnet is started in, and a
/// module the config names is found through the config's `module_dir`, said on stderr.
#[test]
fn the_worker_imports_nothing_from_the_current_directory() {
    let python = python_or_skip!();
    let tmp = tempfile::tempdir().unwrap();
    bad_envs(tmp.path());
    // Modules the worker imports by these names, planted where the user stands.
    let mark = tmp.path().join("PWNED");
    for planted in ["json.py", "numpy.py", "gymnasium.py", "struct.py"] {
        std::fs::write(
            tmp.path().join(planted),
            format!("open({:?}, 'w').write('ran')\n", mark.display().to_string()),
        )
        .unwrap();
    }
    let config = bad_config(tmp.path(), "print.ron", "\"mode\": \"print\"", "", "");
    let output = ok(sapnet()
        .args(["env", "--episodes", "2", "--config"])
        .arg(&config)
        .arg("--python")
        .arg(&python)
        .current_dir(tmp.path())
        .output()
        .unwrap());
    assert!(
        !mark.exists(),
        "a module planted in the current directory ran"
    );
    assert!(
        stderr(&output).contains("imports the Python module bad_envs"),
        "{}",
        stderr(&output)
    );
    // Item 3: its prints were not read as replies: every step a whole one.
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("10.0  terminated"), "{stdout}");
}

/// Item 3: a step or a start that takes too long is killed with the task's timeout, said;
/// no worker is left behind.
#[test]
fn a_hanging_environment_is_killed_at_its_timeout() {
    let python = python_or_skip!();
    let tmp = tempfile::tempdir().unwrap();
    bad_envs(tmp.path());
    for (name, kwargs, timeouts, says) in [
        (
            "step.ron",
            "\"mode\": \"sleep\"",
            "step: 2",
            "more than 2 s for a step",
        ),
        (
            "make.ron",
            "\"make_sleep\": 1000.0",
            "start: 2",
            "more than 2 s for making the environment",
        ),
    ] {
        let config = bad_config(tmp.path(), name, kwargs, timeouts, "");
        let started = Instant::now();
        let output = sapnet()
            .args(["env", "--episodes", "2", "--config"])
            .arg(&config)
            .arg("--python")
            .arg(&python)
            .output()
            .unwrap();
        refused(&output, &["bad_envs:Bad-v0", says, "timeouts"]);
        assert!(
            started.elapsed() < Duration::from_secs(20),
            "{name}: took {:?}",
            started.elapsed()
        );
    }
    let timeouts = bad_config(tmp.path(), "zero.ron", "", "step: 0", "");
    refused(
        &sapnet()
            .args(["env", "--config"])
            .arg(&timeouts)
            .output()
            .unwrap(),
        &["timeouts.step", "seconds from 1 to 86400"],
    );
}

/// Item 3: a run waiting on a hung step stops at SIGTERM and SIGINT within a second
/// (exit 143, 130; the folder says stopped), and SIGKILL takes the worker with sapnet.
#[test]
fn signals_end_a_wait_on_a_hung_step_and_no_worker_outlives_sapnet() {
    let python = python_or_skip!();
    let tmp = tempfile::tempdir().unwrap();
    bad_envs(tmp.path());
    let config = bad_config(
        tmp.path(),
        "hang.ron",
        "\"mode\": \"sleep\"",
        "",
        "protocol: (episodes: 3, runs: 1, methods: [Dqn(hidden: [8])])",
    );
    for (signal, code) in [("TERM", Some(143)), ("INT", Some(130)), ("KILL", None)] {
        let out = tmp.path().join(format!("out-{signal}"));
        let mut child = sapnet()
            .args(["--headless", "--config"])
            .arg(&config)
            .arg("--out")
            .arg(&out)
            .arg("--python")
            .arg(&python)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        // The run's worker is in its third step, asleep.
        let started = Instant::now();
        while workers(Some(child.id())).is_empty() || started.elapsed() < Duration::from_secs(2) {
            assert!(
                started.elapsed() < Duration::from_secs(60),
                "no worker started"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
        let worker = workers(Some(child.id()));
        kill(child.id(), signal);
        let signalled = Instant::now();
        let status = child.wait().unwrap();
        assert!(
            signalled.elapsed() < Duration::from_secs(2),
            "SIG{signal}: took {:?}",
            signalled.elapsed()
        );
        if let Some(code) = code {
            assert_eq!(status.code(), Some(code), "SIG{signal}");
            let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
            assert!(summary.contains("\"status\": \"stopped\""), "{summary}");
        }
        // The worker is gone too, even after a SIGKILL of its parent.
        let gone = Instant::now();
        while worker
            .iter()
            .any(|pid| Path::new("/proc").join(pid).exists())
        {
            assert!(
                gone.elapsed() < Duration::from_secs(2),
                "SIG{signal}: worker {worker:?} outlived sapnet"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

/// Item 13: with a library named, an unknown id is said as such, not as a missing library.
#[test]
fn an_unknown_gymnasium_id_is_said_before_the_library() {
    let python = python_or_skip!();
    let tmp = tempfile::tempdir().unwrap();
    let config = tmp.path().join("unknown.ron");
    std::fs::write(
        &config,
        "(env: Gymnasium(id: \"NoSuchEnv-v9\", return_range: Some([0.0, 1.0])))",
    )
    .unwrap();
    for args in [
        &["--headless"][..],
        &["sources", "--evaluate"],
        &["sources"],
    ] {
        let output = sapnet()
            .args(args)
            .arg("--config")
            .arg(&config)
            .arg("--library")
            .arg(tmp.path().join("lib"))
            .arg("--python")
            .arg(&python)
            .arg(if args[0] == "--headless" {
                "--out"
            } else {
                "--seed"
            })
            .arg(if args[0] == "--headless" {
                tmp.path().join("out").display().to_string()
            } else {
                "0".to_string()
            })
            .output()
            .unwrap();
        refused(&output, &["NoSuchEnv-v9: NameNotFound"]);
        assert!(!stderr(&output).contains("library"), "{}", stderr(&output));
    }
}

/// Item 4: names that are not portable are refused at import and in a received library.
#[test]
fn names_that_could_shift_a_column_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    ok(sapnet()
        .args(["sources", "--config"])
        .arg(configs("tiny_sources.ron"))
        .arg("--library")
        .arg(&library)
        .output()
        .unwrap());
    let fixture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/import/sb3_cartpole.zip");
    for name in ["evil\nname", "a,b", "a\"b", "a\rb", "a\tb", "a b", "é"] {
        let output = sapnet()
            .args(["sources", "import"])
            .arg(&fixture)
            .args(["--name", name, "--config"])
            .arg(configs("tiny_sources.ron"))
            .arg("--library")
            .arg(&library)
            .output()
            .unwrap();
        refused(&output, &["--name", "letters, digits"]);
    }
    // A received library whose manifest lists such a name is refused when read.
    let manifest = library.join("cartpole/library.ron");
    let text = std::fs::read_to_string(&manifest).unwrap();
    std::fs::write(&manifest, text.replace("\"source-1\"", "\"evil,name\"")).unwrap();
    let output = sapnet()
        .args(["--headless", "--config"])
        .arg(configs("tiny_reuse.ron"))
        .arg("--library")
        .arg(&library)
        .arg("--out")
        .arg(tmp.path().join("out"))
        .output()
        .unwrap();
    refused(
        &output,
        &["library.ron", "\"evil,name\"", "letters, digits"],
    );
}

/// Item 7: a kill at any point of an import leaves a library that is as before or holds
/// the policy listed; the next command that touches it finishes the job and says so.
#[test]
fn an_import_killed_anywhere_leaves_the_library_whole() {
    let tmp = tempfile::tempdir().unwrap();
    let fixture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/import/sb3_cartpole.zip");
    for (point, listed) in [
        ("import-journal-written", false),
        ("import-policy-written", false),
        ("import-listed", true),
    ] {
        let library = tmp.path().join(point);
        ok(sapnet()
            .args(["sources", "--config"])
            .arg(configs("tiny_sources.ron"))
            .arg("--library")
            .arg(&library)
            .output()
            .unwrap());
        let import = || {
            let mut command = sapnet();
            command
                .args(["sources", "import"])
                .arg(&fixture)
                .args(["--name", "win", "--config"])
                .arg(configs("tiny_sources.ron"))
                .arg("--library")
                .arg(&library);
            command
        };
        let killed = import().env("SAPNET_KILL_AT", point).output().unwrap();
        assert!(!killed.status.success(), "{point}");
        // The next command that reads the library repairs it and says what it found.
        let output = ok(sapnet()
            .args(["sources", "--config"])
            .arg(configs("tiny_sources.ron"))
            .arg("--library")
            .arg(&library)
            .output()
            .unwrap());
        let said = stderr(&output);
        assert!(said.contains("the import of win"), "{point}: {said}");
        let dir = library.join("cartpole");
        let names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert!(
            !names
                .iter()
                .any(|n| n.starts_with(".import") || n.ends_with(".tmp")),
            "{point}: leftovers {names:?}"
        );
        let manifest = std::fs::read_to_string(dir.join("library.ron")).unwrap();
        assert_eq!(manifest.contains("\"win\""), listed, "{point}: {manifest}");
        assert_eq!(names.contains(&"win.ron".to_string()), listed, "{point}");
        // The library is usable, and the same name can be imported now if it was not.
        if !listed {
            ok(import().output().unwrap());
        }
        ok(sapnet()
            .args(["--headless", "--quick", "--config"])
            .arg(configs("tiny_reuse.ron"))
            .arg("--library")
            .arg(&library)
            .arg("--out")
            .arg(tmp.path().join(format!("out-{point}")))
            .output()
            .unwrap());
    }
}

/// Item 10: `sapnet plot` on a folder whose protocol still runs is refused, naming the
/// process, and writes nothing there.
#[test]
fn plot_refuses_a_folder_another_process_writes() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let mut child = sapnet()
        .args(["--headless", "--episodes", "100000", "--config"])
        .arg(configs("short_cartpole.ron"))
        .arg("--out")
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let started = Instant::now();
    // summary.json is written just after runs/ is made: wait for it, not for runs/.
    while !out.join("summary.json").exists() {
        assert!(started.elapsed() < Duration::from_secs(60), "never started");
        std::thread::sleep(Duration::from_millis(20));
    }
    let before = std::fs::read_to_string(out.join("summary.json")).unwrap();
    let output = sapnet().arg("plot").arg(&out).output().unwrap();
    kill(child.id(), "KILL");
    let _ = child.wait();
    refused(
        &output,
        &[
            "is being written by the sapnet process",
            &format!("PID {}", child.id()),
        ],
    );
    assert_eq!(
        std::fs::read_to_string(out.join("summary.json")).unwrap(),
        before
    );
    assert!(!out.join("comparison.csv").exists());
}

/// Item 11: a reader that leaves (`| head -c 300`) ends every command quietly, exit 0.
#[test]
fn a_closed_stdout_ends_the_output_quietly() {
    let tmp = tempfile::tempdir().unwrap();
    let teach = format!(
        "{} teach --headless --activate 1 --json | head -c 300 >/dev/null; exit ${{PIPESTATUS[0]}}",
        env!("CARGO_BIN_EXE_sapnet")
    );
    let env = format!(
        "{} env --episodes 200 | head -c 10 >/dev/null; exit ${{PIPESTATUS[0]}}",
        env!("CARGO_BIN_EXE_sapnet")
    );
    for script in [teach, env] {
        for _ in 0..5 {
            let output = Command::new("bash")
                .args(["-c", &script])
                .current_dir(tmp.path())
                .output()
                .unwrap();
            assert_eq!(
                output.status.code(),
                Some(0),
                "{script}: {}",
                stderr(&output)
            );
            assert_eq!(stderr(&output), "", "{script}");
        }
    }
}

/// Item 12: each subcommand's help names only its own flags, in its own words.
#[test]
fn help_names_only_a_subcommands_own_flags() {
    let help = |args: &[&str]| {
        let output = ok(sapnet().args(args).arg("--help").output().unwrap());
        String::from_utf8_lossy(&output.stdout).into_owned()
    };
    let sweep = help(&["sweep"]);
    assert!(!sweep.contains("lesson"), "{sweep}");
    assert!(!sweep.contains("--config <FILE>"), "{sweep}");
    for args in [&["sweep", "plan"][..], &["sources"], &["sources", "import"]] {
        let text = help(args);
        assert!(!text.contains("--train-library"), "{args:?}: {text}");
        assert!(!text.contains("lesson"), "{args:?}: {text}");
    }
    assert!(help(&["teach"]).contains("A lesson file"));
}
