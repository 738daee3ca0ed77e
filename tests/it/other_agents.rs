//! Sources from other agents, reused through a declared inter-task mapping: the shipped
//! libraries load, each mapped source acts on the target as its own agent would through
//! χ_X and χ_A, a mapping that does not fit is refused at its field, and the quick
//! protocol over such a library runs every method of the study.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use sapnet::config::Config;
use sapnet::{env, policy_store, sources};

use crate::common::library::{copy_library, quick_protocol};

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets")
        .join(name)
}

fn shipped() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("saved_policies")
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

/// Observations of the target met along random-action episodes.
fn target_observations(config: &Config, n: usize) -> Vec<Vec<f32>> {
    let mut env = env::make(&config.env).unwrap();
    let mut rng = StdRng::seed_from_u64(3);
    let actions = env.action_count();
    let mut seen = vec![env.reset(Some(1)).unwrap().to_vec()];
    while seen.len() < n {
        let step = env.step(rng.random_range(0..actions)).unwrap();
        let (obs, done) = (step.obs.to_vec(), step.done());
        seen.push(obs);
        if done {
            seen.push(env.reset(None).unwrap().to_vec());
        }
    }
    seen
}

#[test]
fn the_shipped_agent_libraries_load_and_each_source_acts_as_its_agent_would() {
    for (file, agents) in [
        (
            "agents_cartpole.ron",
            &[
                "3 actions (left, none, right)",
                "sees (θ, dθ, x, dx)",
                "sees (dx, x, dθ, θ)",
            ][..],
        ),
        (
            "agents_mountain_car.ron",
            &[
                "2 actions",
                "2 actions, weaker engine",
                "2 actions, stronger engine",
            ][..],
        ),
    ] {
        let config = Config::from_file(&asset(file)).unwrap();
        let tasks = sources::tasks(&config);
        let labels: Vec<&str> = tasks.iter().map(|t| t.label.as_str()).collect();
        assert_eq!(labels, agents, "{file}");
        let loaded = sources::load_library(&config, &shipped()).unwrap();
        assert_eq!(loaded.len(), 10, "{file}");
        let dir = sources::library_dir(&shipped(), &config);
        let observations = target_observations(&config, 1000);
        for (source, plan) in loaded.iter().zip(sources::plan(&config)) {
            let task = &tasks[plan.task];
            // Its category is its agent.
            assert_eq!(source.description.source_task, task.label);
            let mapping = task.mapping.as_ref().expect("every task here is mapped");
            let own = policy_store::load(&dir, &plan.name).unwrap().net;
            let mut agreed = 0;
            for obs in &observations {
                // The agent's view of the target's state, and its greedy choice among the
                // actions that have an image, mapped to the target's.
                let seen: Vec<f32> = mapping.state.iter().map(|&i| obs[i]).collect();
                let q = own.q_values(&seen).unwrap();
                let best = (0..q.len())
                    .filter(|&a| mapping.actions[a].is_some())
                    .max_by(|&a, &b| q[a].total_cmp(&q[b]).then(b.cmp(&a)))
                    .unwrap();
                let expected = mapping.actions[best].unwrap();
                agreed += usize::from(source.net.greedy_action(obs).unwrap() == expected);
                let q_target = source.net.q_values(obs).unwrap();
                for (a, image) in mapping.actions.iter().enumerate() {
                    if let Some(t) = *image {
                        let scale = 1.0 + q[a].abs();
                        assert!(
                            (q_target[t] - q[a]).abs() <= 1e-4 * scale,
                            "{file} {}: Q {} vs {}",
                            plan.name,
                            q_target[t],
                            q[a]
                        );
                    }
                }
            }
            // Equal Q-values up to rounding: a choice differs only on a near tie.
            assert!(
                agreed >= observations.len() - 2,
                "{file} {}: {agreed} of {} greedy actions agree",
                plan.name,
                observations.len()
            );
        }
    }
}

