//! The MLP's forward and backward passes, written out by hand.
//!
//! candle's autograd is general: each backward step allocates a zero gradient, adds into
//! it, and rebuilds ReLU's derivative from four tensor operations. For a DQN minibatch
//! (32 rows of ~100 units) that bookkeeping cost more than the matrix products, so the
//! update uses these passes instead (`tests` checks them against candle's autograd):
//!
//! ```text
//! forward:   zₗ = aₗ₋₁·Wₗᵀ + bₗ      aₗ = relu(zₗ)   (no ReLU on the output layer)
//! backward:  ∂Wₗ = ∂zₗᵀ·aₗ₋₁        ∂bₗ = Σ_rows ∂zₗ
//!            ∂zₗ₋₁ = (∂zₗ·Wₗ) ⊙ [aₗ₋₁ > 0]
//! ```
//!
//! Bias, ReLU and the ReLU mask are applied in place on the fresh output of each matrix
//! product, so a layer costs one allocation per pass.

use candle_core::{bail, CpuStorage, InplaceOp2, Layout, Result, Tensor};

use super::host::with_f32;
use super::QNet;

impl QNet {
    /// Q-values `[batch, action_count]` of `obs`, and the input of every layer (`obs` first),
    /// which [`QNet::backward`] needs.
    pub(crate) fn forward_train(&self, obs: &Tensor) -> Result<(Tensor, Vec<Tensor>)> {
        let mut inputs = Vec::with_capacity(self.layers().len());
        let mut x = obs.clone();
        let last = self.layers().len() - 1;
        for (i, layer) in self.layers().iter().enumerate() {
            let z = x.matmul(&layer.weight().t()?)?;
            let bias = layer.bias().expect("every layer has a bias");
            z.inplace_op2(bias, &AddBias { relu: i < last })?;
            inputs.push(std::mem::replace(&mut x, z));
        }
        Ok((x, inputs))
    }

    /// Gradients of the loss with respect to every parameter, in the order of
    /// [`QNet::parameters`], given `grad_q = ∂loss/∂q` and the inputs
    /// [`QNet::forward_train`] returned.
    pub(crate) fn backward(&self, inputs: &[Tensor], grad_q: Tensor) -> Result<Vec<Tensor>> {
        let layers = self.layers();
        let mut grads = vec![None; 2 * layers.len()];
        let mut grad_z = grad_q;
        for (l, (layer, input)) in layers.iter().zip(inputs).enumerate().rev() {
            grads[2 * l] = Some(grad_z.t()?.matmul(input)?);
            grads[2 * l + 1] = Some(column_sums(&grad_z)?);
            if l > 0 {
                let grad_input = grad_z.matmul(layer.weight())?;
                grad_input.inplace_op2(input, &ReluMask)?;
                grad_z = grad_input;
            }
        }
        Ok(grads
            .into_iter()
            .map(|g| g.expect("every layer visited"))
            .collect())
    }
}

/// `Σ_rows t` of a `[rows, columns]` tensor. candle's `sum(0)` walks the rows with a strided
/// index per element and cost more than the matrix products here.
fn column_sums(t: &Tensor) -> Result<Tensor> {
    let (_, columns) = t.dims2()?;
    let sums = with_f32(t, |values| {
        let mut sums = vec![0.0f32; columns];
        for row in values.chunks_exact(columns) {
            for (s, &v) in sums.iter_mut().zip(row) {
                *s += v;
            }
        }
        sums
    })?;
    Tensor::from_vec(sums, columns, t.device())
}

/// `z ← z + b` row by row, then ReLU if asked.
struct AddBias {
    relu: bool,
}

impl InplaceOp2 for AddBias {
    fn name(&self) -> &'static str {
        "add-bias"
    }

    fn cpu_fwd(
        &self,
        z: &mut CpuStorage,
        z_l: &Layout,
        b: &CpuStorage,
        b_l: &Layout,
    ) -> Result<()> {
        let (z, b) = f32_slices(z, z_l, b, b_l)?;
        for row in z.chunks_exact_mut(b.len()) {
            for (z, &b) in row.iter_mut().zip(b) {
                let v = *z + b;
                *z = if self.relu { v.max(0.0) } else { v };
            }
        }
        Ok(())
    }
}

/// `∂a ← ∂a ⊙ [a > 0]`: ReLU's derivative, read from its output.
struct ReluMask;

impl InplaceOp2 for ReluMask {
    fn name(&self) -> &'static str {
        "relu-mask"
    }

    fn cpu_fwd(
        &self,
        g: &mut CpuStorage,
        g_l: &Layout,
        a: &CpuStorage,
        a_l: &Layout,
    ) -> Result<()> {
        let (g, a) = f32_slices(g, g_l, a, a_l)?;
        if g.len() != a.len() {
            bail!(
                "relu-mask: {} gradients for {} activations",
                g.len(),
                a.len()
            )
        }
        // Branch-free: the sign of a ReLU unit is a coin flip the predictor cannot learn.
        for (g, &a) in g.iter_mut().zip(a) {
            let keep = u32::from(a > 0.0).wrapping_neg();
            *g = f32::from_bits(g.to_bits() & keep);
        }
        Ok(())
    }
}

/// The contiguous `f32` data of an in-place op's destination and source.
fn f32_slices<'a>(
    dst: &'a mut CpuStorage,
    dst_l: &Layout,
    src: &'a CpuStorage,
    src_l: &Layout,
) -> Result<(&'a mut [f32], &'a [f32])> {
    let (CpuStorage::F32(dst), CpuStorage::F32(src)) = (dst, src) else {
        bail!("expected f32 tensors")
    };
    let (Some((d0, d1)), Some((s0, s1))) = (dst_l.contiguous_offsets(), src_l.contiguous_offsets())
    else {
        bail!("expected contiguous tensors")
    };
    Ok((&mut dst[d0..d1], &src[s0..s1]))
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

    #[test]
    fn matches_candle_autograd() {
        let mut rng = StdRng::seed_from_u64(0);
        let net = QNet::new(Architecture::new(4, &[7, 5, 6], 3), &mut rng).unwrap();
        // Non-zero biases, so the ReLU masks differ from layer to layer.
        for var in net.parameters().iter().skip(1).step_by(2) {
            var.set(&Tensor::randn(0f32, 0.5, var.shape(), &Device::Cpu).unwrap())
                .unwrap();
        }
        let obs = Tensor::randn(0f32, 1.0, (9, 4), &Device::Cpu).unwrap();
        let weights = Tensor::randn(0f32, 1.0, (9, 3), &Device::Cpu).unwrap();

        let reference_q = autograd_forward(&net, &obs);
        let loss = (&reference_q * &weights).unwrap().sum_all().unwrap();
        let reference = loss.backward().unwrap();

        let (q, inputs) = net.forward_train(&obs).unwrap();
        assert_eq!(
            q.to_vec2::<f32>().unwrap(),
            reference_q.to_vec2::<f32>().unwrap()
        );
        assert_eq!(
            q.to_vec2::<f32>().unwrap(),
            net.forward(&obs).unwrap().to_vec2::<f32>().unwrap()
        );
        let grads = net.backward(&inputs, weights).unwrap();
        for (var, grad) in net.parameters().iter().zip(&grads) {
            let want = reference.get(var).unwrap();
            assert_eq!(grad.dims(), want.dims());
            let diff = (grad - want).unwrap().abs().unwrap().max_all().unwrap();
            assert!(diff.to_scalar::<f32>().unwrap() < 1e-5);
        }
    }
}
