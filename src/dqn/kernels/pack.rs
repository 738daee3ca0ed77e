//! A layer's live units found, and a weight matrix's live columns copied side by side
//! (`dqn/live_units.rs`): with AVX-512's tests and compress where the CPU has them, one
//! value at a time elsewhere. Neither rounds anything, so every path gives the same result.

use super::Isa;

/// A value's bits with its exponent field's carry: bit 31 is set iff the exponent is all
/// ones (an infinity or a NaN). Integer `and` and `add` only.
#[inline(always)]
fn non_finite_bit(x: f32) -> u32 {
    (x.to_bits() & 0x7f80_0000).wrapping_add(0x0080_0000)
}

/// The rows of `units` rows of ReLU outputs (`columns` apart) that are not `+0` in each of
/// their first `batch` values, pushed to `live` and set in `masks` (bit `u % 16` of
/// `masks[u / 16]`); returns the ORed [`non_finite_bit`]s of those values.
///
/// # Panics
/// If `activations` or `masks` is too short for the shapes.
pub(crate) fn live_rows(
    isa: Isa,
    activations: &[f32],
    units: usize,
    columns: usize,
    batch: usize,
    live: &mut Vec<u32>,
    masks: &mut [u16],
) -> u32 {
    if units == 0 {
        return 0;
    }
    assert!(batch <= columns && activations.len() >= (units - 1) * columns + batch);
    assert!(masks.len() * 16 >= units);
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 && isa.supported() {
        // SAFETY: the CPU has AVX-512F; the asserts bound every read.
        return unsafe { live_rows_avx512(activations, units, columns, batch, live, masks) };
    }
    let _ = isa;
    let mut flags = 0;
    for (unit, row) in activations.chunks(columns).take(units).enumerate() {
        let bits = row[..batch].iter().fold(0, |bits, &x| {
            flags |= non_finite_bit(x);
            bits | x.to_bits()
        });
        if bits != 0 {
            live.push(unit as u32);
            masks[unit / 16] |= 1 << (unit % 16);
        }
    }
    flags
}

/// [`live_rows`] a vector of 16 values at a time: ORed, tested once a row; the flags kept
/// in a vector, reduced once. (The compiler's vectorisation of the plain loop spent a
/// fifth of a comparison's time here.)
///
/// # Safety
/// The CPU has AVX-512F; `activations` holds `units` rows of `batch` values, `columns`
/// apart; `masks` covers `units`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn live_rows_avx512(
    activations: &[f32],
    units: usize,
    columns: usize,
    batch: usize,
    live: &mut Vec<u32>,
    masks: &mut [u16],
) -> u32 {
    use std::arch::x86_64::*;
    let (whole, tail) = (batch / 16, (1u32 << (batch % 16)) as u16 - 1);
    let exponent = _mm512_set1_epi32(0x7f80_0000);
    let carry = _mm512_set1_epi32(0x0080_0000);
    let mut flags = _mm512_setzero_si512();
    for unit in 0..units {
        let row = activations.as_ptr().add(unit * columns).cast::<i32>();
        let mut bits = _mm512_setzero_si512();
        let mut take = |x: __m512i| {
            bits = _mm512_or_si512(bits, x);
            let flag = _mm512_add_epi32(_mm512_and_si512(x, exponent), carry);
            flags = _mm512_or_si512(flags, flag);
        };
        for c in 0..whole {
            take(_mm512_loadu_si512(row.add(16 * c).cast()));
        }
        if tail != 0 {
            take(_mm512_maskz_loadu_epi32(tail, row.add(16 * whole)));
        }
        if _mm512_test_epi32_mask(bits, bits) != 0 {
            live.push(unit as u32);
            *masks.get_unchecked_mut(unit / 16) |= 1 << (unit % 16);
        }
    }
    _mm512_reduce_or_epi32(flags) as u32
}

/// Values past the packed ones that [`pack_columns`] may overwrite.
pub(crate) const SLACK: usize = 16;

/// The columns a pass keeps, as a list and as one 16-bit mask per 16 columns (bit `b` of
/// `masks[c]` for column `16c + b`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Columns<'a> {
    pub list: &'a [u32],
    pub masks: &'a [u16],
}

