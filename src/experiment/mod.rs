//! The experiment layer, below both front ends: what to run ([`plan`]), running it within
//! one jobs budget ([`schedule`]), and adding a run's chosen policy to the library
//! ([`library_copy`]). The dashboard and headless mode only render and write.

pub mod library_copy;
pub mod memory;
pub mod plan;
pub mod schedule;

pub use library_copy::{policy_info, LibraryCopies};
pub use plan::{method_ids, plan, run_specs, ConfigField, Plan};
pub use schedule::{schedule, Observer};
