//! The line teach mode asks for — an edge to add, the file to save to, a category, an
//! exercise's ΔA, the answer to a lesson's question — and what Enter does with it. While
//! it is open every key goes to it.

use std::path::PathBuf;

use super::Teach;
use crate::teach::edit::GraphEdit;

/// A line the user types in teach mode, and what Enter does with it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Prompt {
    pub kind: PromptKind,
    pub text: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PromptKind {
    /// `E`: `I J W`, an edge of weight W between policies I and J (0-based, as
    /// `--add-edge` takes them), added or reweighted.
    AddEdge,
    /// `w`: the path the lesson is written to.
    Save,
    /// Exercise mode: the ΔA the next call deposits, or `stop` where eq. 10 stops it.
    Predict,
    /// `n` in a lesson of categories: the new policy's category.
    AddPolicy,
    /// `C`: the picked policy's new category.
    SetCategory,
    /// The lesson's `k`-th question, at a walk's end.
    Question(usize),
}

impl PromptKind {
    /// What the prompt asks, on screen.
    pub fn question(self) -> &'static str {
        match self {
            PromptKind::AddEdge => "add edge I J W (0-based, as --add-edge):",
            PromptKind::Save => "save the lesson to:",
            PromptKind::Predict => "ΔA of the next call (a number, or stop)?",
            PromptKind::AddPolicy => "category of the new policy (as --add-policy):",
            PromptKind::SetCategory => "new category of the picked policy (as --set-category):",
            PromptKind::Question(_) => "the lesson asks:",
        }
    }
}

/// The file `w` offers.
pub const LESSON_FILE: &str = "lesson.ron";

impl Teach {
    /// The line being typed, if any: while there is one every key goes to it.
    pub fn prompt(&self) -> Option<&Prompt> {
        self.prompt.as_ref()
    }

    /// What the prompt asks, on screen: a question's own text.
    pub fn prompt_question(&self) -> Option<String> {
        let prompt = self.prompt.as_ref()?;
        Some(match prompt.kind {
            PromptKind::Question(k) => self.questions.text_of(k)?,
            kind => kind.question().to_string(),
        })
    }

    /// `E`, `w`, `n`, `C`, or `s` in an exercise: starts typing the line `kind` asks for,
    /// with what is likely offered (`lesson.ron`, the picked policy's category).
    pub fn open_prompt(&mut self, kind: PromptKind) {
        self.playback.stop_running();
        self.notice = None;
        let text = match kind {
            PromptKind::AddEdge | PromptKind::Predict | PromptKind::Question(_) => String::new(),
            PromptKind::Save => LESSON_FILE.to_string(),
            PromptKind::AddPolicy | PromptKind::SetCategory => {
                self.category_of(self.cursor).unwrap_or_default()
            }
        };
        self.prompt = Some(Prompt { kind, text });
    }

    /// A character typed into the prompt.
    pub fn prompt_type(&mut self, c: char) {
        if let Some(prompt) = &mut self.prompt {
            prompt.text.push(c);
        }
    }

    /// Backspace in the prompt.
    pub fn prompt_backspace(&mut self) {
        if let Some(prompt) = &mut self.prompt {
            prompt.text.pop();
        }
    }

    /// Esc in the prompt: nothing is done.
    pub fn prompt_cancel(&mut self) {
        if let Some(PromptKind::Question(k)) = self.prompt.take().map(|p| p.kind) {
            self.skip_question(k);
        }
    }

    /// Enter in the prompt: adds the edge, writes the lesson, checks the answer; what went
    /// wrong (a value not read, an edit the lesson or the net refuses, a file not written)
    /// is said and changes nothing.
    pub fn prompt_submit(&mut self) {
        let Some(prompt) = self.prompt.take() else {
            return;
        };
        match prompt.kind {
            PromptKind::AddEdge => {
                let values: Vec<String> =
                    prompt.text.split_whitespace().map(str::to_string).collect();
                match GraphEdit::parse("--add-edge", &values) {
                    Ok(edit) => self.edit_graph(edit),
                    Err(why) => {
                        self.notice = Some(format!("no edge added: {why}"));
                    }
                }
            }
            PromptKind::Predict => self.check_prediction(&prompt.text),
            PromptKind::Question(k) => self.check_question(k, &prompt.text),
            PromptKind::AddPolicy => self.edit_graph(GraphEdit::AddPolicy {
                category: prompt.text.trim().to_string(),
            }),
            PromptKind::SetCategory => self.edit_graph(GraphEdit::SetCategory {
                i: self.cursor,
                category: prompt.text.trim().to_string(),
            }),
            PromptKind::Save => self.save_lesson(&PathBuf::from(prompt.text.trim())),
        }
    }
}
