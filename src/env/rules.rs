//! The checks of a task's physics parameters: the first rule broken, worded with the RON
//! field and the task it belongs to.

/// The first broken rule of one task's physics, located.
pub(in crate::env) struct Rules<'a> {
    field: &'a str,
    task: &'a str,
    broken: Option<String>,
}

impl<'a> Rules<'a> {
    pub(in crate::env) fn new(field: &'a str, task: &'a str) -> Self {
        Self {
            field,
            task,
            broken: None,
        }
    }

    pub(in crate::env) fn holds(&mut self, name: &str, ok: bool, expected: &str) {
        if !ok && self.broken.is_none() {
            self.broken = Some(format!(
                "field `{}.{name}` ({}): expected {expected}",
                self.field, self.task
            ));
        }
    }

    pub(in crate::env) fn finite(&mut self, name: &str, value: f64) {
        self.holds(
            name,
            value.is_finite(),
            &format!("a finite number, got {value:?}"),
        );
    }

    pub(in crate::env) fn positive(&mut self, name: &str, value: f64) {
        self.holds(
            name,
            value > 0.0 && value.is_finite(),
            &format!("a finite number > 0, got {value:?}"),
        );
    }

    pub(in crate::env) fn time_limit(&mut self, steps: u32) {
        self.holds(
            "max_episode_steps",
            steps >= 1,
            "a time limit of at least 1 step, got 0",
        );
    }

    pub(in crate::env) fn result(self) -> Result<(), String> {
        self.broken.map_or(Ok(()), Err)
    }
}
