//! The Q-network: a multilayer perceptron with ReLU between layers and a linear output,
//! one Q-value per action.

use candle_core::{DType, Device, Module, Tensor, Var};
use candle_nn::Linear;
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use super::DqnError;

/// The shape of a Q-network.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Architecture {
    pub observation_size: usize,
    /// Units of each hidden layer, input side first.
    pub hidden: Vec<usize>,
    pub action_count: usize,
}

impl Architecture {
    pub fn new(observation_size: usize, hidden: &[usize], action_count: usize) -> Self {
        Self {
            observation_size,
            hidden: hidden.to_vec(),
            action_count,
        }
    }

    /// Every size must be at least 1; no hidden layer at all is allowed (a linear Q).
    pub fn validate(&self) -> Result<(), DqnError> {
        if self.observation_size == 0 || self.action_count == 0 || self.hidden.contains(&0) {
            return Err(DqnError::Architecture(format!(
                "every layer needs at least one unit, got {self}"
            )));
        }
        Ok(())
    }

    /// Units of every layer: the observation, each hidden layer, the actions.
    pub fn layer_sizes(&self) -> Vec<usize> {
        let mut sizes = vec![self.observation_size];
        sizes.extend(&self.hidden);
        sizes.push(self.action_count);
        sizes
    }

    /// `(out, in)` of each linear layer, input side first.
    pub fn layer_shapes(&self) -> Vec<(usize, usize)> {
        self.layer_sizes()
            .windows(2)
            .map(|w| (w[1], w[0]))
            .collect()
    }

    /// Name and shape of every parameter, in the order of [`QNet::parameters`]:
    /// `layers.{i}.weight` `[out, in]` then `layers.{i}.bias` `[out]`, as PyTorch's
    /// `nn.Linear` stores them (`y = x·Wᵀ + b`).
    pub fn parameter_shapes(&self) -> Vec<(String, Vec<usize>)> {
        self.layer_shapes()
            .into_iter()
            .enumerate()
            .flat_map(|(i, (out, inp))| {
                [
                    (format!("layers.{i}.weight"), vec![out, inp]),
                    (format!("layers.{i}.bias"), vec![out]),
                ]
            })
            .collect()
    }
}

impl std::fmt::Display for Architecture {
    /// `4-100-100-2`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.observation_size)?;
        for units in &self.hidden {
            write!(f, "-{units}")?;
        }
        write!(f, "-{}", self.action_count)
    }
}

/// How a new network's parameters are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Init {
    /// Chainer's `L.Linear`, which ChainerRL's Q-functions (the paper's) use: weights
    /// `N(0, 1/fan_in)`, biases 0.
    #[default]
    LecunNormal,
    /// PyTorch's `nn.Linear`, which Stable-Baselines3 uses: weights and biases uniform in
    /// `±1/√fan_in` (`kaiming_uniform_(a = √5)` for the weights).
    TorchDefault,
}

/// An MLP Q-network on the CPU. Its parameters are candle [`Var`]s, so it can be trained
/// and moved to another thread. Not `Clone`: a clone would share the parameters; see
/// [`QNet::deep_copy`].
#[derive(Debug)]
pub struct QNet {
    architecture: Architecture,
    /// candle-nn's layers over the same parameters: [`QNet::reference_forward`].
    layers: Vec<Linear>,
    /// Weight then bias of each layer; the layers share their storage.
    parameters: Vec<Var>,
}

impl QNet {
    /// A freshly initialised network, as Chainer's `L.Linear` (which ChainerRL's Q-functions
    /// use) initialises one: weights `W ~ N(0, 1/fan_in)` (LeCun normal), biases 0. candle's
    /// own initialisers draw from an unseedable generator, so the draw is ours.
    pub fn new(architecture: Architecture, rng: &mut impl Rng) -> Result<Self, DqnError> {
        Self::with_init(architecture, Init::LecunNormal, rng)
    }

    /// A freshly initialised network, drawn as `init` says, layer by layer (weight, then
    /// bias) from `rng`.
    pub fn with_init(
        architecture: Architecture,
        init: Init,
        rng: &mut impl Rng,
    ) -> Result<Self, DqnError> {
        architecture.validate()?;
        let mut fan_in = 0;
        let values = architecture
            .parameter_shapes()
            .into_iter()
            .map(|(name, shape)| {
                let weight = name.ends_with("weight");
                if weight {
                    fan_in = shape[1];
                }
                let n: usize = shape.iter().product();
                let scale = (1.0 / fan_in as f64).sqrt();
                let values = match (init, weight) {
                    (Init::LecunNormal, true) => (0..n)
                        .map(|_| {
                            let z: f64 = StandardNormal.sample(rng);
                            (scale * z) as f32
                        })
                        .collect(),
                    (Init::LecunNormal, false) => vec![0.0; n],
                    (Init::TorchDefault, _) => (0..n)
                        .map(|_| (scale * rng.random_range(-1.0..1.0)) as f32)
                        .collect(),
                };
                Tensor::from_vec(values, shape, &Device::Cpu)
            })
            .collect::<Result<Vec<_>, _>>()?;
        Self::from_parameters(architecture, values)
    }

