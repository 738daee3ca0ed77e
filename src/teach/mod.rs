//! Teaching: SAP-Net's activation and spreading on a small graph, one `spread` call at a
//! time, with every quantity of eq. 8–11 shown.
//!
//! - [`config`]: the teach file (RON), a graph given by its edges or by policy categories.
//! - [`session`]: a lesson being taught (teach mode's state; the terminal UI draws it),
//!   a room per job under `session/`: the walk with undo and `r`/`R`, the policies' names,
//!   the graph's edits by key and mouse, the line typed, the quiz, the lesson written
//!   back.
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
pub mod headless;
pub mod knobs;
pub mod labels;
pub mod lesson;
pub mod questions;
pub mod session;

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
            ("session/walk.rs", include_str!("session/walk.rs")),
            ("session/playback.rs", include_str!("session/playback.rs")),
            ("session/names.rs", include_str!("session/names.rs")),
            (
                "session/graph_edits.rs",
                include_str!("session/graph_edits.rs"),
            ),
            ("session/prompt.rs", include_str!("session/prompt.rs")),
            ("session/quiz.rs", include_str!("session/quiz.rs")),
            (
                "session/lesson_file.rs",
                include_str!("session/lesson_file.rs"),
            ),
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
