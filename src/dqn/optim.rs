//! Adam, fused into one pass over each parameter's memory.
//!
//! The update is Chainer's (the paper's library), which places ε differently from PyTorch:
//!
//! ```text
//! m ← β₁m + (1 − β₁)g        v ← β₂v + (1 − β₂)g²
//! θ ← θ − α·√(1 − β₂ᵗ)/(1 − β₁ᵗ) · m / (√v + ε)
//! ```
//!
//! PyTorch adds ε to the bias-corrected `√v̂` instead; the two agree once `β₂ᵗ` is small, but
//! with Table I's large ε (1e-3) Chainer's form takes smaller steps early on.
//!
//! candle-nn's `AdamW` spends about ten tensor operations (each an allocation) per parameter
//! per step; this one reads the gradient and writes the parameter and moments in place, on
//! the kernels' instruction set (`kernels/elementwise.rs`: the same bits on every path).
//! Moments below 1e-30 and gradients below 1e-18 are set to zero there: subnormal moments
//! (a dead unit's weights) made each step 35× slower on x86.

use std::cell::RefCell;

use candle_core::{bail, CpuStorage, InplaceOp1, Layout, Result, Var};

use super::kernels::{adam_rows, AdamStep, Buffer, Isa, Rows};
use super::Gradients;
use crate::dqn::DqnConfig;

/// Adam state for one list of parameters.
#[derive(Debug, Clone)]
pub struct Adam {
    learning_rate: f64,
    beta1: f64,
    beta2: f64,
    epsilon: f64,
    max_grad_norm: Option<f64>,
    /// Steps taken, `t` of the bias correction.
    t: i32,
    /// First and second moments of each parameter.
    moments: Vec<(Buffer, Buffer)>,
}

impl Adam {
    pub fn new(parameters: &[Var], config: &DqnConfig) -> Self {
        Self {
            learning_rate: config.learning_rate,
            beta1: config.adam_betas.0,
            beta2: config.adam_betas.1,
            epsilon: config.adam_epsilon,
            max_grad_norm: config.max_grad_norm,
            t: 0,
            moments: parameters
                .iter()
                .map(|p| {
                    let n = p.elem_count();
                    (Buffer::zeros(n), Buffer::zeros(n))
                })
                .collect(),
        }
    }

    /// One step on `parameters` (the same list, in the same order, as at construction)
    /// with their gradients `grads`, one per parameter.
    pub fn step(&mut self, parameters: &[Var], grads: &Gradients) -> Result<()> {
        assert_eq!(
            parameters.len(),
            self.moments.len(),
            "parameter list changed"
        );
        assert_eq!(grads.len(), parameters.len(), "one gradient per parameter");
        // PyTorch's `clip_grad_norm_`: every gradient times `max / (‖g‖ + 1e-6)` if below 1.
        let clip = match self.max_grad_norm {
            Some(max_norm) => (max_norm / (grads.sum_of_squares().sqrt() + 1e-6)).min(1.0),
            None => 1.0,
        };
        self.t += 1;
        let correction1 = 1.0 - self.beta1.powi(self.t);
        let correction2 = 1.0 - self.beta2.powi(self.t);
        let step = AdamStep {
            step_size: (self.learning_rate * correction2.sqrt() / correction1) as f32,
            beta1: self.beta1 as f32,
            beta2: self.beta2 as f32,
            epsilon: self.epsilon as f32,
            clip: clip as f32,
        };
        let isa = Isa::current();
        for ((parameter, grad), (m, v)) in
            parameters.iter().zip(grads.rows()).zip(&mut self.moments)
        {
            let kernel = AdamKernel {
                isa,
                step,
                grad,
                moments: RefCell::new((m, v)),
            };
            parameter.as_tensor().inplace_op1(&kernel)?;
        }
        Ok(())
    }
}

struct AdamKernel<'a> {
    isa: Isa,
    step: AdamStep,
    grad: Rows<'a>,
    /// `InplaceOp1::cpu_fwd` takes `&self`; the moments are this step's only other writes.
    moments: RefCell<(&'a mut Buffer, &'a mut Buffer)>,
}

