//! The Q-network's arithmetic, sized for DQN layers (a few hundred units, minibatches of
//! 32 or 64), in three instruction sets chosen at run time: AVX-512, AVX2 with FMA, and
//! portable Rust.
//!
//! **Same bits on every path.** Every matrix product computes each output element as one
//! chain of fused multiply-adds in a fixed order,
//!
//! ```text
//! acc ← start(r);  for k = 0, 1, …, depth − 1:  acc ← fma(left[r][k], right[k][j], acc)
//! ```
//!
//! The vector paths only run 16 or 8 of these chains at once, one per lane, across the
//! output's columns; no sum is ever split between lanes. An FMA rounds once whether the
//! hardware or `f32::mul_add` does it, so a run gives the same numbers on an AVX-512 server,
//! an AVX2 laptop and an ARM machine. The element-wise passes (Adam, the finiteness check,
//! the clipping norm) are one source compiled once per instruction set: Rust never contracts `a * b + c` into an FMA, so the vectorised
//! loops round exactly as the scalar loop does. `tests` checks the paths against each other
//! bit for bit.

mod avx2;
mod avx512;
mod buffer;
mod elementwise;
mod matvec;
mod pack;
mod portable;

use std::sync::OnceLock;

pub(crate) use buffer::Buffer;
pub(crate) use elementwise::{adam_rows, sum_of_squares, AdamStep, Rows};
pub(crate) use matvec::MatVec;
pub(crate) use pack::{live_rows, pack_columns, spread_columns, Columns, SLACK};

/// Lanes the column count of a product is padded to: one AVX-512 vector, two of AVX2.
pub(crate) const LANES: usize = 16;

/// `n` rounded up to a multiple of [`LANES`].
pub(crate) fn padded(n: usize) -> usize {
    n.div_ceil(LANES) * LANES
}

/// The instruction set the kernels run on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Isa {
    Avx512,
    Avx2,
    Portable,
}

/// What `SAPNET_KERNELS` may say.
pub const KERNELS_VARIABLE: &str = "SAPNET_KERNELS";

impl Isa {
    pub const ALL: [Isa; 3] = [Isa::Avx512, Isa::Avx2, Isa::Portable];

    pub fn name(self) -> &'static str {
        match self {
            Isa::Avx512 => "avx512",
            Isa::Avx2 => "avx2",
            Isa::Portable => "portable",
        }
    }

    /// Whether this CPU can run the path.
    pub fn supported(self) -> bool {
        match self {
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => std::arch::is_x86_feature_detected!("avx512f"),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(not(target_arch = "x86_64"))]
            Isa::Avx512 | Isa::Avx2 => false,
            Isa::Portable => true,
        }
    }

    /// The fastest path this CPU supports.
    pub fn best() -> Isa {
        Isa::ALL
            .into_iter()
            .find(|isa| isa.supported())
            .unwrap_or(Isa::Portable)
    }

    /// The path `SAPNET_KERNELS` asks for (`avx512`, `avx2` or `portable`), or the best one
    /// when it is unset. Results are the same on every path; the variable is for measuring
    /// them.
    pub fn from_env() -> Result<Isa, String> {
        let Some(value) = std::env::var_os(KERNELS_VARIABLE) else {
            return Ok(Isa::best());
        };
        let value = value.to_string_lossy();
        let isa = Isa::ALL
            .into_iter()
            .find(|isa| isa.name() == value.trim())
            .ok_or_else(|| {
                format!("{KERNELS_VARIABLE}={value:?}: expected avx512, avx2 or portable")
            })?;
        if !isa.supported() {
            return Err(format!(
                "{KERNELS_VARIABLE}={value}: this CPU cannot run the {value} kernels (it can run {})",
                Isa::best().name()
            ));
        }
        Ok(isa)
    }

    /// The path every network uses: [`Isa::from_env`], read once; an unusable value falls
    /// back to the best path (the binary reports it at start-up, see `main.rs`).
    pub fn current() -> Isa {
        static CURRENT: OnceLock<Isa> = OnceLock::new();
        *CURRENT.get_or_init(|| Isa::from_env().unwrap_or_else(|_| Isa::best()))
    }
}

/// A matrix read one scalar at a time, so any strides do:
/// `at(r, k) = data[r·row_stride + k·column_stride]`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Strided<'a> {
    pub data: &'a [f32],
    pub row_stride: usize,
    pub column_stride: usize,
}

impl Strided<'_> {
    fn at(&self, r: usize, k: usize) -> f32 {
        self.data[r * self.row_stride + k * self.column_stride]
    }
}

