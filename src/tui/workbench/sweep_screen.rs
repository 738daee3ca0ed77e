//! The Sweep view's screen: the terminal taken, the folder re-read on a thread of its own,
//! keys answered, until the user quits. What it shows is [`super::sweep`]'s state drawn
//! by [`super::sweep_view`].

use std::path::Path;
use std::sync::mpsc;

use anyhow::{Context, Result};
use crossterm::event::{self as term, KeyEventKind};

use super::sweep::{comparisons, SweepBench, SweepState, ValueComparison};
use crate::tui::theme::Theme;

/// What the reading thread sends: the sweep as read, with the comparisons when its done
/// cells changed; or why the read failed.
type Read = Result<(SweepState, Option<Vec<ValueComparison>>), String>;

/// Opens the sweep folder `dir` in the Sweep view until the user quits.
pub fn run(dir: &Path) -> Result<()> {
    let sweep = SweepState::read(dir).with_context(|| format!("sapnet open {}", dir.display()))?;
    // A done cell that cannot be read is refused before the terminal is taken.
    let done = sweep.done();
    let values =
        comparisons(dir, &done).with_context(|| format!("sapnet open {}", dir.display()))?;
    let mut bench = SweepBench::new(sweep, values);
    let theme = Theme::from_env();
    let (reads_tx, reads) = mpsc::channel();
    let (_stop, stop) = mpsc::channel::<()>();
    let owned = dir.to_path_buf();
    std::thread::Builder::new()
        .name("sapnet open: reading the sweep".into())
        .spawn(move || read_on(&owned, done, &reads_tx, &stop))
        .context("starting the thread that reads the sweep")?;
    let (mut terminal, _guard) = super::super::open_terminal()?;
    let mut dirty = true;
    loop {
        for read in reads.try_iter() {
            match read {
                Ok((sweep, values)) => bench.refreshed(sweep, values),
                Err(error) => bench.read_error = Some(error),
            }
            dirty = true;
        }
        if crate::signals::received().is_some() {
            return Ok(());
        }
        if dirty {
            terminal
                .draw(|frame| super::sweep_view::draw(frame, &bench, theme))
                .context("drawing the sweep")?;
            dirty = false;
        }
        if !term::poll(super::super::FRAME).context("reading the keyboard")? {
            continue;
        }
        dirty = true;
        let term::Event::Key(key) = term::read().context("reading the keyboard")? else {
            continue;
        };
        if key.kind == KeyEventKind::Press && !bench.on_key(key) {
            return Ok(());
        }
    }
}

/// Reads the sweep every [`super::REFRESH`] until `stop` is dropped, with the comparisons
/// made again when its done cells changed.
fn read_on(
    dir: &Path,
    mut reported: Vec<usize>,
    reads: &mpsc::Sender<Read>,
    stop: &mpsc::Receiver<()>,
) {
    loop {
        match stop.recv_timeout(super::REFRESH) {
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            _ => return,
        }
        let read = SweepState::read(dir).and_then(|sweep| {
            let done = sweep.done();
            if done == reported {
                Ok((sweep, None))
            } else {
                let values = comparisons(dir, &done)?;
                reported = done;
                Ok((sweep, Some(values)))
            }
        });
        if reads.send(read.map_err(|e| format!("{e:#}"))).is_err() {
            return;
        }
    }
}
