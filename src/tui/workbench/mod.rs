//! The workbench: `sapnet open DIR` shows a results folder — finished, stopped, or live
//! and being written by another process — in views a key apart (`r` Runs, `c`
//! Comparison), and follows it as its runs end.
//!
//! The folder is only read: no file is written or created there and its lock is never
//! taken (the writer is found without it, [`crate::folder_lock::holder`]); its files are
//! read as a folder from elsewhere is ([`crate::results::folder_state`]). A thread looks
//! at the folder every [`REFRESH`], reads it again when its files changed
//! ([`crate::results::folder_changes`]: a finished folder is read once) and, when the set
//! of finished runs changed, makes the comparison again (a bootstrap of seconds for a large protocol), so that the keys
//! never wait for it.
//!
//! - [`state`]: what the workbench keeps and what its keys do; it draws nothing.
//! - [`view`]: the screen around the views (the folder's line, the status bar, `?`);
//!   [`runs_view`], [`comparison_view`]: a file per view; [`cells`]: what they share.
//!
//! `sapnet` without `--headless` runs a protocol in the same views, into the folder it
//! writes (read by the same thread as a folder opened), with the dashboard of one run
//! followed live:
//! - [`session`]: what it keeps and what its keys ask (stop, launch, resume, follow);
//!   [`picker`]: `L`'s configs;
//! - [`session_view`]: drawing it (the Run view, the stop question, the picker);
//! - [`live`]: its loop; [`protocol`]: the protocol's thread (headless's code, tapped);
//!   [`stderr_capture`]: stderr held aside while the screen is up.

pub mod cells;
pub mod comparison_view;
pub mod curves;
pub mod curves_view;
pub mod live;
pub mod mouse;
pub mod opened;
pub mod picker;
pub mod protocol;
pub mod recorded;
pub mod runs_view;
pub mod session;
pub mod session_view;
pub mod state;
mod stderr_capture;
pub mod sweep;
pub mod sweep_screen;
pub mod sweep_view;
pub mod view;

use std::path::Path;
use std::sync::mpsc;
use std::time::Duration;

use anyhow::{Context, Result};
use crossterm::event::{self as term, KeyEventKind};
use ratatui::layout::Rect;

use crate::report::Report;
use crate::results::folder_changes;
use crate::results::folder_state::{FolderReader, FolderState};
use state::{Action, Workbench};

use super::theme::Theme;
use super::FRAME;

/// How often the folder is read again: a run's episode is a fraction of a second, its end
/// seconds to hours; a second keeps the progress current at a few small reads a second.
pub const REFRESH: Duration = Duration::from_secs(1);

/// What the reading thread sends: the folder as read, with the report of its finished
/// runs when they changed (`Some(None)`: none finished); or why the read failed.
type Read = Result<(FolderState, Option<Option<Report>>), String>;

/// Opens `dir` in the workbench until the user quits. A folder that cannot be read is
/// refused before the terminal is taken; a read that fails later is shown, and the last
/// good one kept on screen.
pub fn run(dir: &Path) -> Result<()> {
    let mut reader = FolderReader::new(dir);
    // Looked at before the read: a change during it is seen at the next look.
    let looked = folder_changes::look(dir);
    let folder = reader
        .read()
        .with_context(|| format!("sapnet open {}", dir.display()))?;
    let computing = !folder.finished_key().is_empty();
    let mut workbench = Workbench::new(folder, None);
    workbench.computing = computing;
    let mut opened = opened::Opened::new(workbench);
    let theme = Theme::from_env();
    let (reads_tx, reads) = mpsc::channel();
    // Dropping `_stop` (however the UI ends) wakes the thread and ends it.
    let (_stop, stop) = mpsc::channel::<()>();
    std::thread::Builder::new()
        .name("sapnet open: reading".into())
        .spawn(move || read_on(reader, looked, &reads_tx, &stop))
        .context("starting the thread that reads the folder")?;
    let (mut terminal, _guard) = super::open_terminal()?;
    let mut dirty = true;
    loop {
        for read in reads.try_iter() {
            match read {
                Ok((folder, report)) => opened.workbench.refreshed(folder, report),
                Err(error) => opened.workbench.read_error = Some(error),
            }
            dirty = true;
        }
        if crate::signals::received().is_some() {
            return Ok(());
        }
        if dirty {
            terminal
                .draw(|frame| opened::draw(frame, &opened, theme))
                .context("drawing the workbench")?;
            dirty = false;
        }
        if !term::poll(FRAME).context("reading the keyboard")? {
            continue;
        }
        dirty = true;
        let event = term::read().context("reading the keyboard")?;
        if let term::Event::Mouse(mouse) = event {
            let size: Rect = terminal
                .size()
                .context("reading the terminal's size")?
                .into();
            opened.on_mouse(mouse, size);
            continue;
        }
        let term::Event::Key(key) = event else {
            continue; // a resize redraws
        };
        if key.kind == KeyEventKind::Press && opened.on_key(key) == Action::Quit {
            return Ok(());
        }
    }
}

/// Reads the folder again when its files changed ([`folder_changes`]: looked at every
/// [`REFRESH`]; `looked` is the look of the read on screen) until `stop` is dropped,
/// sending each read, with the report made again when the finished runs changed.
fn read_on(
    mut reader: FolderReader,
    mut looked: folder_changes::Look,
    reads: &mpsc::Sender<Read>,
    stop: &mpsc::Receiver<()>,
) {
    lowest_priority();
    let mut reported = None;
    let mut first = true;
    loop {
        if !first {
            match stop.recv_timeout(REFRESH) {
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                _ => return,
            }
            let look = folder_changes::look(reader.dir());
            if look == looked {
                continue;
            }
            looked = look;
        }
        first = false;
        let read = match reader.read() {
            Ok(folder) => {
                let finished = folder.finished_key();
                if reported.as_ref() == Some(&finished) {
                    Ok((folder, None))
                } else {
                    let report = (!finished.is_empty()).then(|| folder.report());
                    reported = Some(finished);
                    Ok((folder, Some(report)))
                }
            }
            Err(err) => Err(format!("{err:#}")),
        };
        if reads.send(read).is_err() {
            return;
        }
    }
}

/// Puts the calling thread at nice 19: the comparison made again as runs end (a bootstrap
/// of seconds for a large protocol) then takes what training leaves of the cores, never
/// their time (on Linux a thread has a nice value of its own). Best effort: a refusal
/// leaves the thread as it was.
fn lowest_priority() {
    // SAFETY: gettid and setpriority on this thread, no memory involved.
    unsafe {
        let tid = libc::gettid();
        libc::setpriority(libc::PRIO_PROCESS, tid as libc::id_t, 19);
    }
}
