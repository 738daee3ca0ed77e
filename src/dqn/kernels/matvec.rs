//! A layer on one observation, read from its weights as they are stored (`W[r][k]`,
//! row-major): the acting step of a network that learns, whose weights change between two
//! steps, so that no transposed copy of them can be kept (a frozen source keeps one,
//! `dqn/frozen.rs`).
//!
//! The batch products run a batch across a vector's lanes; one observation would leave 15
//! of 16 lanes idle. Here the lanes run across the layer's units: eight rows of `W` are
//! loaded four inputs at a time, rows `i` and `i + 4` into the two halves of a register,
//! and transposed in registers (four unpacks and four shuffles within the halves), so
//! that each lane's chain is one unit's. Every unit is the chain the batch products compute, from its bias over `k`
//! in order,
//!
//! ```text
//! acc ← bias[r];  for k = 0, 1, …, depth − 1:  acc ← fma(W[r][k], x[k], acc)
//! ```
//!
//! then the same ReLU, so the result is the batch pass's to the bit on every path
//! (`tests`). Two groups of eight rows are summed together, their chains independent, so
//! that the chains' latencies overlap (three or four groups ran no faster: the registers
//! spill).

use super::Isa;

/// `out[r] = finish(bias[r] + Σ_k weights[r·depth + k]·input[k])` for `r < rows`, the sum
/// in `k` order, `finish` ReLU (`max(x, 0)`, `+0` for `−0` and NaN) or nothing.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MatVec<'a> {
    pub rows: usize,
    pub depth: usize,
    /// `rows × depth`, row-major.
    pub weights: &'a [f32],
    pub bias: &'a [f32],
    pub input: &'a [f32],
    pub relu: bool,
}

