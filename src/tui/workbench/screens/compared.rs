//! `sapnet open COMPARE`: a folder `sapnet compare` wrote, in the workbench's Comparison
//! view (the table, verdicts and sort keys a protocol's folder has, its numbers those of
//! the folder's `comparison.csv`) and Curves view (each method's runs' returns). The runs
//! are read once from what compare recorded in the folder
//! ([`crate::tui::workbench::compare_folder`]), never from the files they came from; the
//! report is made again on a thread while the screen is up. The Runs view, a run's
//! dashboard and `R` are a protocol's: runs from elsewhere have no record of their steps
//! and nothing to resume, so this screen's keys offer none of them. Nothing is written.

use std::path::Path;
use std::sync::mpsc;

use anyhow::Result;
use crossterm::event::{KeyEvent, MouseEvent};
use ratatui::layout::Rect;
use ratatui::Frame;

use super::workbench::{Host, ScreenCommand, Workbench, COMPARE_KEYS};
use crate::report::Report;
use crate::tui::background;
use crate::tui::event_loop::{self, Flow, Screen};
use crate::tui::theme::Theme;
use crate::tui::workbench::compare_folder::CompareFolder;

/// The workbench on a compare folder, and the report being made.
pub struct CompareScreen {
    pub workbench: Workbench,
    report: Option<mpsc::Receiver<Report>>,
    theme: Theme,
}

impl CompareScreen {
    /// The screen on `dir`, read (a bad file refused, naming it, before a terminal is
    /// taken), its report started.
    pub fn start(dir: &Path) -> Result<Self> {
        let mut compare = CompareFolder::read(dir)?;
        let report = background::spawn("workbench: comparing the runs", compare.report_job());
        compare.computing = true;
        Ok(Self {
            workbench: Workbench::of_compare(compare),
            report: Some(report),
            theme: Theme::from_env(),
        })
    }

    /// Waits for the report (tests, which draw once and look).
    pub fn settle(&mut self) {
        if let Some(rx) = self.report.take() {
            if let Ok(report) = rx.recv() {
                self.took(report);
            }
        }
    }

    fn took(&mut self, report: Report) {
        if let Some(compare) = &mut self.workbench.compare {
            compare.report = Some(report);
            compare.computing = false;
        }
    }

    pub fn on_key(&mut self, key: KeyEvent) -> Flow {
        match self.workbench.on_key(&key, COMPARE_KEYS) {
            Some(ScreenCommand::Quit) => Flow::Quit,
            _ => Flow::Continue,
        }
    }

    pub fn draw(&self, frame: &mut Frame, theme: Theme) {
        let dir = self
            .workbench
            .compare
            .as_ref()
            .map_or(String::new(), |c| c.dir.display().to_string());
        let host = Host {
            keys: COMPARE_KEYS,
            controls: Vec::new(),
            dir,
            state: String::new(),
            active: false,
            waiting: String::new(),
        };
        self.workbench.draw(frame, theme, &host, |_, _| {});
    }
}

impl Screen for CompareScreen {
    fn drain(&mut self) -> (bool, Flow) {
        let made = self.report.as_ref().and_then(|rx| rx.try_recv().ok());
        let Some(report) = made else {
            return (false, Flow::Continue);
        };
        self.report = None;
        self.took(report);
        (true, Flow::Continue)
    }

    fn draw(&self, frame: &mut Frame) {
        CompareScreen::draw(self, frame, self.theme);
    }

    fn on_key(&mut self, key: KeyEvent) -> Flow {
        CompareScreen::on_key(self, key)
    }

    fn on_mouse(&mut self, mouse: MouseEvent, screen: Rect) {
        self.workbench.on_mouse(mouse, screen, COMPARE_KEYS);
    }
}

/// Opens the compare folder `dir` in the workbench until the user quits.
pub fn run(dir: &Path) -> Result<()> {
    event_loop::show(&mut CompareScreen::start(dir)?)
}
