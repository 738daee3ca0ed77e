//! The MLP's forward and backward passes, written out by hand on the kernels of `kernels/`
//! (`tests` checks them against candle's autograd):
//!
//! ```text
//! forward:   zₗ = aₗ₋₁·Wₗᵀ + bₗ      aₗ = relu(zₗ)   (no ReLU on the output layer)
//! backward:  ∂Wₗ = ∂zₗᵀ·aₗ₋₁        ∂bₗ = Σ_rows ∂zₗ
//!            ∂aₗ₋₁ = (∂zₗ·Wₗ) ⊙ [aₗ₋₁ > 0]
//! ```
//!
//! Activations and their gradients are kept transposed, a row per unit and a column per
//! transition, the columns padded to 16: the forward products and the ∂a products then
//! vectorise across the minibatch, with the bias, ReLU and ReLU's mask applied in registers.
//! ∂W vectorises across the layer's inputs instead, so it reads the layer's input
//! transposed back (one small copy per layer), with a column of ones after the last input:
//! that column's sums, `Σ_rows ∂zₗ·1`, are ∂bₗ, and an FMA by 1 rounds as an add does. The parameters stay in their candle [`Var`]s
//! and are read in place.
//!
//! [`Var`]: candle_core::Var

use candle_core::{bail, Result, Storage, Tensor};

use super::kernels::{
    largest_magnitude_bits, padded, sum_of_squares, Buffer, Finish, Isa, Product, Rows, Start,
    Strided, Transpose,
};
use super::{Architecture, QNet};

/// Scratch memory of the passes, for one architecture and batch size at a time; kept between
/// updates so a step allocates nothing.
#[derive(Debug, Default)]
pub(crate) struct Workspace {
    /// Units of every layer, input first.
    sizes: Vec<usize>,
    batch: usize,
    /// `padded(batch)`: the column count of every transposed buffer.
    columns: usize,
    /// The input of each layer, then the Q-values: `[units, columns]`.
    activations: Vec<Buffer>,
    /// The Q-values `[batch, actions]`.
    q: Vec<f32>,
    /// A layer's input and a column of ones `[batch, padded(units + 1)]`, for its weights'
    /// and bias's gradients.
    inputs: Buffer,
    /// ∂z of the layer being differentiated and ∂a of its input, `[units, columns]`.
    grad_out: Buffer,
    grad_in: Buffer,
    gradients: Gradients,
}

impl Workspace {
    /// Sizes the forward pass's buffers for `architecture` and `batch`. Buffers are reused
    /// across shapes (an acting thread runs one network after another); a lane or column
    /// past the batch or a layer's units may hold another shape's values, which no sum
    /// reads.
    fn prepare(&mut self, architecture: &Architecture, batch: usize) {
        if self.is_for(architecture, batch) {
            return;
        }
        let sizes = architecture.layer_sizes();
        let columns = padded(batch);
        self.activations.resize_with(sizes.len(), Buffer::default);
        for (buffer, &units) in self.activations.iter_mut().zip(&sizes) {
            buffer.resize(units * columns);
        }
        self.q.resize(batch * architecture.action_count, 0.0);
        (self.sizes, self.batch, self.columns) = (sizes, batch, columns);
    }

    /// Whether the last forward pass ran `architecture` on `batch` observations.
    pub(crate) fn is_for(&self, architecture: &Architecture, batch: usize) -> bool {
        batch == self.batch && self.shaped_for(architecture)
    }

    /// Whether the buffers are laid out for `architecture`'s layers (compared without
    /// allocating: this runs every pass).
    fn shaped_for(&self, architecture: &Architecture) -> bool {
        let hidden = &architecture.hidden;
        match self.sizes.as_slice() {
            [inputs, middle @ .., outputs] => {
                *inputs == architecture.observation_size
                    && *outputs == architecture.action_count
                    && middle == hidden.as_slice()
            }
            _ => false,
        }
    }

    /// Sizes the backward pass's buffers for the shape of the last forward pass.
    fn prepare_backward(&mut self) {
        let widest = self.sizes.iter().copied().max().unwrap_or(0);
        self.inputs.resize(self.batch * padded(widest + 1));
        self.grad_out.resize(widest * self.columns);
        self.grad_in.resize(widest * self.columns);
        let shapes = self.sizes.windows(2).flat_map(|w| {
            let (inputs, outputs) = (w[0], w[1]);
            [(outputs, inputs, padded(inputs + 1)), (1, outputs, outputs)]
        });
        let fits = self.gradients.parameters.len() == 2 * (self.sizes.len() - 1)
            && shapes.clone().zip(&self.gradients.parameters).all(
                |((rows, columns, stride), p)| {
                    p.columns == columns && p.stride == stride && p.values.len() == rows * stride
                },
            );
        if !fits {
            self.gradients.parameters = shapes
                .map(|(rows, columns, stride)| ParameterGradient::zeros(rows, columns, stride))
                .collect();
        }
    }

