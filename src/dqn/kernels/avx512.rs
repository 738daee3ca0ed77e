//! The products with AVX-512: tiles of 12 output rows by 2 vectors of 16 columns, or 6 rows
//! by 4 vectors, every accumulator in a register (24 of the 32), one broadcast of the left
//! operand per row and step of the sum. Long sums go in steps whose slice of the right
//! operand (32 KiB) stays in L1 for every row tile: a 256-unit layer's products ran at
//! 160–170 GFLOP/s streaming it from L2, 188–198 in steps (one core, peak 219).

#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

use super::{Finish, Product, Start};

const WIDTH: usize = 16;
/// Bytes of the right operand one step of the sums reads.
const STEP_BYTES: usize = 32 * 1024;

/// # Safety
/// The CPU has AVX-512F and `p.check` has passed for `out`.
#[target_feature(enable = "avx512f")]
pub(super) unsafe fn product(p: &Product, out: &mut [f32], out_stride: usize) {
    let mut j = 0;
    while j < p.columns {
        match (p.columns - j) / WIDTH {
            4.. => {
                rows::<6, 4>(p, out, out_stride, j);
                j += 4 * WIDTH;
            }
            2 | 3 => {
                rows::<12, 2>(p, out, out_stride, j);
                j += 2 * WIDTH;
            }
            _ => {
                rows::<12, 1>(p, out, out_stride, j);
                j += WIDTH;
            }
        }
    }
}

/// A product whose chains start from a bias per column (one observation's pass,
/// [`Start::ColumnBias`]): each row's columns up to 8 vectors at once, each chain in `k`
/// order as the tiles run theirs. A function of its own, chosen by `Product::run`: a
/// branch to it in [`product`] changed how the tiles compiled (1.3% more instructions in a
/// DQN run, under callgrind).
///
/// # Safety
/// As [`product`]'s; `bias` holds `p.columns` values.
#[target_feature(enable = "avx512f")]
pub(super) unsafe fn column_bias_product(
    p: &Product,
    bias: &[f32],
    out: &mut [f32],
    out_stride: usize,
) {
    for r in 0..p.rows {
        let mut j = 0;
        while j < p.columns {
            j += match (p.columns - j) / WIDTH {
                8.. => column_chunk::<8>(p, bias, out, out_stride, r, j),
                4..=7 => column_chunk::<4>(p, bias, out, out_stride, r, j),
                2 | 3 => column_chunk::<2>(p, bias, out, out_stride, r, j),
                _ => column_chunk::<1>(p, bias, out, out_stride, r, j),
            };
        }
    }
}

/// Row `r`, columns `j..j + 16·V`, from `bias[j..]`; returns the columns done.
#[target_feature(enable = "avx512f")]
#[inline]
unsafe fn column_chunk<const V: usize>(
    p: &Product,
    bias: &[f32],
    out: &mut [f32],
    out_stride: usize,
    r: usize,
    j: usize,
) -> usize {
    let left = p.left.data.as_ptr();
    let (lr, lk) = (p.left.row_stride, p.left.column_stride);
    let mut acc: [__m512; V] =
        std::array::from_fn(|v| _mm512_loadu_ps(bias.as_ptr().add(j + v * WIDTH)));
    for k in 0..p.depth {
        let l = _mm512_set1_ps(*left.add(r * lr + k * lk));
        let x = p.right.as_ptr().add(k * p.right_stride + j);
        for (v, a) in acc.iter_mut().enumerate() {
            *a = _mm512_fmadd_ps(l, _mm512_loadu_ps(x.add(v * WIDTH)), *a);
        }
    }
    let zero = _mm512_setzero_ps();
    for (v, &a) in acc.iter().enumerate() {
        let at = r * out_stride + j + v * WIDTH;
        let value = match p.finish {
            Finish::Keep => a,
            Finish::Relu => _mm512_max_ps(a, zero),
            Finish::MaskBy(by) => {
                let keep =
                    _mm512_cmp_ps_mask::<_CMP_GT_OQ>(_mm512_loadu_ps(by.as_ptr().add(at)), zero);
                _mm512_maskz_mov_ps(keep, a)
            }
        };
        _mm512_storeu_ps(out.as_mut_ptr().add(at), value);
    }
    V * WIDTH
}

