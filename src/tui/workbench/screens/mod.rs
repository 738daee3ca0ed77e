//! The screens the workbench's views are shown on, each on the one event loop
//! ([`crate::tui::event_loop`]):
//!
//! - [`workbench`]: what `sapnet open DIR` and a protocol's session share — a results
//!   folder's views and the Run view a tab apart, the keys routed to them;
//! - [`opened`]: `sapnet open DIR`;
//! - [`session`]: `sapnet` (a protocol trained in the UI: stop, launch, resume);
//! - [`sweep`]: `sapnet open SWEEP`;
//! - [`compared`]: `sapnet open COMPARE`, a `sapnet compare` folder;
//! - [`folders`]: `sapnet open PARENT`, the folders under it, each opened on one of the
//!   screens above.

pub mod compared;
pub mod folders;
pub mod opened;
pub mod session;
pub mod sweep;
pub mod workbench;