    /// A network with the given parameters, in the order of
    /// [`Architecture::parameter_shapes`]. The values are copied.
    pub fn from_parameters(
        architecture: Architecture,
        values: Vec<Tensor>,
    ) -> Result<Self, DqnError> {
        architecture.validate()?;
        let expected = architecture.parameter_shapes();
        if values.len() != expected.len() {
            return Err(DqnError::Architecture(format!(
                "{architecture} has {} parameter tensors, got {}",
                expected.len(),
                values.len()
            )));
        }
        let mut parameters = Vec::with_capacity(values.len());
        for ((name, shape), value) in expected.iter().zip(values) {
            if value.dims() != shape.as_slice() {
                return Err(DqnError::Architecture(format!(
                    "{name} of {architecture} has shape {shape:?}, got {:?}",
                    value.dims()
                )));
            }
            // Detached, so that `from_tensor` copies even a tensor that is another's `Var`.
            let value = value
                .to_device(&Device::Cpu)?
                .to_dtype(DType::F32)?
                .detach();
            parameters.push(Var::from_tensor(&value)?);
        }
        let layers = parameters
            .chunks(2)
            .map(|wb| Linear::new(wb[0].as_detached_tensor(), Some(wb[1].as_detached_tensor())))
            .collect();
        Ok(Self {
            architecture,
            layers,
            parameters,
        })
    }

    pub fn architecture(&self) -> &Architecture {
        &self.architecture
    }

    /// Weight then bias of each layer, input side first.
    pub fn parameters(&self) -> &[Var] {
        &self.parameters
    }

    /// `(name, tensor)` of every parameter, named as in [`Architecture::parameter_shapes`].
    pub fn named_parameters(&self) -> Vec<(String, Tensor)> {
        self.architecture
            .parameter_shapes()
            .into_iter()
            .zip(&self.parameters)
            .map(|((name, _), var)| (name, var.as_detached_tensor()))
            .collect()
    }

    /// The same Q-values through candle-nn's `Linear` layers and candle's matrix products:
    /// the reference the kernels are checked against (equal within rounding, not to the bit).
    pub fn reference_forward(&self, obs: &Tensor) -> candle_core::Result<Tensor> {
        let last = self.layers.len() - 1;
        let mut x = obs.clone();
        for (i, layer) in self.layers.iter().enumerate() {
            x = layer.forward(&x)?;
            if i < last {
                x = x.relu()?;
            }
        }
        Ok(x)
    }

    /// Overwrites this network's parameters with `source`'s (the hard target update).
    ///
    /// # Panics
    /// If the architectures differ (a caller bug).
    pub fn copy_from(&self, source: &QNet) -> Result<(), DqnError> {
        assert_eq!(
            self.architecture, source.architecture,
            "copy between architectures"
        );
        for (dst, src) in self.parameters.iter().zip(&source.parameters) {
            dst.set(src.as_tensor())?;
        }
        Ok(())
    }

