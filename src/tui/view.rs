//! The shape of a view (gitui's `Component`, demo2's tabs): it owns its state, draws it in
//! the area the screen gives it, says what its keys do through its one table
//! ([`crate::tui::keys`]) and which of them the status bar offers now. What it cannot do
//! itself (show another view, follow a run) it hands back as an intent for its screen to
//! route; what the screen shares (the folder as last read) comes in as its model, never
//! owned by a view.
//!
//! Keys reach a view after the screen's overlays; a key its table does not list, or a
//! command that does not apply now, comes back [`Outcome::Ignored`] and the screen offers it
//! to its own table (the tabs, `?`, quitting).

use crossterm::event::{KeyEvent, MouseEvent};
use ratatui::layout::Rect;
use ratatui::Frame;

use super::keys::{self, Binding};
use super::theme::Theme;

/// What a key or a click did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome<I> {
    /// Not the view's: the screen's table may take it.
    Ignored,
    /// Done; the view changed.
    Done,
    /// Taken, and this says what it did or why it could not (shown until the next key).
    Said(String),
    /// For the screen to do.
    Intent(I),
}

pub trait View {
    /// What the view reads and does not own (the folder as last read; `()` for nothing).
    type Model: ?Sized;
    /// What its keys do.
    type Command: Copy + PartialEq + std::fmt::Debug + 'static;
    /// What it asks of its screen.
    type Intent;

    /// The view's own keys: its matcher, its part of the status bar and of `?`.
    fn keys(&self) -> &'static [Binding<Self::Command>];

    /// Does `command`; [`Outcome::Ignored`] when it does not apply now (Esc with nothing to
    /// go back from), so that the screen's table may take the key.
    fn apply(&mut self, model: &Self::Model, command: Self::Command) -> Outcome<Self::Intent>;

    fn draw(&self, model: &Self::Model, frame: &mut Frame, area: Rect, theme: Theme);

    /// Whether the status bar offers `command`'s line now (a line's first command names
    /// it); every line with bar words, unless the view says otherwise.
    fn offers(&self, _model: &Self::Model, _command: Self::Command) -> bool {
        true
    }

    /// The bar's words for `command`'s line now, when they depend on the state (pause or
    /// resume); the table's otherwise.
    fn words(&self, _model: &Self::Model, _command: Self::Command) -> Option<&'static str> {
        None
    }

    /// A mode that takes keys before the table (a line being typed, teach mode): what it
    /// did with `key`, or `None` to let the table have it.
    fn capture(&mut self, _model: &Self::Model, _key: &KeyEvent) -> Option<Outcome<Self::Intent>> {
        None
    }

    /// While a mode takes the keys, `?` lists its keys instead of the view's.
    fn mode_help(&self, _model: &Self::Model) -> Option<Vec<(&'static str, &'static str)>> {
        None
    }

    /// What `?` says after the keys: the mouse, the symbols drawn.
    fn legend(&self, _model: &Self::Model) -> Vec<(&'static str, &'static str)> {
        Vec::new()
    }

    /// A mouse event in the view's `area`.
    fn on_mouse(
        &mut self,
        _model: &Self::Model,
        _mouse: MouseEvent,
        _area: Rect,
    ) -> Outcome<Self::Intent> {
        Outcome::Ignored
    }

    /// What `key` does: the mode that takes it, else the table. Views do not override
    /// this: their table is their only matcher.
    fn on_key(&mut self, model: &Self::Model, key: &KeyEvent) -> Outcome<Self::Intent> {
        if let Some(outcome) = self.capture(model, key) {
            return outcome;
        }
        match keys::command(self.keys(), key) {
            Some(command) => self.apply(model, command),
            None => Outcome::Ignored,
        }
    }

    /// The status bar's part of this view: each line it offers now, in the table's order.
    fn bar(&self, model: &Self::Model) -> Vec<(&'static str, &'static str)> {
        self.keys()
            .iter()
            .filter_map(|b| {
                let (keys, words) = b.bar?;
                let &(_, command) = b.keys.first()?;
                self.offers(model, command)
                    .then(|| (keys, self.words(model, command).unwrap_or(words)))
            })
            .collect()
    }
}
