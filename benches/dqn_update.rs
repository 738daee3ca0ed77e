//! One DQN gradient update, as `shared/bench/torch_update_bench.py` times PyTorch's: online
//! forward and gather, target forward, TD target, Huber loss, backward, Adam step, for
//! 4-100-2, 4-100-100-2 and 4-100-100-100-2 at batch 32 (and the shipped CartPole library's
//! largest source, 4-64-114-149-2). Sampling is not timed: the batches are drawn before the
//! clock starts, and a batch not drawn from a buffer runs the target network in full (no
//! kept target values, `dqn/target_values.rs`).
//!
//! `cargo bench --bench dqn_update`; the PyTorch peer, in the same session:
//! `python3 shared/bench/torch_update_bench.py --batches 32`.
//!
//! Also times one greedy action, the forward pass an agent makes every step.
//!
//! `SAPNET_RUN_ONCE=<n>` takes `n` greedy actions and `n` highest Q-values (`2n` passes of
//! one observation) of each acting network once, without criterion, and prints a digest of
//! them: for counting instructions
//! under `valgrind --tool=callgrind` (the difference between `n` and `0`), and for checking
//! that two builds act alike.

use std::time::Duration;

use criterion::{criterion_group, BenchmarkId, Criterion};
use rand::{rngs::StdRng, Rng, SeedableRng};
use rand_distr::StandardNormal;
use sapnet::dqn::DqnConfig;
use sapnet::dqn::{Architecture, Batch, DqnAgent, QNet, Transition};

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

const POOL: usize = 64;

fn random_batches(obs_size: usize, actions: usize, size: usize, rng: &mut StdRng) -> Vec<Batch> {
    (0..POOL)
        .map(|_| {
            let mut batch = Batch::new();
            for _ in 0..size {
                let obs: Vec<f32> = (0..obs_size).map(|_| rng.sample(StandardNormal)).collect();
                let next_obs: Vec<f32> =
                    (0..obs_size).map(|_| rng.sample(StandardNormal)).collect();
                batch.push(Transition {
                    obs: &obs,
                    action: rng.random_range(0..actions),
                    reward: rng.sample(StandardNormal),
                    next_obs: &next_obs,
                    terminated: rng.random::<f64>() < 0.05,
                    truncated: false,
                });
            }
            batch
        })
        .collect()
}

fn update(c: &mut Criterion) {
    // candle sizes its matmul thread pool from RAYON_NUM_THREADS; at these sizes one thread
    // beats two, and the PyTorch peer runs on one.
    if std::env::var_os("RAYON_NUM_THREADS").is_none() {
        std::env::set_var("RAYON_NUM_THREADS", "1");
    }
    let mut group = c.benchmark_group("dqn_update");
    group.measurement_time(Duration::from_secs(5));
    // The paper's three shapes and the shipped library's largest source at ChainerRL's
    // batch, and the zoo's CartPole network at its batch of 64 (about 34 MFLOP per update:
    // the GFLOP/s figure of BENCHMARKS.md).
    let cases: [(&[usize], usize); 5] = [
        (&[100], 32),
        (&[100, 100], 32),
        (&[100, 100, 100], 32),
        (&[64, 114, 149], 32),
        (&[256, 256], 64),
    ];
    for (hidden, size) in cases {
        let mut rng = StdRng::seed_from_u64(0);
        let architecture = Architecture::new(4, hidden, 2);
        let name = architecture.to_string();
        let net = QNet::new(architecture, &mut rng).expect("network");
        let config = DqnConfig {
            batch_size: size,
            ..DqnConfig::default()
        };
        let mut agent = DqnAgent::new(net, &config).expect("agent");
        let batches = random_batches(4, 2, size, &mut rng);
        let mut i = 0;
        group.bench_function(BenchmarkId::new(format!("batch{size}"), name), |b| {
            b.iter(|| {
                i = (i + 1) % POOL;
                agent.update(&batches[i]).expect("finite loss")
            })
        });
    }
    group.finish();
}

/// The networks whose greedy action is timed: the paper's smallest and deepest, and the
/// widest of the shipped CartPole library's sources.
const ACTING: [&[usize]; 3] = [&[100], &[100, 100, 100], &[64, 114, 149]];

/// Acting costs a forward pass of one observation every environment step.
fn greedy_action(c: &mut Criterion) {
    let mut group = c.benchmark_group("dqn_greedy_action");
    for hidden in ACTING {
        let architecture = Architecture::new(4, hidden, 2);
        let name = architecture.to_string();
        let net = QNet::new(architecture, &mut StdRng::seed_from_u64(0)).expect("network");
        let obs = [0.01f32, -0.2, 0.03, 0.4];
        group.bench_function(name, |b| {
            b.iter(|| net.greedy_action(&obs).expect("action"))
        });
    }
    group.finish();
}

criterion_group!(benches, update, greedy_action);

fn main() {
    if let Some(n) = std::env::var("SAPNET_RUN_ONCE")
        .ok()
        .and_then(|n| n.parse::<usize>().ok())
    {
        let mut rng = StdRng::seed_from_u64(0);
        let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
        let mut eat = |word: u64| {
            hash ^= word;
            hash = hash.wrapping_mul(0x100_0000_01b3);
        };
        for hidden in ACTING {
            let net = QNet::new(Architecture::new(4, hidden, 2), &mut rng).expect("network");
            for _ in 0..n {
                let obs: [f32; 4] = std::array::from_fn(|_| rng.random_range(-2.0..2.0));
                eat(net.greedy_action(&obs).expect("action") as u64);
                eat(u64::from(net.max_q(&obs).expect("value").to_bits()));
            }
        }
        println!("{n} greedy actions and highest values of each of {ACTING:?}: digest {hash:016x}");
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
