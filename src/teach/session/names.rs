//! What teach mode calls the policies: the lesson's names where they tell the policies
//! apart on the graph, else π0…; and, for names π0…, the paper's π1…πN (`p`).

use crate::teach::labels;

/// The policies' names as the screen shows them, and as the lesson gave them.
#[derive(Debug, Clone)]
pub(super) struct Names {
    /// π0… or the lesson's own names.
    shown: Vec<String>,
    /// The names the lesson gave, where they could not tell the policies apart on the
    /// graph (`1×100`, `2×100` both read `100`): the policies are then called π0…, and the
    /// activations table gives these beside.
    descriptions: Option<Vec<String>>,
    /// The names as the paper numbers policies, π1…πN, where the shown ones are π0…πN−1.
    paper: Option<Vec<String>>,
    /// Show `paper` (`p`).
    paper_numbering: bool,
}

impl Names {
    /// The names a lesson gives, as the screen will call its policies.
    pub(super) fn new(given: Vec<String>) -> Self {
        let (shown, descriptions) = match labels::distinct_labels(&given) {
            Some(_) => (given, None),
            None => (
                (0..given.len()).map(|i| format!("π{i}")).collect(),
                Some(given),
            ),
        };
        let zero_based = shown
            .iter()
            .enumerate()
            .all(|(i, name)| *name == format!("π{i}"));
        let paper = zero_based.then(|| (1..=shown.len()).map(|i| format!("π{i}")).collect());
        Self {
            shown,
            descriptions,
            paper,
            paper_numbering: false,
        }
    }

    /// The lesson's names after an edit (a policy added or removed): the numbering `p`
    /// chose stays where it still applies.
    pub(super) fn renamed(&mut self, given: Vec<String>) {
        let paper_numbering = self.paper_numbering;
        *self = Self::new(given);
        self.paper_numbering = paper_numbering && self.paper.is_some();
    }

    /// π0… as the lesson gives them, or π1… (`p`).
    pub(super) fn shown(&self) -> &[String] {
        match (&self.paper, self.paper_numbering) {
            (Some(paper), true) => paper,
            _ => &self.shown,
        }
    }

    pub(super) fn descriptions(&self) -> Option<&[String]> {
        self.descriptions.as_deref()
    }

    /// The names as the lesson gave them, for the lesson file.
    pub(super) fn given(&self) -> Vec<String> {
        self.descriptions
            .clone()
            .unwrap_or_else(|| self.shown.clone())
    }

    /// `p`: π1…πN or back to π0…; `false` when the lesson names its policies itself.
    pub(super) fn toggle_numbering(&mut self) -> bool {
        if self.paper.is_some() {
            self.paper_numbering = !self.paper_numbering;
        }
        self.paper.is_some()
    }

    /// `π0…` or `π1…`, none for names the lesson gives.
    pub(super) fn numbering(&self) -> Option<&'static str> {
        self.paper.as_ref().map(|_| {
            if self.paper_numbering {
                "π1…"
            } else {
                "π0…"
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(list: &[&str]) -> Vec<String> {
        list.iter().map(ToString::to_string).collect()
    }

    #[test]
    fn names_that_read_alike_become_indices_and_p_renumbers_them() {
        let mut table2 = Names::new(names(&["1×100", "2×100"]));
        assert_eq!(table2.shown(), ["π0", "π1"]);
        assert_eq!(table2.descriptions(), Some(&names(&["1×100", "2×100"])[..]));
        assert_eq!(table2.given(), ["1×100", "2×100"]);
        assert!(table2.toggle_numbering());
        assert_eq!(
            (table2.shown(), table2.numbering()),
            (&names(&["π1", "π2"])[..], Some("π1…"))
        );
        table2.renamed(names(&["1×100", "2×100", "π2"]));
        assert_eq!(table2.shown(), ["π1", "π2", "π3"], "p stays on");

        let mut own = Names::new(names(&["left", "right"]));
        assert!(!own.toggle_numbering());
        assert_eq!(
            (own.shown(), own.numbering()),
            (&names(&["left", "right"])[..], None)
        );
    }
}
