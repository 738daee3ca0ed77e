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
use std::time::{Duration, Instant};

use criterion::{criterion_group, Criterion};
use rand::rngs::StdRng;
use rand::SeedableRng;
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use sapnet::config::Config;
use sapnet::dqn::{Architecture, QNet};
use sapnet::reuse::Method;
use sapnet::sapnet::PolicyDescription;
use sapnet::trainer::{self, Event, MethodId, RunSpec, SourcePolicy, StreamOptions};
use sapnet::tui::dashboard::Dashboard;
use sapnet::tui::dashboard_view as view;
use sapnet::tui::theme::Theme;

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Learning steps per measured run. Before them both sides act the same number of
/// warm-up steps without learning: the transfer loop 10 × 50 (N × `replay_start_size`),
/// the DQN 500 (its `replay_start_size` raised to match).
const STEPS: u64 = 3_000;

/// Learning steps of each run in `SAPNET_AB_PAIRS` mode: long enough (~0.5 s) that the
/// dashboard draws a dozen frames while the trainer works.
const AB_STEPS: u64 = 40_000;

fn sources(n: u64) -> Arc<Vec<SourcePolicy>> {
    Arc::new(
        (0..n)
            .map(|i| {
                SourcePolicy::new(
                    format!("source-{i}"),
                    QNet::new(
                        Architecture::new(4, &[100], 2),
                        &mut StdRng::seed_from_u64(i),
                    )
                    .expect("network"),
                    PolicyDescription::new(vec![100], "cartpole"),
                    // Scores for the selectors that read them (BestSource picks source-3).
                    Some(if i == 3 { 500.0 } else { 10.0 + i as f64 }),
                )
                .expect("network")
            })
            .collect(),
    )
}

/// Runs `train` with its events drained on another thread every 10 ms, as both front ends
/// drain them (headless between progress updates, the TUI once per frame): never parked
/// on the channel, so that no send has to wake a thread. Returns the time `train` took:
/// the front end's shutdown (waiting out the sleep it is in) is not training time.
fn drained(train: impl FnOnce(&mpsc::Sender<Event>, &trainer::CommandReceiver)) -> Duration {
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
    let (_commands, commands) = trainer::command_channel();
    let started = Instant::now();
    train(&events, &commands);
    let took = started.elapsed();
    drop(events);
    drain.join().expect("drain thread");
    took
}

/// As [`drained`], but the thread is the dashboard's: every frame (33 ms) it folds the
/// events into a [`Dashboard`] and draws it at 200×60, so that training competes with
/// the UI's work as it does with the TUI open.
fn watched(train: impl FnOnce(&mpsc::Sender<Event>, &trainer::CommandReceiver)) -> Duration {
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
    let (_commands, commands) = trainer::command_channel();
    let started = Instant::now();
    train(&events, &commands);
    let took = started.elapsed();
    drop(events);
    ui.join().expect("UI thread");
    took
}

/// The DQN and the transfer run (with `stream`) over the same `steps` learning steps.
fn specs(stream: StreamOptions, steps: u64) -> (RunSpec, RunSpec) {
    let config = Config::default();
    let warm_up = 10 * config.dqn.replay_start_size as u64;
    let mut dqn = RunSpec::scratch(
        0,
        "dqn[100]",
        config.env.clone(),
        sapnet::dqn::DqnConfig {
            replay_start_size: config.dqn.replay_start_size * 10,
            ..config.dqn.clone()
        },
        vec![100],
        u32::MAX,
        0,
        1,
    );
    dqn.budget = sapnet::config::Budget::Steps(steps + warm_up);
    let transfer = RunSpec {
        run: 0,
        method: MethodId::new(0, &Method::SapNet),
        reuse: Method::SapNet,
        env: config.env.clone(),
        dqn: config.dqn.clone(),
        sapnet: config.sapnet.clone(),
        sources: sources(10),
        budget: sapnet::config::Budget::Steps(steps + warm_up),
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
    let (dqn, _) = specs(StreamOptions::episodes(), STEPS);
    let transfer = |stream| specs(stream, STEPS).1;
    let config = Config::default();

    let mut group = c.benchmark_group("transfer_overhead");
    group.sample_size(20);
    group.measurement_time(Duration::from_secs(20));
    group.bench_function("dqn[100]", |b| {
        b.iter_custom(|n| {
            (0..n)
                .map(|_| drained(|e, c| drop(trainer::train(&dqn, e, c).expect("run"))))
                .sum()
        })
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
            b.iter_custom(|n| {
                (0..n)
                    .map(|_| drained(|e, c| drop(trainer::train(&spec, e, c).expect("run"))))
                    .sum()
            })
        });
    }
    let live = transfer(StreamOptions::live());
    group.bench_function("sapnet 10x[100] live, dashboard drawn at 30 fps", |b| {
        b.iter_custom(|n| {
            (0..n)
                .map(|_| watched(|e, c| drop(trainer::train(&live, e, c).expect("run"))))
                .sum()
        })
    });
    // One source, warming up as long as the others: SAP-Net's bookkeeping without the
    // cost of keeping ten networks warm in the caches.
    let single = RunSpec {
        dqn: sapnet::dqn::DqnConfig {
            replay_start_size: config.dqn.replay_start_size * 10,
            ..config.dqn.clone()
        },
        sources: sources(1),
        ..transfer(StreamOptions::episodes())
    };
    group.bench_function("sapnet 1x[100] results only", |b| {
        b.iter_custom(|n| {
            (0..n)
                .map(|_| drained(|e, c| drop(trainer::train(&single, e, c).expect("run"))))
                .sum()
        })
    });
    group.finish();
}

