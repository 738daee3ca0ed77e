//! Steps per second of the native environments with random actions, resets included: the
//! loop of `shared/bench/env_throughput.py`, so the figures compare with Gymnasium's.
//!
//! Actions are drawn before the clock starts, as the Python script does with NumPy. The
//! episode ends on `terminated` or `truncated` (the time limit is built into the native
//! environments, as `gym.make` adds it) and is reset with `reset(None)`.
//!
//! `cargo bench --bench env_throughput` first prints the median steps/s of
//! `SAPNET_BENCH_RUNS` (default 5) timed runs of `SAPNET_BENCH_STEPS` (default 10⁷) steps per
//! environment, then runs the criterion benchmarks.

use std::hint::black_box;
use std::time::Instant;

use criterion::{Criterion, Throughput};
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use sapnet::env::{
    make, Acrobot, AcrobotParams, CartPole, CartPoleParams, EnvConfig, Environment, MountainCar,
    MountainCarParams,
};

/// Steps per criterion iteration: long enough to include many resets.
const CHUNK: usize = 10_000;

fn configs() -> [EnvConfig; 3] {
    [
        EnvConfig::CartPole(CartPoleParams::default()),
        EnvConfig::MountainCar(MountainCarParams::default()),
        EnvConfig::Acrobot(AcrobotParams::default()),
    ]
}

/// Uniform random actions in `0..action_count`, drawn with a fast generator.
fn draw_actions(action_count: usize, steps: usize, seed: u64) -> Vec<u8> {
    let mut rng = SmallRng::seed_from_u64(seed);
    let n = u8::try_from(action_count).expect("fewer than 256 actions");
    (0..steps).map(|_| rng.random_range(0..n)).collect()
}

/// Steps `env` through `actions`, resetting when an episode ends; returns the number of
/// resets. Every observation is handed to `black_box`, as a learner would read it, so that
/// none of the step's work is optimised away.
#[inline]
fn run<E: Environment + ?Sized>(env: &mut E, actions: &[u8]) -> usize {
    let mut resets = 0;
    for &a in actions {
        let step = env.step(usize::from(a)).expect("a native step cannot fail");
        black_box(step.obs);
        if step.done() {
            env.reset(None).expect("a native reset cannot fail");
            resets += 1;
        }
    }
    resets
}

fn env_var(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .map(|v| {
            v.parse()
                .unwrap_or_else(|_| panic!("{name}={v} is not a count"))
        })
        .unwrap_or(default)
}

/// Times `runs` runs of `steps` steps of the environment `make` builds, monomorphised (no
/// dynamic dispatch), and prints the median steps/s in the Python script's format.
fn report<E: Environment>(make: impl Fn() -> E, steps: usize, runs: usize) {
    let mut rates = Vec::with_capacity(runs);
    let mut resets = 0;
    let mut id = String::new();
    for seed in 0..runs as u64 {
        let mut env = make();
        id = env.id().to_string();
        let actions = draw_actions(env.action_count(), steps, seed);
        env.reset(Some(seed)).unwrap();
        let start = Instant::now();
        resets = black_box(run(&mut env, black_box(&actions)));
        rates.push(steps as f64 / start.elapsed().as_secs_f64());
    }
    let (min, max) = rates.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| {
        (lo.min(r), hi.max(r))
    });
    println!(
        "{id:16} native    median {:10.0} steps/s (min {min:.0}, max {max:.0}; resets/run ~{resets})",
        median(rates)
    );
}

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    let mid = xs.len() / 2;
    if xs.len() % 2 == 1 {
        xs[mid]
    } else {
        (xs[mid - 1] + xs[mid]) / 2.0
    }
}

/// `SAPNET_BENCH_ENVS` (comma-separated ids, like the script's `--envs`) selects
/// environments; all by default.
fn print_steps_per_second(steps: usize, runs: usize) {
    let wanted = std::env::var("SAPNET_BENCH_ENVS").ok();
    let selected = |id: &str| {
        wanted
            .as_deref()
            .is_none_or(|w| w.split(',').any(|x| x == id))
    };
    println!("native environments, steps/run {steps}, runs {runs}");
    if selected("CartPole-v1") {
        report(|| CartPole::new(CartPoleParams::default()), steps, runs);
    }
    if selected("MountainCar-v0") {
        report(
            || MountainCar::new(MountainCarParams::default()),
            steps,
            runs,
        );
    }
    if selected("Acrobot-v1") {
        report(|| Acrobot::new(AcrobotParams::default()), steps, runs);
    }
}

/// The same loop through `env::make`'s `Box<dyn Environment>`, as the trainer holds it.
fn criterion_benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("boxed_env_random_actions");
    group.throughput(Throughput::Elements(CHUNK as u64));
    for config in configs() {
        let mut env = make(&config).unwrap();
        let actions = draw_actions(env.action_count(), CHUNK, 0);
        env.reset(Some(0)).unwrap();
        let id = env.id().to_string();
        group.bench_function(id, |b| b.iter(|| run(env.as_mut(), black_box(&actions))));
    }
    group.finish();
}

fn main() {
    // `cargo bench` passes `--bench`; `cargo test --benches` does not and only needs a
    // smoke run.
    let benchmarking = std::env::args().any(|a| a == "--bench");
    let (steps, runs) = if benchmarking {
        (
            env_var("SAPNET_BENCH_STEPS", 10_000_000),
            env_var("SAPNET_BENCH_RUNS", 5),
        )
    } else {
        (CHUNK, 1)
    };
    print_steps_per_second(steps, runs);

    let mut c = Criterion::default().configure_from_args();
    criterion_benches(&mut c);
    c.final_summary();
}
