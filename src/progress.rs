//! Progress on stderr: on a terminal, a bar for the whole protocol and one per run in
//! progress; otherwise (logs, CI) a plain line every few seconds, so scripted runs stay
//! readable. Both count in the unit that bounds the runs (episodes, or steps under a step
//! budget) and estimate what is left from the rate of the last minute, not from the start:
//! episodes lengthen as policies learn. Bars take the terminal's width (`wide_bar`), so a
//! line fits 80 columns instead of wrapping mid-number.

use std::collections::{BTreeMap, VecDeque};
use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::trainer::EpisodeRecord;

/// Returns averaged in the progress line, as in the paper's curves.
const WINDOW: usize = 10;
const PLAIN_INTERVAL: Duration = Duration::from_secs(5);
/// How far back the rate behind the estimate of the time left looks.
const RATE_WINDOW: Duration = Duration::from_secs(60);

/// What bounds a run, and so what progress counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    Episodes,
    /// Runs with a step budget (`protocol.max_steps`).
    Steps,
}

impl Unit {
    fn name(self) -> &'static str {
        match self {
            Unit::Episodes => "episodes",
            Unit::Steps => "steps",
        }
    }

    /// How much of the plan one episode did.
    fn of(self, record: &EpisodeRecord) -> u64 {
        match self {
            Unit::Episodes => 1,
            Unit::Steps => u64::from(record.steps),
        }
    }
}

/// One run in progress.
struct RunProgress {
    bar: Option<ProgressBar>,
    planned: u64,
    done: u64,
    recent: VecDeque<f64>,
}

pub struct Progress {
    unit: Unit,
    planned: u64,
    done: u64,
    multi: Option<MultiProgress>,
    total: Option<ProgressBar>,
    runs: BTreeMap<(String, u32), RunProgress>,
    /// `(when, done)` over the last [`RATE_WINDOW`].
    samples: VecDeque<(Instant, u64)>,
    last_line: Instant,
}

impl Progress {
    /// Progress over `planned` units of work in all.
    pub fn new(planned: u64, unit: Unit) -> Self {
        let (multi, total) = if std::io::stderr().is_terminal() {
            let multi = MultiProgress::with_draw_target(ProgressDrawTarget::stderr());
            let total = multi.add(ProgressBar::new(planned));
            total.set_style(style(&format!(
                "{{prefix:>20}} [{{wide_bar}}] {{pos}}/{{len}} {}, {{elapsed}} elapsed{{msg}}",
                unit.name()
            )));
            total.set_prefix("protocol");
            (Some(multi), Some(total))
        } else {
            (None, None)
        };
        Self {
            unit,
            planned,
            done: 0,
            multi,
            total,
            runs: BTreeMap::new(),
            samples: VecDeque::new(),
            last_line: Instant::now(),
        }
    }

    /// A run of `method` started, planned to do `planned` units.
    pub fn run_started(&mut self, method: &str, run: u32, planned: u64) {
        let label = format!("{method} run {run}");
        let bar = match &self.multi {
            Some(multi) => {
                let bar = multi.add(ProgressBar::new(planned));
                bar.set_style(style(&format!(
                    "{{prefix:>20}} [{{wide_bar}}] {{pos}}/{{len}} {}, {{msg}}",
                    self.unit.name()
                )));
                bar.set_prefix(label);
                Some(bar)
            }
            None => {
                eprintln!("{label}: started");
                None
            }
        };
        self.runs.insert(
            (method.to_string(), run),
            RunProgress {
                bar,
                planned,
                done: 0,
                recent: VecDeque::with_capacity(WINDOW),
            },
        );
    }

