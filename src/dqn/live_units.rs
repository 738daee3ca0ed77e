//! The hidden units a minibatch leaves dead, and the passes' arithmetic left out for them.
//!
//! A ReLU unit whose output is `+0` for every transition of a minibatch is *dead* for it. In
//! the 300-episode reuse comparison on the shipped CartPole library, 40% of the hidden units
//! were dead for the minibatch that passed through them, and 27% of the weights joined two
//! units live for it (counted over the learners' backward passes, observations and
//! Q-values counted live; BENCHMARKS.md). What a dead unit contributes, with finite weights
//! (a library refuses a policy with a non-finite weight, an update with a non-finite
//! gradient is refused, and Adam's steps are then finite):
//!
//! - **Its terms in the next layer's forward sums**, `w·(+0)`, are signed zeros: added to a
//!   sum they change it only where it is zero, and then only its sign, which the next
//!   ReLU erases (`max(±0, +0)` is `+0`, `kernels::Finish::Relu`). So a hidden layer's
//!   sums run over the live units of its input only, and give the same activations to the
//!   bit. The output layer has no ReLU after it: its sums keep every term.
//! - **Its weights' gradient** `∂Wₗ[o] = Σ_b ∂zₗ[o][b]·aₗ₋₁[b]` is a row of zeros: ReLU's mask
//!   made each `∂zₗ[o][b]` `+0`, and `+0·x` is a signed zero for finite `x`. So those rows
//!   are written as `+0`, not computed, *when every input of the pass is finite*
//!   ([`LiveUnits::scan`] checks; a pass with a non-finite activation computes everything).
//! - **Its terms in the gradient of the layer below**, `w·∂zₗ[o]`, are signed zeros too;
//!   and **its own input gradient** is masked to `+0` whatever the sum: neither is computed.
//! - **Its column of the next layer's weight gradient**, `Σ_b ∂zₗ₊₁[o][b]·(+0)`, is `+0`
//!   for finite `∂z`: written as zeros. (A non-finite `∂zₗ₊₁[o][b]` makes the bias's
//!   gradient `Σ_b ∂zₗ₊₁[o][b]` non-finite too, and the update is refused either way.)
//!
//! So the forward pass is the same to the bit, and a gradient can differ only in the sign of
//! a zero (a sum left at `−0` by an underflowing product, where the full sum would add a
//! `+0` term). Adam reads a zero gradient of either sign as `+0` (its `GRADIENT_FLOOR`
//! flush), and the finiteness check and the clipping norm cannot tell them apart: the
//! weights after each update are the same to the bit. `backprop.rs`'s tests check passes
//! that leave dead units out against passes that do not.
//!
//! The passes compute on *packed* operands, the live units' rows and columns copied side by
//! side, so that the products run on the same dense kernels: a copy moves each weight once,
//! a product over a minibatch of 32 multiplies and adds it 32 times.

use super::kernels::{self, Columns, Isa, Rows};

/// The units of one layer's activations that are not dead for the minibatch.
#[derive(Debug, Default, Clone)]
pub(crate) struct LiveUnits {
    /// The live units, in order.
    units: Vec<u32>,
    /// The same, a bit per unit in 16-unit masks (for [`kernels::pack_columns`]).
    masks: Vec<u16>,
    /// Whether any unit is dead.
    some_dead: bool,
}

impl LiveUnits {
    /// Reads `units` rows of `activations` (`columns` apart; a transition per column, the
    /// first `batch` of them the minibatch's): a unit is live unless its row is `+0` in each
    /// of those columns. Returns whether all of them are finite.
    pub(crate) fn scan(
        &mut self,
        isa: Isa,
        activations: &[f32],
        units: usize,
        columns: usize,
        batch: usize,
    ) -> bool {
        self.units.clear();
        self.masks.clear();
        self.masks.resize(units.div_ceil(16), 0);
        let (live, masks) = (&mut self.units, &mut self.masks);
        let flags = kernels::live_rows(isa, activations, units, columns, batch, live, masks);
        self.some_dead = self.units.len() < units;
        flags & 0x8000_0000 == 0
    }

