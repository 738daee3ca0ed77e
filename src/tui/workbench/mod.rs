//! The workbench: a protocol's results in views a key apart, on every screen that shows
//! them — `sapnet open DIR` (a results folder, finished or being written elsewhere),
//! `sapnet` (a protocol trained here, one run followed live), `sapnet open SWEEP` (a
//! sweep's cells and comparisons), `sapnet open COMPARE` (a `sapnet compare` folder's
//! Comparison and Curves).
//!
//! - [`views`]: a file per view (Runs, Comparison, Curves, Run, Sweep), each owning its
//!   state and its one key table ([`crate::tui::view::View`]);
//! - [`screens`]: a file per screen, which keeps what its views share (the folder as
//!   read), routes keys and intents, and runs on the one event loop
//!   ([`crate::tui::event_loop`]);
//! - [`frame`]: what is drawn around every view — the header, the status bar, `?`, the
//!   notice — once for all of them;
//! - [`folder`], [`sweep_folder`], [`compare_folder`]: the folders as the views read
//!   them, and the thread that reads a results folder again; [`recorded`]: a finished run's dashboard from its
//!   files; [`cells`]: what the views' tables share.

pub mod cells;
pub mod compare_folder;
pub mod folder;
pub mod frame;
pub mod recorded;
pub mod screens;
pub mod sweep_folder;
pub mod views;
