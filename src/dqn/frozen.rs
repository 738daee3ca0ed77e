//! A network that never learns again (a library's source as recorded), laid out for acting
//! on one observation.
//!
//! The training path's pass runs a batch across a vector's 16 lanes, so one observation
//! padded to 16 would leave 15 lanes computing nothing. Here each layer's weights are kept
//! transposed, `Wᵀ[k][r]`, with the units padded to 16, and one observation's pass runs the
//! lanes across the layer's units: a sixteenth of the work. Only for weights that do not
//! change: the layout is made once. A network that learns acts through
//! [`QNet::q_values`], which transposes its weights in registers at every call
//! (`kernels::MatVec`): the same bits, dearer than this pass (transposing is most of it).
//!
//! **The same bits** as [`QNet::q_values`]: every unit's value is the same chain of fused
//! multiply-adds, from its bias over `k = 0, 1, …` in order (an FMA's product is exact, so
//! which operand is which changes nothing), then the same ReLU.

use std::cell::RefCell;

use super::kernels::{padded, Finish, Isa, Product, Start, Strided};
use super::q_values::{argmax, highest};
use super::{DqnError, QNet};

/// A frozen copy of a network's weights in the layout of one observation's pass.
#[derive(Debug, Clone)]
pub struct FrozenNet {
    observation_size: usize,
    layers: Vec<Layer>,
}

/// One layer: `inputs` values in, `outputs` out, the units padded to `columns`.
#[derive(Debug, Clone)]
struct Layer {
    inputs: usize,
    outputs: usize,
    columns: usize,
    /// `Wᵀ`, `inputs` rows of `columns` (the padding zero).
    weights: Vec<f32>,
    /// `columns` values (the padding zero).
    bias: Vec<f32>,
}

impl FrozenNet {
    /// `net`'s weights as they are now, laid out for acting.
    pub fn of(net: &QNet) -> Result<Self, DqnError> {
        let sizes = net.architecture().layer_sizes();
        let mut layers = Vec::with_capacity(sizes.len() - 1);
        for (l, pair) in sizes.windows(2).enumerate() {
            let (inputs, outputs) = (pair[0], pair[1]);
            let columns = padded(outputs);
            let layer = net.with_layer(l, |weight, bias| {
                let mut transposed = vec![0.0; inputs * columns];
                for r in 0..outputs {
                    for k in 0..inputs {
                        transposed[k * columns + r] = weight[r * inputs + k];
                    }
                }
                let mut padded_bias = vec![0.0; columns];
                padded_bias[..outputs].copy_from_slice(&bias[..outputs]);
                Layer {
                    inputs,
                    outputs,
                    columns,
                    weights: transposed,
                    bias: padded_bias,
                }
            })?;
            layers.push(layer);
        }
        Ok(Self {
            observation_size: sizes[0],
            layers,
        })
    }

    /// Q-values of one observation.
    pub fn q_values(&self, obs: &[f32]) -> Result<Vec<f32>, DqnError> {
        self.with_q_values(obs, <[f32]>::to_vec)
    }

    /// The highest Q-value of one observation, folded as [`QNet::max_q`] folds it.
    pub fn max_q(&self, obs: &[f32]) -> Result<f32, DqnError> {
        self.with_q_values(obs, highest)
    }

    /// The action of highest Q-value; ties go to the lowest index.
    pub fn greedy_action(&self, obs: &[f32]) -> Result<usize, DqnError> {
        self.with_q_values(obs, argmax)
    }

    /// Calls `f` with the Q-values of one observation, computed in buffers kept per thread.
    fn with_q_values<R>(&self, obs: &[f32], f: impl FnOnce(&[f32]) -> R) -> Result<R, DqnError> {
        if obs.len() != self.observation_size {
            return Err(DqnError::ObservationSize {
                expected: self.observation_size,
                got: obs.len(),
            });
        }
        thread_local! {
            static BUFFERS: RefCell<(Vec<f32>, Vec<f32>)> = RefCell::default();
        }
        BUFFERS.with_borrow_mut(|(input, output)| {
            let isa = Isa::current();
            input.clear();
            input.extend_from_slice(obs);
            let last = self.layers.len() - 1;
            for (l, layer) in self.layers.iter().enumerate() {
                output.clear();
                output.resize(layer.columns, 0.0);
                Product {
                    rows: 1,
                    depth: layer.inputs,
                    columns: layer.columns,
                    left: Strided {
                        data: input,
                        row_stride: layer.inputs,
                        column_stride: 1,
                    },
                    right: &layer.weights,
                    right_stride: layer.columns,
                    start: Start::ColumnBias(&layer.bias),
                    finish: if l < last { Finish::Relu } else { Finish::Keep },
                }
                .run(isa, output, layer.columns);
                std::mem::swap(input, output);
            }
            let actions = self.layers[last].outputs;
            Ok(f(&input[..actions]))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dqn::{Architecture, Init};
    use rand::{rngs::StdRng, Rng, SeedableRng};

    /// Every shape the library holds and then some (units around a multiple of 16, one
    /// layer, four), both initialisations: the same bits as the training path's pass, on
    /// many observations.
    #[test]
    fn a_frozen_pass_gives_the_bits_of_the_networks_own() {
        let mut rng = StdRng::seed_from_u64(3);
        let shapes: [(usize, &[usize], usize); 6] = [
            (4, &[100], 2),
            (4, &[64, 114, 149], 2),
            (6, &[16, 17], 3),
            (8, &[15], 4),
            (2, &[1], 3),
            (11, &[33, 47, 5, 64], 5),
        ];
        for (observation_size, hidden, actions) in shapes {
            for init in [Init::LecunNormal, Init::TorchDefault] {
                let architecture = Architecture::new(observation_size, hidden, actions);
                let net = QNet::with_init(architecture, init, &mut rng).unwrap();
                let frozen = FrozenNet::of(&net).unwrap();
                for _ in 0..50 {
                    let obs: Vec<f32> = (0..observation_size)
                        .map(|_| rng.random_range(-3.0f32..3.0))
                        .collect();
                    let expected = net.q_values(&obs).unwrap();
                    let got = frozen.q_values(&obs).unwrap();
                    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&got), bits(&expected), "{hidden:?} {init:?}");
                    assert_eq!(
                        frozen.greedy_action(&obs).unwrap(),
                        net.greedy_action(&obs).unwrap()
                    );
                    assert_eq!(
                        frozen.max_q(&obs).unwrap().to_bits(),
                        net.max_q(&obs).unwrap().to_bits()
                    );
                }
                assert!(matches!(
                    frozen.q_values(&vec![0.0; observation_size + 1]),
                    Err(DqnError::ObservationSize { .. })
                ));
            }
        }
    }
}