    /// Every unit counted live: for a layer whose dead units are not left out.
    pub(crate) fn all(&mut self) {
        self.units.clear();
        self.masks.clear();
        self.some_dead = false;
    }

    /// The live units, if some are dead (else the passes take the whole layer).
    pub(crate) fn subset(&self) -> Option<&[u32]> {
        self.some_dead.then_some(&self.units)
    }

    /// The live units as the columns [`kernels::pack_columns`] keeps.
    fn columns(&self) -> Columns<'_> {
        Columns {
            list: &self.units,
            masks: &self.masks,
        }
    }
}

/// Whether the first `batch` values of each of `rows` rows (`columns` apart) are finite: the
/// gradients' finiteness check (`kernels::largest_magnitude_bits`) on those values.
pub(crate) fn all_finite(
    isa: Isa,
    values: &[f32],
    rows: usize,
    columns: usize,
    batch: usize,
) -> bool {
    let rows = Rows {
        values: &values[..rows * columns],
        columns: batch,
        stride: columns,
    };
    kernels::largest_magnitude_bits(isa, rows) < f32::INFINITY.to_bits()
}

/// `to ← from`, 16 values at a time where it can: a copy of a known length is a few vector
/// moves, where `copy_from_slice` on a row of a few dozen values calls `memmove`.
#[inline]
fn copy(to: &mut [f32], from: &[f32]) {
    let mut to_chunks = to.chunks_exact_mut(16);
    let mut from_chunks = from.chunks_exact(16);
    for (t, f) in (&mut to_chunks).zip(&mut from_chunks) {
        t.copy_from_slice(f);
    }
    for (t, &f) in to_chunks
        .into_remainder()
        .iter_mut()
        .zip(from_chunks.remainder())
    {
        *t = f;
    }
}

/// The rows `rows` of `src` (each `width` values, `stride` apart), side by side at the
/// start of `dst` (`width` apart).
pub(crate) fn pack_rows(src: &[f32], stride: usize, width: usize, rows: &[u32], dst: &mut [f32]) {
    if width == 0 {
        return;
    }
    for (to, &r) in dst.chunks_exact_mut(width).zip(rows) {
        let at = r as usize * stride;
        copy(to, &src[at..at + width]);
    }
}

/// The live units' columns of the first `rows` rows of `src` (rows `stride` apart), side by
/// side at the start of `dst` (rows `live`'s count apart).
pub(crate) fn pack_columns(
    isa: Isa,
    src: &[f32],
    stride: usize,
    rows: usize,
    live: &LiveUnits,
    dst: &mut [f32],
) {
    kernels::pack_columns(isa, src, stride, rows, live.columns(), dst);
}

