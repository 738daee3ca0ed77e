//! Adam's update, one source compiled once per instruction set: the compiler vectorises the
//! loop but, as Rust never fuses a multiply and an add on its own, each lane rounds as the
//! scalar loop does.

use super::Isa;

/// `fn $name(isa, args…) -> T`: `$body(args…)` compiled once for AVX-512, once for AVX2 and
/// once for the baseline, run on `isa` if the CPU has it. The body is safe Rust with no
/// reductions the compiler could reorder, so every copy computes the same bits.
macro_rules! per_isa {
    ($(#[$doc:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),*) -> $ret:ty = $body:ident) => {
        $(#[$doc])*
        $vis fn $name(isa: Isa, $($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx512f")]
            unsafe fn avx512($($arg: $ty),*) -> $ret {
                $body($($arg),*)
            }
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2,fma")]
            unsafe fn avx2($($arg: $ty),*) -> $ret {
                $body($($arg),*)
            }
            match isa {
                // SAFETY: the CPU has the features (`Isa::supported`); the body is safe.
                #[cfg(target_arch = "x86_64")]
                Isa::Avx512 if isa.supported() => unsafe { avx512($($arg),*) },
                #[cfg(target_arch = "x86_64")]
                Isa::Avx2 if isa.supported() => unsafe { avx2($($arg),*) },
                _ => $body($($arg),*),
            }
        }
    };
}

/// Chainer's Adam for one step (see `optim.rs`), with the step's bias-corrected step size
/// and the gradient's clipping factor.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AdamStep {
    pub step_size: f32,
    pub beta1: f32,
    pub beta2: f32,
    pub epsilon: f32,
    pub clip: f32,
}

/// Moments smaller than this are set to zero. A weight whose gradient stays 0 (a dead ReLU
/// unit's) has moments that shrink geometrically, by β₁ and β₂ a step, into f32's
/// subnormal range, and arithmetic on subnormals costs x86 a microcode assist each: Adam
/// ran 35× slower on them (measured, BENCHMARKS.md). Above `1e-30` every intermediate of
/// the update stays normal (the smallest normal is 1.2e-38); the step such a moment gives,
/// `α·m / (√v + ε)`, is below 1e-30·α/ε, far under any weight's last bit. A flush written
/// as a comparison rounds nothing, so every path gives the same bits (FTZ/DAZ modes would
/// not: they are x86's, and ARM's differ).
pub(crate) const MOMENT_FLOOR: f32 = 1e-30;

/// Gradients smaller than this count as zero, so that `g²` stays normal too.
pub(crate) const GRADIENT_FLOOR: f32 = 1e-18;

/// `x`, or `+0` if `|x| < floor`.
#[inline(always)]
fn flush(x: f32, floor: f32) -> f32 {
    if x.abs() < floor {
        0.0
    } else {
        x
    }
}

/// A gradient stored in rows of `columns` values that lie `stride` apart.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Rows<'a> {
    pub values: &'a [f32],
    pub columns: usize,
    pub stride: usize,
}

/// One Adam step on a parameter (`theta`, and its moments `m` and `v`, stored densely in
/// rows of `grad.columns` values).
///
/// # Panics
/// If the slices do not hold the same number of rows.
pub(crate) fn adam_rows(
    isa: Isa,
    step: &AdamStep,
    theta: &mut [f32],
    m: &mut [f32],
    v: &mut [f32],
    grad: Rows,
) {
    if grad.columns == 0 {
        return;
    }
    let rows = theta.len() / grad.columns;
    assert!(theta.len() == rows * grad.columns && m.len() == theta.len() && v.len() == theta.len());
    assert!(
        grad.stride >= grad.columns
            && grad.values.len() >= rows.saturating_sub(1) * grad.stride + grad.columns
    );
    adam(isa, step, theta, m, v, grad)
}

per_isa!(fn adam(step: &AdamStep, theta: &mut [f32], m: &mut [f32], v: &mut [f32], grad: Rows) -> () = adam_body);

/// `m ← m + (1 − β₁)(g − m)`, `v ← v + (1 − β₂)(g² − v)`, `θ ← θ − α·m / (√v + ε)`,
/// with tiny values set to zero (see [`MOMENT_FLOOR`]).
#[inline(always)]
fn adam_body(step: &AdamStep, theta: &mut [f32], m: &mut [f32], v: &mut [f32], grad: Rows) {
    let (b1, b2, columns) = (step.beta1, step.beta2, grad.columns);
    let rows = theta
        .chunks_exact_mut(columns)
        .zip(m.chunks_exact_mut(columns))
        .zip(v.chunks_exact_mut(columns))
        .zip(grad.values.chunks(grad.stride));
    for (((theta, m), v), grad) in rows {
        let values = theta.iter_mut().zip(m).zip(v).zip(&grad[..columns]);
        for (((p, m), v), &g) in values {
            let g = flush(g * step.clip, GRADIENT_FLOOR);
            *m = flush(*m + (1.0 - b1) * (g - *m), MOMENT_FLOOR);
            *v = flush(*v + (1.0 - b2) * (g * g - *v), MOMENT_FLOOR);
            *p -= step.step_size * *m / (v.sqrt() + step.epsilon);
        }
    }
}

per_isa!(
    /// `max |x|` of a gradient's rows, as bits: see `kernels::largest_magnitude_bits`.
    pub(super) fn largest_magnitude_bits(rows: Rows) -> u32 = largest_body
);

#[inline(always)]
fn largest_body(rows: Rows) -> u32 {
    rows.values
        .chunks(rows.stride.max(1))
        .map(|row| {
            row[..rows.columns]
                .iter()
                .fold(0u32, |most, x| most.max(x.to_bits() & 0x7fff_ffff))
        })
        .max()
        .unwrap_or(0)
}

per_isa!(
    /// `Σ x²` in `f64` over a gradient's rows, in eight running sums (value `n` of a row into
    /// sum `n mod 8`, the sums then added pairwise), so that the adds do not wait on each
    /// other; the order is fixed, so every path gives the same bits.
    pub(crate) fn sum_of_squares(rows: Rows) -> f64 = squares_body
);

#[inline(always)]
fn squares_body(rows: Rows) -> f64 {
    let mut total = 0.0;
    for row in rows.values.chunks(rows.stride.max(1)) {
        let row = &row[..rows.columns];
        let mut sums = [0.0f64; 8];
        let chunks = row.chunks_exact(8);
        let tail = chunks.remainder();
        for chunk in chunks {
            for (sum, &x) in sums.iter_mut().zip(chunk) {
                *sum += f64::from(x) * f64::from(x);
            }
        }
        for (sum, &x) in sums.iter_mut().zip(tail) {
            *sum += f64::from(x) * f64::from(x);
        }
        total += ((sums[0] + sums[1]) + (sums[2] + sums[3]))
            + ((sums[4] + sums[5]) + (sums[6] + sums[7]));
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{rngs::StdRng, Rng, SeedableRng};

    #[test]
    fn every_path_gives_the_same_bits() {
        let mut rng = StdRng::seed_from_u64(5);
        let (rows, columns, stride) = (7, 37, 48);
        let grad: Vec<f32> = (0..rows * stride)
            .map(|_| rng.random_range(-3.0..3.0))
            .collect();
        let start: Vec<f32> = (0..rows * columns)
            .map(|_| rng.random_range(-1.0..1.0))
            .collect();
        let step = AdamStep {
            step_size: 1e-3,
            beta1: 0.9,
            beta2: 0.999,
            epsilon: 1e-3,
            clip: 0.7,
        };
        let mut results = Vec::new();
        for isa in Isa::ALL.into_iter().filter(|i| i.supported()) {
            let (mut theta, mut m, mut v) = (start.clone(), start.clone(), start.clone());
            for value in v.iter_mut() {
                *value = value.abs();
            }
            for _ in 0..3 {
                let rows = Rows {
                    values: &grad,
                    columns,
                    stride,
                };
                adam_rows(isa, &step, &mut theta, &mut m, &mut v, rows);
            }
            let bits = |x: &[f32]| x.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
            results.push((bits(&theta), bits(&m), bits(&v)));
        }
        for other in &results[1..] {
            assert_eq!(&results[0], other);
        }
    }

    #[test]
    fn sums_of_squares_agree_with_a_plain_sum_and_between_paths() {
        let values: Vec<f32> = (0..3 * 40).map(|i| (i as f32 * 0.37).sin()).collect();
        let rows = Rows {
            values: &values,
            columns: 37,
            stride: 40,
        };
        let plain: f64 = values
            .chunks(40)
            .flat_map(|row| &row[..37])
            .map(|&x| f64::from(x).powi(2))
            .sum();
        let sums: Vec<u64> = Isa::ALL
            .into_iter()
            .filter(|i| i.supported())
            .map(|isa| sum_of_squares(isa, rows).to_bits())
            .collect();
        assert!((f64::from_bits(sums[0]) - plain).abs() < 1e-12 * plain);
        assert!(sums.iter().all(|&s| s == sums[0]));
    }
}
