//! How the dashboard writes its figures where columns are narrow: counts, large step
//! numbers, activations, and a row of scores as a sparkline.

use crate::reuse::ScoreColumn;

/// `1234567` → `1,234,567`.
pub(super) fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// `values` as a sparkline of ▁…█ scaled to `top`; blank where a value is 0 or below.
pub(super) fn sparkline(values: impl Iterator<Item = f64>, top: f64) -> String {
    const BARS: [char; 8] = ['▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'];
    values
        .map(|v| {
            if v <= 0.0 || top <= 0.0 || !v.is_finite() {
                ' '
            } else {
                BARS[((v / top * 7.0).round() as usize).min(7)]
            }
        })
        .collect()
}

/// A count in at most five characters, so that a long run's tallies fit their column:
/// 9999, then 10k … 9999k, then 10M ….
pub(super) fn count(n: u64) -> String {
    match n {
        0..10_000 => n.to_string(),
        // Up to where rounding to thousands would make 10000k.
        10_000..9_999_500 => format!("{}k", (n + 500) / 1000),
        _ => format!("{}M", (n + 500_000) / 1_000_000),
    }
}

/// A score in the table's nine characters: a count (random's `acted`, GPI's `wins`…) as a
/// whole number (`47262`; `−1200` less the highest, with `d`), anything else as
/// [`format_activation`].
pub(super) fn format_score(score: ScoreColumn, a: f64) -> String {
    if score.counted {
        format!("{a:.0}").replace('-', "−")
    } else {
        format_activation(a)
    }
}

/// An activation in the table's nine characters: three decimals, or an exponent from
/// 100000 on.
pub(super) fn format_activation(a: f64) -> String {
    if a.abs() >= 1e5 {
        format!("{a:.3e}")
    } else {
        format!("{a:.3}")
    }
}

#[cfg(test)]
mod tests {
    use super::{count, format_score, sparkline};
    use crate::reuse::{a2t, gpi, qswitch, random, sapnet};

    #[test]
    fn counted_scores_have_no_decimals_and_the_others_three() {
        assert_eq!(format_score(gpi::SCORE, 47262.0), "47262");
        assert_eq!(format_score(qswitch::SCORE, 143_250.0), "143250");
        assert_eq!(format_score(random::SCORE, 0.0), "0");
        // `d`: a count less the highest.
        assert_eq!(format_score(gpi::SCORE, -1200.0), "−1200");
        assert_eq!(format_score(sapnet::SCORE, 12.34567), "12.346");
        assert_eq!(format_score(a2t::SCORE, 0.25), "0.250");
    }

    #[test]
    fn sparklines_share_one_scale() {
        assert_eq!(sparkline([0.0, 1.0, 4.0, 8.0].into_iter(), 8.0), " ▂▅█");
        assert_eq!(sparkline([3.0].into_iter(), 0.0), " ");
    }

    #[test]
    fn counts_fit_five_characters() {
        assert_eq!(count(0), "0");
        assert_eq!(count(9_999), "9999");
        assert_eq!(count(10_000), "10k");
        assert_eq!(count(143_250), "143k");
        assert_eq!(count(37_813), "38k");
        assert_eq!(count(9_999_499), "9999k");
        assert_eq!(count(9_999_500), "10M");
        assert_eq!(count(12_600_000), "13M");
    }
}
