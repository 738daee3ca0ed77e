//! Headless mode's printing: where a protocol's files are and each run on stderr, the
//! comparison on stdout. The protocol itself is run by [`crate::experiment::protocol`],
//! the engine every front end drives.

mod summary;

pub use summary::{print_comparison, print_summary, RanIn};
