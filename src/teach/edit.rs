//! Edits of a lesson's graph — `sapnet teach --add-edge I J W --cut-edge I J --add-policy
//! CATEGORY --remove-policy I --set-category I CATEGORY --save OUT` (issue 39), for
//! lessons prepared by script, and the same edits by key and by mouse in teach mode: each
//! applied in the order given, each refused with the reason the lesson or the net gives.

use std::path::Path;

use anyhow::{Context, Result};

use super::category;
use super::lesson::{TeachConfig, MAX_LESSON_POLICIES};
use super::questions::Answer;
use crate::sapnet::Prototype;

/// One edit of the graph M (its edges are undirected) or of its policies.
#[derive(Debug, Clone, PartialEq)]
pub enum GraphEdit {
    /// An edge between `i` and `j` of weight `w`, added or, if there is one, reweighted.
    Add { i: usize, j: usize, w: f64 },
    /// The edge between `i` and `j` removed.
    Cut { i: usize, j: usize },
    /// A new policy, last, in `category` (the first prototype's key) where the lesson is
    /// built from `descriptions`; `-` where it gives its `edges` (the policy joins
    /// nothing until an edge is added).
    AddPolicy { category: String },
    /// Policy `i` and its edges removed; the policies after it move down one number.
    RemovePolicy { i: usize },
    /// Policy `i` moved to `category` (the first prototype's key): M is rebuilt (eq. 3–5).
    SetCategory { i: usize, category: String },
}

/// The category `--add-policy` takes in a lesson given by its edges: none.
pub const NO_CATEGORY: &str = "-";

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
            ("--add-policy", 1) => Ok(Self::AddPolicy {
                category: values[0].clone(),
            }),
            ("--remove-policy", 1) => Ok(Self::RemovePolicy { i: index(0, "I")? }),
            ("--set-category", 2) => Ok(Self::SetCategory {
                i: index(0, "I")?,
                category: values[1].clone(),
            }),
            _ => Err(format!("expected {flag} with its values, got {values:?}")),
        }
    }

    /// As the user typed it, for messages.
    pub fn flag(&self) -> String {
        match self {
            Self::Add { i, j, w } => format!("--add-edge {i} {j} {w}"),
            Self::Cut { i, j } => format!("--cut-edge {i} {j}"),
            Self::AddPolicy { category } => format!("--add-policy {category}"),
            Self::RemovePolicy { i } => format!("--remove-policy {i}"),
            Self::SetCategory { i, category } => format!("--set-category {i} {category}"),
        }
    }

    /// Where policy `k` stands after this edit: `None` if it is removed.
    pub fn renumbered(&self, k: usize) -> Option<usize> {
        match *self {
            Self::RemovePolicy { i } if k == i => None,
            Self::RemovePolicy { i } if k > i => Some(k - 1),
            _ => Some(k),
        }
    }

    /// `values`, one per policy, as they stand after this edit: a new policy's is
    /// `fresh`, a removed one's dropped.
    pub fn renumber<T: Clone>(&self, values: &[T], fresh: T) -> Vec<T> {
        let mut values = values.to_vec();
        match *self {
            Self::AddPolicy { .. } => values.push(fresh),
            Self::RemovePolicy { i } if i < values.len() => {
                values.remove(i);
            }
            _ => {}
        }
        values
    }
}

impl TeachConfig {
    /// Applies `edit` to the lesson's `edges`; refused where the lesson's graph is built
    /// from categories, an index names no policy, an edge would join a policy to itself,
    /// a weight is not above 0, or a cut edge is not there. The net's own bounds (a walk
    /// that would not end) are checked when the lesson is built ([`TeachConfig::lesson`]).
    pub fn apply(&mut self, edit: &GraphEdit) -> Result<(), String> {
        self.apply_edit(edit)?;
        // A saved walk's position was on the graph before the edit.
        self.walk = None;
        Ok(())
    }