    /// The gradients of the last [`QNet::backward`].
    pub(crate) fn gradients(&self) -> &Gradients {
        &self.gradients
    }
}

/// The gradient of every parameter of a network, in the order of [`QNet::parameters`].
#[derive(Debug, Default, Clone)]
pub struct Gradients {
    parameters: Vec<ParameterGradient>,
}

/// A parameter's gradient: rows of `columns` values, `stride` apart (a weight's rows are
/// padded to whole vectors, and hold its bias's gradient in column `columns`).
#[derive(Debug, Clone)]
struct ParameterGradient {
    values: Buffer,
    columns: usize,
    stride: usize,
}

impl ParameterGradient {
    fn zeros(rows: usize, columns: usize, stride: usize) -> Self {
        Self {
            values: Buffer::zeros(rows * stride),
            columns,
            stride,
        }
    }

    fn rows(&self) -> impl Iterator<Item = &[f32]> {
        self.values
            .chunks(self.stride.max(1))
            .map(|row| &row[..self.columns])
    }
}

impl Gradients {
    /// Gradients given as tensors, one per parameter (from candle's autograd, say).
    pub fn from_tensors(tensors: &[Tensor]) -> Result<Self> {
        let parameters = tensors
            .iter()
            .map(|t| {
                let columns = t.dims().last().copied().unwrap_or(1);
                let dense = t.flatten_all()?.to_vec1::<f32>()?;
                let mut values = Buffer::zeros(dense.len());
                values.copy_from_slice(&dense);
                Ok(ParameterGradient {
                    values,
                    columns,
                    stride: columns,
                })
            })
            .collect::<Result<_>>()?;
        Ok(Self { parameters })
    }

    pub fn len(&self) -> usize {
        self.parameters.len()
    }

    pub fn is_empty(&self) -> bool {
        self.parameters.is_empty()
    }

    /// Each gradient, densely, as a tensor of `shape` taken from the matching parameter.
    pub fn to_tensors(&self, shapes: &[Vec<usize>]) -> Result<Vec<Tensor>> {
        self.parameters
            .iter()
            .zip(shapes)
            .map(|(p, shape)| {
                let values: Vec<f32> = p.rows().flatten().copied().collect();
                Tensor::from_vec(values, shape.as_slice(), &candle_core::Device::Cpu)
            })
            .collect()
    }

    /// Whether every value is finite.
    pub fn all_finite(&self) -> bool {
        let isa = Isa::current();
        self.rows()
            .all(|rows| largest_magnitude_bits(isa, rows) < f32::INFINITY.to_bits())
    }

    /// `Σ g²` over every value, in `f64`, row by row (`kernels::sum_of_squares`).
    pub fn sum_of_squares(&self) -> f64 {
        let isa = Isa::current();
        self.rows().map(|rows| sum_of_squares(isa, rows)).sum()
    }

    pub(crate) fn rows(&self) -> impl Iterator<Item = Rows<'_>> {
        self.parameters.iter().map(|p| Rows {
            values: &p.values,
            columns: p.columns,
            stride: p.stride,
        })
    }
}

impl QNet {
    /// Calls `f` with layer `l`'s weights and bias, read in place (locking two parameters,
    /// not all of them: nothing is collected, so a pass allocates nothing).
    pub(super) fn with_layer<R>(&self, l: usize, f: impl FnOnce(&[f32], &[f32]) -> R) -> Result<R> {
        let parameters = self.parameters();
        let (weight, bias) = (&parameters[2 * l], &parameters[2 * l + 1]);
        let (weight, weight_layout) = weight.storage_and_layout();
        let (bias, bias_layout) = bias.storage_and_layout();
        Ok(f(
            cpu_values(&weight, weight_layout)?,
            cpu_values(&bias, bias_layout)?,
        ))
    }

