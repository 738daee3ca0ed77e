//! Sampling a minibatch from the replay buffer, as every update does: 32 (or 64) draws
//! uniformly with replacement, each transition gathered into the batch's columns. Timed at
//! 800k stored CartPole transitions (most draws miss every cache, as late in a long run)
//! and at 10k (the buffer in the caches, as early in a run).
//!
//! `cargo bench --bench replay_sample`.
//!
//! `SAPNET_RUN_ONCE=<batches>` samples that many batches of 32 from the 800k buffer, once,
//! without criterion: for counting instructions under `valgrind --tool=callgrind`, which is
//! repeatable where the machine's timings are not. It prints a digest of every batch drawn,
//! so that two builds can be checked to draw the same minibatches bit for bit.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, BenchmarkId, Criterion};
use rand::{rngs::StdRng, Rng, SeedableRng};
use sapnet::dqn::{Batch, ReplayBuffer, Transition};

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// CartPole's observation width.
const OBS: usize = 4;

/// A buffer of `stored` random transitions (capacity 10⁶, as the paper's settings).
fn filled(stored: usize) -> ReplayBuffer {
    let mut rng = StdRng::seed_from_u64(7);
    let mut replay = ReplayBuffer::new(1_000_000, OBS);
    let mut obs = [0f32; OBS];
    let mut next = [0f32; OBS];
    for i in 0..stored {
        obs.iter_mut()
            .for_each(|x| *x = rng.random_range(-2.0..2.0));
        next.iter_mut()
            .for_each(|x| *x = rng.random_range(-2.0..2.0));
        replay.push(Transition {
            obs: &obs,
            action: i % 2,
            reward: 1.0,
            next_obs: &next,
            terminated: i % 97 == 0,
            truncated: i % 501 == 0,
        });
    }
    replay
}

fn sample(c: &mut Criterion) {
    let mut group = c.benchmark_group("replay_sample");
    group.measurement_time(Duration::from_secs(5));
    for stored in [800_000, 10_000] {
        let replay = filled(stored);
        for size in [32, 64] {
            let mut rng = StdRng::seed_from_u64(1);
            let mut batch = Batch::new();
            let id = BenchmarkId::new(format!("batch{size}"), format!("{}k", stored / 1000));
            group.bench_function(id, |b| {
                b.iter(|| {
                    replay.sample_into(size, &mut batch, &mut rng);
                    black_box(&batch);
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, sample);

/// FNV-1a over every value of a batch, as bits.
fn digest(batch: &Batch, mut hash: u64) -> u64 {
    let mut eat = |word: u64| {
        hash ^= word;
        hash = hash.wrapping_mul(0x100_0000_01b3);
    };
    batch.obs().iter().for_each(|x| eat(u64::from(x.to_bits())));
    batch
        .next_obs()
        .iter()
        .for_each(|x| eat(u64::from(x.to_bits())));
    batch.actions().iter().for_each(|&a| eat(u64::from(a)));
    batch
        .rewards()
        .iter()
        .for_each(|x| eat(u64::from(x.to_bits())));
    batch.terminated().iter().for_each(|&t| eat(u64::from(t)));
    batch.truncated().iter().for_each(|&t| eat(u64::from(t)));
    batch
        .slots()
        .unwrap_or_default()
        .iter()
        .for_each(|&s| eat(s as u64));
    hash
}

fn main() {
    if let Some(batches) = std::env::var("SAPNET_RUN_ONCE")
        .ok()
        .and_then(|n| n.parse::<usize>().ok())
    {
        let replay = filled(800_000);
        let mut rng = StdRng::seed_from_u64(1);
        let mut batch = Batch::new();
        let mut hash = 0xcbf2_9ce4_8422_2325;
        for _ in 0..batches {
            replay.sample_into(32, &mut batch, &mut rng);
            hash = digest(&batch, hash);
        }
        println!("{batches} batches of 32 from 800k transitions: digest {hash:016x}");
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
