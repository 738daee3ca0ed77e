//! The experiment layer, below every front end: what to run ([`plan`]: the runs, their
//! seeds and their library), running it into a results folder ([`protocol`]: new, resumed,
//! extended with methods; its output folder, its observer of the runs' events, the tap a
//! screen listens on, the TensorBoard writer), and adding a run's chosen policy to the
//! library ([`library_copy`]). Running the runs within one jobs budget is the trainer's
//! ([`crate::trainer::scheduler`]). Front ends (headless printing, the workbench, `sweep
//! run`) drive this engine and hear its events; they never drive one another.

pub mod library_copy;
mod observer;
mod output;
pub mod plan;
pub mod protocol;
mod tap;
mod tensorboard_runs;

pub use library_copy::{policy_info, LibraryCopies};
pub use output::{default_out_dir, OutputOptions};
pub use plan::{plan, run_specs, ConfigField, Plan};
pub use protocol::{
    resume, resume_taken, resume_tapped, run, run_opened, AddedMethods, OpenedOutput, RunOptions,
    StoppedProtocol,
};
pub use tap::{Tap, Watched};
pub use tensorboard_runs::{event_dir_name, TENSORBOARD_DIR};
