//! `f32` buffers that start on a cache line. Every row the kernels read or write is a
//! multiple of 16 values (64 bytes) long, so in such a buffer every row starts on a line and
//! no AVX-512 load or store is split between two lines (a split one costs two).

use std::ops::{Deref, DerefMut};

/// One cache line of values.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(64))]
struct Line([f32; 16]);

/// A growable `[f32]` whose first value is 64-byte aligned.
#[derive(Debug, Clone, Default)]
pub(crate) struct Buffer {
    lines: Vec<Line>,
    len: usize,
}

impl Buffer {
    pub(crate) fn zeros(len: usize) -> Self {
        let mut buffer = Self::default();
        buffer.resize(len);
        buffer
    }

    /// Grows with zeros or shrinks to `len` values; the values kept stay.
    pub(crate) fn resize(&mut self, len: usize) {
        let kept_lines = self.lines.len();
        self.lines.resize(len.div_ceil(16), Line::default());
        let old = std::mem::replace(&mut self.len, len);
        // New lines come zeroed; values past the old length in the lines kept may be left
        // from a longer past.
        let stale = old..len.min(16 * kept_lines);
        if !stale.is_empty() {
            self[stale].fill(0.0);
        }
    }
}

impl Deref for Buffer {
    type Target = [f32];

    fn deref(&self) -> &[f32] {
        // SAFETY: `Line` is `repr(C)` over 16 `f32`s, so the lines are `16 × lines.len()`
        // contiguous, initialised `f32`s, and `len` never exceeds that.
        unsafe { std::slice::from_raw_parts(self.lines.as_ptr().cast(), self.len) }
    }
}

impl DerefMut for Buffer {
    fn deref_mut(&mut self) -> &mut [f32] {
        // SAFETY: as in `deref`, with the exclusive borrow of `lines`.
        unsafe { std::slice::from_raw_parts_mut(self.lines.as_mut_ptr().cast(), self.len) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn starts_on_a_line_and_grows_with_zeros() {
        let mut buffer = Buffer::zeros(5);
        assert_eq!(buffer.as_ptr() as usize % 64, 0);
        buffer.fill(3.0);
        buffer.resize(2);
        buffer.resize(40);
        assert_eq!(&buffer[..2], &[3.0, 3.0]);
        assert!(buffer[2..].iter().all(|&x| x == 0.0));
        assert_eq!(buffer.len(), 40);
        // Shrinking within a line and past lines, then growing again.
        buffer.fill(5.0);
        buffer.resize(20);
        buffer.resize(3);
        buffer.resize(48);
        assert_eq!(&buffer[..3], &[5.0; 3]);
        assert!(buffer[3..].iter().all(|&x| x == 0.0));
    }
}
