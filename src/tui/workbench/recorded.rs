//! The dashboard of a run that ended before the screen opened, made from its files
//! ([`crate::results::recorded_run`]): Enter on it in the Runs view shows it, in
//! `sapnet open` as in a protocol's session ([`super::screens`]).

use anyhow::Result;

use crate::results::folder_state::FolderState;
use crate::results::recorded_run;
use crate::trainer::MethodId;
use crate::tui::dashboard::{Dashboard, FromFiles};
use crate::tui::reference::Band;

/// Run `run` of `method` in `folder` on a dashboard of `task`, with `reference`'s bands
/// under its curve: the events its files keep, fed as a live run's would be.
pub fn dashboard(
    folder: &FolderState,
    method: &MethodId,
    run: u32,
    task: &str,
    reference: &[Band],
) -> Result<Dashboard> {
    let mut dashboard = Dashboard::new(task);
    dashboard.reference = reference.to_vec();
    dashboard.follow(method.label());
    // Fed as read: the dashboard keeps what it shows (its curve thinned), not the events.
    let recorded = recorded_run::read(folder, method, run, &mut |event| dashboard.on_event(event))?;
    dashboard.from_files = Some(FromFiles {
        activations: recorded.activations,
        learner: recorded.learner,
    });
    Ok(dashboard)
}