    fn apply_edit(&mut self, edit: &GraphEdit) -> Result<(), String> {
        match edit {
            GraphEdit::AddPolicy { category } => return self.add_policy(category),
            GraphEdit::RemovePolicy { i } => return self.remove_policy(*i),
            GraphEdit::SetCategory { i, category } => return self.set_category(*i, category),
            GraphEdit::Add { .. } | GraphEdit::Cut { .. } => {}
        }
        if !self.descriptions.is_empty() {
            return Err(
                "this lesson builds its graph from categories (`descriptions`, eq. \
                        3-5): edit its descriptions, or give the graph by its `edges`"
                    .into(),
            );
        }
        let n = self.count()?;
        let (i, j) = match *edit {
            GraphEdit::Add { i, j, .. } | GraphEdit::Cut { i, j } => (i, j),
            _ => unreachable!("the policies' edits returned above"),
        };
        for k in [i, j] {
            self.policy_exists(k, n)?;
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
        let weight = match edit {
            GraphEdit::Add { w, .. } => Some(*w),
            _ => None,
        };
        match (weight, at) {
            (Some(w), _) if !(w.is_finite() && w > 0.0) => {
                Err(format!("the weight must be a number above 0, got {w}"))
            }
            (Some(w), Some(k)) => {
                self.edges[k].2 = w;
                Ok(())
            }
            (Some(w), None) => {
                self.edges.push((i, j, w));
                Ok(())
            }
            (None, Some(k)) => {
                self.edges.remove(k);
                Ok(())
            }
            (None, None) => Err(format!("there is no edge between {i} and {j}")),
        }
    }

    /// `--add-policy CATEGORY`: a policy added last, in `category` where the lesson is
    /// built from categories, joined to nothing (`-`) where it gives its edges.
    fn add_policy(&mut self, category: &str) -> Result<(), String> {
        let n = self.count()?;
        if n >= MAX_LESSON_POLICIES {
            return Err(format!(
                "the lesson has {n} policies, the most a lesson may have"
            ));
        }
        if self.descriptions.is_empty() {
            if category.trim() != NO_CATEGORY {
                return Err(format!(
                    "this lesson gives its graph by `edges`, so its policies have no \
                     category: `{NO_CATEGORY}` adds a policy joined to nothing (then join it \
                     with --add-edge)"
                ));
            }
        } else {
            let prototype = self.first_prototype()?;
            let policy = category::new_policy(&prototype, &self.descriptions, category)?;
            self.descriptions.push(policy);
        }
        if self.policies > 0 {
            self.policies += 1;
        }
        if !self.names.is_empty() {
            self.names.push(format!("π{n}"));
        }
        if let Some(initial) = &mut self.initial {
            initial.push(0.0);
        }
        Ok(())
    }

    /// `--remove-policy I`: policy `i` and its edges gone, the later ones renumbered.
    fn remove_policy(&mut self, i: usize) -> Result<(), String> {
        let n = self.count()?;
        self.policy_exists(i, n)?;
        if n == 1 {
            return Err("a lesson keeps at least one policy".into());
        }
        // A question's hidden answer follows its policy to its new number; a question
        // whose answer is this policy would be left without one.
        if self.questions.iter().any(|q| q.answer == Answer::Policy(i)) {
            return Err(format!(
                "policy {i} is the answer to one of the lesson's questions: change the \
                 question first"
            ));
        }
        for question in &mut self.questions {
            if let Answer::Policy(k) = &mut question.answer {
                if *k > i {
                    *k -= 1;
                }
            }
        }
        let renumber = |k: usize| if k > i { k - 1 } else { k };
        self.edges = self
            .edges
            .iter()
            .filter(|&&(a, b, _)| a != i && b != i)
            .map(|&(a, b, w)| (renumber(a), renumber(b), w))
            .collect();
        if !self.descriptions.is_empty() {
            self.descriptions.remove(i);
        }
        if !self.names.is_empty() {
            self.names.remove(i);
        }
        if self.policies > 0 {
            self.policies -= 1;
        }
        if let Some(initial) = &mut self.initial {
            if i < initial.len() {
                initial.remove(i);
            }
        }
        Ok(())
    }

    /// `--set-category I CATEGORY`: policy `i`'s description changed so that the first
    /// prototype gives it `category`; M follows from the categories when the lesson is
    /// built.
    fn set_category(&mut self, i: usize, category: &str) -> Result<(), String> {
        let n = self.count()?;
        self.policy_exists(i, n)?;
        if self.descriptions.is_empty() {
            return Err(
                "this lesson gives its graph by `edges`, so its policies have no \
                        category (eq. 3-5 build M from categories where the lesson gives \
                        `descriptions`): change its edges instead"
                    .into(),
            );
        }
        let prototype = self.first_prototype()?;
        self.descriptions[i] = category::with_key(&prototype, &self.descriptions[i], category)?;
        Ok(())
    }

    /// The prototype whose key is a policy's category (the first one, as the screen
    /// groups the graph's nodes by it).
    pub fn first_prototype(&self) -> Result<Prototype, String> {
        self.prototypes
            .first()
            .map(|p| p.prototype.clone())
            .ok_or_else(|| "the lesson has no prototype to give its policies a category".into())
    }

    fn policy_exists(&self, k: usize, n: usize) -> Result<(), String> {
        if k < n {
            Ok(())
        } else {
            Err(format!(
                "there is no policy {k}; the lesson has {n}, numbered 0 to {}",
                n.saturating_sub(1)
            ))
        }
    }

    /// Writes the lesson to `path` in the format `teach --config` reads, atomically; a
    /// FIFO, a device, a socket or a directory at `path` is refused, and a file there keeps
    /// its permissions (see [`crate::safe_io::write_user_file`]).
    pub fn save(&self, path: &Path) -> Result<()> {
        // Written as it is read (a saved walk is `Some(activate: 1, calls: 5)`).
        let body = crate::ron_file::ron_options()
            .to_string_pretty(self, ron::ser::PrettyConfig::default())
            .context("writing the lesson as RON")?;
        let text = format!(
            "// A sapnet lesson (`sapnet teach --config {}`).\n{body}\n",
            path.display()
        );
        crate::safe_io::write_user_file(path, |out| std::io::Write::write_all(out, text.as_bytes()))
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
        lesson
            .apply(&GraphEdit::Add { i: 0, j: 3, w: 0.3 })
            .unwrap();
        assert!(lesson.edges.contains(&(0, 3, 0.3)));
        // Undirected: (3, 0) is the same edge.
        lesson
            .apply(&GraphEdit::Add { i: 3, j: 0, w: 0.2 })
            .unwrap();
        assert!(lesson.edges.contains(&(0, 3, 0.2)));
        assert_eq!(lesson.edges.len(), 5);
        lesson.apply(&GraphEdit::Cut { i: 3, j: 0 }).unwrap();
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
            let error = lesson.apply(&edit).unwrap_err();
            assert!(error.contains(says), "{edit:?}: {error}");
            assert_eq!(lesson.edges, fig2().edges, "a refused edit changed nothing");
        }
    }