impl Columns<'_> {
    /// The masks have as many bits as the list has columns (the vector paths count on it).
    fn check_masks(&self) {
        let bits: usize = self.masks.iter().map(|m| m.count_ones() as usize).sum();
        assert!(bits == self.list.len(), "the masks hold the list");
    }
}

/// `dst[r·n + i] = src[r·stride + columns.list[i]]` for the first `rows` rows, `n` the
/// columns kept. The [`SLACK`] values after them may be overwritten.
///
/// # Panics
/// If a slice is too short for the shapes and the slack, or the masks do not cover the
/// list.
pub(crate) fn pack_columns(
    isa: Isa,
    src: &[f32],
    stride: usize,
    rows: usize,
    columns: Columns,
    dst: &mut [f32],
) {
    let width = columns.list.len();
    let Some(&last) = columns.list.last() else {
        return;
    };
    if rows == 0 {
        return;
    }
    assert!(dst.len() >= rows * width + SLACK && (last as usize) < stride);
    assert!(src.len() > (rows - 1) * stride + last as usize);
    assert!(columns.masks.len() * 16 > last as usize);
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 && isa.supported() {
        columns.check_masks();
        // SAFETY: the CPU has AVX-512F; the asserts bound every lane a mask selects.
        unsafe { compress(src, stride, rows, columns.masks, width, dst) };
        return;
    }
    let _ = isa;
    for (to, from) in dst
        .chunks_exact_mut(width)
        .zip(src.chunks(stride))
        .take(rows)
    {
        for (t, &c) in to.iter_mut().zip(columns.list) {
            *t = from[c as usize];
        }
    }
}

/// Each row's 16-column chunks loaded under their mask (masked-off lanes are not read, and
/// AVX-512 suppresses their faults), compressed to the front of a register and stored
/// whole: the next chunk's store overwrites the lanes past the kept ones (a masked store
/// took a quarter of the time here), the last of all spills into the slack.
///
/// # Safety
/// The CPU has AVX-512F; every column the masks select is below `stride` and inside `src`
/// for each of the `rows` rows; `dst` holds `rows × width + SLACK` values, `width` the
/// masks' bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,popcnt")]
unsafe fn compress(
    src: &[f32],
    stride: usize,
    rows: usize,
    masks: &[u16],
    width: usize,
    dst: &mut [f32],
) {
    use std::arch::x86_64::*;
    for r in 0..rows {
        let from = src.as_ptr().add(r * stride);
        let mut to = dst.as_mut_ptr().add(r * width);
        for (c, &mask) in masks.iter().enumerate() {
            if mask == 0 {
                continue;
            }
            let values = _mm512_maskz_loadu_ps(mask, from.add(16 * c));
            _mm512_storeu_ps(to, _mm512_maskz_compress_ps(mask, values));
            to = to.add(mask.count_ones() as usize);
        }
    }
}

/// The inverse of [`pack_columns`] for one row: `dst[columns.list[i]] = packed[i]`, every
/// other value of `dst`'s first `16 × masks.len()` set to `+0`.
///
/// # Panics
/// If `packed` holds fewer values than the list, or `dst` fewer than the masks cover.
pub(crate) fn spread_columns(isa: Isa, packed: &[f32], columns: Columns, dst: &mut [f32]) {
    let covered = 16 * columns.masks.len();
    assert!(packed.len() >= columns.list.len() && dst.len() >= covered);
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 && isa.supported() {
        columns.check_masks();
        // SAFETY: the CPU has AVX-512F; the asserts bound every read and write.
        unsafe { expand(packed, columns.masks, dst) };
        return;
    }
    let _ = isa;
    dst[..covered].fill(0.0);
    for (&value, &c) in packed.iter().zip(columns.list) {
        dst[c as usize] = value;
    }
}

