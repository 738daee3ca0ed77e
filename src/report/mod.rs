//! What a protocol's finished runs say, below both front ends: the methods side by side
//! ([`comparison`]) and the plots ([`plots`]), from the runs' records ([`runs`]). The
//! headless protocol writes them into its results folder, `sapnet plot` writes them again
//! from the folder's files, `sweep merge` per axis value, and the dashboard draws a
//! finished protocol's curves under the live ones.

pub mod comparison;
pub mod plots;
pub mod runs;

pub use comparison::MethodComparison;
pub use plots::{write_all as write_plots, Curve, PlotData, SelectionHistory};
pub use runs::{moving_average, LibraryEntry, RunSummary};
