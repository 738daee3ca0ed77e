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
    Strided, Transpose, SLACK,
};
use super::live_units::{all_finite, pack_columns, pack_rows, spread_gradient, LiveUnits};
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
    /// The live units of each layer's input, for the hidden layers (`live_units.rs`).
    live: Vec<LiveUnits>,
    /// The live units' activations of each hidden layer with dead units, packed.
    packed_activations: Vec<Buffer>,
    /// Layer `l`'s weights at its input's live units, packed, where its forward sums left
    /// the dead ones out.
    packed_weights: Vec<Buffer>,
    /// Whether every layer's input was finite in the last forward pass: if not, the
    /// backward pass leaves no dead unit out (`live_units.rs`).
    finite: bool,
    /// Whether dead units are kept in the passes (for tests that compare both ways).
    keep_dead: bool,
    /// A layer's input (its live units', where some are dead) and a column of ones
    /// `[batch, padded(units + 1)]`, for its weights' and bias's gradients.
    inputs: Buffer,
    /// ∂z of the layer being differentiated and ∂a of its input, `[units, columns]`.
    grad_out: Buffer,
    grad_in: Buffer,
    /// A layer's weights at its live outputs (and live inputs), packed for ∂a; its weights'
    /// gradient at its live outputs and inputs, before it is spread back over the layer.
    packed_left: Buffer,
    packed_gradient: Buffer,
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
        self.live.resize_with(sizes.len(), LiveUnits::default);
        self.live[0].all();
        self.packed_activations
            .resize_with(sizes.len(), Buffer::default);
        for (buffer, &units) in self.packed_activations.iter_mut().zip(&sizes) {
            buffer.resize(units * columns);
        }
        self.packed_weights
            .resize_with(sizes.len() - 1, Buffer::default);
        for (buffer, w) in self.packed_weights.iter_mut().zip(sizes.windows(2)) {
            buffer.resize(w[0] * w[1] + SLACK);
        }
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
        let most = |size: fn(&[usize]) -> usize| self.sizes.windows(2).map(size).max();
        self.packed_left
            .resize(most(|w| w[0] * w[1]).unwrap_or(0) + SLACK);
        self.packed_gradient
            .resize(most(|w| w[1] * padded(w[0] + 1)).unwrap_or(0));
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
        work.finite = all_finite(isa, &work.activations[0], sizes[0], columns, batch);
        for l in 0..layers {
            let (inputs, outputs) = (sizes[l], sizes[l + 1]);
            let hidden_output = l + 1 < layers;
            let (done, next) = work.activations.split_at_mut(l + 1);
            // A hidden layer's sums leave its input's dead units out; the output layer's
            // keep every term (`live_units.rs`).
            let live_inputs = work.live[l].subset().filter(|_| hidden_output);
            let packed_weights = &mut work.packed_weights[l];
            self.with_layer(l, |weight, bias| {
                let (left, depth, right) = match live_inputs {
                    Some(live) => {
                        pack_columns(isa, weight, inputs, outputs, &work.live[l], packed_weights);
                        let left = Strided {
                            data: packed_weights,
                            row_stride: live.len(),
                            column_stride: 1,
                        };
                        (left, live.len(), &work.packed_activations[l][..])
                    }
                    None => {
                        let left = Strided {
                            data: weight,
                            row_stride: inputs,
                            column_stride: 1,
                        };
                        (left, inputs, &done[l][..])
                    }
                };
                Product {
                    rows: outputs,
                    depth,
                    columns,
                    left,
                    right,
                    right_stride: columns,
                    start: Start::Bias(bias),
                    finish: if hidden_output {
                        Finish::Relu
                    } else {
                        Finish::Keep
                    },
                }
                .run(isa, &mut next[0], columns)
            })?;
            if hidden_output {
                let live = &mut work.live[l + 1];
                if work.keep_dead {
                    live.all();
                    work.finite &= all_finite(isa, &next[0], outputs, columns, batch);
                } else {
                    work.finite &= live.scan(isa, &next[0], outputs, columns, batch);
                }
                if let Some(units) = live.subset() {
                    let packed = &mut work.packed_activations[l + 1];
                    pack_rows(&next[0], columns, columns, units, packed);
                }
            }
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
        // Dead units are left out only where every input was finite (`live_units.rs`); δ
        // (`grad_out`) then holds the live units' rows only.
        let live = |h: usize| work.live[h].subset().filter(|_| work.finite);
        for l in (0..layers).rev() {
            let (inputs, outputs) = (sizes[l], sizes[l + 1]);
            let stride = padded(inputs + 1);
            let live_outputs = live(l + 1).filter(|_| l + 1 < layers);
            let live_inputs = live(l).filter(|_| l > 0);
            let computed_rows = live_outputs.map_or(outputs, <[u32]>::len);
            let input = &work.activations[l];
            // ∂W's columns are the live inputs' only, then the bias's (its dead inputs'
            // columns are zeros: `live_units.rs`).
            let (live_input_rows, transposed) = match live_inputs {
                Some(live) => (live.len(), &work.packed_activations[l][..]),
                None => (inputs, &input[..]),
            };
            let packed_stride = padded(live_input_rows + 1);
            Transpose {
                src: transposed,
                src_stride: columns,
                rows: live_input_rows,
                columns: batch,
            }
            .run(isa, &mut work.inputs, packed_stride);
            for row in work.inputs.chunks_exact_mut(packed_stride).take(batch) {
                row[live_input_rows] = 1.0;
            }
            let (weight, bias) = match &mut work.gradients.parameters[2 * l..] {
                [weight, bias, ..] => (weight, bias),
                _ => unreachable!("two gradients per layer"),
            };
            let gradient = Product {
                rows: computed_rows,
                depth: batch,
                columns: packed_stride,
                left: Strided {
                    data: &work.grad_out,
                    row_stride: columns,
                    column_stride: 1,
                },
                right: &work.inputs,
                right_stride: packed_stride,
                start: Start::Zero,
                finish: Finish::Keep,
            };
            if live_outputs.is_none() && live_inputs.is_none() {
                gradient.run(isa, &mut weight.values, stride);
            } else {
                gradient.run(isa, &mut work.packed_gradient, packed_stride);
                let live_input_units = live_inputs.map(|_| &work.live[l]);
                spread_gradient(
                    isa,
                    &work.packed_gradient,
                    packed_stride,
                    live_outputs,
                    live_input_units,
                    outputs,
                    (inputs, stride),
                    &mut weight.values,
                );
            }
            for (o, db) in bias.values.iter_mut().enumerate() {
                *db = weight.values[o * stride + inputs];
            }
            if l > 0 {
                let (packed_left, packed_weights) = (&mut work.packed_left, &work.packed_weights);
                self.with_layer(l, |weight, _| {
                    // left[i][o] = Wₗ[o][i], over the live outputs and inputs.
                    let (data, column_stride): (&[f32], usize) = match (live_outputs, live_inputs) {
                        (None, None) => (weight, inputs),
                        (Some(outs), None) => {
                            pack_rows(weight, inputs, inputs, outs, packed_left);
                            (packed_left, inputs)
                        }
                        // The forward pass packed a hidden layer's live inputs' columns.
                        (None, Some(ins)) if l + 1 < layers => (&packed_weights[l], ins.len()),
                        (None, Some(ins)) => {
                            pack_columns(isa, weight, inputs, outputs, &work.live[l], packed_left);
                            (packed_left, ins.len())
                        }
                        (Some(outs), Some(ins)) => {
                            let width = ins.len();
                            pack_rows(&packed_weights[l], width, width, outs, packed_left);
                            (packed_left, width)
                        }
                    };
                    let mask = match live_inputs {
                        Some(_) => &work.packed_activations[l][..],
                        None => &input[..],
                    };
                    Product {
                        rows: live_inputs.map_or(inputs, <[u32]>::len),
                        depth: computed_rows,
                        columns,
                        left: Strided {
                            data,
                            row_stride: 1,
                            column_stride,
                        },
                        right: &work.grad_out,
                        right_stride: columns,
                        start: Start::Zero,
                        finish: Finish::MaskBy(mask),
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
    use rand::{rngs::StdRng, Rng, SeedableRng};

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

    /// A network whose biases leave units dead for some minibatches in every hidden layer.
    fn sparse_net(seed: u64) -> QNet {
        let mut rng = StdRng::seed_from_u64(seed);
        let net = QNet::new(Architecture::new(4, &[40, 37, 50], 3), &mut rng).unwrap();
        for var in net.parameters().iter().skip(1).step_by(2) {
            var.set(&Tensor::randn(-0.4f32, 0.6, var.shape(), &Device::Cpu).unwrap())
                .unwrap();
        }
        net
    }

    fn random_values(n: usize, scale: f32, rng: &mut StdRng) -> Vec<f32> {
        (0..n).map(|_| rng.random_range(-scale..scale)).collect()
    }

    fn bits(values: impl IntoIterator<Item = f32>) -> Vec<u32> {
        values.into_iter().map(f32::to_bits).collect()
    }

    /// The gradient values, with a zero of either sign read as `+0` (as Adam reads it).
    fn unsigned_zero_bits(work: &Workspace) -> Vec<u32> {
        let rows = work.gradients().rows().collect::<Vec<_>>();
        let values = rows.iter().flat_map(|r| {
            r.values
                .chunks(r.stride)
                .flat_map(|row| &row[..r.columns])
                .map(|&x| if x == 0.0 { 0.0 } else { x })
        });
        bits(values)
    }

    /// `live_units.rs`'s claim: leaving dead units out changes no Q-value, and no gradient
    /// but for the sign of a zero, on every path, for minibatches with a padded tail.
    #[test]
    fn leaving_dead_units_out_changes_no_q_value_and_no_gradient_but_a_zeros_sign() {
        let net = sparse_net(3);
        let mut rng = StdRng::seed_from_u64(4);
        let mut some_dead = 0;
        for batch in [1, 9, 32, 40] {
            let obs = random_values(batch * 4, 2.0, &mut rng);
            let grad_q = random_values(batch * 3, 1.0, &mut rng);
            for isa in Isa::ALL.into_iter().filter(|i| i.supported()) {
                let mut kept = Workspace {
                    keep_dead: true,
                    ..Workspace::default()
                };
                let mut left_out = Workspace::default();
                let q_kept = bits(
                    net.forward_with(isa, &obs, batch, &mut kept)
                        .unwrap()
                        .to_vec(),
                );
                let q = bits(
                    net.forward_with(isa, &obs, batch, &mut left_out)
                        .unwrap()
                        .to_vec(),
                );
                assert_eq!(q, q_kept, "{isa:?}, batch {batch}");
                some_dead += left_out
                    .live
                    .iter()
                    .filter(|l| l.subset().is_some())
                    .count();
                net.backward_with(isa, &mut kept, &grad_q).unwrap();
                net.backward_with(isa, &mut left_out, &grad_q).unwrap();
                assert_eq!(
                    unsigned_zero_bits(&left_out),
                    unsigned_zero_bits(&kept),
                    "{isa:?}, batch {batch}"
                );
            }
        }
        assert!(
            some_dead > 8,
            "the minibatches left units dead ({some_dead} layers)"
        );
    }

    /// Adam on the gradients of passes that leave dead units out gives the weights of Adam on
    /// passes that do not, to the bit, update after update.
    #[test]
    fn leaving_dead_units_out_gives_the_same_weights_after_every_update() {
        let config = crate::dqn::DqnConfig::default();
        let net = sparse_net(5);
        let twin = net.deep_copy().unwrap();
        let (mut adam, mut twin_adam) = (
            crate::dqn::Adam::new(net.parameters(), &config),
            crate::dqn::Adam::new(twin.parameters(), &config),
        );
        let mut kept = Workspace {
            keep_dead: true,
            ..Workspace::default()
        };
        let mut left_out = Workspace::default();
        let mut rng = StdRng::seed_from_u64(6);
        let isa = Isa::current();
        for update in 0..60 {
            let batch = [32, 7][update % 2];
            let obs = random_values(batch * 4, 2.0, &mut rng);
            let grad_q = random_values(batch * 3, 1.0, &mut rng);
            net.forward_with(isa, &obs, batch, &mut left_out).unwrap();
            net.backward_with(isa, &mut left_out, &grad_q).unwrap();
            adam.step(net.parameters(), left_out.gradients()).unwrap();
            twin.forward_with(isa, &obs, batch, &mut kept).unwrap();
            twin.backward_with(isa, &mut kept, &grad_q).unwrap();
            twin_adam.step(twin.parameters(), kept.gradients()).unwrap();
        }
        let weights = |net: &QNet| -> Vec<u32> {
            let values = net
                .parameters()
                .iter()
                .flat_map(|p| p.flatten_all().unwrap().to_vec1::<f32>().unwrap());
            bits(values)
        };
        let (a, b) = (weights(&net), weights(&twin));
        let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
        assert_eq!(differ, 0, "weights that differ, of {}", a.len());
    }

    /// With an infinite activation, the backward pass leaves out nothing (a dead unit's
    /// weight gradient is then `0·∞`, NaN, in the full pass): the same bits, NaNs included.
    #[test]
    fn a_non_finite_activation_makes_the_backward_pass_leave_nothing_out() {
        let net = sparse_net(7);
        let mut rng = StdRng::seed_from_u64(8);
        let batch = 9;
        let mut obs = random_values(batch * 4, 2.0, &mut rng);
        obs[4..8].fill(f32::MAX); // the hidden layers' sums overflow
        let grad_q = random_values(batch * 3, 1.0, &mut rng);
        let isa = Isa::current();
        let mut kept = Workspace {
            keep_dead: true,
            ..Workspace::default()
        };
        let mut left_out = Workspace::default();
        net.forward_with(isa, &obs, batch, &mut kept).unwrap();
        net.forward_with(isa, &obs, batch, &mut left_out).unwrap();
        assert!(!left_out.finite, "an activation overflows");
        net.backward_with(isa, &mut kept, &grad_q).unwrap();
        net.backward_with(isa, &mut left_out, &grad_q).unwrap();
        let all = |work: &Workspace| -> Vec<u32> {
            let rows = work.gradients().rows().collect::<Vec<_>>();
            let values = rows.iter().flat_map(|r| {
                r.values
                    .chunks(r.stride)
                    .flat_map(|row| row[..r.columns].to_vec())
            });
            bits(values.collect::<Vec<_>>())
        };
        let (a, b) = (all(&left_out), all(&kept));
        let nan = a.iter().filter(|&&x| f32::from_bits(x).is_nan()).count();
        assert!(nan > 0, "the full pass's gradient holds NaNs");
        let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
        assert_eq!(differ, 0, "gradient values that differ, of {}", a.len());
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