impl InplaceOp1 for AdamKernel<'_> {
    fn name(&self) -> &'static str {
        "adam-step"
    }

    fn cpu_fwd(&self, storage: &mut CpuStorage, layout: &Layout) -> Result<()> {
        let CpuStorage::F32(theta) = storage else {
            bail!("adam-step works on f32 parameters")
        };
        let Some((start, end)) = layout.contiguous_offsets() else {
            bail!("adam-step needs contiguous parameters")
        };
        let theta = &mut theta[start..end];
        let (m, v) = &mut *self.moments.borrow_mut();
        let rows = theta.len() / self.grad.columns.max(1);
        if m.len() != theta.len() || rows * self.grad.columns != theta.len() {
            bail!(
                "adam-step: {} values, rows of {} gradients, {} moments",
                theta.len(),
                self.grad.columns,
                m.len()
            )
        }
        adam_rows(self.isa, &self.step, theta, m, v, self.grad);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use candle_core::{Device, Tensor};

    fn config() -> DqnConfig {
        DqnConfig::default()
    }

    fn step(adam: &mut Adam, theta: &Var, loss: &Tensor) {
        let grad = loss.backward().unwrap().get(theta).unwrap().clone();
        let grads = Gradients::from_tensors(&[grad]).unwrap();
        adam.step(std::slice::from_ref(theta), &grads).unwrap();
    }

    /// Chainer's update written out for one scalar parameter.
    fn chainer_adam(theta: f64, grads: &[f64], c: &DqnConfig) -> f64 {
        let (mut theta, mut m, mut v) = (theta, 0.0, 0.0);
        for (t, &g) in grads.iter().enumerate() {
            let t = t as i32 + 1;
            let (b1, b2) = c.adam_betas;
            m += (1.0 - b1) * (g - m);
            v += (1.0 - b2) * (g * g - v);
            let alpha = c.learning_rate * (1.0 - b2.powi(t)).sqrt() / (1.0 - b1.powi(t));
            theta -= alpha * m / (v.sqrt() + c.adam_epsilon);
        }
        theta
    }

    #[test]
    fn follows_chainers_update() {
        // loss = k·θ, so the gradient is k, a different constant at each step.
        let theta = Var::new(&[0.5f32], &Device::Cpu).unwrap();
        let mut adam = Adam::new(std::slice::from_ref(&theta), &config());
        let ks = [2.0, -0.5, 0.01, 3.0];
        for &k in &ks {
            let loss = (theta.as_tensor() * k).unwrap().sum_all().unwrap();
            step(&mut adam, &theta, &loss);
        }
        let got = f64::from(theta.as_tensor().to_vec1::<f32>().unwrap()[0]);
        let want = chainer_adam(0.5, &ks, &config());
        assert!((got - want).abs() < 1e-6, "{got} vs {want}");
    }

    #[test]
    fn clips_the_global_gradient_norm() {
        let theta = Var::new(&[0.0f32, 0.0], &Device::Cpu).unwrap();
        let c = DqnConfig {
            max_grad_norm: Some(1.0),
            ..config()
        };
        // Gradient (30, 40) has norm 50: clipped to (0.6, 0.8).
        let weights = Tensor::new(&[30.0f32, 40.0], &Device::Cpu).unwrap();
        let loss = theta.as_tensor().mul(&weights).unwrap().sum_all().unwrap();
        let mut adam = Adam::new(std::slice::from_ref(&theta), &c);
        step(&mut adam, &theta, &loss);
        let got = theta.as_tensor().to_vec1::<f32>().unwrap();
        let want = [chainer_adam(0.0, &[0.6], &c), chainer_adam(0.0, &[0.8], &c)];
        for (g, w) in got.iter().zip(want) {
            assert!((f64::from(*g) - w).abs() < 1e-6, "{got:?} vs {want:?}");
        }
    }
}
