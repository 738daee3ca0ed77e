//! Sweeps: a grid of configs run as independent cells, by Slurm array jobs, GNU parallel or
//! this machine, then merged into one report.
//!
//! ```text
//! SWEEP/
//!   sweep.ron              the manifest: every cell's id, axis values and config hash
//!   cells/0000.ron …       each cell's complete config
//!   slurm.sbatch           an array job over the cells
//!   parallel.txt           the GNU parallel command line
//!   results/0000/ …        a finished cell's results (renamed into place when whole)
//!   failed/0003.txt        why a cell's last attempt failed
//!   logs/                  the cells' stdout and stderr under Slurm
//!   merged/                `sapnet sweep merge`: comparisons per axis value, episodes.csv
//! ```
//!
//! - [`grid`]: the grid file and its expansion into cells.
//! - [`plan`]: `sweep plan`, the folder above.
//! - [`run`]: `sweep run` (one cell, or all locally) and `sweep prepare` (the libraries).
//!
//! The folder's format — its manifest, its cells' states (`sweep status`), the merged
//! reports (`sweep merge`) — is the results layer's ([`crate::results::sweep`]).

pub mod grid;
pub mod plan;
pub mod run;
