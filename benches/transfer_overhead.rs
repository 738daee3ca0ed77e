//! What SAP-Net costs on top of the DQN it drives: training steps of the transfer loop
//! (Algorithm 3: selection by eq. 6, one update, judgment, activation and spreading, the
//! tallies and events) against a single DQN of the same architecture, over the same number
//! of CartPole steps. All ten sources are 4-100-2, so both sides make one update of the same
//! network per step and the difference is SAP-Net's.
//!
//! `cargo bench --bench transfer_overhead`. Three transfer variants: results-only events
//! (headless), every step streamed as the TUI asks (`StreamOptions::live()`, drained by a
//! thread), and with every positive activation traced as well.

use std::sync::mpsc;
use std::sync::Arc;
use std::thread;
use std::time::Duration;

use criterion::{criterion_group, Criterion};
use rand::rngs::StdRng;
use rand::SeedableRng;
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use sapnet::config::Config;
use sapnet::dqn::{Architecture, QNet};
use sapnet::sapnet::PolicyDescription;
use sapnet::trainer::{self, DqnRunSpec, Event, SourcePolicy, StreamOptions, TransferRunSpec};
use sapnet::tui::dashboard::Dashboard;
use sapnet::tui::theme::Theme;
use sapnet::tui::view;

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Learning steps per measured run. Before them both sides act the same number of
/// warm-up steps without learning: the transfer loop 10 × 50 (N × `replay_start_size`),
/// the DQN 500 (its `replay_start_size` raised to match).
const STEPS: u64 = 3_000;

fn sources(n: u64) -> Arc<Vec<SourcePolicy>> {
    Arc::new(
        (0..n)
            .map(|i| SourcePolicy {
                name: format!("source-{i}"),
                net: QNet::new(
                    Architecture::new(4, &[100], 2),
                    &mut StdRng::seed_from_u64(i),
                )
                .expect("network"),
                description: PolicyDescription::new(vec![100], "cartpole"),
                final_score: None,
            })
            .collect(),
    )
}

/// Runs `train` with its events drained on another thread every 10 ms, as both front ends
/// drain them (headless between progress updates, the TUI once per frame): never parked
/// on the channel, so that no send has to wake a thread.
fn drained(train: impl FnOnce(&mpsc::Sender<Event>, &mpsc::Receiver<trainer::Command>)) {
    let (events, received) = mpsc::channel::<Event>();
    let drain = thread::spawn(move || {
        let mut count = 0;
        loop {
            thread::sleep(Duration::from_millis(10));
            count += received.try_iter().count();
            match received.try_recv() {
                Ok(_) => count += 1,
                Err(mpsc::TryRecvError::Empty) => {}
                Err(mpsc::TryRecvError::Disconnected) => return count,
            }
        }
    });
    let (_commands, commands) = mpsc::channel();
    train(&events, &commands);
    drop(events);
    drain.join().expect("drain thread");
}

/// As [`drained`], but the thread is the dashboard's: every frame (33 ms) it folds the
/// events into a [`Dashboard`] and draws it at 200×60, so that training competes with
/// the UI's work as it does with the TUI open.
fn watched(train: impl FnOnce(&mpsc::Sender<Event>, &mpsc::Receiver<trainer::Command>)) {
    let (events, received) = mpsc::channel::<Event>();
    let ui = thread::spawn(move || {
        let mut dashboard = Dashboard::new("CartPole-v1");
        let mut terminal = Terminal::new(TestBackend::new(200, 60)).expect("test terminal");
        let theme = Theme { color: true };
        loop {
            thread::sleep(sapnet::tui::FRAME);
            let mut open = true;
            loop {
                match received.try_recv() {
                    Ok(event) => dashboard.on_event(event),
                    Err(mpsc::TryRecvError::Empty) => break,
                    Err(mpsc::TryRecvError::Disconnected) => {
                        open = false;
                        break;
                    }
                }
            }
            terminal
                .draw(|f| view::draw_dashboard(f, &dashboard, theme))
                .expect("draw");
            if !open {
                return dashboard.step;
            }
        }
    });
    let (_commands, commands) = mpsc::channel();
    train(&events, &commands);
    drop(events);
    ui.join().expect("UI thread");
}

