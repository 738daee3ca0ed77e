//! The standard normal distribution, the two functions of it the rank tests and the
//! sample-size formula need: the upper tail, for a z statistic's p-value, and the
//! quantile, for the z of a level or a power.

use std::f64::consts::FRAC_1_SQRT_2;

/// The upper tail `Q(z) = P(Z > z) = ½·erfc(z/√2)`, computed from the complementary
/// error function so that it keeps its relative precision far into the tail (at z = 8,
/// `1 − Φ(z)` would round to 0 in f64). scipy's `special.ndtr(-z)` (Cephes' `ndtr`)
/// computes the same expression.
pub fn upper_tail(z: f64) -> f64 {
    0.5 * libm::erfc(z * FRAC_1_SQRT_2)
}

/// The quantile `Φ⁻¹(p)`: the z below which a standard normal falls with probability p,
/// by Wichura's algorithm AS 241 (PPND16), "The Percentage Points of the Normal
/// Distribution", Applied Statistics 37(3), 477–484 (1988): a rational function of
/// `p − ½` in the centre and of `√(−ln(min(p, 1 − p)))` in the tails, accurate to about
/// 1 part in 10¹⁶. `p = 0` and `p = 1` give −∞ and +∞.
///
/// Precondition: `0 ≤ p ≤ 1`.
pub fn quantile(p: f64) -> f64 {
    debug_assert!((0.0..=1.0).contains(&p), "a probability, not {p}");
    if p == 0.0 {
        return f64::NEG_INFINITY;
    }
    if p == 1.0 {
        return f64::INFINITY;
    }
    let q = p - 0.5;
    if q.abs() <= 0.425 {
        let r = 0.180_625 - q * q;
        return q * polynomial(&as241::CENTRAL_NUMERATOR, r)
            / polynomial(&as241::CENTRAL_DENOMINATOR, r);
    }
    // The tails, by symmetry from the smaller of p and 1 − p.
    let r = (-(p.min(1.0 - p)).ln()).sqrt();
    let z = if r <= 5.0 {
        polynomial(&as241::NEAR_TAIL_NUMERATOR, r - 1.6)
            / polynomial(&as241::NEAR_TAIL_DENOMINATOR, r - 1.6)
    } else {
        polynomial(&as241::FAR_TAIL_NUMERATOR, r - 5.0)
            / polynomial(&as241::FAR_TAIL_DENOMINATOR, r - 5.0)
    };
    if q < 0.0 {
        -z
    } else {
        z
    }
}

/// `c[0] + c[1]·x + … + c[7]·x⁷`, by Horner's rule.
fn polynomial(coefficients: &[f64; 8], x: f64) -> f64 {
    coefficients.iter().rev().fold(0.0, |sum, c| sum * x + c)
}

/// AS 241's coefficients (Wichura's A, B, C, D, E, F), lowest power first; each
/// denominator's constant term is 1.
mod as241 {
    // Printed as Wichura printed them, with more digits than an f64 holds, so that they
    // can be checked against the paper digit for digit.
    #![allow(clippy::excessive_precision)]