impl MatVec<'_> {
    /// Runs the layer on `isa` into `out[..rows]`. The vector paths (AVX-512 and AVX2) both
    /// run the AVX2 kernel: the same bits, and on AVX-512 a 16-lane transpose would take as
    /// many shuffles per value.
    ///
    /// # Panics
    /// If a slice is too short for the shapes.
    pub(crate) fn run(&self, isa: Isa, out: &mut [f32]) {
        let (rows, depth) = (self.rows, self.depth);
        assert!(
            Some(self.weights.len()) >= rows.checked_mul(depth)
                && self.bias.len() >= rows
                && self.input.len() >= depth
                && out.len() >= rows,
            "matrix-vector operands too short"
        );
        if rows == 0 {
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if isa != Isa::Portable && Isa::Avx2.supported() {
            // SAFETY: the CPU has AVX2 and FMA; the assert above bounds every access.
            unsafe { avx2::run(self, out) };
            return;
        }
        let _ = isa;
        self.portable(out);
    }

    /// The reference: one chain per row, `mul_add` rounding once as an FMA does.
    fn portable(&self, out: &mut [f32]) {
        let rows = self.weights.chunks_exact(self.depth.max(1)).take(self.rows);
        for ((o, row), &b) in out.iter_mut().zip(rows).zip(self.bias) {
            let mut acc = b;
            if self.depth > 0 {
                for (&w, &x) in row.iter().zip(self.input) {
                    acc = w.mul_add(x, acc);
                }
            }
            *o = if !self.relu || acc > 0.0 { acc } else { 0.0 };
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use super::MatVec;

    const WIDTH: usize = 8;
    /// Inputs per step, and the distance between the two rows a lane pair holds.
    const QUARTER: usize = 4;
    /// Groups of eight rows summed together.
    const GROUPS: usize = 2;

    /// # Safety
    /// The CPU has AVX2 and FMA; `m`'s slices hold `rows × depth` weights, `rows` biases,
    /// `depth` inputs, and `out` `rows` values.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn run(m: &MatVec, out: &mut [f32]) {
        let mut r = 0;
        while r + GROUPS * WIDTH <= m.rows {
            groups::<GROUPS>(m, out, r);
            r += GROUPS * WIDTH;
        }
        match (m.rows - r).div_ceil(WIDTH) {
            0 => {}
            1 => groups::<1>(m, out, r),
            _ => groups::<2>(m, out, r),
        }
    }

    /// Rows `r0..r0 + 8·G` (those past `rows` read the last row again, and are not
    /// stored).
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    unsafe fn groups<const G: usize>(m: &MatVec, out: &mut [f32], r0: usize) {
        let last = m.rows - 1;
        let row = |g: usize, i: usize| (r0 + g * WIDTH + i).min(last);
        let weights = m.weights.as_ptr();
        let rows: [[*const f32; WIDTH]; G] =
            std::array::from_fn(|g| std::array::from_fn(|i| weights.add(row(g, i) * m.depth)));
        let mut acc: [__m256; G] = std::array::from_fn(|g| {
            let bias: [f32; WIDTH] = std::array::from_fn(|i| *m.bias.get_unchecked(row(g, i)));
            _mm256_loadu_ps(bias.as_ptr())
        });
        let x = m.input.as_ptr();
        let mut k = 0;
        while k < m.depth {
            let count = (m.depth - k).min(QUARTER);
            // The last inputs, fewer than four, are loaded under a mask: nothing past a row
            // is read.
            let lanes: [i32; QUARTER] = std::array::from_fn(|i| if i < count { -1 } else { 0 });
            let mask = _mm_loadu_si128(lanes.as_ptr().cast());
            let load = |at: *const f32| {
                if count == QUARTER {
                    _mm_loadu_ps(at)
                } else {
                    _mm_maskload_ps(at, mask)
                }
            };
            for (g, a) in acc.iter_mut().enumerate() {
                // Rows i and i + 4 side by side, four inputs each: the loads put each row
                // in its lane, so that the in-lane shuffles alone transpose them.
                let pair = |i: usize| {
                    _mm256_insertf128_ps::<1>(
                        _mm256_castps128_ps256(load(rows[g][i].add(k))),
                        load(rows[g][i + QUARTER].add(k)),
                    )
                };
                let columns = transpose([pair(0), pair(1), pair(2), pair(3)]);
                for (kk, column) in columns.iter().take(count).enumerate() {
                    *a = _mm256_fmadd_ps(*column, _mm256_set1_ps(*x.add(k + kk)), *a);
                }
            }
            k += count;
        }
        let zero = _mm256_setzero_ps();
        for (g, &a) in acc.iter().enumerate() {
            let value = if m.relu { _mm256_max_ps(a, zero) } else { a };
            let start = r0 + g * WIDTH;
            if start + WIDTH <= m.rows {
                _mm256_storeu_ps(out.as_mut_ptr().add(start), value);
            } else {
                let mut kept = [0f32; WIDTH];
                _mm256_storeu_ps(kept.as_mut_ptr(), value);
                let count = m.rows.saturating_sub(start);
                out[start..start + count].copy_from_slice(&kept[..count]);
            }
        }
    }

    /// In each 128-bit lane, four rows of four values to their four columns: column `kk`
    /// holds input `kk` of rows 0–3 in its low lane and of rows 4–7 in its high lane.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    unsafe fn transpose(r: [__m256; 4]) -> [__m256; 4] {
        let t = [
            _mm256_unpacklo_ps(r[0], r[1]),
            _mm256_unpackhi_ps(r[0], r[1]),
            _mm256_unpacklo_ps(r[2], r[3]),
            _mm256_unpackhi_ps(r[2], r[3]),
        ];
        [
            _mm256_shuffle_ps::<0x44>(t[0], t[2]),
            _mm256_shuffle_ps::<0xEE>(t[0], t[2]),
            _mm256_shuffle_ps::<0x44>(t[1], t[3]),
            _mm256_shuffle_ps::<0xEE>(t[1], t[3]),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Finish, Product, Start, Strided, LANES};
    use super::*;
    use proptest::prelude::*;
    use rand::{rngs::StdRng, Rng, SeedableRng};

    /// The layer through the batch products, the observation in lane 0 of 16 (the other
    /// lanes hold other values, as a batch's would): the bits the matrix-vector kernel
    /// must give.
    fn by_the_batch_product(m: &MatVec, isa: Isa, rng: &mut StdRng) -> Vec<f32> {
        let mut right = vec![0f32; m.depth * LANES];
        for (k, row) in right.chunks_exact_mut(LANES).enumerate() {
            row.iter_mut()
                .for_each(|x| *x = rng.random_range(-1.0..1.0));
            row[0] = m.input[k];
        }
        let mut out = vec![f32::NAN; m.rows * LANES];
        Product {
            rows: m.rows,
            depth: m.depth,
            columns: LANES,
            left: Strided {
                data: m.weights,
                row_stride: m.depth,
                column_stride: 1,
            },
            right: &right,
            right_stride: LANES,
            start: Start::Bias(m.bias),
            finish: if m.relu { Finish::Relu } else { Finish::Keep },
        }
        .run(isa, &mut out, LANES);
        out.iter().step_by(LANES).copied().collect()
    }

    fn bits(values: &[f32]) -> Vec<u32> {
        values.iter().map(|x| x.to_bits()).collect()
    }

    /// Every path, every tail of rows and inputs, with and without ReLU, gives the batch
    /// products' bits, on random values sprinkled with −0, NaN and infinities.
    fn check(rows: usize, depth: usize, seed: u64) -> Result<(), TestCaseError> {
        let mut rng = StdRng::seed_from_u64(seed);
        let special = [-0.0f32, 0.0, f32::NAN, f32::INFINITY, 1e-40];
        let value = |rng: &mut StdRng| {
            if rng.random_range(0..40) == 0 {
                special[rng.random_range(0..special.len())]
            } else {
                rng.random_range(-2.0f32..2.0)
            }
        };
        let weights: Vec<f32> = (0..rows * depth).map(|_| value(&mut rng)).collect();
        let bias: Vec<f32> = (0..rows).map(|_| value(&mut rng)).collect();
        let input: Vec<f32> = (0..depth).map(|_| value(&mut rng)).collect();
        for relu in [false, true] {
            let m = MatVec {
                rows,
                depth,
                weights: &weights,
                bias: &bias,
                input: &input,
                relu,
            };
            for isa in Isa::ALL.into_iter().filter(|i| i.supported()) {
                let expected = by_the_batch_product(&m, isa, &mut rng);
                let mut out = vec![7.0f32; rows + 3];
                m.run(isa, &mut out);
                prop_assert_eq!(
                    bits(&out[..rows]),
                    bits(&expected),
                    "{:?} relu {}",
                    isa,
                    relu
                );
                prop_assert_eq!(bits(&out[rows..]), bits(&[7.0; 3]), "past the rows");
            }
        }
        Ok(())
    }

    #[test]
    fn the_library_s_shapes_give_the_batch_products_bits() {
        for (rows, depth) in [
            (100, 4),
            (2, 100),
            (64, 4),
            (114, 64),
            (149, 114),
            (2, 149),
            (256, 256),
            (1, 1),
            (33, 17),
            (31, 9),
            (8, 8),
        ] {
            check(rows, depth, (rows * 1000 + depth) as u64).unwrap();
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn any_shape_gives_the_batch_products_bits(
            rows in 1usize..80,
            depth in 1usize..50,
            seed in any::<u64>(),
        ) {
            check(rows, depth, seed)?;
        }
    }
}
