//! A network's Q-values on this CPU's kernels (the forward pass of `backprop.rs`), for a
//! batch and for the one observation an acting step reads.
//!
//! One observation does not go through the batch pass, which runs a batch across a
//! vector's 16 lanes (15 of them idle for one observation): each layer runs the lanes
//! across its units, reading its weights in place (`kernels::MatVec`), as a learning
//! network's weights change between two steps. Every unit is the same chain of fused
//! multiply-adds from its bias over its inputs in order, then the same ReLU: the same bits
//! as the batch pass (`one_observation_gives_the_bits_of_the_batch_pass`).

use std::cell::RefCell;

use candle_core::{DType, Device, Tensor};

use super::backprop::Workspace;
use super::kernels::{Isa, MatVec};
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
            static ACTING: RefCell<OneObservation> = RefCell::default();
        }
        ACTING.with_borrow_mut(|work| {
            let q = self.one_observation(Isa::current(), obs, work)?;
            Ok(f(q))
        })
    }

    /// The Q-values of `obs` (one observation, of the right size), computed in `work`.
    fn one_observation<'w>(
        &self,
        isa: Isa,
        obs: &[f32],
        work: &'w mut OneObservation,
    ) -> Result<&'w [f32], DqnError> {
        let OneObservation { input, output } = work;
        input.clear();
        input.extend_from_slice(obs);
        // Units of layer `i`, the observation's first (`layer_sizes` without its `Vec`).
        let architecture = self.architecture();
        let hidden = &architecture.hidden;
        let size = |i: usize| match i {
            0 => architecture.observation_size,
            i if i <= hidden.len() => hidden[i - 1],
            _ => architecture.action_count,
        };
        let layers = hidden.len() + 1;
        for l in 0..layers {
            let (inputs, outputs) = (size(l), size(l + 1));
            // Grown, never shrunk: every value a layer reads, the layer before wrote.
            if output.len() < outputs {
                output.resize(outputs, 0.0);
            }
            self.with_layer(l, |weights, bias| {
                MatVec {
                    rows: outputs,
                    depth: inputs,
                    weights,
                    bias,
                    input,
                    relu: l + 1 < layers,
                }
                .run(isa, output);
            })?;
            std::mem::swap(input, output);
        }
        Ok(&input[..architecture.action_count])
    }
}

/// The buffers of one observation's pass: a layer's input and output.
#[derive(Debug, Default)]
struct OneObservation {
    input: Vec<f32>,
    output: Vec<f32>,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dqn::{Architecture, Init};
    use rand::{rngs::StdRng, Rng, SeedableRng};

    fn bits(values: &[f32]) -> Vec<u32> {
        values.iter().map(|x| x.to_bits()).collect()
    }

    /// One observation's pass gives the batch pass's bits, on every path, for every shape
    /// the library holds and then some (units around multiples of 8 and 16, one layer and
    /// five, both initialisations, non-zero biases): alone, and as a row of a batch of 7.
    /// The shapes take turns in the same buffers, as the networks of a run do on a thread,
    /// and the weights change between calls, as a learning network's do.
    #[test]
    fn one_observation_gives_the_bits_of_the_batch_pass() {
        let mut rng = StdRng::seed_from_u64(5);
        let shapes: [(usize, &[usize], usize); 8] = [
            (4, &[100], 2),
            (4, &[64, 114, 149], 2),
            (4, &[256, 256], 2),
            (2, &[1], 3),
            (6, &[16, 17], 3),
            (8, &[15], 4),
            (11, &[33, 47, 5, 64, 9], 5),
            (9, &[], 7),
        ];
        let isas: Vec<Isa> = Isa::ALL.into_iter().filter(|i| i.supported()).collect();
        let mut one = OneObservation::default();
        let mut batch = Workspace::default();
        for round in 0..3 {
            for (observation_size, hidden, actions) in shapes {
                let init = [Init::LecunNormal, Init::TorchDefault][round % 2];
                let architecture = Architecture::new(observation_size, hidden, actions);
                let net = QNet::with_init(architecture, init, &mut rng).unwrap();
                for var in net.parameters().iter().skip(1).step_by(2) {
                    let values: Vec<f32> = (0..var.elem_count())
                        .map(|_| rng.random_range(-0.5..0.5))
                        .collect();
                    var.set(&Tensor::from_vec(values, var.shape(), &Device::Cpu).unwrap())
                        .unwrap();
                }
                for _ in 0..10 {
                    let rows: Vec<f32> = (0..7 * observation_size)
                        .map(|_| rng.random_range(-3.0f32..3.0))
                        .collect();
                    let obs = &rows[2 * observation_size..3 * observation_size];
                    for &isa in &isas {
                        let alone = bits(net.forward_with(isa, obs, 1, &mut batch).unwrap());
                        let row = bits(
                            &net.forward_with(isa, &rows, 7, &mut batch).unwrap()
                                [2 * actions..3 * actions],
                        );
                        let got = bits(net.one_observation(isa, obs, &mut one).unwrap());
                        assert_eq!(got, alone, "{isa:?} {hidden:?}");
                        assert_eq!(got, row, "{isa:?} {hidden:?}");
                    }
                    let q = net
                        .forward_with(isas[0], obs, 1, &mut batch)
                        .unwrap()
                        .to_vec();
                    assert_eq!(net.greedy_action(obs).unwrap(), argmax(&q));
                    assert_eq!(net.max_q(obs).unwrap().to_bits(), highest(&q).to_bits());
                    assert_eq!(bits(&net.q_values(obs).unwrap()), bits(&q));
                }
            }
        }
    }
}
