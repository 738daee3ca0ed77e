//! Candidates by category (the paper's section IV: "calculate selection candidates of
//! policies by using categories, or exclude policies presumed to be unnecessary"): a
//! category of eq. 5's first prototype whose members keep being judged negative is left
//! out of eq. 6's draw for a while.
//!
//! The rule: each category counts the negative judgments of its members since its last
//! positive one. When the count reaches `after`, the category is excluded for `steps`
//! learning steps (its members' probabilities are 0; eq. 6 renormalises over the others)
//! and its count starts again from 0. A category is never excluded when it would leave no
//! candidate: the last category standing stays. Activations are left as they are, so an
//! excluded category comes back with what it had.

use serde::{Deserialize, Serialize};

/// `SapNetWith(exclusion: Some(after: 50, steps: 2000))`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Exclusion {
    /// Negative judgments of a category's members in a row (no positive between) that
    /// exclude it; ≥ 1.
    pub after: u32,
    /// Learning steps it then stays excluded; ≥ 1.
    pub steps: u64,
}

impl Exclusion {
    /// The ranges serde cannot check; `field` is where the knob sits in the config.
    pub fn validate(&self, field: &str) -> Result<(), String> {
        if self.after == 0 {
            return Err(format!(
                "field `{field}.after`: expected at least 1 negative judgment, got 0"
            ));
        }
        if !(1..=crate::limits::MAX_STEPS).contains(&self.steps) {
            return Err(format!(
                "field `{field}.steps`: expected 1 to {} steps, got {}",
                crate::limits::MAX_STEPS,
                self.steps
            ));
        }
        Ok(())
    }
}

/// The rule's state over one run: which category each policy is in, each category's count
/// of negatives in a row and the step its exclusion ends.
#[derive(Debug, Clone)]
pub struct Exclusions {
    rule: Exclusion,
    /// Each policy's category, numbered from 0.
    category: Vec<usize>,
    negatives: Vec<u32>,
    /// Per category, the learning step at which its exclusion ends.
    until: Vec<Option<u64>>,
    /// Per policy, whether its category is excluded: `until` seen per policy, kept because
    /// eq. 6's draw reads it at every step.
    excluded: Vec<bool>,
    /// Exclusions made so far, per category.
    made: Vec<u64>,
}

impl Exclusions {
    /// `category[i]` is policy i's category (as [`crate::sapnet::Prototype::group_indices`]
    /// numbers them).
    pub fn new(rule: Exclusion, category: Vec<usize>) -> Self {
        let categories = category.iter().max().map_or(0, |&c| c + 1);
        Self {
            rule,
            negatives: vec![0; categories],
            until: vec![None; categories],
            excluded: vec![false; category.len()],
            made: vec![0; categories],
            category,
        }
    }

    /// A judgment of policy `i` at learning step `step`.
    pub fn judged(&mut self, i: usize, positive: bool, step: u64) {
        let c = self.category[i];
        if positive {
            self.negatives[c] = 0;
            return;
        }
        self.negatives[c] = self.negatives[c].saturating_add(1);
        if self.negatives[c] < self.rule.after || self.until[c].is_some() {
            return;
        }
        self.negatives[c] = 0;
        let others_stand = (0..self.until.len()).any(|k| k != c && self.until[k].is_none());
        if others_stand {
            self.until[c] = Some(step.saturating_add(self.rule.steps));
            self.made[c] += 1;
            self.mark();
        }
    }

    /// Learning step `step` began: exclusions whose time is up end.
    pub fn at_step(&mut self, step: u64) {
        let mut ended = false;
        for until in &mut self.until {
            if until.is_some_and(|u| step >= u) {
                *until = None;
                ended = true;
            }
        }
        if ended {
            self.mark();
        }
    }

    /// Brings `excluded` up to date with `until`.
    fn mark(&mut self) {
        for (excluded, &c) in self.excluded.iter_mut().zip(&self.category) {
            *excluded = self.until[c].is_some();
        }
    }

    /// Whether policy `i` is excluded now.
    pub fn is_excluded(&self, i: usize) -> bool {
        self.excluded[i]
    }

    /// Whether any policy is excluded now.
    pub fn any(&self) -> bool {
        self.until.iter().any(Option::is_some)
    }

    /// Per policy, whether it is excluded now.
    pub fn excluded(&self) -> &[bool] {
        &self.excluded
    }

    /// Exclusions made so far, over all categories.
    pub fn made(&self) -> u64 {
        self.made.iter().sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Policies 0 and 1 in category 0, policy 2 in category 1.
    fn two_categories(after: u32, steps: u64) -> Exclusions {
        Exclusions::new(Exclusion { after, steps }, vec![0, 0, 1])
    }

    #[test]
    fn negatives_in_a_row_of_a_category_exclude_it_for_its_steps() {
        let mut e = two_categories(3, 10);
        e.judged(0, false, 1);
        e.judged(1, false, 2);
        assert!(!e.any(), "two negatives of three");
        e.judged(0, false, 3);
        assert_eq!(e.excluded(), [true, true, false]);
        e.at_step(12);
        assert!(e.is_excluded(0), "excluded until step 13");
        e.at_step(13);
        assert!(!e.any());
        assert_eq!(e.made(), 1);
    }

    #[test]
    fn a_positive_judgment_starts_the_count_again() {
        let mut e = two_categories(2, 10);
        e.judged(0, false, 1);
        e.judged(1, true, 2);
        e.judged(0, false, 3);
        assert!(!e.any());
        // Another category's judgments do not count for this one.
        e.judged(2, false, 4);
        assert!(!e.any());
        e.judged(1, false, 5);
        assert_eq!(e.excluded(), [true, true, false]);
    }

    #[test]
    fn the_last_category_standing_is_never_excluded() {
        let mut e = two_categories(1, 100);
        e.judged(2, false, 1);
        assert_eq!(e.excluded(), [false, false, true]);
        e.judged(0, false, 2);
        assert_eq!(
            e.excluded(),
            [false, false, true],
            "category 0 is all that is left"
        );
        let mut one = Exclusions::new(Exclusion { after: 1, steps: 5 }, vec![0, 0]);
        one.judged(0, false, 1);
        assert!(
            !one.any(),
            "a library of one category has nothing to exclude"
        );
    }

    #[test]
    fn zero_is_refused_at_its_field() {
        let e = Exclusion { after: 0, steps: 5 };
        assert_eq!(
            e.validate("protocol.methods[1].SapNetWith.exclusion"),
            Err("field `protocol.methods[1].SapNetWith.exclusion.after`: expected at least 1 negative judgment, got 0".into())
        );
        assert!(Exclusion { after: 2, steps: 0 }.validate("x").is_err());
        // Issue 34, item 8: "for ever" wrapped around to the next step.
        let err = Exclusion {
            after: 1,
            steps: u64::MAX,
        }
        .validate("x")
        .unwrap_err();
        assert!(err.contains("expected 1 to 1000000000000 steps"), "{err}");
    }
}