    fn table2() -> TeachConfig {
        crate::ron_file::parse_ron(include_str!("../../assets/teach_table2.ron"), "t2").unwrap()
    }

    /// Table II: categories of 3, 4 and 3 policies (1, 2 and 3 hidden layers), each a
    /// clique: 3 + 6 + 3 edges.
    #[test]
    fn a_policy_changes_category_and_m_follows() {
        let mut lesson = table2();
        let edit = GraphEdit::SetCategory {
            i: 0,
            category: "2".into(),
        };
        lesson.apply(&edit).unwrap();
        assert_eq!(lesson.descriptions[0].hidden, [100, 100]);
        let built = lesson.lesson().unwrap();
        // Categories of 2, 5 and 3: 1 + 10 + 3 edges; policy 0 joined to 3…6.
        assert_eq!(built.net.graph().edges().count(), 14);
        assert_eq!(built.net.graph().weight(0, 3), Some(0.95));
        assert_eq!(built.net.graph().weight(0, 1), None);
        assert_eq!(built.groups.unwrap()[..4], [0, 1, 1, 0]);
    }

    #[test]
    fn policies_are_added_to_a_category_and_removed() {
        let mut lesson = table2();
        let add = GraphEdit::AddPolicy {
            category: "3".into(),
        };
        lesson.apply(&add).unwrap();
        assert_eq!(lesson.descriptions[10].hidden, [100, 100, 100]);
        assert_eq!(lesson.names[10], "π10");
        let built = lesson.lesson().unwrap();
        // The third category now has 4 policies: 3 + 6 + 6 edges.
        assert_eq!(built.net.len(), 11);
        assert_eq!(built.net.graph().edges().count(), 15);
        assert_eq!(built.net.graph().weight(10, 7), Some(0.95));

        let mut added = fig2();
        added
            .apply(&GraphEdit::AddPolicy {
                category: "-".into(),
            })
            .unwrap();
        let built = added.lesson().unwrap();
        assert_eq!(built.net.len(), 5);
        assert_eq!(built.net.graph().degree(4), 0);
        // Fig. 2's edges (0,1) (0,2) (1,2) (1,3) without π1: (0,2) is now (0,1).
        let mut removed = fig2();
        let question = |i| crate::teach::questions::Question {
            ask: "Which?".into(),
            answer: Answer::Policy(i),
        };
        removed.questions = vec![question(3)];
        removed.apply(&GraphEdit::RemovePolicy { i: 1 }).unwrap();
        assert_eq!(removed.edges, [(0, 1, 0.4)]);
        assert_eq!(removed.questions, [question(2)], "the answer renumbered");
        let e = removed
            .apply(&GraphEdit::RemovePolicy { i: 2 })
            .unwrap_err();
        assert!(
            e.contains("the answer to one of the lesson's questions"),
            "{e}"
        );
        assert_eq!(removed.lesson().unwrap().net.len(), 3);
    }

