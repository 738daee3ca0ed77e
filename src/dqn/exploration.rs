//! ε-greedy exploration (ChainerRL's `ConstantEpsilonGreedy` and `LinearDecayEpsilonGreedy`).

use rand::Rng;

use crate::dqn::Exploration;

/// Chooses a uniformly random action with probability ε, else the greedy one.
#[derive(Debug, Clone, PartialEq)]
pub struct EpsilonGreedy {
    schedule: Exploration,
}

impl EpsilonGreedy {
    pub fn new(schedule: Exploration) -> Self {
        Self { schedule }
    }

    /// ε after `step` steps of the policy.
    pub fn epsilon(&self, step: u64) -> f64 {
        match self.schedule {
            Exploration::Constant { epsilon } => epsilon,
            Exploration::Linear { start, end, steps } => {
                if step >= steps {
                    end
                } else {
                    start + (end - start) * step as f64 / steps as f64
                }
            }
        }
    }

    /// The action at `step`. `greedy` is only called when the choice is greedy, so an
    /// exploring step costs no forward pass. The random action may equal the greedy one.
    pub fn choose<E>(
        &self,
        step: u64,
        action_count: usize,
        rng: &mut impl Rng,
        greedy: impl FnOnce() -> Result<usize, E>,
    ) -> Result<usize, E> {
        match self.explore(step, action_count, rng) {
            Some(action) => Ok(action),
            None => greedy(),
        }
    }

    /// The coin of [`choose`](Self::choose) alone: the random action when it falls on
    /// exploring at `step`, `None` when the step is greedy. The same draws as `choose`.
    pub fn explore(&self, step: u64, action_count: usize, rng: &mut impl Rng) -> Option<usize> {
        (rng.random::<f64>() < self.epsilon(step)).then(|| rng.random_range(0..action_count))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{rngs::StdRng, SeedableRng};
    use std::convert::Infallible;

    #[test]
    fn constant_epsilon_is_constant() {
        let e = EpsilonGreedy::new(Exploration::Constant { epsilon: 0.03 });
        assert_eq!(e.epsilon(0), 0.03);
        assert_eq!(e.epsilon(1_000_000), 0.03);
    }

    #[test]
    fn linear_epsilon_falls_then_stays() {
        let e = EpsilonGreedy::new(Exploration::Linear {
            start: 1.0,
            end: 0.1,
            steps: 100,
        });
        assert_eq!(e.epsilon(0), 1.0);
        assert!((e.epsilon(50) - 0.55).abs() < 1e-12);
        assert_eq!(e.epsilon(100), 0.1);
        assert_eq!(e.epsilon(10_000), 0.1);
    }

    #[test]
    fn explores_at_rate_epsilon() {
        let e = EpsilonGreedy::new(Exploration::Constant { epsilon: 0.2 });
        let mut rng = StdRng::seed_from_u64(1);
        let n = 20_000;
        let mut greedy_calls = 0;
        let mut non_greedy = 0;
        for _ in 0..n {
            let a = e
                .choose(0, 4, &mut rng, || {
                    greedy_calls += 1;
                    Ok::<_, Infallible>(0)
                })
                .unwrap();
            non_greedy += usize::from(a != 0);
        }
        // Random actions hit the greedy one a quarter of the time: 0.2 · 3/4 = 0.15.
        let explore = 1.0 - greedy_calls as f64 / n as f64;
        assert!((explore - 0.2).abs() < 0.015, "{explore}");
        assert!((non_greedy as f64 / n as f64 - 0.15).abs() < 0.015);
    }
}
