//! SIGINT, SIGTERM and SIGHUP: each asks the runs to stop after their current step, so
//! that what they did is written; the process then exits with 128 + the signal's number
//! (130, 143, 129), as shells expect of an interrupted command. A terminal UI leaves at its
//! next frame; if it cannot (its terminal closed under it), the process ends a few seconds
//! later all the same.

use std::io::Write;
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::sync::mpsc::{self, Receiver};
use std::thread;
use std::time::Duration;

use anyhow::{Context, Result};
use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

use crate::trainer::Command;

/// The first signal received, 0 before any.
static RECEIVED: AtomicI32 = AtomicI32::new(0);

/// A terminal UI is on screen: it leaves on a signal at its next frame, but a terminal that
/// went away (SIGHUP when its window closes) can hold the UI in its read for ever.
static INTERACTIVE: AtomicBool = AtomicBool::new(false);

/// How long a terminal UI has to leave by itself after a signal before the process ends.
const UI_GRACE: Duration = Duration::from_secs(3);

/// Says whether a terminal UI is on screen (see [`stop_on_signals`]).
pub fn set_interactive(on: bool) {
    INTERACTIVE.store(on, Ordering::SeqCst);
}

/// Starts listening: every signal sends [`Command::Stop`] on the returned channel. The
/// listening thread keeps the sender for the life of the process.
pub fn stop_on_signals() -> Result<Receiver<Command>> {
    let (sender, commands) = mpsc::channel();
    let mut signals =
        Signals::new([SIGINT, SIGTERM, SIGHUP]).context("installing the signal handlers")?;
    thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            for signal in signals.forever() {
                if RECEIVED.swap(signal, Ordering::SeqCst) == 0 {
                    // A run waiting for a Gymnasium worker stops waiting.
                    crate::env::gymnasium::interrupt_waits();
                    // stderr may be a terminal that is gone: never panic on it.
                    let _ = writeln!(
                        std::io::stderr(),
                        "\n{}: finishing the current step",
                        name(signal)
                    );
                    if INTERACTIVE.load(Ordering::SeqCst) {
                        thread::spawn(move || {
                            thread::sleep(UI_GRACE);
                            ratatui::restore();
                            std::process::exit(i32::from(exit_code(signal)));
                        });
                    }
                }
                let _ = sender.send(Command::Stop);
            }
        })
        .context("starting the signal thread")?;
    Ok(commands)
}

/// The first signal received, if any.
pub fn received() -> Option<i32> {
    match RECEIVED.load(Ordering::SeqCst) {
        0 => None,
        signal => Some(signal),
    }
}

/// The exit code of a process that `signal` stopped: 128 + its number.
pub fn exit_code(signal: i32) -> u8 {
    u8::try_from(128 + signal).unwrap_or(u8::MAX)
}

fn name(signal: i32) -> &'static str {
    match signal {
        SIGINT => "interrupted",
        SIGTERM => "terminated (SIGTERM)",
        SIGHUP => "hung up (SIGHUP)",
        _ => "signalled",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exit_codes_follow_the_shells_convention() {
        assert_eq!(exit_code(SIGINT), 130);
        assert_eq!(exit_code(SIGTERM), 143);
        assert_eq!(exit_code(SIGHUP), 129);
    }
}
