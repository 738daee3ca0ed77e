//! A run's training episodes, what its scores and curves are computed from: the type
//! sapnet's own runs and other tools' runs (`outside_runs`) are both read into, below the
//! report that compares them.

/// A run's training episodes in order, as `episodes.csv` lists them: what its scores and
/// curves are computed from.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TrainingEpisodes {
    /// Each episode's undiscounted return.
    pub returns: Vec<f64>,
    /// Each episode's length in environment steps.
    pub lengths: Vec<u32>,
}

impl TrainingEpisodes {
    /// Episodes of `returns`, each `length` steps long (a test's or a sketch's runs).
    pub fn uniform(returns: &[f64], length: u32) -> Self {
        Self {
            returns: returns.to_vec(),
            lengths: vec![length; returns.len()],
        }
    }

    pub fn push(&mut self, episode_return: f64, length: u32) {
        self.returns.push(episode_return);
        self.lengths.push(length);
    }

    pub fn len(&self) -> usize {
        self.returns.len()
    }

    pub fn is_empty(&self) -> bool {
        self.returns.is_empty()
    }

    /// The environment steps of all its episodes: where the last one ended.
    pub fn steps(&self) -> u64 {
        self.lengths.iter().map(|&l| u64::from(l)).sum()
    }

    /// The environment step each episode ended at, counted from the run's first.
    pub fn ends(&self) -> Vec<u64> {
        self.lengths
            .iter()
            .scan(0u64, |steps, &l| {
                *steps += u64::from(l);
                Some(*steps)
            })
            .collect()
    }
}