    pub(super) const CENTRAL_NUMERATOR: [f64; 8] = [
        3.387_132_872_796_366_608,
        1.331_416_678_917_843_774_5e2,
        1.971_590_950_306_551_442_7e3,
        1.373_169_376_550_946_112_5e4,
        4.592_195_393_154_987_145_7e4,
        6.726_577_092_700_870_085_3e4,
        3.343_057_558_358_812_810_5e4,
        2.509_080_928_730_122_672_7e3,
    ];
    pub(super) const CENTRAL_DENOMINATOR: [f64; 8] = [
        1.0,
        4.231_333_070_160_091_125_2e1,
        6.871_870_074_920_579_083e2,
        5.394_196_021_424_751_107_7e3,
        2.121_379_430_158_659_586_7e4,
        3.930_789_580_009_271_061e4,
        2.872_908_573_572_194_267_4e4,
        5.226_495_278_852_854_561e3,
    ];
    pub(super) const NEAR_TAIL_NUMERATOR: [f64; 8] = [
        1.423_437_110_749_683_577_34,
        4.630_337_846_156_545_295_9,
        5.769_497_221_460_691_405_5,
        3.647_848_324_763_204_605_04,
        1.270_458_252_452_368_382_58,
        2.417_807_251_774_506_117_7e-1,
        2.272_384_498_926_918_458_33e-2,
        7.745_450_142_783_414_076_4e-4,
    ];
    pub(super) const NEAR_TAIL_DENOMINATOR: [f64; 8] = [
        1.0,
        2.053_191_626_637_758_821_87,
        1.676_384_830_183_803_849_4,
        6.897_673_349_851_000_045_5e-1,
        1.481_039_764_274_800_745_9e-1,
        1.519_866_656_361_645_719_66e-2,
        5.475_938_084_995_344_946e-4,
        1.050_750_071_644_416_843_24e-9,
    ];
    pub(super) const FAR_TAIL_NUMERATOR: [f64; 8] = [
        6.657_904_643_501_103_777_2,
        5.463_784_911_164_114_369_9,
        1.784_826_539_917_291_335_8,
        2.965_605_718_285_048_912_3e-1,
        2.653_218_952_657_612_309_3e-2,
        1.242_660_947_388_078_438_6e-3,
        2.711_555_568_743_487_578_15e-5,
        2.010_334_399_292_288_132_65e-7,
    ];
    pub(super) const FAR_TAIL_DENOMINATOR: [f64; 8] = [
        1.0,
        5.998_322_065_558_879_376_9e-1,
        1.369_298_809_227_358_053_1e-1,
        1.487_536_129_085_061_485_25e-2,
        7.868_691_311_456_132_591e-4,
        1.846_318_317_510_054_681_8e-5,
        1.421_511_758_316_445_888_7e-7,
        2.044_263_103_389_939_785_64e-15,
    ];
}

#[cfg(test)]
mod tests {
    use super::*;

    /// |got − want| within `tolerance` of |want| (or absolutely, near 0).
    fn close(got: f64, want: f64, tolerance: f64) -> bool {
        (got - want).abs() <= tolerance * want.abs().max(1e-300)
    }

    #[test]
    fn the_quantile_is_scipys_norm_ppf() {
        // scipy 1.17.1's norm.ppf(q), from scripts/stats_reference.py: the centre
        // (|q − ½| ≤ 0.425, up to its edge at 0.075 and 0.925), the near tail and, past
        // r = √(−ln q) = 5 (q < 1.4e-11), the far tail.
        let cases = [
            (1e-300, -37.0470962993612),
            (1e-20, -9.262340089798409),
            (1e-10, -6.361340902404056),
            (1e-05, -4.264890793922825),
            (0.01, -2.3263478740408408),
            (0.025, -1.9599639845400545),
            (0.075, -1.4395314709384563),
            (0.2, -0.8416212335729142),
            (0.8, 0.8416212335729143),
            (0.925, 1.4395314709384563),
            (0.975, 1.959963984540054),
            (0.999999, 4.753424308817087),
        ];
        for (p, want) in cases {
            let got = quantile(p);
            assert!(
                close(got, want, 1e-12),
                "quantile({p}) = {got}, scipy {want}"
            );
        }
        assert_eq!(quantile(0.5), 0.0);
        assert_eq!(quantile(0.0), f64::NEG_INFINITY);
        assert_eq!(quantile(1.0), f64::INFINITY);
    }

    #[test]
    fn the_upper_tail_is_scipys_norm_sf_far_into_the_tail() {
        // scipy 1.17.1's norm.sf(z), from scripts/stats_reference.py.
        let cases = [
            (-3.0, 0.9986501019683699),
            (-0.5, 0.6914624612740131),
            (0.0, 0.5),
            (0.5, 0.3085375387259869),
            (1.0, 0.15865525393145707),
            (1.959963984540054, 0.025),
            (3.0, 0.0013498980316300933),
            (8.0, 6.22096057427174e-16),
            (20.0, 2.7536241186061556e-89),
            (37.0, 5.7255712225239266e-300),
        ];
        for (z, want) in cases {
            let got = upper_tail(z);
            assert!(
                close(got, want, 1e-12),
                "upper_tail({z}) = {got}, scipy {want}"
            );
        }
        assert_eq!(upper_tail(f64::INFINITY), 0.0);
        assert_eq!(upper_tail(f64::NEG_INFINITY), 1.0);
    }
}
