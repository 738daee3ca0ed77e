//! Edits of a lesson's graph made before it is taught — `sapnet teach --add-edge I J W
//! --cut-edge I J --save OUT` (issue 39), for lessons prepared by script: each edit
//! applied in the order given, each refused with the reason the lesson or the net gives.

use std::path::Path;

use anyhow::{Context, Result};

use super::lesson::TeachConfig;

/// One edit of the graph M (its edges are undirected).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GraphEdit {
    /// An edge between `i` and `j` of weight `w`, added or, if there is one, reweighted.
    Add { i: usize, j: usize, w: f64 },
    /// The edge between `i` and `j` removed.
    Cut { i: usize, j: usize },
}

impl GraphEdit {
    /// The edit a flag's values say: `--add-edge I J W` or `--cut-edge I J`.
    pub fn parse(flag: &str, values: &[String]) -> Result<Self, String> {
        let index = |k: usize, name: &str| -> Result<usize, String> {
            values[k].parse().map_err(|_| {
                format!(
                    "{name}: expected a policy's index (0, 1, …), got {:?}",
                    values[k]
                )
            })
        };
        match (flag, values.len()) {
            ("--add-edge", 3) => {
                let w: f64 = values[2]
                    .parse()
                    .map_err(|_| format!("W: expected a weight, got {:?}", values[2]))?;
                Ok(Self::Add {
                    i: index(0, "I")?,
                    j: index(1, "J")?,
                    w,
                })
            }
            ("--cut-edge", 2) => Ok(Self::Cut {
                i: index(0, "I")?,
                j: index(1, "J")?,
            }),
            _ => Err(format!("expected {flag} with its values, got {values:?}")),
        }
    }

    /// As the user typed it, for messages.
    pub fn flag(&self) -> String {
        match *self {
            Self::Add { i, j, w } => format!("--add-edge {i} {j} {w}"),
            Self::Cut { i, j } => format!("--cut-edge {i} {j}"),
        }
    }
}

impl TeachConfig {
    /// Applies `edit` to the lesson's `edges`; refused where the lesson's graph is built
    /// from categories, an index names no policy, an edge would join a policy to itself,
    /// a weight is not above 0, or a cut edge is not there. The net's own bounds (a walk
    /// that would not end) are checked when the lesson is built ([`TeachConfig::lesson`]).
    pub fn apply(&mut self, edit: GraphEdit) -> Result<(), String> {
        if !self.descriptions.is_empty() {
            return Err(
                "this lesson builds its graph from categories (`descriptions`, eq. \
                        3-5): edit its descriptions, or give the graph by its `edges`"
                    .into(),
            );
        }
        let n = self.count()?;
        let (i, j) = match edit {
            GraphEdit::Add { i, j, .. } | GraphEdit::Cut { i, j } => (i, j),
        };
        if let Some(k) = [i, j].into_iter().find(|&k| k >= n) {
            return Err(format!(
                "there is no policy {k}; the lesson has {n}, numbered 0 to {}",
                n.saturating_sub(1)
            ));
        }
        if i == j {
            return Err(format!(
                "an edge joins two policies, not policy {i} to itself"
            ));
        }
        let at = self
            .edges
            .iter()
            .position(|&(a, b, _)| (a, b) == (i, j) || (a, b) == (j, i));
        match (edit, at) {
            (GraphEdit::Add { w, .. }, _) if !(w.is_finite() && w > 0.0) => {
                Err(format!("the weight must be a number above 0, got {w}"))
            }
            (GraphEdit::Add { w, .. }, Some(k)) => {
                self.edges[k].2 = w;
                Ok(())
            }
            (GraphEdit::Add { w, .. }, None) => {
                self.edges.push((i, j, w));
                Ok(())
            }
            (GraphEdit::Cut { .. }, Some(k)) => {
                self.edges.remove(k);
                Ok(())
            }
            (GraphEdit::Cut { .. }, None) => Err(format!("there is no edge between {i} and {j}")),
        }
    }

    /// Writes the lesson to `path` in the format `teach --config` reads, atomically.
    pub fn save(&self, path: &Path) -> Result<()> {
        let body = ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default())
            .context("writing the lesson as RON")?;
        let text = format!(
            "// A sapnet lesson (`sapnet teach --config {}`).\n{body}\n",
            path.display()
        );
        crate::safe_io::write_atomically(path, |out| {
            std::io::Write::write_all(out, text.as_bytes())
        })
        .with_context(|| format!("writing {}", path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fig2() -> TeachConfig {
        crate::ron_file::parse_ron(super::super::lesson::FIG2, "fig2").unwrap()
    }

    #[test]
    fn edges_are_added_reweighted_and_cut_in_order() {
        let mut lesson = fig2();
        lesson.apply(GraphEdit::Add { i: 0, j: 3, w: 0.3 }).unwrap();
        assert!(lesson.edges.contains(&(0, 3, 0.3)));
        // Undirected: (3, 0) is the same edge.
        lesson.apply(GraphEdit::Add { i: 3, j: 0, w: 0.2 }).unwrap();
        assert!(lesson.edges.contains(&(0, 3, 0.2)));
        assert_eq!(lesson.edges.len(), 5);
        lesson.apply(GraphEdit::Cut { i: 3, j: 0 }).unwrap();
        assert_eq!(lesson.edges, fig2().edges);
        assert!(lesson.lesson().is_ok());
    }

    #[test]
    fn edits_that_break_the_lesson_are_refused_saying_why() {
        let cases = [
            (GraphEdit::Add { i: 0, j: 9, w: 0.3 }, "no policy 9"),
            (GraphEdit::Add { i: 2, j: 2, w: 0.3 }, "to itself"),
            (GraphEdit::Add { i: 0, j: 3, w: 0.0 }, "above 0"),
            (
                GraphEdit::Add {
                    i: 0,
                    j: 3,
                    w: f64::NAN,
                },
                "above 0",
            ),
            (GraphEdit::Cut { i: 0, j: 3 }, "no edge between 0 and 3"),
        ];
        for (edit, says) in cases {
            let mut lesson = fig2();
            let error = lesson.apply(edit).unwrap_err();
            assert!(error.contains(says), "{edit:?}: {error}");
            assert_eq!(lesson.edges, fig2().edges, "a refused edit changed nothing");
        }
    }

    #[test]
    fn values_are_read_as_the_flags_say() {
        let v = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        assert_eq!(
            GraphEdit::parse("--add-edge", &v(&["0", "3", "0.3"])),
            Ok(GraphEdit::Add { i: 0, j: 3, w: 0.3 })
        );
        assert_eq!(
            GraphEdit::parse("--cut-edge", &v(&["1", "2"])),
            Ok(GraphEdit::Cut { i: 1, j: 2 })
        );
        assert!(GraphEdit::parse("--add-edge", &v(&["a", "3", "0.3"]))
            .unwrap_err()
            .contains("I: expected a policy's index"));
        assert!(GraphEdit::parse("--add-edge", &v(&["0", "3", "heavy"]))
            .unwrap_err()
            .contains("W: expected a weight"));
    }

    #[test]
    fn a_saved_lesson_reads_back_as_it_was() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("lesson.ron");
        let mut lesson = fig2();
        lesson.apply(GraphEdit::Add { i: 0, j: 3, w: 0.3 }).unwrap();
        lesson.save(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let back: TeachConfig = crate::ron_file::parse_ron(&text, "lesson.ron").unwrap();
        assert_eq!(back, lesson);
    }
}
