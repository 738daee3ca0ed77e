//! The experiment layer, below both front ends: what to run ([`plan`]: the runs, their
//! seeds and their library) and adding a run's chosen policy to the library
//! ([`library_copy`]). Running the runs within one jobs budget is the trainer's
//! ([`crate::trainer::scheduler`]). The dashboard and headless mode only render and write.

pub mod library_copy;
pub mod plan;

pub use library_copy::{policy_info, LibraryCopies};
pub use plan::{plan, run_specs, ConfigField, Plan};
