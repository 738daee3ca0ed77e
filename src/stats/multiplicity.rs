//! Adjusting p-values for the number of comparisons a table makes: with twenty pairs
//! tested at 0.05, one would come out "significant" by chance alone.

/// Holm's step-down adjustment (S. Holm, "A Simple Sequentially Rejective Multiple Test
/// Procedure", Scandinavian Journal of Statistics 6(2), 65–70, 1979): with the m p-values
/// sorted, `p_(1) ≤ … ≤ p_(m)`,
///
/// `adjusted p_(i) = max_{j ≤ i} min(1, (m − j + 1)·p_(j))`,
///
/// returned in the input's order. A comparison whose adjusted p is below α is rejected by
/// Holm's procedure at family-wise error rate α, over every comparison in `p_values`:
/// never less powerful than Bonferroni's `m·p`, and as safe. The running maximum keeps
/// the order of the p-values (a smaller p never gets a larger adjusted p); ties get the
/// same adjusted p whatever their order. The same numbers as statsmodels'
/// `multipletests(p_values, method="holm")[1]`.
///
/// Precondition: every p-value lies in [0, 1].
pub fn holm(p_values: &[f64]) -> Vec<f64> {
    debug_assert!(
        p_values.iter().all(|p| (0.0..=1.0).contains(p)),
        "p-values in [0, 1]: {p_values:?}"
    );
    let m = p_values.len();
    let mut ascending: Vec<usize> = (0..m).collect();
    ascending.sort_by(|&a, &b| p_values[a].total_cmp(&p_values[b]));
    let mut adjusted = vec![0.0; m];
    let mut running_max: f64 = 0.0;
    for (j, &i) in ascending.iter().enumerate() {
        // j counts from 0, so the factor m − j + 1 of the formula is m − j here.
        running_max = running_max.max(((m - j) as f64 * p_values[i]).min(1.0));
        adjusted[i] = running_max;
    }
    adjusted
}

#[cfg(test)]
mod tests {
    use super::*;

    // Expected values: statsmodels 0.15.0's multipletests(p, method="holm")[1], printed
    // by scripts/stats_reference.py (which checks them against the formula too).

    #[test]
    fn holm_multiplies_the_smallest_by_m_and_keeps_the_input_order() {
        // Sorted 0.005, 0.01, 0.03, 0.04, 0.2 times 5, 4, 3, 2, 1: 0.025, 0.04, 0.09,
        // 0.08 → 0.09 (the running maximum), 0.2.
        assert_eq!(
            holm(&[0.01, 0.04, 0.03, 0.005, 0.2]),
            [0.04, 0.09, 0.09, 0.025, 0.2]
        );
    }

    #[test]
    fn ties_share_an_adjusted_p_and_none_exceeds_one() {
        // Sorted 0.001, 0.02, 0.02, 0.3, 0.5, 0.9 times 6, 5, 4, 3, 2, 1: 0.006, 0.1,
        // 0.08 → 0.1, 0.9 (as f64: 3·0.3), 1.0 (clipped), 0.9 → 1.0.
        assert_eq!(
            holm(&[0.02, 0.02, 0.5, 0.9, 0.001, 0.3]),
            [0.1, 0.1, 1.0, 1.0, 0.006, 0.8999999999999999]
        );
    }

    #[test]
    fn one_comparison_is_left_as_it_is() {
        assert_eq!(holm(&[0.03]), [0.03]);
        assert!(holm(&[]).is_empty());
    }
}
