//! A small observation vector that lives on the stack, so a step never allocates.

use std::ops::Deref;

/// Largest observation among the built-in environments (Acrobot's six values).
pub const MAX_OBSERVATION_SIZE: usize = 6;

/// An `f32` observation of at most [`MAX_OBSERVATION_SIZE`] values; derefs to `&[f32]`.
#[derive(Clone, Copy, PartialEq)]
pub struct Observation {
    values: [f32; MAX_OBSERVATION_SIZE],
    len: usize,
}

impl Observation {
    /// # Panics
    /// If `values` is longer than [`MAX_OBSERVATION_SIZE`] (an environment bug).
    // Inlined so the copy has a constant length in `step`, with no call and no `memmove`.
    #[inline]
    pub fn from_slice(values: &[f32]) -> Self {
        assert!(values.len() <= MAX_OBSERVATION_SIZE, "observation too long");
        let mut buf = [0.0; MAX_OBSERVATION_SIZE];
        buf[..values.len()].copy_from_slice(values);
        Self {
            values: buf,
            len: values.len(),
        }
    }
}

impl Deref for Observation {
    type Target = [f32];
    #[inline]
    fn deref(&self) -> &[f32] {
        &self.values[..self.len]
    }
}

impl std::fmt::Debug for Observation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}
