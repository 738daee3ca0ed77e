//! Lock-in, defined once, and said the same way by the stdout table, `comparison.csv`
//! (`lock_in_median_step`, `locked_runs`) and the dashboard: the first step, after the
//! warm-up, at which one source's probability of being picked passes [`THRESHOLD`] — a
//! selection learned from the run that has collapsed onto one source.
//!
//! It means something for a method whose probabilities of picking a source are learned
//! during the run: SAP-Net (the softmax over activations) and PRQ-learning (the softmax
//! over reuse gains). It means nothing for the others, which show `-` everywhere: a rule
//! picks (UCB1's index, GPI's max over Q-functions, the Q-switch's critic), a draw of
//! fixed odds (random: 1/N each, never above 0.99; the oracle: 1 from its first step, which
//! records of older versions date at the end of the warm-up), weights that combine rather
//! than pick (A2T's attention), or no library at all (DQN from scratch, QDagger's student).
//! The trainer records a run's lock-in step only where [`measured`] says it means something.

use super::MethodKind;

/// The probability one source must pass for its method to have locked in.
pub const THRESHOLD: f64 = 0.99;

/// Whether lock-in means something for a method of this kind.
pub fn measured(kind: MethodKind) -> bool {
    kind.picks_by_probability
}

/// Over a method's finished runs, as the table's `lock-in step` column says it: the median
/// step over the runs that locked in, and how many of all did (`501 (2/2)`); `never (0/2)`;
/// `-` for a method it means nothing for.
pub fn over_runs(measured: bool, median: Option<f64>, locked: usize, runs: usize) -> String {
    match median {
        _ if !measured => "-".into(),
        Some(step) => format!("{step:.0} ({locked}/{runs})"),
        None => format!("never (0/{runs})"),
    }
}

/// One run's, as the dashboard says it while the run goes on: the step, and the source
/// (`501 (source-9)`); `not yet`; `-` for a method it means nothing for.
pub fn of_run(measured: bool, locked: Option<(&str, u64)>) -> String {
    match locked {
        _ if !measured => "-".into(),
        Some((source, step)) => format!("{step} ({source})"),
        None => "not yet".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reuse::Method;

    #[test]
    fn measured_for_the_learned_selections_only() {
        let every: Vec<Method> = [
            "SapNet",
            "SapNetWith(judgment: Episode)",
            "Random",
            "RandomPerEpisode",
            "Ucb1",
            "Prql()",
            "Gpi()",
            "QSwitch()",
            "QDagger()",
            "A2t()",
            "BestSource",
            "Dqn(hidden: [16])",
        ]
        .map(|text| crate::ron_file::ron_options().from_str(text).unwrap())
        .to_vec();
        let kinds: Vec<&str> = every
            .iter()
            .filter(|m| measured(m.kind()))
            .map(|m| m.kind().family)
            .collect();
        assert_eq!(kinds, ["SapNet", "SapNet", "Prql"]);
    }

    #[test]
    fn said_the_same_way_over_runs_and_for_one() {
        assert_eq!(over_runs(true, Some(501.0), 2, 2), "501 (2/2)");
        assert_eq!(over_runs(true, None, 0, 2), "never (0/2)");
        assert_eq!(over_runs(false, Some(501.0), 2, 2), "-");
        assert_eq!(over_runs(false, None, 0, 2), "-");
        assert_eq!(of_run(true, Some(("source-9", 501))), "501 (source-9)");
        assert_eq!(of_run(true, None), "not yet");
        assert_eq!(of_run(false, Some(("source-9", 501))), "-");
    }
}