    /// Q-values `[batch, action_count]` of the observations `obs` (`[batch,
    /// observation_size]`, row-major), computed on `isa`. `work` keeps every layer's input
    /// for [`QNet::backward`].
    pub(crate) fn forward_with<'w>(
        &self,
        isa: Isa,
        obs: &[f32],
        batch: usize,
        work: &'w mut Workspace,
    ) -> Result<&'w [f32]> {
        let architecture = self.architecture();
        if obs.len() != batch * architecture.observation_size {
            bail!(
                "{} observation values for a batch of {batch} observations of {}",
                obs.len(),
                architecture.observation_size
            )
        }
        work.prepare(architecture, batch);
        let columns = work.columns;
        let sizes = &work.sizes;
        Transpose {
            src: obs,
            src_stride: sizes[0],
            rows: batch,
            columns: sizes[0],
        }
        .run(isa, &mut work.activations[0], columns);
        let layers = sizes.len() - 1;
        for l in 0..layers {
            let (inputs, outputs) = (sizes[l], sizes[l + 1]);
            let (done, next) = work.activations.split_at_mut(l + 1);
            self.with_layer(l, |weight, bias| {
                Product {
                    rows: outputs,
                    depth: inputs,
                    columns,
                    left: Strided {
                        data: weight,
                        row_stride: inputs,
                        column_stride: 1,
                    },
                    right: &done[l],
                    right_stride: columns,
                    start: Start::Bias(bias),
                    finish: if l + 1 < layers {
                        Finish::Relu
                    } else {
                        Finish::Keep
                    },
                }
                .run(isa, &mut next[0], columns)
            })?;
        }
        let actions = sizes[layers];
        Transpose {
            src: &work.activations[layers],
            src_stride: columns,
            rows: actions,
            columns: batch,
        }
        .run(isa, &mut work.q, actions);
        Ok(&work.q)
    }

    /// Gradients of the loss with respect to every parameter, into `work`, given `grad_q =
    /// ∂loss/∂q` (`[batch, action_count]`) for the batch `work`'s last forward pass saw.
    pub(crate) fn backward_with(
        &self,
        isa: Isa,
        work: &mut Workspace,
        grad_q: &[f32],
    ) -> Result<()> {
        let (batch, columns) = (work.batch, work.columns);
        let layers = work.sizes.len().saturating_sub(1);
        if !work.shaped_for(self.architecture()) || grad_q.len() != batch * work.sizes[layers] {
            bail!("backward without the matching forward pass")
        }
        work.prepare_backward();
        let sizes = &work.sizes;
        Transpose {
            src: grad_q,
            src_stride: sizes[layers],
            rows: batch,
            columns: sizes[layers],
        }
        .run(isa, &mut work.grad_out, columns);
        for l in (0..layers).rev() {
            let (inputs, outputs) = (sizes[l], sizes[l + 1]);
            let stride = padded(inputs + 1);
            let input = &work.activations[l];
            Transpose {
                src: input,
                src_stride: columns,
                rows: inputs,
                columns: batch,
            }
            .run(isa, &mut work.inputs, stride);
            for row in work.inputs.chunks_exact_mut(stride).take(batch) {
                row[inputs] = 1.0;
            }
            let (weight, bias) = match &mut work.gradients.parameters[2 * l..] {
                [weight, bias, ..] => (weight, bias),
                _ => unreachable!("two gradients per layer"),
            };
            Product {
                rows: outputs,
                depth: batch,
                columns: stride,
                left: Strided {
                    data: &work.grad_out,
                    row_stride: columns,
                    column_stride: 1,
                },
                right: &work.inputs,
                right_stride: stride,
                start: Start::Zero,
                finish: Finish::Keep,
            }
            .run(isa, &mut weight.values, stride);
            for (o, db) in bias.values.iter_mut().enumerate() {
                *db = weight.values[o * stride + inputs];
            }
            if l > 0 {
                self.with_layer(l, |weight, _| {
                    Product {
                        rows: inputs,
                        depth: outputs,
                        columns,
                        left: Strided {
                            data: weight,
                            row_stride: 1,
                            column_stride: inputs,
                        },
                        right: &work.grad_out,
                        right_stride: columns,
                        start: Start::Zero,
                        finish: Finish::MaskBy(input),
                    }
                    .run(isa, &mut work.grad_in, columns)
                })?;
                std::mem::swap(&mut work.grad_out, &mut work.grad_in);
            }
        }
        Ok(())
    }
}