/// What each output chain starts from.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Start<'a> {
    Zero,
    /// `bias[r]` for every element of row `r`.
    Bias(&'a [f32]),
    /// `bias[j]` for every element of column `j`: a layer's pass over one observation laid
    /// out with the units along the columns ([`crate::dqn::FrozenNet`]).
    ColumnBias(&'a [f32]),
}

impl Start<'_> {
    fn at(&self, r: usize, j: usize) -> f32 {
        match self {
            Start::Zero => 0.0,
            Start::Bias(bias) => bias[r],
            Start::ColumnBias(bias) => bias[j],
        }
    }
}

/// What is applied to each finished sum before it is stored.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Finish<'a> {
    Keep,
    /// `max(x, 0)`, with `+0` for `−0` and NaN (x86's `max(x, 0)` operand order).
    Relu,
    /// `x` where `by[r][j] > 0`, else `+0`: ReLU's derivative read from its output, which
    /// has the output's shape and stride.
    MaskBy(&'a [f32]),
}

/// `out[r][j] = finish(start(r) + Σ_k left[r][k]·right[k][j])`, the sum in `k` order, for
/// `r < rows` and `j < columns` (a multiple of [`LANES`]). `out` has row stride
/// `out_stride`; `right[k][j] = right[k·right_stride + j]`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Product<'a> {
    pub rows: usize,
    pub depth: usize,
    pub columns: usize,
    pub left: Strided<'a>,
    pub right: &'a [f32],
    pub right_stride: usize,
    pub start: Start<'a>,
    pub finish: Finish<'a>,
}

impl Product<'_> {
    /// Runs the product on `isa` into `out`.
    ///
    /// # Panics
    /// If a slice is too short for the shapes, `columns` is not a multiple of [`LANES`], or
    /// `isa` is not [`Isa::supported`]: caller bugs the vector paths must never read past.
    pub(crate) fn run(&self, isa: Isa, out: &mut [f32], out_stride: usize) {
        self.check(out.len(), out_stride);
        if self.rows == 0 || self.columns == 0 {
            return;
        }
        match isa {
            Isa::Portable => portable::product(self, out, out_stride),
            // SAFETY: `check` bounds every access the kernels make; the CPU has the features.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => {
                assert!(isa.supported(), "AVX-512 kernels on a CPU without AVX-512");
                match self.start {
                    Start::ColumnBias(bias) => unsafe {
                        avx512::column_bias_product(self, bias, out, out_stride)
                    },
                    _ => unsafe { avx512::product(self, out, out_stride) },
                }
            }
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => {
                assert!(
                    isa.supported(),
                    "AVX2 kernels on a CPU without AVX2 and FMA"
                );
                match self.start {
                    Start::ColumnBias(bias) => unsafe {
                        avx2::column_bias_product(self, bias, out, out_stride)
                    },
                    _ => unsafe { avx2::product(self, out, out_stride) },
                }
            }
            #[cfg(not(target_arch = "x86_64"))]
            Isa::Avx512 | Isa::Avx2 => panic!("{} kernels on a non-x86 CPU", isa.name()),
        }
    }

    /// Every index the kernels touch is in bounds.
    fn check(&self, out_len: usize, out_stride: usize) {
        assert_eq!(self.columns % LANES, 0, "columns padded to {LANES}");
        if self.rows == 0 || self.columns == 0 {
            return;
        }
        let last_row = |stride: usize, rows: usize| (rows - 1) * stride + self.columns;
        assert!(out_stride >= self.columns && out_len >= last_row(out_stride, self.rows));
        if self.depth > 0 {
            assert!(self.right_stride >= self.columns);
            assert!(self.right.len() >= last_row(self.right_stride, self.depth));
            let l = self.left;
            let last = (self.rows - 1) * l.row_stride + (self.depth - 1) * l.column_stride;
            assert!(l.data.len() > last, "left operand too short");
        }
        match self.start {
            Start::Zero => {}
            Start::Bias(bias) => assert!(bias.len() >= self.rows, "one bias per row"),
            Start::ColumnBias(bias) => {
                assert!(bias.len() >= self.columns, "one bias per column")
            }
        }
        if let Finish::MaskBy(by) = self.finish {
            assert!(
                by.len() >= last_row(out_stride, self.rows),
                "mask too short"
            );
        }
    }
}

/// `rows × columns` values of `src`, rows `src_stride` apart, to be copied transposed.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Transpose<'a> {
    pub src: &'a [f32],
    pub src_stride: usize,
    pub rows: usize,
    pub columns: usize,
}