/// Every row of the columns `j..j + 16·V`, `R` rows at a time, then 6, then the rest; the
/// sums in steps of `k` short enough for their slice of `right` to stay in L1 while every
/// row tile reads it. A tile stores its partial sums and reloads them for the next steps:
/// the chain goes on in the same order, so the bits do not change.
#[target_feature(enable = "avx512f")]
unsafe fn rows<const R: usize, const V: usize>(
    p: &Product,
    out: &mut [f32],
    out_stride: usize,
    j: usize,
) {
    let step = (STEP_BYTES / (4 * WIDTH * V)).max(1);
    let mut k0 = 0;
    loop {
        let k1 = (k0 + step).min(p.depth);
        let mut r = 0;
        while r + R <= p.rows {
            tile::<R, V>(p, out, out_stride, r, j, k0, k1);
            r += R;
        }
        while r + 6 <= p.rows {
            tile::<6, V>(p, out, out_stride, r, j, k0, k1);
            r += 6;
        }
        match p.rows - r {
            0 => {}
            1 => tile::<1, V>(p, out, out_stride, r, j, k0, k1),
            2 => tile::<2, V>(p, out, out_stride, r, j, k0, k1),
            3 => tile::<3, V>(p, out, out_stride, r, j, k0, k1),
            4 => tile::<4, V>(p, out, out_stride, r, j, k0, k1),
            _ => tile::<5, V>(p, out, out_stride, r, j, k0, k1),
        }
        if k1 >= p.depth {
            break;
        }
        k0 = k1;
    }
}

/// Rows `r0..r0 + R`, columns `j..j + 16·V`.
#[target_feature(enable = "avx512f")]
#[inline]
unsafe fn tile<const R: usize, const V: usize>(
    p: &Product,
    out: &mut [f32],
    out_stride: usize,
    r0: usize,
    j: usize,
    k0: usize,
    k1: usize,
) {
    let left = p.left.data.as_ptr();
    let (lr, lk) = (p.left.row_stride, p.left.column_stride);
    let right = p.right.as_ptr().add(j);
    let mut acc = [[_mm512_setzero_ps(); V]; R];
    if k0 > 0 {
        for (r, row) in acc.iter_mut().enumerate() {
            let at = out.as_ptr().add((r0 + r) * out_stride + j);
            for (v, a) in row.iter_mut().enumerate() {
                *a = _mm512_loadu_ps(at.add(v * WIDTH));
            }
        }
    } else if let Start::Bias(bias) = p.start {
        for (r, row) in acc.iter_mut().enumerate() {
            *row = [_mm512_set1_ps(*bias.get_unchecked(r0 + r)); V];
        }
    }
    let last = k1 >= p.depth;
    for k in k0..k1 {
        let x = right.add(k * p.right_stride);
        let mut xs = [_mm512_setzero_ps(); V];
        for (v, xv) in xs.iter_mut().enumerate() {
            *xv = _mm512_loadu_ps(x.add(v * WIDTH));
        }
        for (r, row) in acc.iter_mut().enumerate() {
            let l = _mm512_set1_ps(*left.add((r0 + r) * lr + k * lk));
            for (a, &xv) in row.iter_mut().zip(&xs) {
                *a = _mm512_fmadd_ps(l, xv, *a);
            }
        }
    }
    let zero = _mm512_setzero_ps();
    for (r, row) in acc.iter().enumerate() {
        let at = (r0 + r) * out_stride + j;
        for (v, &a) in row.iter().enumerate() {
            let at = at + v * WIDTH;
            let value = match p.finish {
                _ if !last => a,
                Finish::Keep => a,
                Finish::Relu => _mm512_max_ps(a, zero),
                Finish::MaskBy(by) => {
                    let keep = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(
                        _mm512_loadu_ps(by.as_ptr().add(at)),
                        zero,
                    );
                    _mm512_maskz_mov_ps(keep, a)
                }
            };
            _mm512_storeu_ps(out.as_mut_ptr().add(at), value);
        }
    }
}
