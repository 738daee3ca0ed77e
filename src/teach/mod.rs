//! Teaching: SAP-Net's activation and spreading on a small graph, one `spread` call at a
//! time, with every quantity of eq. 8–11 shown.
//!
//! - [`config`]: the teach file (RON), a graph given by its edges or by policy categories.
//! - [`session`]: a lesson being taught (teach mode's state; the terminal UI draws it):
//!   what its rooms share, the picked policy, the panel shown. Its rooms:
//!   - [`walk`]: one activation's spreading stepped a call at a time, with undo, and A
//!     and P through time; [`playback`]: `r` and `R`;
//!   - [`names`]: what the screen calls the policies;
//!   - [`graph_edits`]: the knobs and the graph edited by key and by mouse;
//!   - [`prompt`]: the line typed; [`quiz`]: the exercise and the lesson's questions;
//!   - [`lesson_file`]: the lesson written back (`w`).
//! - [`knobs`]: the session's live edits (T_ω, 𝒜, τ, paths, an edge's weight) and what
//!   each changed.
//! - [`labels`]: short names for policies and tasks, for a graph node or a narrow column.
//! - [`edit`]: the graph's edits (edges, policies, categories), by flag before a lesson is
//!   taught or by key in it, and the lesson saved (`--save`, `w`).
//! - [`category`]: a policy's category as the first prototype's key, typed and changed.
//! - [`questions`]: a lesson's questions with hidden answers, asked when a walk ends.
//! - [`headless`]: `sapnet teach --headless`, the trace as a table or as JSON.
//!
//! Nothing here draws: the terminal UI (`tui`) imports this module, never the reverse.

pub mod category;
pub mod edit;
pub mod graph_edits;
pub mod headless;
pub mod knobs;
pub mod labels;
pub mod lesson;
pub mod lesson_file;
pub mod names;
pub mod playback;
pub mod prompt;
pub mod questions;
pub mod quiz;
pub mod session;
pub mod walk;

pub use lesson::{Lesson, TeachConfig};
pub use session::Teach;

#[cfg(test)]
mod tests {
    /// The model sits below the front ends: a lesson can be stepped, edited and checked
    /// without a terminal, and the terminal UI imports it, never the reverse.
    #[test]
    fn teaching_imports_no_front_end() {
        let files = [
            ("mod.rs", include_str!("mod.rs")),
            ("edit.rs", include_str!("edit.rs")),
            ("category.rs", include_str!("category.rs")),
            ("questions.rs", include_str!("questions.rs")),
            ("lesson.rs", include_str!("lesson.rs")),
            ("headless.rs", include_str!("headless.rs")),
            ("knobs.rs", include_str!("knobs.rs")),
            ("labels.rs", include_str!("labels.rs")),
            ("session.rs", include_str!("session.rs")),
            ("walk.rs", include_str!("walk.rs")),
            ("playback.rs", include_str!("playback.rs")),
            ("names.rs", include_str!("names.rs")),
            ("graph_edits.rs", include_str!("graph_edits.rs")),
            ("prompt.rs", include_str!("prompt.rs")),
            ("quiz.rs", include_str!("quiz.rs")),
            ("lesson_file.rs", include_str!("lesson_file.rs")),
        ];
        // The paths are put together, so that this test does not find them in itself.
        let front_ends = [["crate", "tui::"], ["ratatui", ""], ["crossterm", ""]];
        for (file, text) in files {
            for path in front_ends.map(|parts| parts.join("::")) {
                assert!(!text.contains(&path), "{file} names {path}");
            }
        }
    }
}
