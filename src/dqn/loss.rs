//! The DQN loss: Huber on the TD error of the taken actions, mean over the batch
//! (ChainerRL's `clip_delta=True` with `batch_accumulator="mean"`).

use std::sync::Arc;

use candle_core::{bail, CpuStorage, CustomOp1, Layout, Result, Shape, Tensor};

use super::host::with_f32;

/// Huber loss of one error `x`: `x²/2` while `|x| ≤ δ`, then `δ(|x| − δ/2)`.
pub fn huber(x: f64, delta: f64) -> f64 {
    let a = x.abs();
    if a <= delta {
        0.5 * a * a
    } else {
        delta * (a - 0.5 * delta)
    }
}

/// `mean_b huber(q[b, actions[b]] − targets[b])` as a scalar tensor that backpropagates
/// into `q` (`[batch, action_count]`).
///
/// One fused op rather than gather, subtract, abs, compare, select and mean: each candle op
/// allocates and adds a node to the backward graph, and at DQN's sizes that overhead costs
/// more than the arithmetic.
///
/// # Panics
/// If `actions` and `targets` do not have one entry per row of `q`.
pub fn td_huber_loss(q: &Tensor, actions: &[u32], targets: &[f32], delta: f64) -> Result<Tensor> {
    let (batch, _) = q.dims2()?;
    assert_eq!(actions.len(), batch, "one action per row");
    assert_eq!(targets.len(), batch, "one target per row");
    q.apply_op1_arc(Arc::new(Box::new(TdHuber {
        actions: actions.to_vec(),
        targets: targets.to_vec(),
        delta: delta as f32,
    })))
}

struct TdHuber {
    actions: Vec<u32>,
    targets: Vec<f32>,
    delta: f32,
}

impl TdHuber {
    /// `q[b, a_b] − y_b` for every row.
    fn errors<'a>(&'a self, q: &'a [f32]) -> impl Iterator<Item = f32> + 'a {
        let actions_per_row = q.len() / self.targets.len();
        self.actions
            .iter()
            .zip(&self.targets)
            .enumerate()
            .map(move |(b, (&a, &y))| q[b * actions_per_row + a as usize] - y)
    }
}

impl CustomOp1 for TdHuber {
    fn name(&self) -> &'static str {
        "td-huber-loss"
    }

    fn cpu_fwd(&self, storage: &CpuStorage, layout: &Layout) -> Result<(CpuStorage, Shape)> {
        let Some((start, end)) = layout.contiguous_offsets() else {
            bail!("td-huber-loss needs contiguous Q-values")
        };
        let q = &storage.as_slice::<f32>()?[start..end];
        if let Some(&a) = self
            .actions
            .iter()
            .find(|&&a| a as usize >= layout.dims()[1])
        {
            bail!("action {a} out of range for {} actions", layout.dims()[1])
        }
        let delta = f64::from(self.delta);
        let sum: f64 = self.errors(q).map(|x| huber(f64::from(x), delta)).sum();
        let mean = (sum / self.targets.len() as f64) as f32;
        Ok((CpuStorage::F32(vec![mean]), Shape::from(())))
    }

    /// d loss / d q[b, a_b] = clamp(q[b, a_b] − y_b, −δ, δ) / batch; zero for other actions.
    fn bwd(&self, q: &Tensor, _loss: &Tensor, grad_loss: &Tensor) -> Result<Option<Tensor>> {
        let (batch, actions_per_row) = q.dims2()?;
        let scale = grad_loss.to_scalar::<f32>()? / batch as f32;
        let grad = with_f32(q, |q| {
            let mut grad = vec![0.0f32; q.len()];
            for (b, x) in self.errors(q).enumerate() {
                let a = self.actions[b] as usize;
                grad[b * actions_per_row + a] = x.clamp(-self.delta, self.delta) * scale;
            }
            grad
        })?;
        Ok(Some(Tensor::from_vec(grad, q.shape(), q.device())?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use candle_core::{Device, Var};

    #[test]
    fn huber_by_hand() {
        assert_eq!(huber(0.0, 1.0), 0.0);
        assert_eq!(huber(0.5, 1.0), 0.125);
        assert_eq!(huber(-0.5, 1.0), 0.125);
        assert_eq!(huber(1.0, 1.0), 0.5);
        assert_eq!(huber(3.0, 1.0), 2.5);
        assert_eq!(huber(-3.0, 1.0), 2.5);
        assert_eq!(huber(3.0, 2.0), 4.0);
    }

    #[test]
    fn td_loss_by_hand() {
        // Errors: 0.5 − 0 = 0.5 (row 0, action 1) and 2 − (−1) = 3 (row 1, action 0).
        let q = Tensor::new(&[[9.0f32, 0.5], [2.0, 9.0]], &Device::Cpu).unwrap();
        let loss = td_huber_loss(&q, &[1, 0], &[0.0, -1.0], 1.0).unwrap();
        assert_eq!(loss.to_scalar::<f32>().unwrap(), (0.125 + 2.5) / 2.0);
    }

    #[test]
    fn matches_candle_huber_and_its_gradient() {
        let q = Var::new(
            &[[0.3f32, -1.2, 4.0], [2.5, 0.1, -0.7], [0.0, 0.2, 0.4]],
            &Device::Cpu,
        )
        .unwrap();
        let actions = [2u32, 0, 1];
        let targets = [1.0f32, 0.0, 0.5];
        let ours = td_huber_loss(q.as_tensor(), &actions, &targets, 1.0).unwrap();
        let index = Tensor::new(&[[2u32], [0], [1]], &Device::Cpu).unwrap();
        let taken = q.as_tensor().gather(&index, 1).unwrap().squeeze(1).unwrap();
        let y = Tensor::new(&targets, &Device::Cpu).unwrap();
        let reference = candle_nn::loss::huber(&taken, &y, 1.0).unwrap();
        let (a, b) = (
            ours.to_scalar::<f32>().unwrap(),
            reference.to_scalar::<f32>().unwrap(),
        );
        assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        let g_ours = ours
            .backward()
            .unwrap()
            .get(q.as_tensor())
            .unwrap()
            .to_vec2::<f32>();
        let g_ref = reference
            .backward()
            .unwrap()
            .get(q.as_tensor())
            .unwrap()
            .to_vec2::<f32>();
        let (g_ours, g_ref) = (g_ours.unwrap(), g_ref.unwrap());
        for (x, y) in g_ours.iter().flatten().zip(g_ref.iter().flatten()) {
            assert!((x - y).abs() < 1e-6, "{g_ours:?} vs {g_ref:?}");
        }
        // The clipped error: 4 − 1 = 3 → δ/3, 2.5 → δ/3, −0.3 → −0.1.
        assert_eq!(g_ours[0][2], 1.0 / 3.0);
        assert!((g_ours[2][1] + 0.1).abs() < 1e-6);
    }

    #[test]
    fn refuses_an_out_of_range_action() {
        let q = Tensor::zeros((1, 2), candle_core::DType::F32, &Device::Cpu).unwrap();
        assert!(td_huber_loss(&q, &[2], &[0.0], 1.0).is_err());
    }
}