criterion_group!(benches, overhead);

/// `SAPNET_RUN_ONCE=dqn|sapnet|live cargo bench --bench transfer_overhead` runs that case
/// once, on this thread, without criterion: for counting its instructions under
/// `valgrind --tool=callgrind --separate-threads=yes`, which is repeatable where the
/// machine's timings are not. Any other value is read as a method of `protocol.methods`
/// (`Ucb1`, `Random`, `SapNetWith(judgment: Episode)`…) and run as the transfer case is,
/// over the same ten sources.
///
/// `SAPNET_AB_PAIRS=N cargo bench --bench transfer_overhead` times N pairs, in turn, of the
/// headless run (results-only events, drained every 10 ms) and the TUI's (every step
/// streamed, the dashboard drawn at 30 fps): pairs taken back to back see the same machine,
/// so the median of their ratios is steadier than two criterion figures taken minutes apart.
fn main() {
    if let Some(pairs) = std::env::var("SAPNET_AB_PAIRS")
        .ok()
        .and_then(|n| n.parse::<usize>().ok())
        .filter(|&n| n > 0)
    {
        one_thread();
        headless_against_dashboard(pairs);
        return;
    }
    if let Ok(case) = std::env::var("SAPNET_RUN_ONCE") {
        one_thread();
        let stream = match case.as_str() {
            "live" => StreamOptions::live(),
            _ => StreamOptions::episodes(),
        };
        let (dqn, mut transfer) = specs(stream, STEPS);
        if !matches!(case.as_str(), "dqn" | "sapnet" | "live") {
            let method: Method = sapnet::ron_file::parse_ron(&case, "SAPNET_RUN_ONCE")
                .unwrap_or_else(|e| panic!("{e}"));
            transfer.method = MethodId::new(0, &method);
            transfer.reuse = method;
        }
        drained(|e, c| match case.as_str() {
            "dqn" => drop(trainer::train(&dqn, e, c).expect("run")),
            _ => drop(trainer::train(&transfer, e, c).expect("run")),
        });
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}

/// Prints the TUI's training speed as a share of headless's, over `pairs` alternating runs.
fn headless_against_dashboard(pairs: usize) {
    let headless = specs(StreamOptions::episodes(), AB_STEPS).1;
    let live = specs(StreamOptions::live(), AB_STEPS).1;
    let run_headless =
        || drained(|e, c| drop(trainer::train(&headless, e, c).expect("run"))).as_secs_f64();
    let run_watched =
        || watched(|e, c| drop(trainer::train(&live, e, c).expect("run"))).as_secs_f64();
    // One of each first, unmeasured: caches, allocator and page tables warm.
    run_headless();
    run_watched();
    let mut shares = Vec::with_capacity(pairs);
    let (mut headless_s, mut watched_s) = (Vec::new(), Vec::new());
    for k in 0..pairs {
        // Alternate which goes first, so neither always follows the other.
        let (h, w) = if k % 2 == 0 {
            let h = run_headless();
            (h, run_watched())
        } else {
            let w = run_watched();
            (run_headless(), w)
        };
        headless_s.push(h);
        watched_s.push(w);
        // Speed is steps per second over the same steps: the TUI's share is h / w.
        shares.push(h / w);
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let quartiles = |v: &[f64]| (v[v.len() / 4], v[3 * v.len() / 4]);
    let h = median(&mut headless_s);
    let w = median(&mut watched_s);
    let share = median(&mut shares);
    let (q1, q3) = quartiles(&shares);
    println!("{pairs} pairs of {AB_STEPS} learning steps (+ warm-up), 10 sources 4-100-2");
    println!(
        "headless (results only, drained every 10 ms): median {:.1} ms",
        h * 1e3
    );
    println!(
        "TUI (every step streamed, dashboard drawn at 30 fps): median {:.1} ms",
        w * 1e3
    );
    println!(
        "TUI speed / headless speed, per pair: median {:.1}%, quartiles {:.1}% to {:.1}%",
        share * 100.0,
        q1 * 100.0,
        q3 * 100.0
    );
}
