// Each test binary (and the render bench) uses a part of the script.
#[allow(dead_code)]
pub mod library;
#[allow(dead_code)]
pub mod python;
#[allow(dead_code)]
pub mod signal;
#[allow(dead_code)]
pub mod tmux;
#[allow(dead_code)]
pub mod tui_script;