/// Each 16-column chunk of `dst` from the next values of `packed`, as many as its mask has
/// bits, loaded under a mask (no read past them) and expanded to the mask's lanes.
///
/// # Safety
/// The CPU has AVX-512F; `packed` holds the masks' bits in values, `dst` 16 a mask.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,popcnt")]
unsafe fn expand(packed: &[f32], masks: &[u16], dst: &mut [f32]) {
    use std::arch::x86_64::*;
    let mut from = packed.as_ptr();
    for (c, &mask) in masks.iter().enumerate() {
        let kept = mask.count_ones();
        let front = (u32::MAX.checked_shr(32 - kept).unwrap_or(0)) as u16;
        let values = _mm512_maskz_loadu_ps(front, from);
        _mm512_storeu_ps(
            dst.as_mut_ptr().add(16 * c),
            _mm512_maskz_expand_ps(mask, values),
        );
        from = from.add(kept as usize);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_path_finds_the_same_live_rows_and_flags() {
        // 40 units, a batch of 21 in 32 columns; unit u live if u % 3 == 0, and one NaN.
        let (units, columns, batch) = (40, 32, 21);
        let mut activations = vec![0.0f32; units * columns];
        for u in (0..units).step_by(3) {
            activations[u * columns + (u % batch)] = 0.5;
        }
        activations[5 * columns + 30] = 2.0; // padding: unit 5 stays dead
        let expected: Vec<u32> = (0..units as u32).step_by(3).collect();
        for nan in [false, true] {
            if nan {
                activations[7 * columns + 20] = f32::NAN;
            }
            for isa in Isa::ALL.into_iter().filter(|i| i.supported()) {
                let (mut live, mut masks) = (Vec::new(), vec![0u16; 3]);
                let flags = live_rows(
                    isa,
                    &activations,
                    units,
                    columns,
                    batch,
                    &mut live,
                    &mut masks,
                );
                let mut expected = expected.clone();
                if nan {
                    expected.insert(3, 7);
                }
                assert_eq!(live, expected, "{isa:?}");
                for u in 0..units {
                    let set = masks[u / 16] & (1 << (u % 16)) != 0;
                    assert_eq!(set, live.contains(&(u as u32)), "{isa:?} unit {u}");
                }
                assert_eq!(flags & 0x8000_0000 != 0, nan, "{isa:?}");
            }
        }
    }

    /// Lists of columns out of 37 (chunk edges, one, all, none) with their masks.
    fn column_lists() -> Vec<(Vec<u32>, Vec<u16>)> {
        let lists = [
            vec![0u32, 3, 15, 16, 17, 31, 36],
            vec![36],
            (0..37).collect(),
            vec![],
        ];
        lists
            .into_iter()
            .map(|list| {
                let mut masks = vec![0u16; 3];
                for &c in &list {
                    masks[c as usize / 16] |= 1 << (c % 16);
                }
                (list, masks)
            })
            .collect()
    }

    #[test]
    fn every_path_spreads_packed_values_back_to_their_columns() {
        for (list, masks) in column_lists() {
            let columns = Columns {
                list: &list,
                masks: &masks,
            };
            let packed: Vec<f32> = (1..=list.len()).map(|x| x as f32).collect();
            for isa in Isa::ALL.into_iter().filter(|i| i.supported()) {
                let mut dst = vec![-1.0f32; 49];
                spread_columns(isa, &packed, columns, &mut dst);
                for (c, &value) in dst[..48].iter().enumerate() {
                    let want = list.iter().position(|&l| l as usize == c);
                    assert_eq!(value, want.map_or(0.0, |i| packed[i]), "{isa:?} column {c}");
                }
                assert_eq!(dst[48], -1.0, "{isa:?}: nothing past the masks");
            }
        }
    }

    #[test]
    fn every_path_packs_the_listed_columns() {
        let (rows, stride) = (5, 37);
        let src: Vec<f32> = (0..rows * stride).map(|x| x as f32).collect();
        for (list, masks) in column_lists() {
            let columns = Columns {
                list: &list,
                masks: &masks,
            };
            for isa in Isa::ALL.into_iter().filter(|i| i.supported()) {
                let mut dst = vec![-1.0f32; rows * list.len() + SLACK];
                pack_columns(isa, &src, stride, rows, columns, &mut dst);
                for r in 0..rows {
                    for (i, &c) in list.iter().enumerate() {
                        assert_eq!(dst[r * list.len() + i], src[r * stride + c as usize]);
                    }
                }
            }
        }
    }
}
