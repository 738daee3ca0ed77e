//! One activation with spreading, and one selection, at the paper's Table II values.
//!
//! Run: `cargo bench --bench sapnet_spread`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use rand::rngs::StdRng;
use rand::SeedableRng;

use sapnet::sapnet::{BaseGraph, PolicyDescription, SapNet, SapNetParams, TraceSink, TraceStep};

/// A listener that hears every call, stopped ones included: what the fast path avoids.
#[derive(Default)]
struct CountCalls(usize);

impl TraceSink for CountCalls {
    fn record(&mut self, _: TraceStep) {
        self.0 += 1;
    }
}

/// N policies with 1, 2 or 3 hidden layers in turn, Table II parameters.
fn policies(n: usize) -> Vec<PolicyDescription> {
    (0..n)
        .map(|i| PolicyDescription::new(vec![100; 1 + i % 3], "CartPole-v1"))
        .collect()
}

fn spread(c: &mut Criterion) {
    let mut group = c.benchmark_group("activate");
    // The Table II library: three hidden-layer categories, same-category edges at 0.95.
    let table2 = SapNet::from_policies(&policies(10), SapNetParams::default()).unwrap();
    // Complete graphs at Table II weights: every policy in one category (one hidden layer
    // each), so every edge weighs 0.95 and activation reaches all N − 1 others.
    let complete = |n: usize| {
        let one_category: Vec<_> = (0..n)
            .map(|_| PolicyDescription::new(vec![100], "CartPole-v1"))
            .collect();
        let params = SapNetParams {
            base_graph: BaseGraph::Complete,
            ..SapNetParams::default()
        };
        SapNet::from_policies(&one_category, params).unwrap()
    };
    for (name, net) in [
        ("table2_n10", table2.clone()),
        ("complete_n100", complete(100)),
        ("complete_n1000", complete(1000)),
    ] {
        group.bench_with_input(BenchmarkId::from_parameter(name), &net, |b, net| {
            let mut net = net.clone();
            let mut i = 0;
            b.iter(|| {
                net.activate(black_box(i), true);
                i = (i + 1) % net.len();
            });
        });
    }
    // The same activation with all 999·999 stopped calls made and heard.
    let net = complete(1000);
    group.bench_function("complete_n1000_every_call", |b| {
        let mut net = net.clone();
        let mut calls = CountCalls::default();
        b.iter(|| net.activate_traced(black_box(0), true, &mut calls));
        black_box(calls.0);
    });
    group.finish();

    c.bench_function("select/table2_n10", |b| {
        let mut net = table2.clone();
        for i in [0, 3, 3, 7] {
            net.activate(i, true);
        }
        let mut rng = StdRng::seed_from_u64(0);
        b.iter(|| black_box(net.select(&mut rng)));
    });
}

criterion_group!(benches, spread);
criterion_main!(benches);
