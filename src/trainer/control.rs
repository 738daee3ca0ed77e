//! How a run obeys the front end's [`Command`]s between steps.

use std::sync::mpsc::TryRecvError;
use std::time::Duration;

use super::events::{Command, StreamOptions};
use super::CommandReceiver;

/// The command channel of one run and what it has asked for so far.
pub(crate) struct Control<'a> {
    commands: &'a CommandReceiver,
    paused: bool,
    /// Steps granted by `Command::Step` while paused.
    granted: u32,
    delay: Duration,
    trace: bool,
    /// What the run streams, as it began or as `Command::Stream` changed it.
    stream: StreamOptions,
}

/// What the run does next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Next {
    Step,
    Stop,
}

impl<'a> Control<'a> {
    pub fn new(commands: &'a CommandReceiver, stream: StreamOptions) -> Self {
        Self {
            commands,
            paused: false,
            granted: 0,
            delay: Duration::ZERO,
            trace: stream.trace,
            stream,
        }
    }

    /// Called before every step: applies pending commands, waits while paused (a closed
    /// channel counts as `Stop`), and sleeps the throttle delay.
    pub fn before_step(&mut self) -> Next {
        loop {
            match self.commands.receiver.try_recv() {
                Ok(command) => {
                    if self.apply(command) == Next::Stop {
                        return Next::Stop;
                    }
                }
                Err(TryRecvError::Disconnected) => return Next::Stop,
                Err(TryRecvError::Empty) => break,
            }
        }
        while self.paused && self.granted == 0 {
            match self.commands.receiver.recv() {
                Ok(command) => {
                    if self.apply(command) == Next::Stop {
                        return Next::Stop;
                    }
                }
                Err(_) => return Next::Stop,
            }
        }
        if self.paused {
            self.granted -= 1;
        }
        if !self.delay.is_zero() {
            std::thread::sleep(self.delay);
        }
        Next::Step
    }

    fn apply(&mut self, command: Command) -> Next {
        match command {
            Command::Stop => return Next::Stop,
            Command::Pause => self.paused = true,
            Command::Resume => {
                self.paused = false;
                self.granted = 0;
            }
            Command::Step => {
                if self.paused {
                    self.granted += 1;
                }
            }
            Command::Throttle(delay) => self.delay = delay,
            Command::Trace(on) => self.trace = on,
            Command::Stream(live) => {
                self.stream = if live {
                    StreamOptions::live()
                } else {
                    StreamOptions::episodes()
                };
            }
        }
        Next::Step
    }

    /// A person is watching step by step (paused or throttled): every step deserves a
    /// snapshot.
    pub fn is_slow(&self) -> bool {
        self.paused || self.delay >= Duration::from_millis(1)
    }

    pub fn trace(&self) -> bool {
        self.trace
    }

    pub fn stream(&self) -> StreamOptions {
        self.stream
    }
}

#[cfg(test)]
mod tests {

    use super::*;

    #[test]
    fn runs_until_stopped() {
        let (tx, rx) = super::super::command_channel();
        let mut control = Control::new(&rx, StreamOptions::episodes());
        assert_eq!(control.before_step(), Next::Step);
        tx.send(Command::Stop).unwrap();
        assert_eq!(control.before_step(), Next::Stop);
    }

    #[test]
    fn a_stream_command_moves_the_live_stream() {
        let (tx, rx) = super::super::command_channel();
        let mut control = Control::new(&rx, StreamOptions::episodes());
        assert!(!control.stream().steps);
        tx.send(Command::Stream(true)).unwrap();
        assert_eq!(control.before_step(), Next::Step);
        assert_eq!(control.stream(), StreamOptions::live());
        tx.send(Command::Stream(false)).unwrap();
        assert_eq!(control.before_step(), Next::Step);
        assert_eq!(control.stream(), StreamOptions::episodes());
    }

    #[test]
    fn a_closed_channel_stops() {
        let (tx, rx) = super::super::command_channel();
        drop(tx);
        assert_eq!(
            Control::new(&rx, StreamOptions::episodes()).before_step(),
            Next::Stop
        );
    }

    #[test]
    fn paused_runs_take_only_granted_steps() {
        let (tx, rx) = super::super::command_channel();
        let mut control = Control::new(&rx, StreamOptions::episodes());
        for command in [Command::Pause, Command::Step, Command::Step] {
            tx.send(command).unwrap();
        }
        assert_eq!(control.before_step(), Next::Step);
        assert!(control.is_slow());
        assert_eq!(control.before_step(), Next::Step);
        // No grant left: the next call blocks until a command arrives.
        tx.send(Command::Resume).unwrap();
        assert_eq!(control.before_step(), Next::Step);
        assert!(!control.is_slow());
    }

    #[test]
    fn stop_ends_a_pause() {
        let (tx, rx) = super::super::command_channel();
        let mut control = Control::new(&rx, StreamOptions::episodes());
        tx.send(Command::Pause).unwrap();
        tx.send(Command::Stop).unwrap();
        assert_eq!(control.before_step(), Next::Stop);
    }

    #[test]
    fn trace_and_throttle_are_remembered() {
        let (tx, rx) = super::super::command_channel();
        let mut control = Control::new(&rx, StreamOptions::episodes());
        tx.send(Command::Trace(true)).unwrap();
        tx.send(Command::Throttle(Duration::from_millis(2)))
            .unwrap();
        assert_eq!(control.before_step(), Next::Step);
        assert!(control.trace());
        assert!(control.is_slow());
    }
}
