//! Progress on stderr: a bar on a terminal, a plain line every few seconds otherwise (logs,
//! CI), so scripted runs stay readable.

use std::collections::VecDeque;
use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

use crate::trainer::EpisodeRecord;

/// Returns averaged in the progress line, as in the paper's curves.
const WINDOW: usize = 10;
const PLAIN_INTERVAL: Duration = Duration::from_secs(5);

pub struct Progress {
    bar: Option<ProgressBar>,
    planned: u64,
    done: u64,
    recent: VecDeque<f64>,
    last_line: Instant,
}

impl Progress {
    pub fn new(planned_episodes: u64) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::new(planned_episodes);
            bar.set_style(
                ProgressStyle::with_template(
                    "{prefix:>14} [{bar:30}] {pos}/{len} episodes, {elapsed} (eta {eta}) {msg}",
                )
                .expect("the template is valid")
                .progress_chars("=> "),
            );
            bar
        });
        Self {
            bar,
            planned: planned_episodes,
            done: 0,
            recent: VecDeque::with_capacity(WINDOW),
            last_line: Instant::now(),
        }
    }

    pub fn run_started(&mut self, method: &str, run: u32) {
        self.recent.clear();
        let prefix = format!("{method} run {}", run + 1);
        match &self.bar {
            Some(bar) => bar.set_prefix(prefix),
            None => eprintln!("{prefix}: started"),
        }
    }

    pub fn episode(&mut self, record: &EpisodeRecord) {
        self.done += 1;
        if self.recent.len() == WINDOW {
            self.recent.pop_front();
        }
        self.recent.push_back(record.reward);
        let average = self.recent.iter().sum::<f64>() / self.recent.len() as f64;
        match &self.bar {
            Some(bar) => {
                bar.set_message(format!(
                    "return {:.0}, MA{WINDOW} {average:.1}",
                    record.reward
                ));
                bar.inc(1);
            }
            None if self.last_line.elapsed() >= PLAIN_INTERVAL => {
                self.last_line = Instant::now();
                eprintln!(
                    "{} run {}: episode {} ({}/{} in all), return {:.0}, MA{WINDOW} {average:.1}",
                    record.method,
                    record.run + 1,
                    record.episode,
                    self.done,
                    self.planned,
                    record.reward
                );
            }
            None => {}
        }
    }

    /// A line above the bar (or a plain line), for what the user should know at once.
    pub fn warn(&self, message: &str) {
        match &self.bar {
            Some(bar) => bar.println(format!("warning: {message}")),
            None => eprintln!("warning: {message}"),
        }
    }

    /// Ends the bar; `complete` false leaves it where it stopped.
    pub fn finish(&mut self, complete: bool) {
        if let Some(bar) = self.bar.take() {
            if complete {
                bar.finish();
            } else {
                bar.abandon();
            }
        }
    }
}