/// A parameter's values in place: its CPU storage between the layout's offsets.
fn cpu_values<'a>(storage: &'a Storage, layout: &candle_core::Layout) -> Result<&'a [f32]> {
    let Storage::Cpu(cpu) = storage else {
        bail!("the Q-network's parameters live on the CPU")
    };
    let Some((start, end)) = layout.contiguous_offsets() else {
        bail!("the Q-network's parameters are contiguous")
    };
    Ok(&cpu.as_slice::<f32>()?[start..end])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dqn::Architecture;
    use candle_core::{Device, Var};
    use rand::{rngs::StdRng, SeedableRng};

    /// The same network through candle's autograd.
    fn autograd_forward(net: &QNet, obs: &Tensor) -> Tensor {
        let p: Vec<&Var> = net.parameters().iter().collect();
        let mut x = obs.clone();
        for (l, wb) in p.chunks(2).enumerate() {
            x = x
                .matmul(&wb[0].t().unwrap())
                .unwrap()
                .broadcast_add(wb[1])
                .unwrap();
            if l + 1 < p.len() / 2 {
                x = x.relu().unwrap();
            }
        }
        x
    }

    fn max_difference(a: &Tensor, b: &Tensor) -> f32 {
        (a - b)
            .unwrap()
            .abs()
            .unwrap()
            .flatten_all()
            .unwrap()
            .max(0)
            .unwrap()
            .to_scalar::<f32>()
            .unwrap()
    }

    /// Every path against candle's autograd, within rounding, and against each other, to the
    /// bit; batches of 9 (a padded tail) and 40.
    #[test]
    fn matches_candle_autograd_on_every_path() {
        let mut rng = StdRng::seed_from_u64(0);
        let net = QNet::new(Architecture::new(4, &[7, 21, 6], 3), &mut rng).unwrap();
        // Non-zero biases, so the ReLU masks differ from layer to layer.
        for var in net.parameters().iter().skip(1).step_by(2) {
            var.set(&Tensor::randn(0f32, 0.5, var.shape(), &Device::Cpu).unwrap())
                .unwrap();
        }
        let shapes: Vec<Vec<usize>> = net.parameters().iter().map(|p| p.dims().to_vec()).collect();
        for batch in [9, 40] {
            let obs = Tensor::randn(0f32, 1.0, (batch, 4), &Device::Cpu).unwrap();
            let weights = Tensor::randn(0f32, 1.0, (batch, 3), &Device::Cpu).unwrap();
            let reference_q = autograd_forward(&net, &obs);
            let loss = (&reference_q * &weights).unwrap().sum_all().unwrap();
            let reference = loss.backward().unwrap();

            let obs_values = obs.flatten_all().unwrap().to_vec1::<f32>().unwrap();
            let grad_q = weights.flatten_all().unwrap().to_vec1::<f32>().unwrap();
            let mut seen: Option<(Vec<u32>, Vec<u32>)> = None;
            for isa in Isa::ALL.into_iter().filter(|i| i.supported()) {
                let mut work = Workspace::default();
                let q = net
                    .forward_with(isa, &obs_values, batch, &mut work)
                    .unwrap();
                let q = Tensor::from_slice(q, (batch, 3), &Device::Cpu).unwrap();
                assert!(max_difference(&q, &reference_q) < 1e-5, "{isa:?}");
                let q_bits = q
                    .flatten_all()
                    .unwrap()
                    .to_vec1::<f32>()
                    .unwrap()
                    .iter()
                    .map(|x| x.to_bits())
                    .collect();
                net.backward_with(isa, &mut work, &grad_q).unwrap();
                let grads = work.gradients().to_tensors(&shapes).unwrap();
                let mut grad_bits = Vec::new();
                for (var, grad) in net.parameters().iter().zip(&grads) {
                    let want = reference.get(var).unwrap();
                    assert_eq!(grad.dims(), want.dims());
                    assert!(max_difference(grad, want) < 1e-4, "{isa:?}");
                    let values = grad.flatten_all().unwrap().to_vec1::<f32>().unwrap();
                    grad_bits.extend(values.iter().map(|x| x.to_bits()));
                }
                match &seen {
                    None => seen = Some((q_bits, grad_bits)),
                    Some(first) => assert_eq!(first, &(q_bits, grad_bits), "{isa:?}"),
                }
            }
        }
    }

    #[test]
    fn a_backward_needs_its_forward() {
        let net = QNet::new(Architecture::new(2, &[3], 2), &mut StdRng::seed_from_u64(1)).unwrap();
        let mut work = Workspace::default();
        assert!(net
            .backward_with(Isa::Portable, &mut work, &[0.0; 4])
            .is_err());
        assert!(net
            .forward_with(Isa::Portable, &[0.0; 3], 2, &mut work)
            .is_err());
    }
}