/// `assets/agents_cartpole.ron` with `from` replaced by `to`, written under `dir`.
fn edited(dir: &Path, from: &str, to: &str) -> PathBuf {
    let text = std::fs::read_to_string(asset("agents_cartpole.ron")).unwrap();
    assert!(text.contains(from), "{from}");
    let path = dir.join("edited.ron");
    std::fs::write(&path, text.replacen(from, to, 1)).unwrap();
    path
}

#[test]
fn a_mapping_that_does_not_fit_is_refused_at_its_field() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "mapping: Some(state: [2, 3, 0, 1], actions: [Some(0), Some(1)])",
            "mapping: Some(state: [2, 3, 4, 1], actions: [Some(0), Some(1)])",
            "field `sources.tasks[1].mapping.state[2]`: expected one of the target's state \
             variables 0 to 3, got 4",
        ),
        (
            "mapping: Some(state: [0, 1, 2, 3], actions: [Some(0), None, Some(1)])",
            "mapping: Some(state: [0, 1, 2, 3], actions: [Some(0), None])",
            "field `sources.tasks[0].mapping.actions`: source action 2 has no image",
        ),
        (
            "mapping: Some(state: [0, 1, 2, 3], actions: [Some(0), None, Some(1)])",
            "mapping: None",
            "field `sources.tasks[0]`: its agent has 4 observation values and 3 actions, the \
             target's 4 observation values and 2 actions: give its `mapping",
        ),
    ];
    for (from, to, expected) in cases {
        let config = edited(dir.path(), from, to);
        let output = sapnet(&["--headless", "--config", config.to_str().unwrap()]);
        assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
        assert!(
            stderr(&output).contains(expected),
            "{}\nwanted: {expected}",
            stderr(&output)
        );
        assert!(
            stderr(&output).contains("edited.ron"),
            "names the file: {}",
            stderr(&output)
        );
    }
}

#[test]
fn a_config_and_a_library_that_declare_other_mappings_are_told_apart() {
    let dir = tempfile::tempdir().unwrap();
    let library = dir.path().join("library");
    copy_library("cartpole-agents", &library);
    // A valid mapping, but not the one the library declares.
    let config = edited(
        dir.path(),
        "mapping: Some(state: [1, 0, 3, 2], actions: [Some(0), Some(1)])",
        "mapping: Some(state: [1, 0, 3, 2], actions: [Some(1), Some(0)])",
    );
    let output = sapnet(&[
        "sources",
        "--evaluate",
        "--config",
        config.to_str().unwrap(),
        "--library",
        library.to_str().unwrap(),
    ]);
    assert!(!output.status.success());
    let said = stderr(&output);
    for part in [
        "declares the mapping of sees (dx, x, dθ, θ) as χ_X [1, 0, 3, 2] · χ_A [0, 1]",
        "training.tasks[2].mapping",
        "the config's sources.tasks[2].mapping as χ_X [1, 0, 3, 2] · χ_A [1, 0]",
        "no retraining is needed",
    ] {
        assert!(said.contains(part), "{said}\nwanted: {part}");
    }
}

#[test]
fn the_quick_protocol_over_other_agents_runs_every_method_of_the_study() {
    let dir = tempfile::tempdir().unwrap();
    let (_, summary) = quick_protocol(&asset("agents_cartpole.ron"), "cartpole-agents", dir.path());
    let runs = summary["runs"].as_array().unwrap();
    for method in [
        "sapnet",
        "sapnet-episode",
        "sapnet-td",
        "sapnet-advantage",
        "sapnet-episode-and-loss",
        "sapnet-exclude10x1000",
        "random",
        "ucb1",
        "best-source",
        "dqn[100]",
    ] {
        let of_method = runs.iter().filter(|r| r["method"] == method).count();
        assert_eq!(of_method, 2, "{method}");
    }
    // Every source acted in the random selector's runs: each mapped source steps the
    // target (`source_steps`, its acting steps after the warm-up).
    for run in runs.iter().filter(|r| r["method"] == "random") {
        let steps: Vec<u64> = run["source_steps"]
            .as_array()
            .unwrap()
            .iter()
            .map(|n| n.as_u64().unwrap())
            .collect();
        assert_eq!(steps.len(), 10);
        assert!(steps.iter().all(|&n| n > 0), "{steps:?}");
    }
}
