//! Helpers shared by the tests of `tests/it/` (and, for `tui_script.rs`, by the render
//! bench, which includes that file by path: so this folder stays beside `it/`).

pub mod cli;
pub mod library;
pub mod python;
pub mod signal;
pub mod tmux;
pub mod tui_script;