    #[test]
    fn policy_edits_the_lesson_cannot_take_are_refused_saying_why() {
        let cases = [
            (
                fig2(),
                GraphEdit::AddPolicy {
                    category: "2".into(),
                },
                "no category: `-` adds",
            ),
            (
                fig2(),
                GraphEdit::SetCategory {
                    i: 0,
                    category: "2".into(),
                },
                "no category",
            ),
            (
                fig2(),
                GraphEdit::RemovePolicy { i: 4 },
                "there is no policy 4",
            ),
            (
                table2(),
                GraphEdit::SetCategory {
                    i: 0,
                    category: "two".into(),
                },
                "a number of hidden layers",
            ),
            (
                table2(),
                GraphEdit::SetCategory {
                    i: 10,
                    category: "2".into(),
                },
                "there is no policy 10",
            ),
            (
                table2(),
                GraphEdit::Add { i: 0, j: 3, w: 0.3 },
                "from categories",
            ),
        ];
        for (mut lesson, edit, says) in cases {
            let before = lesson.clone();
            let error = lesson.apply(&edit).unwrap_err();
            assert!(error.contains(says), "{edit:?}: {error}");
            assert_eq!(lesson, before, "a refused edit changed nothing");
        }
        let mut one = crate::ron_file::parse_ron::<TeachConfig>("(policies: 1)", "one").unwrap();
        let e = one.apply(&GraphEdit::RemovePolicy { i: 0 }).unwrap_err();
        assert_eq!(e, "a lesson keeps at least one policy");
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
        assert_eq!(
            GraphEdit::parse("--set-category", &v(&["1", "2"])),
            Ok(GraphEdit::SetCategory {
                i: 1,
                category: "2".into()
            })
        );
        assert_eq!(
            GraphEdit::parse("--remove-policy", &v(&["3"])),
            Ok(GraphEdit::RemovePolicy { i: 3 })
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
        lesson
            .apply(&GraphEdit::Add { i: 0, j: 3, w: 0.3 })
            .unwrap();
        lesson.save(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let back: TeachConfig = crate::ron_file::parse_ron(&text, "lesson.ron").unwrap();
        assert_eq!(back, lesson);
    }

    /// A link the user names is written through, the link kept; a link planted where the
    /// temporary file goes is replaced, never followed; a link to nothing is refused.
    #[test]
    fn a_lesson_is_saved_through_a_named_link_never_a_planted_one() {
        use std::os::unix::fs::symlink;
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("real.ron");
        std::fs::write(&real, "old").unwrap();
        let named = dir.path().join("named.ron");
        symlink(&real, &named).unwrap();
        fig2().save(&named).unwrap();
        assert!(std::fs::symlink_metadata(&named)
            .unwrap()
            .file_type()
            .is_symlink());
        let text = std::fs::read_to_string(&real).unwrap();
        assert!(text.starts_with("// A sapnet lesson"), "{text}");

        let victim = dir.path().join("victim");
        std::fs::write(&victim, "keep").unwrap();
        symlink(&victim, dir.path().join(".real.tmp.ron")).unwrap();
        fig2().save(&real).unwrap();
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep");
        assert!(!dir.path().join(".real.tmp.ron").exists());

        let dangling = dir.path().join("dangling.ron");
        symlink(dir.path().join("nowhere/lesson.ron"), &dangling).unwrap();
        let error = format!("{:#}", fig2().save(&dangling).unwrap_err());
        assert!(error.contains("a symbolic link to nothing"), "{error}");
    }
}
