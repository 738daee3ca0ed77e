//! A network's Q-values on this CPU's kernels (the forward pass of `backprop.rs`), for a
//! batch and for the one observation an acting step reads.

use std::cell::RefCell;

use candle_core::{DType, Device, Tensor};

use super::backprop::Workspace;
use super::kernels::Isa;
use super::{DqnError, QNet};

impl QNet {
    /// Q-values `[batch, action_count]` of observations `[batch, observation_size]`, on this
    /// CPU's kernels (the training path: the same bits on every CPU).
    pub fn forward(&self, obs: &Tensor) -> candle_core::Result<Tensor> {
        let (batch, _) = obs.dims2()?;
        let values = obs.to_dtype(DType::F32)?.flatten_all()?.to_vec1::<f32>()?;
        let mut work = Workspace::default();
        let q = self.forward_with(Isa::current(), &values, batch, &mut work)?;
        Tensor::from_slice(q, (batch, self.architecture().action_count), &Device::Cpu)
    }

    /// Q-values of one observation.
    pub fn q_values(&self, obs: &[f32]) -> Result<Vec<f32>, DqnError> {
        self.with_q_values(obs, <[f32]>::to_vec)
    }

    /// The highest Q-value of one observation, folded as the update's TD targets fold a row.
    pub fn max_q(&self, obs: &[f32]) -> Result<f32, DqnError> {
        self.with_q_values(obs, highest)
    }

    /// The action of highest Q-value; ties go to the lowest index, as `argmax` does.
    pub fn greedy_action(&self, obs: &[f32]) -> Result<usize, DqnError> {
        self.with_q_values(obs, argmax)
    }

    /// Calls `f` with the Q-values of one observation.
    fn with_q_values<R>(&self, obs: &[f32], f: impl FnOnce(&[f32]) -> R) -> Result<R, DqnError> {
        let expected = self.architecture().observation_size;
        if obs.len() != expected {
            return Err(DqnError::ObservationSize {
                expected,
                got: obs.len(),
            });
        }
        thread_local! {
            /// Acting is one forward pass per step: its buffers are kept per thread.
            static ACTING: RefCell<Workspace> = RefCell::default();
        }
        ACTING.with_borrow_mut(|work| Ok(f(self.forward_with(Isa::current(), obs, 1, work)?)))
    }
}

/// The highest of `values`, folded as the update's TD targets fold a row.
pub(crate) fn highest(values: &[f32]) -> f32 {
    values.iter().copied().fold(f32::MIN, f32::max)
}

/// Index of the first maximum; NaN never wins.
pub(crate) fn argmax(values: &[f32]) -> usize {
    let mut best = 0;
    for (i, &v) in values.iter().enumerate() {
        if v > values[best] || values[best].is_nan() {
            best = i;
        }
    }
    best
}