    pub fn episode(&mut self, record: &EpisodeRecord) {
        let work = self.unit.of(record);
        self.done += work;
        let now = Instant::now();
        self.samples.push_back((now, self.done));
        while self
            .samples
            .front()
            .is_some_and(|&(t, _)| now.duration_since(t) > RATE_WINDOW)
        {
            self.samples.pop_front();
        }
        let eta = self.eta();
        let key = (record.method.label().to_string(), record.run);
        let Some(run) = self.runs.get_mut(&key) else {
            return;
        };
        run.done += work;
        if run.recent.len() == WINDOW {
            run.recent.pop_front();
        }
        run.recent.push_back(record.reward);
        let average = run.recent.iter().sum::<f64>() / run.recent.len() as f64;
        match (&run.bar, &self.total) {
            (Some(bar), Some(total)) => {
                bar.set_message(format!(
                    "return {:.0}, MA{WINDOW} {average:.1}",
                    record.reward
                ));
                bar.set_position(run.done);
                total.set_position(self.done);
                total.set_message(eta.map_or(String::new(), |e| format!(", {} left", clock(e))));
            }
            _ if self.last_line.elapsed() >= PLAIN_INTERVAL => {
                self.last_line = Instant::now();
                eprintln!(
                    "{} run {}: {} {}/{}, return {:.0}, MA{WINDOW} {average:.1} · protocol \
                     {}/{} {} ({:.1}%){}",
                    record.method,
                    record.run,
                    singular(self.unit),
                    run.done,
                    run.planned,
                    record.reward,
                    self.done,
                    self.planned,
                    self.unit.name(),
                    100.0 * self.done as f64 / self.planned.max(1) as f64,
                    eta.map_or(String::new(), |e| format!(", {} left", clock(e)))
                );
            }
            _ => {}
        }
    }

    /// A run ended: its bar goes.
    pub fn run_finished(&mut self, method: &str, run: u32) {
        if let Some(RunProgress { bar: Some(bar), .. }) =
            self.runs.remove(&(method.to_string(), run))
        {
            bar.finish_and_clear();
            if let Some(multi) = &self.multi {
                multi.remove(&bar);
            }
        }
    }

    /// A line above the bars (or a plain line), for what the user should know at once.
    pub fn warn(&self, message: &str) {
        match &self.multi {
            Some(multi) => {
                let _ = multi.println(format!("warning: {message}"));
            }
            None => eprintln!("warning: {message}"),
        }
    }

    /// Ends the bars; `complete` false leaves the protocol's where it stopped.
    pub fn finish(&mut self, complete: bool) {
        for (_, run) in std::mem::take(&mut self.runs) {
            if let Some(bar) = run.bar {
                bar.finish_and_clear();
            }
        }
        if let Some(total) = self.total.take() {
            if complete {
                total.finish();
            } else {
                total.abandon();
            }
        }
    }

    /// The time left at the rate of the last minute, once there is a rate.
    fn eta(&self) -> Option<Duration> {
        let (&(first, from), &(last, to)) = (self.samples.front()?, self.samples.back()?);
        eta(
            to - from,
            last.duration_since(first),
            self.planned.saturating_sub(self.done),
        )
    }
}

fn style(template: &str) -> ProgressStyle {
    ProgressStyle::with_template(template)
        .expect("the template is valid")
        .progress_chars("=> ")
}

fn singular(unit: Unit) -> &'static str {
    match unit {
        Unit::Episodes => "episode",
        Unit::Steps => "step",
    }
}

/// The time `left` units take at `done` units per `elapsed`; none before a second's worth.
fn eta(done: u64, elapsed: Duration, left: u64) -> Option<Duration> {
    if done == 0 || elapsed < Duration::from_secs(1) {
        return None;
    }
    Some(elapsed.mul_f64(left as f64 / done as f64))
}

/// `1h02m`, `4m05s`, `12s`.
fn clock(d: Duration) -> String {
    let s = d.as_secs();
    match (s / 3600, s / 60 % 60, s % 60) {
        (0, 0, s) => format!("{s}s"),
        (0, m, s) => format!("{m}m{s:02}s"),
        (h, m, _) => format!("{h}h{m:02}m"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_time_left_is_the_recent_rate_over_what_is_left() {
        // 600 units in the last 60 s: 10/s, so 3,000 left take 300 s.
        assert_eq!(
            eta(600, Duration::from_secs(60), 3000),
            Some(Duration::from_secs(300))
        );
        assert_eq!(eta(0, Duration::from_secs(60), 3000), None);
        assert_eq!(eta(5, Duration::from_millis(200), 3000), None);
    }

    #[test]
    fn clocks_read_at_a_glance() {
        assert_eq!(clock(Duration::from_secs(12)), "12s");
        assert_eq!(clock(Duration::from_secs(245)), "4m05s");
        assert_eq!(clock(Duration::from_secs(3720)), "1h02m");
    }
}