/// The DQN and the transfer run (with `stream`) over the same steps.
fn specs(stream: StreamOptions) -> (DqnRunSpec, TransferRunSpec) {
    let config = Config::default();
    let warm_up = 10 * config.dqn.replay_start_size as u64;
    let dqn = DqnRunSpec {
        run: 0,
        method: "dqn[100]".into(),
        env: config.env.clone(),
        dqn: sapnet::config::DqnConfig {
            replay_start_size: config.dqn.replay_start_size * 10,
            ..config.dqn.clone()
        },
        hidden: vec![100],
        episodes: u32::MAX,
        max_steps: Some(STEPS + warm_up),
        test_episodes: 0,
        seed: 1,
        stream: StreamOptions::episodes(),
    };
    let transfer = TransferRunSpec {
        run: 0,
        method: "sapnet".into(),
        env: config.env.clone(),
        dqn: config.dqn.clone(),
        sapnet: config.sapnet.clone(),
        sources: sources(10),
        episodes: u32::MAX,
        max_steps: Some(STEPS + warm_up),
        test_episodes: 0,
        seed: 1,
        stream,
    };
    (dqn, transfer)
}

fn one_thread() {
    if std::env::var_os("RAYON_NUM_THREADS").is_none() {
        std::env::set_var("RAYON_NUM_THREADS", "1");
    }
}

fn overhead(c: &mut Criterion) {
    one_thread();
    let (dqn, _) = specs(StreamOptions::episodes());
    let transfer = |stream| specs(stream).1;
    let config = Config::default();

    let mut group = c.benchmark_group("transfer_overhead");
    group.sample_size(20);
    group.measurement_time(Duration::from_secs(20));
    group.bench_function("dqn[100]", |b| {
        b.iter(|| drained(|e, c| drop(trainer::train(&dqn, e, c).expect("run"))))
    });
    for (name, stream) in [
        ("sapnet 10x[100] results only", StreamOptions::episodes()),
        ("sapnet 10x[100] live", StreamOptions::live()),
        (
            "sapnet 10x[100] live+trace",
            StreamOptions {
                trace: true,
                ..StreamOptions::live()
            },
        ),
    ] {
        let spec = transfer(stream);
        group.bench_function(name, |b| {
            b.iter(|| drained(|e, c| drop(trainer::train_transfer(&spec, e, c).expect("run"))))
        });
    }
    let live = transfer(StreamOptions::live());
    group.bench_function("sapnet 10x[100] live, dashboard drawn at 30 fps", |b| {
        b.iter(|| watched(|e, c| drop(trainer::train_transfer(&live, e, c).expect("run"))))
    });
    // One source, warming up as long as the others: SAP-Net's bookkeeping without the
    // cost of keeping ten networks warm in the caches.
    let single = TransferRunSpec {
        dqn: sapnet::config::DqnConfig {
            replay_start_size: config.dqn.replay_start_size * 10,
            ..config.dqn.clone()
        },
        sources: sources(1),
        ..transfer(StreamOptions::episodes())
    };
    group.bench_function("sapnet 1x[100] results only", |b| {
        b.iter(|| drained(|e, c| drop(trainer::train_transfer(&single, e, c).expect("run"))))
    });
    group.finish();
}

criterion_group!(benches, overhead);

/// `SAPNET_RUN_ONCE=dqn|sapnet|live cargo bench --bench transfer_overhead` runs that case
/// once, on this thread, without criterion: for counting its instructions under
/// `valgrind --tool=callgrind --separate-threads=yes`, which is repeatable where the
/// machine's timings are not.
fn main() {
    if let Ok(case) = std::env::var("SAPNET_RUN_ONCE") {
        one_thread();
        let stream = match case.as_str() {
            "live" => StreamOptions::live(),
            _ => StreamOptions::episodes(),
        };
        let (dqn, transfer) = specs(stream);
        drained(|e, c| match case.as_str() {
            "dqn" => drop(trainer::train(&dqn, e, c).expect("run")),
            _ => drop(trainer::train_transfer(&transfer, e, c).expect("run")),
        });
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
