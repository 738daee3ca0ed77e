//! sapnet's integration tests, as one crate: each file of this folder is a module, so that
//! `cargo test --release` compiles and links the tests once (each of the ~30 files was a
//! test binary of its own, linked against the whole crate and its dependencies).
//!
//! Run one file's tests with `cargo test --release --test it <file>::`, e.g.
//! `cargo test --release --test it pinned_numbers::`.
//!
//! The tests share one process and run side by side: a test must not change the process's
//! environment or current directory, and one that looks for processes (pgrep, pkill)
//! matches only its own children or its own command line.

// Shared with the render bench (benches/tui_render.rs), which includes a file of it by path.
#[path = "../common/mod.rs"]
mod common;

mod compare_cli;
mod config_files;
mod docs_links;
mod dqn_agent;
mod dqn_learns;
mod dqn_policy_store;
mod env_vectors;
mod gymnasium_bridge;
mod headless_cli;
mod hostile_folders;
mod import_cli;
mod judgment_signals;
mod key_tables;
mod layers;
mod method_behaviour;
mod open_compare;
mod open_parent;
mod other_agents;
mod pinned_numbers;
mod pool_cli;
mod quick_start;
mod received_folders;
mod recorded_runs;
mod resume_cli;
mod sapnet_properties;
mod sapnet_selection;
mod sapnet_spreading;
mod sapnet_validation;
mod shipped_folders;
mod signals_cli;
mod sources_cli;
mod sweep_cli;
mod teach_cli;
mod teach_lesson;
mod teach_screen;
mod tensorboard_cli;
mod tensorboard_files;
mod trainer_failure;
mod trainer_stop;
mod transfer_cli;
mod transfer_run;
mod tui_snapshots;
mod tui_state;
mod tui_tmux;
mod variants_cli;
mod ways_back;
mod workbench;
mod workbench_protocol;
