//! The products with AVX2 and FMA: tiles of up to 6 output rows by 2 vectors of 8 columns,
//! twelve accumulators in the sixteen registers.

#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

use super::{Finish, Product, Start, Transpose};

const WIDTH: usize = 8;
const ROWS: usize = 6;

/// # Safety
/// The CPU has AVX2 and FMA and `p.check` has passed for `out` (so the columns are a
/// multiple of 16, two vectors).
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn product(p: &Product, out: &mut [f32], out_stride: usize) {
    for j in (0..p.columns).step_by(2 * WIDTH) {
        let mut r = 0;
        while r + ROWS <= p.rows {
            tile::<ROWS>(p, out, out_stride, r, j);
            r += ROWS;
        }
        match p.rows - r {
            0 => {}
            1 => tile::<1>(p, out, out_stride, r, j),
            2 => tile::<2>(p, out, out_stride, r, j),
            3 => tile::<3>(p, out, out_stride, r, j),
            4 => tile::<4>(p, out, out_stride, r, j),
            _ => tile::<5>(p, out, out_stride, r, j),
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
#[target_feature(enable = "avx2,fma")]
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

/// Row `r`, columns `j..j + 8·V`, from `bias[j..]`; returns the columns done.
#[target_feature(enable = "avx2,fma")]
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
    let mut acc: [__m256; V] =
        std::array::from_fn(|v| _mm256_loadu_ps(bias.as_ptr().add(j + v * WIDTH)));
    for k in 0..p.depth {
        let l = _mm256_set1_ps(*left.add(r * lr + k * lk));
        let x = p.right.as_ptr().add(k * p.right_stride + j);
        for (v, a) in acc.iter_mut().enumerate() {
            *a = _mm256_fmadd_ps(l, _mm256_loadu_ps(x.add(v * WIDTH)), *a);
        }
    }
    let zero = _mm256_setzero_ps();
    for (v, &a) in acc.iter().enumerate() {
        let at = r * out_stride + j + v * WIDTH;
        let value = match p.finish {
            Finish::Keep => a,
            Finish::Relu => _mm256_max_ps(a, zero),
            Finish::MaskBy(by) => {
                let by = _mm256_loadu_ps(by.as_ptr().add(at));
                _mm256_and_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(by, zero), a)
            }
        };
        _mm256_storeu_ps(out.as_mut_ptr().add(at), value);
    }
    V * WIDTH
}

/// Rows `r0..r0 + R`, columns `j..j + 16`.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn tile<const R: usize>(
    p: &Product,
    out: &mut [f32],
    out_stride: usize,
    r0: usize,
    j: usize,
) {
    let left = p.left.data.as_ptr();
    let (lr, lk) = (p.left.row_stride, p.left.column_stride);
    let right = p.right.as_ptr().add(j);
    let mut acc = [[_mm256_setzero_ps(); 2]; R];
    if let Start::Bias(bias) = p.start {
        for (r, row) in acc.iter_mut().enumerate() {
            *row = [_mm256_set1_ps(*bias.get_unchecked(r0 + r)); 2];
        }
    }
    for k in 0..p.depth {
        let x = right.add(k * p.right_stride);
        let xs = [_mm256_loadu_ps(x), _mm256_loadu_ps(x.add(WIDTH))];
        for (r, row) in acc.iter_mut().enumerate() {
            let l = _mm256_set1_ps(*left.add((r0 + r) * lr + k * lk));
            for (a, &xv) in row.iter_mut().zip(&xs) {
                *a = _mm256_fmadd_ps(l, xv, *a);
            }
        }
    }
    let zero = _mm256_setzero_ps();
    for (r, row) in acc.iter().enumerate() {
        let at = (r0 + r) * out_stride + j;
        for (v, &a) in row.iter().enumerate() {
            let at = at + v * WIDTH;
            let value = match p.finish {
                Finish::Keep => a,
                Finish::Relu => _mm256_max_ps(a, zero),
                Finish::MaskBy(by) => {
                    let by = _mm256_loadu_ps(by.as_ptr().add(at));
                    _mm256_and_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(by, zero), a)
                }
            };
            _mm256_storeu_ps(out.as_mut_ptr().add(at), value);
        }
    }
}

/// The 8 × 8 blocks of a [`Transpose`] whose rows and columns are multiples of 8, by the
/// classic unpack, shuffle and lane-permute network.
///
/// # Safety
/// The CPU has AVX2; `t.src` and `dst` hold every block (checked by `Transpose::run`).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn transpose_blocks(t: &Transpose, dst: &mut [f32], dst_stride: usize) {
    let (rows, columns, src_stride) = (t.rows, t.columns, t.src_stride);
    let (src, dst) = (t.src.as_ptr(), dst.as_mut_ptr());
    for i in (0..rows).step_by(8) {
        for j in (0..columns).step_by(8) {
            let r: [__m256; 8] =
                std::array::from_fn(|k| _mm256_loadu_ps(src.add((i + k) * src_stride + j)));
            let t = [
                _mm256_unpacklo_ps(r[0], r[1]),
                _mm256_unpackhi_ps(r[0], r[1]),
                _mm256_unpacklo_ps(r[2], r[3]),
                _mm256_unpackhi_ps(r[2], r[3]),
                _mm256_unpacklo_ps(r[4], r[5]),
                _mm256_unpackhi_ps(r[4], r[5]),
                _mm256_unpacklo_ps(r[6], r[7]),
                _mm256_unpackhi_ps(r[6], r[7]),
            ];
            let u = [
                _mm256_shuffle_ps::<0x44>(t[0], t[2]),
                _mm256_shuffle_ps::<0xEE>(t[0], t[2]),
                _mm256_shuffle_ps::<0x44>(t[1], t[3]),
                _mm256_shuffle_ps::<0xEE>(t[1], t[3]),
                _mm256_shuffle_ps::<0x44>(t[4], t[6]),
                _mm256_shuffle_ps::<0xEE>(t[4], t[6]),
                _mm256_shuffle_ps::<0x44>(t[5], t[7]),
                _mm256_shuffle_ps::<0xEE>(t[5], t[7]),
            ];
            for k in 0..4 {
                let low = _mm256_permute2f128_ps::<0x20>(u[k], u[k + 4]);
                let high = _mm256_permute2f128_ps::<0x31>(u[k], u[k + 4]);
                _mm256_storeu_ps(dst.add((j + k) * dst_stride + i), low);
                _mm256_storeu_ps(dst.add((j + k + 4) * dst_stride + i), high);
            }
        }
    }
}
