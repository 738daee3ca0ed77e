//! The DQN loss: Huber on the TD error of the taken actions, mean over the batch
//! (ChainerRL's `clip_delta=True` with `batch_accumulator="mean"`).

use super::DqnError;

/// Huber loss of one error `x`: `x²/2` while `|x| ≤ δ`, then `δ(|x| − δ/2)`.
pub fn huber(x: f64, delta: f64) -> f64 {
    let a = x.abs();
    if a <= delta {
        0.5 * a * a
    } else {
        delta * (a - 0.5 * delta)
    }
}

/// The loss `mean_b huber(q[b, a_b] − y_b)` and its gradient with respect to `q`, for
/// Q-values `q` (`[batch, action_count]`, row-major), the actions `a` taken and the TD
/// targets `y`. The gradient is `clamp(q[b, a_b] − y_b, −δ, δ) / batch` at the taken
/// actions and zero elsewhere.
///
/// Computed on plain slices: a chain of candle ops (gather, subtract, abs, compare, select,
/// mean, and their backward) allocates a tensor per step for 32 numbers.
///
/// # Panics
/// If `actions` and `targets` do not have one entry per row of `q`.
pub fn td_huber_loss(
    q: &[f32],
    actions: &[u32],
    targets: &[f32],
    delta: f64,
) -> Result<(f64, Vec<f32>), DqnError> {
    let batch = targets.len();
    assert_eq!(actions.len(), batch, "one action per row");
    assert!(
        batch > 0 && q.len().is_multiple_of(batch),
        "one row of Q-values per target"
    );
    let action_count = q.len() / batch;
    let mut grad = vec![0.0f32; q.len()];
    let mut sum = 0.0f64;
    for (b, (&a, &y)) in actions.iter().zip(targets).enumerate() {
        let a = a as usize;
        if a >= action_count {
            return Err(DqnError::ActionOutOfRange {
                action: a,
                action_count,
            });
        }
        let error = f64::from(q[b * action_count + a]) - f64::from(y);
        sum += huber(error, delta);
        grad[b * action_count + a] = (error.clamp(-delta, delta) / batch as f64) as f32;
    }
    Ok((sum / batch as f64, grad))
}

#[cfg(test)]
mod tests {
    use super::*;
    use candle_core::{Device, Tensor, Var};

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
        let q = [9.0, 0.5, 2.0, 9.0];
        let (loss, grad) = td_huber_loss(&q, &[1, 0], &[0.0, -1.0], 1.0).unwrap();
        assert_eq!(loss, (0.125 + 2.5) / 2.0);
        assert_eq!(grad, [0.0, 0.25, 0.5, 0.0]);
    }

    #[test]
    fn matches_candle_huber_and_its_gradient() {
        let values = [[0.3f32, -1.2, 4.0], [2.5, 0.1, -0.7], [0.0, 0.2, 0.4]];
        let q = Var::new(&values, &Device::Cpu).unwrap();
        let actions = [2u32, 0, 1];
        let targets = [1.0f32, 0.0, 0.5];
        let flat: Vec<f32> = values.iter().flatten().copied().collect();
        let (loss, grad) = td_huber_loss(&flat, &actions, &targets, 1.0).unwrap();

        let index = Tensor::new(&[[2u32], [0], [1]], &Device::Cpu).unwrap();
        let taken = q.as_tensor().gather(&index, 1).unwrap().squeeze(1).unwrap();
        let y = Tensor::new(&targets, &Device::Cpu).unwrap();
        let reference = candle_nn::loss::huber(&taken, &y, 1.0).unwrap();
        let want = f64::from(reference.to_scalar::<f32>().unwrap());
        assert!((loss - want).abs() < 1e-6, "{loss} vs {want}");
        let want = reference
            .backward()
            .unwrap()
            .get(q.as_tensor())
            .unwrap()
            .flatten_all();
        for (x, y) in grad.iter().zip(want.unwrap().to_vec1::<f32>().unwrap()) {
            assert!((x - y).abs() < 1e-6, "{grad:?}");
        }
        // The clipped errors: 4 − 1 = 3 → δ/3; −0.3 → −0.1.
        assert_eq!(grad[2], 1.0 / 3.0);
        assert!((grad[7] + 0.1).abs() < 1e-6);
    }

    #[test]
    fn refuses_an_out_of_range_action() {
        let err = td_huber_loss(&[0.0, 0.0], &[2], &[0.0], 1.0).unwrap_err();
        assert!(matches!(
            err,
            DqnError::ActionOutOfRange {
                action: 2,
                action_count: 2
            }
        ));
    }
}
