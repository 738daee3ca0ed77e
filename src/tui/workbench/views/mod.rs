//! The workbench's views, a file each (gitui's `tabs/`, demo2's `tabs/`): each owns its
//! state and implements [`crate::tui::view::View`] — its table of keys, what they do, how
//! it draws in the area its screen gives it.
//!
//! - [`runs`]: every planned run, its status, progress, curve and source;
//! - [`comparison`]: the methods side by side, aggregates with intervals, whiskers, pairs;
//! - [`curves`]: each method's learning curve over its runs, with its band;
//! - [`run`]: one run's dashboard, followed live or read from its files;
//! - [`sweep`]: a sweep folder's cells and each axis value's comparison;
//! - [`folders`]: the folders sapnet wrote under a parent folder, to open one.
//!
//! The first three read the folder their screen keeps ([`super::folder::Folder`]).

pub mod comparison;
pub mod curves;
pub mod folders;
pub mod run;
pub mod runs;
pub mod sweep;

/// What a view of a results folder asks of its screen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Intent {
    /// Enter in the Runs view: the run of this row of the folder in the Run view.
    ShowRun(usize),
}
