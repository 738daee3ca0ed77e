//! Teach mode's edits of the lesson: a knob turned (`1`…`5`, `+`/`−`: T_ω, 𝒜, τ, the
//! paths, an edge's weight M), the graph edited by key (`E`, `x`, `n`, `D`, `C`) or by
//! mouse (`M`). Each goes through the checks `sapnet teach --add-edge` and its kin make,
//! a refusal changes nothing and is said, and the walk on screen restarts from the
//! activations it started from, so that its end before and after can be compared.

use super::prompt::PromptKind;
use super::Teach;
use crate::teach::edit::{GraphEdit, NO_CATEGORY};
use crate::teach::knobs::{refusal, walk_end, EditReport, Knob};

/// The weight of an edge added by the mouse (`M`): Fig. 2's; `5` and `+`/`−` change it.
pub const MOUSE_EDGE_WEIGHT: f64 = 0.4;

/// What the next edit acts on, and what the last one did.
#[derive(Debug, Clone, Default)]
pub(super) struct Editing {
    /// What `+` and `−` change (`1`…`5`).
    knob: Knob,
    /// Which of the picked policy's edges a weight edit changes (`e` moves it).
    pub(super) edge: usize,
    /// The last knob turned and what it changed.
    last: Option<EditReport>,
    /// `M`: clicks edit edges — a first click picks a policy, a second joins it to the
    /// one clicked or cuts their edge.
    linking: bool,
    /// In `M` mode, the policy the first click picked.
    link_from: Option<usize>,
}

impl Teach {
    /// Picks policy `i` (a click on its node or row); out of range changes nothing. In
    /// `M` mode a second click on another policy joins the two (weight
    /// [`MOUSE_EDGE_WEIGHT`]) or cuts their edge, and a second click on the same one lets
    /// it go.
    pub fn pick(&mut self, i: usize) {
        if i >= self.net.len() {
            return;
        }
        match self.editing.link_from.take() {
            Some(from) if self.editing.linking && from != i => {
                let edit = if self.net.graph().weight(from, i).is_some() {
                    GraphEdit::Cut { i: from, j: i }
                } else {
                    GraphEdit::Add {
                        i: from,
                        j: i,
                        w: MOUSE_EDGE_WEIGHT,
                    }
                };
                self.edit_graph(edit);
                self.select_edge_to(i);
                return;
            }
            Some(_) => {
                self.notice = Some(format!("{} let go", self.names()[i]));
            }
            None if self.editing.linking => {
                self.editing.link_from = Some(i);
                self.notice = Some(format!(
                    "{} picked: click another policy to join them or cut their edge",
                    self.names()[i]
                ));
            }
            None => {}
        }
        self.cursor = i;
        self.editing.edge = 0;
    }

    /// `M`: clicks edit edges, or pick as before.
    pub fn toggle_linking(&mut self) {
        self.editing.linking = !self.editing.linking;
        self.editing.link_from = None;
        self.notice = Some(if self.editing.linking {
            "M: click a policy, then another: joined at 0.4 (5 and +/− reweigh) or their \
             edge cut; M again ends it"
                .to_string()
        } else {
            "M ended: a click picks a policy".to_string()
        });
    }

    /// Whether clicks edit edges (`M`).
    pub fn is_linking(&self) -> bool {
        self.editing.linking
    }

    /// Selects the picked policy's edge to `j`, if there is one, for `5` and `x`.
    fn select_edge_to(&mut self, j: usize) {
        if let Some(at) = self
            .net
            .graph()
            .neighbours(self.cursor)
            .position(|(k, _)| k == j)
        {
            self.editing.edge = at;
            self.editing.knob = Knob::EdgeWeight;
        }
    }

