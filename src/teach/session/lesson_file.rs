//! The lesson on screen written back as a lesson file (`w`): what `sapnet teach --config`
//! reads, so that the walk on screen can be replayed, or reopened where it stood.

use std::path::Path;

use super::Teach;
use crate::teach::lesson::{TeachConfig, WalkPosition};

impl Teach {
    /// The lesson as it stands, in the format `sapnet teach --config` reads: the graph
    /// (its edges, or the policies' descriptions where categories build it), T_ω, 𝒜, τ
    /// and the paths as edited, the policies' names as the lesson gave them, and as
    /// `initial` the activations the walk on screen started from (so `--activate` of its
    /// policy replays it), or those on screen without a walk.
    pub fn lesson_file(&self) -> TeachConfig {
        let params = self.net.params();
        let activations = match &self.walk {
            Some(w) => w.before().to_vec(),
            None => self.net.activations().to_vec(),
        };
        let names = self.names.given();
        let default_names = names
            .iter()
            .enumerate()
            .all(|(i, name)| *name == format!("π{i}"));
        let defaults = TeachConfig::default();
        let by_categories = self.has_categories();
        TeachConfig {
            policies: self.net.len(),
            names: if default_names { Vec::new() } else { names },
            edges: if by_categories {
                Vec::new()
            } else {
                self.net.graph().edges().collect()
            },
            descriptions: self.source.descriptions.clone(),
            prototypes: if by_categories {
                params.prototypes.clone()
            } else {
                defaults.prototypes
            },
            delta: if by_categories {
                params.delta
            } else {
                defaults.delta
            },
            base_graph: if by_categories {
                params.base_graph
            } else {
                defaults.base_graph
            },
            threshold: params.threshold,
            coefficient: params.coefficient,
            temperature: params.temperature,
            paths: params.paths,
            initial: activations.iter().any(|&a| a != 0.0).then_some(activations),
            walk: self.walk.as_ref().map(|w| WalkPosition {
                activate: w.policy(),
                calls: w.calls_made(),
            }),
            decay: self.timeline.decay,
            questions: self.questions.list().to_vec(),
        }
    }

    /// `w`'s Enter: writes the lesson to `path` and says how to open it, or why it was not
    /// written.
    pub(super) fn save_lesson(&mut self, path: &Path) {
        self.notice = Some(match self.lesson_file().save(path) {
            Ok(()) => format!(
                "wrote {}: `sapnet teach --config {}` opens it{}",
                path.display(),
                path.display(),
                self.walk
                    .as_ref()
                    .map(|w| format!(
                        " at call {} of {}'s walk",
                        w.calls_made(),
                        self.names()[w.policy()]
                    ))
                    .unwrap_or_default()
            ),
            Err(error) => format!("not saved: {error:#}"),
        });
    }
}