impl Transpose<'_> {
    /// `dst[j·dst_stride + i] = src[i·src_stride + j]` for `i < rows`, `j < columns`: 8 × 8
    /// blocks in AVX registers where the CPU has AVX2, the edges (and other CPUs) one value
    /// at a time. A copy rounds nothing: every path gives the same result.
    ///
    /// # Panics
    /// If a slice is too short for the shapes.
    pub(crate) fn run(&self, isa: Isa, dst: &mut [f32], dst_stride: usize) {
        let Transpose {
            src,
            src_stride,
            rows,
            columns,
        } = *self;
        if rows == 0 || columns == 0 {
            return;
        }
        assert!(src_stride >= columns && src.len() >= (rows - 1) * src_stride + columns);
        assert!(dst_stride >= rows && dst.len() >= (columns - 1) * dst_stride + rows);
        let (full_rows, full_columns) = self.blocks(isa, dst, dst_stride);
        let one_by_one =
            |dst: &mut [f32], i_range: std::ops::Range<usize>, j_range: std::ops::Range<usize>| {
                for i in i_range {
                    for j in j_range.clone() {
                        dst[j * dst_stride + i] = src[i * src_stride + j];
                    }
                }
            };
        one_by_one(dst, 0..full_rows, full_columns..columns);
        one_by_one(dst, full_rows..rows, 0..columns);
    }

    /// The whole 8 × 8 blocks on AVX2, if the path and the CPU have it: returns the rows and
    /// columns they covered.
    fn blocks(&self, isa: Isa, dst: &mut [f32], dst_stride: usize) -> (usize, usize) {
        #[cfg(target_arch = "x86_64")]
        if isa != Isa::Portable && Isa::Avx2.supported() {
            let covered = Transpose {
                rows: self.rows / 8 * 8,
                columns: self.columns / 8 * 8,
                ..*self
            };
            // SAFETY: the CPU has AVX2; `run` bounded both slices.
            unsafe { avx2::transpose_blocks(&covered, dst, dst_stride) };
            return (covered.rows, covered.columns);
        }
        let _ = (isa, dst, dst_stride);
        (0, 0)
    }
}

