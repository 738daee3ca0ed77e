//! One frame of the dashboard and of teach mode at 200×60, drawn into ratatui's
//! TestBackend (the terminal's own I/O is not timed): the UI thread's work per frame.
//!
//! `cargo bench --bench tui_render`

#[allow(dead_code)] // the tests use more of the script than the bench
#[path = "../tests/common/tui_script.rs"]
mod tui_script;

use criterion::{criterion_group, criterion_main, Criterion};
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use sapnet::teach::lesson::TeachConfig;
use sapnet::teach::Teach;
use sapnet::tui::dashboard::Dashboard;
use sapnet::tui::theme::Theme;
use sapnet::tui::{dashboard_view, teach_view};

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn render(c: &mut Criterion) {
    // A full CartPole protocol's length: 5,000 episodes of both curves.
    let mut dashboard = Dashboard::new("CartPole-v1");
    dashboard.on_event(tui_script::sapnet_start());
    dashboard.on_event(tui_script::baseline_start());
    for event in tui_script::episodes(5000) {
        dashboard.on_event(event);
    }
    let mut terminal = Terminal::new(TestBackend::new(200, 60)).expect("test terminal");
    let theme = Theme { color: true };
    let mut group = c.benchmark_group("tui_render");
    group.bench_function("dashboard 200x60, 5000 episodes", |b| {
        b.iter(|| {
            terminal
                .draw(|f| dashboard_view::draw_dashboard(f, &dashboard, theme))
                .expect("draw");
        })
    });

    let lesson = TeachConfig::load(None).expect("Fig. 2");
    let mut teach = Teach::new(lesson.names, lesson.net);
    teach.activate();
    for _ in 0..10 {
        teach.step();
    }
    group.bench_function("teach 200x60, Fig. 2 after 10 calls", |b| {
        b.iter(|| {
            terminal
                .draw(|f| teach_view::draw(f, &teach, false, theme))
                .expect("draw");
        })
    });
    group.finish();
}

criterion_group!(benches, render);
criterion_main!(benches);
