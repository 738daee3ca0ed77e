//! Teaching: SAP-Net's activation and spreading on a small graph, one `spread` call at a
//! time, with every quantity of eq. 8–11 shown.
//!
//! - [`config`]: the teach file (RON), a graph given by its edges or by policy categories.
//! - [`headless`]: `sapnet teach --headless`, the trace as a table or as JSON.

pub mod config;
pub mod headless;

pub use config::{Lesson, TeachConfig};