/// `max |x|` over every value of `rows` of a gradient, as bits (`< 0x7f80_0000` iff all are
/// finite), without an early exit so that the loop vectorises.
pub(crate) fn largest_magnitude_bits(isa: Isa, rows: Rows) -> u32 {
    elementwise::largest_magnitude_bits(isa, rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use rand::{rngs::StdRng, Rng, SeedableRng};

    fn supported() -> Vec<Isa> {
        Isa::ALL.into_iter().filter(|i| i.supported()).collect()
    }

    fn random(n: usize, rng: &mut StdRng) -> Vec<f32> {
        (0..n).map(|_| rng.random_range(-1.0f32..1.0)).collect()
    }

    /// A product of every kind on random operands, on every supported path.
    fn outputs(rows: usize, depth: usize, columns: usize, seed: u64) -> Vec<Vec<f32>> {
        let mut rng = StdRng::seed_from_u64(seed);
        let left = random(rows * depth + 3, &mut rng);
        let right = random(depth * (columns + 16) + 1, &mut rng);
        let bias = random(rows, &mut rng);
        let column_bias = random(columns, &mut rng);
        let mask = random(rows * columns, &mut rng);
        let mut results = Vec::new();
        for isa in supported() {
            let mut all = Vec::new();
            let kinds = [
                (Start::Zero, Finish::Keep, (depth, 1)),
                (Start::Bias(&bias), Finish::Relu, (depth, 1)),
                (Start::Zero, Finish::MaskBy(&mask), (1, rows)),
                (Start::ColumnBias(&column_bias), Finish::Relu, (depth, 1)),
                (Start::ColumnBias(&column_bias), Finish::Keep, (1, rows)),
            ];
            for (start, finish, (row_stride, column_stride)) in kinds {
                let mut out = vec![f32::NAN; rows * columns];
                Product {
                    rows,
                    depth,
                    columns,
                    left: Strided {
                        data: &left,
                        row_stride,
                        column_stride,
                    },
                    right: &right,
                    right_stride: columns + 16,
                    start,
                    finish,
                }
                .run(isa, &mut out, columns);
                all.extend(out);
            }
            results.push(all);
        }
        results
    }

    #[test]
    fn a_product_is_its_defining_sum() {
        // 2×2 by 2×16: left [[1, 2], [3, 4]], right rows 0.5 and −1 everywhere.
        let left = [1.0f32, 2.0, 3.0, 4.0];
        let mut right = vec![0.5f32; 16];
        right.extend([-1.0f32; 16]);
        for isa in supported() {
            let mut out = vec![0.0; 32];
            Product {
                rows: 2,
                depth: 2,
                columns: 16,
                left: Strided {
                    data: &left,
                    row_stride: 2,
                    column_stride: 1,
                },
                right: &right,
                right_stride: 16,
                start: Start::Bias(&[10.0, 0.0]),
                finish: Finish::Relu,
            }
            .run(isa, &mut out, 16);
            // Row 0: 10 + 0.5 − 2 = 8.5; row 1: 0 + 1.5 − 4 = −2.5 → ReLU 0.
            assert!(out[..16].iter().all(|&x| x == 8.5), "{isa:?}");
            assert!(out[16..].iter().all(|&x| x == 0.0), "{isa:?}");
        }
    }

    #[test]
    fn relu_and_mask_give_positive_zero() {
        let left = [1.0f32];
        let mut right = vec![-0.0f32; 16];
        right[1] = f32::NAN;
        right[2] = 2.0;
        let mut mask = vec![1.0f32; 16];
        mask[2] = -0.0;
        for isa in supported() {
            let mut relu = vec![7.0; 16];
            let mut masked = vec![7.0; 16];
            let product = Product {
                rows: 1,
                depth: 1,
                columns: 16,
                left: Strided {
                    data: &left,
                    row_stride: 1,
                    column_stride: 1,
                },
                right: &right,
                right_stride: 16,
                start: Start::Bias(&[-0.0]),
                finish: Finish::Relu,
            };
            product.run(isa, &mut relu, 16);
            Product {
                finish: Finish::MaskBy(&mask),
                ..product
            }
            .run(isa, &mut masked, 16);
            assert_eq!(relu[0].to_bits(), 0, "{isa:?}: relu(−0) is +0");
            assert_eq!(relu[1].to_bits(), 0, "{isa:?}: relu(NaN) is +0");
            assert_eq!(relu[2], 2.0);
            assert_eq!(masked[2].to_bits(), 0, "{isa:?}: masked by −0");
            assert!(masked[1].is_nan(), "{isa:?}: a kept NaN stays");
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Every path gives the portable path's bits, for any shape: row and column tails,
        /// depth 0, strided left operands.
        #[test]
        fn every_path_gives_the_same_bits(
            rows in 0usize..20,
            depth in 0usize..40,
            blocks in 0usize..9,
            seed in any::<u64>(),
        ) {
            let results = outputs(rows, depth, blocks * LANES, seed);
            let bits = |v: &Vec<f32>| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            for other in &results[1..] {
                prop_assert_eq!(bits(&results[0]), bits(other));
            }
        }
    }

    /// Sums long enough for the AVX-512 path to take them in several steps (it keeps 32 KiB
    /// of the right operand in L1: 128 steps at 64 columns, 512 at 16) still give the
    /// portable path's bits.
    #[test]
    fn long_sums_taken_in_steps_give_the_same_bits() {
        for (rows, depth, columns) in [(13, 300, 64), (7, 1100, 16), (20, 257, 96)] {
            let results = outputs(rows, depth, columns, 11);
            for other in &results[1..] {
                assert_eq!(
                    results[0].iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                    other.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                    "{rows}×{depth}×{columns}"
                );
            }
        }
    }

    #[test]
    fn transpose_swaps_rows_and_columns() {
        let src = [1.0, 2.0, 3.0, 0.0, 4.0, 5.0, 6.0, 0.0]; // 2×3, stride 4
        let mut dst = [0.0; 6];
        Transpose {
            src: &src,
            src_stride: 4,
            rows: 2,
            columns: 3,
        }
        .run(Isa::Portable, &mut dst, 2);
        assert_eq!(dst, [1.0, 4.0, 2.0, 5.0, 3.0, 6.0]);
        // Blocks and edges, on every path.
        let (rows, columns) = (19, 21);
        let src: Vec<f32> = (0..rows * 24).map(|x| x as f32).collect();
        for isa in supported() {
            let mut dst = vec![-1.0; columns * 20];
            Transpose {
                src: &src,
                src_stride: 24,
                rows,
                columns,
            }
            .run(isa, &mut dst, 20);
            for i in 0..rows {
                for j in 0..columns {
                    assert_eq!(dst[j * 20 + i], src[i * 24 + j], "{isa:?} {i} {j}");
                }
            }
        }
    }

    #[test]
    fn the_variable_picks_a_path() {
        assert_eq!(padded(1), 16);
        assert_eq!(padded(32), 32);
        assert_eq!(padded(0), 0);
        assert!(Isa::best().supported());
        assert!(Isa::current().supported());
    }
}