    /// An independent copy: training one does not move the other.
    pub fn deep_copy(&self) -> Result<Self, DqnError> {
        let values = self
            .parameters
            .iter()
            .map(|v| v.as_tensor().clone())
            .collect();
        Self::from_parameters(self.architecture.clone(), values)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dqn::q_values::argmax;
    use rand::{rngs::StdRng, SeedableRng};

    fn net(hidden: &[usize], seed: u64) -> QNet {
        let arch = Architecture::new(4, hidden, 2);
        QNet::new(arch, &mut StdRng::seed_from_u64(seed)).unwrap()
    }

    fn flat(net: &QNet) -> Vec<f32> {
        net.parameters()
            .iter()
            .flat_map(|v| {
                v.as_tensor()
                    .flatten_all()
                    .unwrap()
                    .to_vec1::<f32>()
                    .unwrap()
            })
            .collect()
    }

    #[test]
    fn any_hidden_shape_maps_a_batch_to_one_q_per_action() {
        for hidden in [&[100][..], &[87, 113], &[60, 40, 90], &[]] {
            let q = net(hidden, 0);
            let x = Tensor::zeros((32, 4), DType::F32, &Device::Cpu).unwrap();
            assert_eq!(q.forward(&x).unwrap().dims(), &[32, 2]);
            assert_eq!(q.parameters().len(), 2 * (hidden.len() + 1));
        }
        assert_eq!(net(&[87, 113], 0).architecture().to_string(), "4-87-113-2");
    }

    /// PyTorch's `nn.Linear`: every weight and bias within ±1/√fan_in, spread over it
    /// (a uniform draw has variance bound²/3).
    #[test]
    fn torch_default_initialisation_is_uniform_within_one_over_root_fan_in() {
        let arch = Architecture::new(4, &[256, 256], 2);
        let net = QNet::with_init(arch, Init::TorchDefault, &mut StdRng::seed_from_u64(3)).unwrap();
        let fans = [4.0_f64, 4.0, 256.0, 256.0, 256.0, 256.0];
        for (p, fan_in) in net.parameters().iter().zip(fans) {
            let bound = 1.0 / fan_in.sqrt();
            let values: Vec<f32> = p.as_tensor().flatten_all().unwrap().to_vec1().unwrap();
            assert!(values.iter().all(|&v| f64::from(v).abs() <= bound));
            if values.len() >= 256 {
                let variance =
                    values.iter().map(|&v| f64::from(v).powi(2)).sum::<f64>() / values.len() as f64;
                let expected = bound * bound / 3.0;
                assert!(
                    (variance / expected - 1.0).abs() < 0.15,
                    "{variance} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn initialisation_is_seeded_lecun_normal_with_zero_bias() {
        assert_eq!(flat(&net(&[50], 7)), flat(&net(&[50], 7)));
        assert_ne!(flat(&net(&[50], 7)), flat(&net(&[50], 8)));
        let q = net(&[400], 1);
        let w = q.parameters()[2].as_tensor().flatten_all().unwrap();
        let w = w.to_vec1::<f32>().unwrap();
        let var = w.iter().map(|x| x * x).sum::<f32>() / w.len() as f32;
        assert!((var - 1.0 / 400.0).abs() < 0.2 / 400.0, "{var}");
        let b = q.parameters()[1].as_tensor().to_vec1::<f32>().unwrap();
        assert!(b.iter().all(|&x| x == 0.0));
    }

    #[test]
    fn greedy_action_is_the_argmax_of_the_batch_forward() {
        let q = net(&[16], 3);
        let obs = [0.1, -0.4, 0.3, 2.0];
        let x = Tensor::from_slice(&obs, (1, 4), &Device::Cpu).unwrap();
        let batch = q.forward(&x).unwrap().to_vec2::<f32>().unwrap();
        assert_eq!(q.q_values(&obs).unwrap(), batch[0]);
        assert_eq!(q.greedy_action(&obs).unwrap(), argmax(&batch[0]));
        assert!(matches!(
            q.greedy_action(&[0.0; 3]),
            Err(DqnError::ObservationSize {
                expected: 4,
                got: 3
            })
        ));
    }

    #[test]
    fn argmax_takes_the_first_maximum() {
        assert_eq!(argmax(&[1.0, 3.0, 3.0]), 1);
        assert_eq!(argmax(&[f32::NAN, -1.0]), 1);
    }

    #[test]
    fn copies_are_independent_and_copy_from_syncs() {
        let a = net(&[8], 1);
        let b = net(&[8], 2);
        let c = a.deep_copy().unwrap();
        b.copy_from(&a).unwrap();
        assert_eq!(flat(&a), flat(&b));
        a.parameters()[0]
            .set(&a.parameters()[0].as_tensor().affine(2.0, 0.0).unwrap())
            .unwrap();
        assert_ne!(flat(&a), flat(&b));
        assert_eq!(flat(&b), flat(&c));
    }

    #[test]
    fn refuses_empty_layers_and_wrong_shapes() {
        let arch = Architecture::new(4, &[0], 2);
        assert!(QNet::new(arch, &mut StdRng::seed_from_u64(0)).is_err());
        let arch = Architecture::new(4, &[3], 2);
        let wrong = vec![Tensor::zeros((3, 5), DType::F32, &Device::Cpu).unwrap(); 4];
        let err = QNet::from_parameters(arch, wrong).unwrap_err().to_string();
        assert!(err.contains("layers.0.weight"), "{err}");
    }

    #[test]
    fn is_send() {
        fn send<T: Send>() {}
        send::<QNet>();
    }
}
