//! How teach mode's panels write names and numbers in narrow columns: a names column's
//! width, an activation in a fixed width, a change signed.

/// The characters of the longest of `names`.
pub(super) fn name_width_of(names: &[String]) -> u16 {
    names.iter().map(|n| n.chars().count()).max().unwrap_or(0) as u16
}

/// A column for the longest of `names`, within `least..=most` characters (`least` where
/// `most` is smaller).
pub(super) fn name_width(names: &[String], least: usize, most: usize) -> u16 {
    usize::from(name_width_of(names)).min(most).max(least) as u16
}

/// `x` in at most `width` characters: six decimals as the hand computations have them
/// (0.833333), fewer as the integer part grows (1639.5420), then an exponent (2.3600e5).
pub(super) fn fit(x: f64, width: usize) -> String {
    for decimals in (1..=6).rev() {
        let text = format!("{x:.decimals$}");
        if text.chars().count() <= width {
            return text;
        }
    }
    format!("{x:.3e}")
}

/// `+0.8333`, `−0.0120`, ` 0` : a change, signed, 0 plain.
pub(super) fn signed(x: f64, decimals: usize) -> String {
    if x == 0.0 {
        "0".to_string()
    } else {
        format!("{x:+.decimals$}").replace('-', "−")
    }
}

#[cfg(test)]
mod tests {
    use super::fit;

    #[test]
    fn activations_fit_their_column() {
        assert_eq!(fit(0.833_333_3, 10), "0.833333");
        assert_eq!(fit(1639.542, 10), "1639.54200");
        assert_eq!(fit(-1639.542, 10), "-1639.5420");
        assert_eq!(fit(236_000.5, 10), "236000.500");
        assert_eq!(fit(2.36e12, 10), "2.360e12");
    }
}