    /// `n`: adds a policy — at once where the lesson gives its edges (joined to nothing),
    /// or asking its category where categories build M.
    pub fn add_policy(&mut self) {
        if self.has_categories() {
            self.open_prompt(PromptKind::AddPolicy);
        } else {
            self.edit_graph(GraphEdit::AddPolicy {
                category: NO_CATEGORY.to_string(),
            });
        }
    }

    /// `D`: removes the picked policy and its edges.
    pub fn remove_policy(&mut self) {
        self.edit_graph(GraphEdit::RemovePolicy { i: self.cursor });
    }

    /// `C`: asks the picked policy's new category (refused where there are none).
    pub fn change_category(&mut self) {
        if self.has_categories() {
            self.open_prompt(PromptKind::SetCategory);
        } else {
            self.edit_graph(GraphEdit::SetCategory {
                i: self.cursor,
                category: NO_CATEGORY.to_string(),
            });
        }
    }

    /// What `+` and `−` change.
    pub fn knob(&self) -> Knob {
        self.editing.knob
    }

    /// `1`…`5`: chooses what `+` and `−` change.
    pub fn choose_knob(&mut self, knob: Knob) {
        self.editing.knob = knob;
    }

    /// The edge a weight edit changes: the picked policy's `e`-th, as `(picked, other)`.
    pub fn selected_edge(&self) -> Option<(usize, usize)> {
        let degree = self.net.graph().degree(self.cursor);
        (degree > 0).then(|| {
            let (j, _) = self
                .net
                .graph()
                .neighbours(self.cursor)
                .nth(self.editing.edge % degree)
                .expect("within the degree");
            (self.cursor, j)
        })
    }

    /// `e`: selects the picked policy's next edge (and chooses the weight knob).
    pub fn next_edge(&mut self) {
        let degree = self.net.graph().degree(self.cursor);
        if degree > 0 {
            self.editing.edge = (self.editing.edge + 1) % degree;
        }
        self.editing.knob = Knob::EdgeWeight;
    }

    /// The last edit and what it changed, until the next one.
    pub fn last_edit(&self) -> Option<&EditReport> {
        self.editing.last.as_ref()
    }

    /// `+` / `−`: turns the chosen knob one step. The walk on screen restarts from the
    /// activations it started from, and [`last_edit`](Self::last_edit) compares its end
    /// before and after. A value the net refuses changes nothing and is said.
    pub fn edit(&mut self, up: bool) {
        self.playback.stop();
        self.notice = None;
        let (policy, before) = self.walk_start();
        let mut start = self.net.clone();
        start
            .set_activations(before.clone())
            .expect("activations of the same graph");
        let knob = self.editing.knob;
        let edge = self.selected_edge();
        let from = knob.value(&start, edge);
        let turned = match knob.turn(&start, edge, up) {
            Ok(net) => net,
            Err(refused) => {
                // In the screen's names: the net's message numbers the policies from 0.
                let names = self.names();
                let (what, why) = match (knob, edge) {
                    (Knob::EdgeWeight, Some((i, j))) => (
                        format!("M({},{})", names[i], names[j]),
                        refusal(&refused, names),
                    ),
                    (Knob::EdgeWeight, None) => (
                        "M".to_string(),
                        format!("{} has no edge to change", names[self.cursor]),
                    ),
                    (knob, _) => (knob.symbol().to_string(), refusal(&refused, names)),
                };
                self.notice = Some(format!("{what} stays {from}: {why}"));
                return;
            }
        };
        let (old_a, old_p, old_calls) = walk_end(&start, policy, &before);
        let (new_a, new_p, new_calls) = walk_end(&turned, policy, &before);
        self.editing.last = Some(EditReport {
            knob,
            edge: edge.filter(|_| knob == Knob::EdgeWeight),
            to: knob.value(&turned, edge),
            from,
            policy,
            calls: (old_calls, new_calls),
            activations: (old_a, new_a),
            probabilities: (old_p, new_p),
        });
        self.net = turned;
        if knob == Knob::EdgeWeight && self.has_categories() {
            // M is now set by hand, not by the categories: the lesson gives its edges.
            self.source.descriptions.clear();
            self.notice = Some(
                "M set by hand: the lesson now gives its graph by its edges, not by categories"
                    .to_string(),
            );
        }
        if let Some(policy) = policy {
            self.restart_walk(policy, before);
        }
    }

