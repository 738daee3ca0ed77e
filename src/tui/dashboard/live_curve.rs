//! A live learning curve: each episode's return and its moving average, one point per
//! episode, thinned by half whenever it passes [`CURVE_POINTS`] so memory stays bounded
//! over any run.

use std::collections::VecDeque;

/// Points kept per curve; beyond it every other point is dropped and the stride doubles.
pub const CURVE_POINTS: usize = 4096;

/// Episodes averaged by the reward chart's moving average (the paper's 10).
const WINDOW: usize = 10;

/// One learning curve: episode returns, their moving average, thinned as it grows.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LiveCurve {
    /// `(episode, return)` of the kept episodes.
    pub returns: Vec<(f64, f64)>,
    /// `(episode, MA10)`.
    pub average: Vec<(f64, f64)>,
    window: VecDeque<f64>,
    stride: u32,
    seen: u32,
}

impl LiveCurve {
    pub(super) fn push(&mut self, episode: u32, reward: f64) {
        self.window.push_back(reward);
        if self.window.len() > WINDOW {
            self.window.pop_front();
        }
        self.seen += 1;
        if self.stride == 0 {
            self.stride = 1;
        }
        if !self.seen.is_multiple_of(self.stride) {
            return;
        }
        let mean = self.window.iter().sum::<f64>() / self.window.len() as f64;
        self.returns.push((f64::from(episode), reward));
        self.average.push((f64::from(episode), mean));
        if self.returns.len() > CURVE_POINTS {
            thin(&mut self.returns);
            thin(&mut self.average);
            self.stride *= 2;
        }
    }

    /// The latest moving average.
    pub fn last_average(&self) -> Option<f64> {
        (!self.window.is_empty())
            .then(|| self.window.iter().sum::<f64>() / self.window.len() as f64)
    }
}

fn thin(points: &mut Vec<(f64, f64)>) {
    let mut i = 0;
    points.retain(|_| {
        i += 1;
        i % 2 == 0
    });
}