/// A weight gradient computed over the live units only, spread back over the layer's rows
/// (`rows` of `dst`, `stride` apart, the bias's gradient in column `inputs`). `packed` holds
/// a row per live output (per output, when `live_outputs` is `None`), `packed_stride`
/// apart: the live inputs' columns side by side, then the bias's (when `live_inputs` is
/// `None`, the whole row as `dst` lays it out). Every other value is `+0`: what the full
/// product gives a dead unit's row and column.
#[allow(clippy::too_many_arguments)]
pub(crate) fn spread_gradient(
    isa: Isa,
    packed: &[f32],
    packed_stride: usize,
    live_outputs: Option<&[u32]>,
    live_inputs: Option<&LiveUnits>,
    rows: usize,
    (inputs, stride): (usize, usize),
    dst: &mut [f32],
) {
    let mut packed_rows = packed.chunks(packed_stride);
    let mut listed = live_outputs.map(|l| l.iter().peekable());
    for (r, row) in dst.chunks_mut(stride).take(rows).enumerate() {
        let computed = match &mut listed {
            Some(listed) => listed.next_if(|&&l| l as usize == r).is_some(),
            None => true,
        };
        let Some(from) = computed.then(|| packed_rows.next()).flatten() else {
            let mut chunks = row.chunks_exact_mut(16);
            for chunk in &mut chunks {
                chunk.copy_from_slice(&[0.0; 16]);
            }
            chunks.into_remainder().fill(0.0);
            continue;
        };
        match live_inputs {
            Some(live) => {
                let width = live.units.len();
                kernels::spread_columns(isa, &from[..width], live.columns(), row);
                row[inputs] = from[width];
            }
            None => copy(row, &from[..stride]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_unit_is_dead_only_if_every_transition_of_the_batch_gives_it_plus_zero() {
        // 3 units, a batch of 2 in 4 columns (the last two are padding).
        let activations = [
            0.0, 0.0, 9.0, 9.0, // dead: the padding does not count
            0.0, 0.5, 0.0, 0.0, // live
            -0.0, 0.0, 0.0, 0.0, // a −0 is not +0: counted live
        ];
        let mut live = LiveUnits::default();
        assert!(live.scan(Isa::current(), &activations, 3, 4, 2));
        assert_eq!(live.subset(), Some(&[1, 2][..]));
        assert!(live.scan(Isa::current(), &activations[4..], 2, 4, 2));
        assert_eq!(live.subset(), None, "none dead");
        live.all();
        assert_eq!(live.subset(), None);
    }

    #[test]
    fn a_non_finite_value_of_the_batch_is_seen_and_the_padding_is_not() {
        let mut live = LiveUnits::default();
        assert!(!live.scan(Isa::current(), &[0.0, f32::INFINITY, 0.0, 0.0], 2, 2, 2));
        assert!(!live.scan(Isa::current(), &[f32::NAN, 1.0], 1, 2, 2));
        assert!(live.scan(Isa::current(), &[1.0, f32::NAN], 1, 2, 1));
        assert!(all_finite(
            Isa::current(),
            &[1.0, 2.0, f32::NAN, 3.0, 4.0, f32::INFINITY],
            2,
            3,
            2
        ));
        assert!(!all_finite(
            Isa::current(),
            &[1.0, -f32::INFINITY, 0.0],
            1,
            3,
            2
        ));
    }

    #[test]
    fn packing_keeps_the_listed_rows_and_columns_and_spreading_puts_them_back() {
        // 3 rows of 4 values, stride 5.
        let src: Vec<f32> = (0..15).map(|x| x as f32).collect();
        let mut packed = [-1.0f32; 9];
        pack_rows(&src, 5, 4, &[0, 2], &mut packed);
        assert_eq!(packed, [0.0, 1.0, 2.0, 3.0, 10.0, 11.0, 12.0, 13.0, -1.0]);
        // Units 1 and 3 of 4 live, for a batch of 1.
        let mut live = LiveUnits::default();
        assert!(live.scan(Isa::current(), &[0.0, 1.0, 0.0, 2.0], 4, 1, 1));
        let mut packed = [-1.0f32; 6 + kernels::SLACK];
        pack_columns(Isa::current(), &src, 5, 3, &live, &mut packed);
        assert_eq!(packed[..6], [1.0, 3.0, 6.0, 8.0, 11.0, 13.0]);

        // A gradient of 3 rows, 2 inputs and the bias (stride 3); rows 1 and 2 computed.
        let packed = [1.0, 2.0, 9.0, 3.0, 4.0, 9.0]; // 2 rows of 3
        let mut dst = [7.0f32; 13];
        let isa = Isa::current();
        spread_gradient(isa, &packed, 3, Some(&[1, 2]), None, 3, (2, 3), &mut dst);
        assert_eq!(
            dst,
            [0.0, 0.0, 0.0, 1.0, 2.0, 9.0, 3.0, 4.0, 9.0, 7.0, 7.0, 7.0, 7.0]
        );
        // Inputs 1 and 3 of 4 live, all 2 rows computed: a row of 16 (4 inputs, the bias).
        let mut live = LiveUnits::default();
        assert!(live.scan(isa, &[0.0, 1.0, 0.0, 2.0], 4, 1, 1));
        let packed = [1.0, 2.0, 5.0, 3.0, 4.0, 6.0];
        let mut dst = [7.0f32; 33];
        spread_gradient(isa, &packed, 3, None, Some(&live), 2, (4, 16), &mut dst);
        assert_eq!(dst[..6], [0.0, 1.0, 0.0, 2.0, 5.0, 0.0]);
        assert_eq!(dst[16..22], [0.0, 3.0, 0.0, 4.0, 6.0, 0.0]);
        assert_eq!(dst[32], 7.0);
    }
}
