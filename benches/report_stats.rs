//! The statistics of a comparison: every interval, probability of improvement and profile
//! of `Report::of` (10,000 stratified resamples each), for the reuse comparison's 11
//! methods at 5 runs each (55 runs: the target, under a second) and at 10 and 20.
//!
//! Run: `cargo bench --bench report_stats`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use sapnet::config::Config;
use sapnet::report::{Report, RunSummary, TaskRuns, TrainingEpisodes, TrainingRuns};
use sapnet::trainer::{MethodId, RunRecord};

/// The reuse comparison's methods with `runs` runs each: returns and test scores drawn at
/// random (the statistics cost the same whatever the numbers), 1,000 episodes a run.
/// What a report reads of a protocol: its config, its runs and their training returns.
type Protocol = (Config, Vec<RunSummary>, TrainingRuns);

fn protocol(runs: u32) -> Protocol {
    let mut config = Config::from_ron(
        include_str!("../assets/reuse_cartpole.ron"),
        "reuse_cartpole.ron",
    )
    .unwrap();
    config.protocol.runs = runs;
    let mut rng = StdRng::seed_from_u64(1);
    let mut summaries = Vec::new();
    let mut rewards = TrainingRuns::new();
    for method in MethodId::all(&config.protocol.methods) {
        for run in 0..runs {
            let returns: Vec<f64> = (0..1000).map(|_| rng.random_range(0.0..500.0)).collect();
            let record = RunRecord {
                run,
                method: method.clone(),
                seed: 0,
                episodes: 1000,
                steps: 0,
                updates: 0,
                cut_episode: None,
                non_greedy_steps: None,
                chosen: None,
                source_steps: vec![1; 10],
                lock_in_step: Some(600),
                positive: Vec::new(),
                negative: Vec::new(),
                exclusions: 0,
                test_returns: (0..5).map(|_| rng.random_range(0.0..500.0)).collect(),
                stopped: false,
                wall_s: 0.0,
            };
            summaries.push(RunSummary::new(record, &returns, 10));
            rewards.insert(
                (method.clone(), run),
                std::sync::Arc::new(TrainingEpisodes::uniform(&returns, 20)),
            );
        }
    }
    (config, summaries, rewards)
}

fn report(c: &mut Criterion) {
    let mut group = c.benchmark_group("report");
    group.sample_size(10);
    for runs in [5, 10, 20] {
        let (config, summaries, rewards) = protocol(runs);
        let task = TaskRuns {
            task: "cartpole",
            config: &config,
            library: &[],
            runs: &summaries,
            episodes: &rewards,
        };
        group.bench_with_input(
            BenchmarkId::new("of", format!("11_methods_x_{runs}_runs")),
            &task,
            |b, task| b.iter(|| black_box(Report::of(std::slice::from_ref(task)))),
        );
    }
    group.finish();
}

criterion_group!(benches, report);
criterion_main!(benches);
