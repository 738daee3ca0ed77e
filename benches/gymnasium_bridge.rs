//! The Gymnasium bridge's cost per step: the loop of `shared/bench/env_throughput.py` (random
//! actions drawn before the clock starts, reset on `terminated` or `truncated`) run through
//! `env::make(Gymnasium(id: …))`, whose environment steps in its Python worker. Compare
//! with the script's `make` mode, run back to back in the same Python:
//!
//!     SAPNET_BENCH_PYTHON=/path/to/venv/bin/python cargo bench --bench gymnasium_bridge
//!     /path/to/venv/bin/python ../shared/bench/env_throughput.py --envs CartPole-v1,LunarLander-v3
//!
//! Without `SAPNET_BENCH_PYTHON` (or an active virtualenv) it says so and measures nothing.

use std::time::Instant;

use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use sapnet::env::{make, EnvConfig, GymnasiumParams};

fn main() {
    let python = std::env::var_os("SAPNET_BENCH_PYTHON").or_else(|| {
        std::env::var_os("VIRTUAL_ENV")
            .map(|v| std::path::PathBuf::from(v).join("bin/python").into())
    });
    let Some(python) = python else {
        eprintln!("no Python with Gymnasium: set SAPNET_BENCH_PYTHON (nothing measured)");
        return;
    };
    let steps: usize = std::env::var("SAPNET_BENCH_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(200_000);
    let runs: u64 = 5;
    for id in ["CartPole-v1", "LunarLander-v3"] {
        let config = EnvConfig::Gymnasium(GymnasiumParams {
            id: id.into(),
            python: Some(python.clone().into()),
            ..GymnasiumParams::default()
        });
        let mut rates = Vec::new();
        for seed in 0..runs {
            let mut env = make(&config).expect("the Gymnasium task starts");
            let n = env.action_count();
            let actions: Vec<usize> = {
                let mut rng = SmallRng::seed_from_u64(seed);
                (0..steps).map(|_| rng.random_range(0..n)).collect()
            };
            env.reset(Some(seed)).expect("reset");
            let start = Instant::now();
            for &a in &actions {
                let step = env.step(a).expect("step");
                if step.done() {
                    env.reset(None).expect("reset");
                }
            }
            rates.push(steps as f64 / start.elapsed().as_secs_f64());
        }
        rates.sort_by(f64::total_cmp);
        let median = rates[rates.len() / 2];
        println!(
            "{id:16} bridge    median {median:10.0} steps/s = {:.2} µs/step (min {:.0}, max {:.0})",
            1e6 / median,
            rates[0],
            rates[rates.len() - 1]
        );
    }
}