    /// `x`: cuts the picked policy's selected edge (`e` selects it).
    pub fn cut_selected_edge(&mut self) {
        self.playback.stop_running();
        match self.selected_edge() {
            Some((i, j)) => self.edit_graph(GraphEdit::Cut { i, j }),
            None => self.notice = Some(format!("{} has no edge to cut", self.names()[self.cursor])),
        }
    }

    /// Edits the graph or its policies as `sapnet teach --add-edge`, `--cut-edge`,
    /// `--add-policy`, `--remove-policy` and `--set-category` do (the same checks, the
    /// same refusals), then builds the net the lesson file would: a refusal changes
    /// nothing and is said. The walk on screen restarts from the activations it started
    /// from (a new policy's 0, a removed one's dropped), as a knob's turn restarts it.
    pub fn edit_graph(&mut self, edit: GraphEdit) {
        self.playback.stop();
        self.notice = None;
        let (policy, before) = self.walk_start();
        let mut lesson = self.lesson_file();
        // The walk restarts on the edited graph: no position to check against it.
        lesson.walk = None;
        let built = match lesson.apply(&edit).and_then(|()| lesson.lesson()) {
            Ok(built) => built,
            Err(why) => {
                self.notice = Some(format!("{}: {why}", edit.flag()));
                return;
            }
        };
        let old_calls = walk_end(&self.net, policy, &before).2;
        let moved = policy.and_then(|p| edit.renumbered(p));
        // The built net holds the lesson's `initial`: the walk's starting activations,
        // renumbered.
        let before = built.net.activations().to_vec();
        let new_calls = walk_end(&built.net, moved, &before).2;
        let count_changed = built.net.len() != self.net.len();
        self.net = built.net;
        self.source = lesson;
        self.names.renamed(built.names);
        self.groups = match built.groups {
            Some(groups) => Some(groups),
            None if count_changed => None,
            None => self.groups.take(),
        };
        self.renumber_policies(&edit);
        self.notice = Some(match (policy, moved) {
            (Some(_), Some(p)) => format!(
                "{} done: {}'s walk {old_calls} → {new_calls} calls, restarted",
                edit.flag(),
                self.names()[p]
            ),
            (Some(_), None) => format!(
                "{} done: the walk's own policy is gone, so is its walk",
                edit.flag()
            ),
            (None, _) => format!("{} done", edit.flag()),
        });
        match moved {
            Some(policy) => self.restart_walk(policy, before),
            None => {
                self.walk = None;
                self.set_activations(before);
            }
        }
    }

    /// What is kept per policy follows an edit that adds or removes one: the lesson's
    /// starting activations, the live run's exclusions, the cursor (onto a new policy).
    fn renumber_policies(&mut self, edit: &GraphEdit) {
        self.initial = edit.renumber(&self.initial, 0.0);
        if !self.excluded.is_empty() {
            self.excluded = edit.renumber(&self.excluded, false);
        }
        self.cursor = edit
            .renumbered(self.cursor)
            .unwrap_or(self.cursor)
            .min(self.net.len() - 1);
        if matches!(edit, GraphEdit::AddPolicy { .. }) {
            self.cursor = self.net.len() - 1;
        }
        self.editing.edge = 0;
    }

    /// The walk on screen's policy and the activations it started from; without a walk,
    /// the activations as they stand.
    fn walk_start(&self) -> (Option<usize>, Vec<f64>) {
        match &self.walk {
            Some(w) => (Some(w.policy()), w.before().to_vec()),
            None => (None, self.net.activations().to_vec()),
        }
    }
}
