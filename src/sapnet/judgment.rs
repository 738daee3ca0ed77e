//! Judging a transition (paper II-F, eq. 7).

/// Whether the step that moved the selected policy's statistic loss from `e_before` (E_t)
/// to `e_after` (E_{t+1}) was a positive transition: `T_a = E_{t+1} − E_t ≤ 0`, the loss
/// did not rise. A NaN loss is judged negative.
pub fn judge(e_before: f64, e_after: f64) -> bool {
    let t_a = e_after - e_before;
    t_a <= 0.0
}

#[cfg(test)]
mod tests {
    use super::judge;

    #[test]
    fn a_loss_that_does_not_rise_is_positive() {
        assert!(judge(0.5, 0.4));
        assert!(judge(0.5, 0.5));
        assert!(!judge(0.5, 0.6));
        assert!(!judge(0.5, f64::NAN));
    }
}
