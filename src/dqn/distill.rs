//! QDagger's distillation term (Agarwal et al., "Reincarnating Reinforcement Learning",
//! NeurIPS 2022): the cross-entropy between the teacher's and the student's softmax over
//! Q-values at temperature τ,
//!
//! ```text
//! L_distil = mean_b Σ_a −softmax(Q_T(s_b)/τ)_a · log softmax(Q_S(s_b)/τ)_a
//! ∂L_distil/∂Q_S(s_b, a) = (softmax(Q_S(s_b)/τ)_a − softmax(Q_T(s_b)/τ)_a) / (τ · batch)
//! ```
//!
//! The mean over the batch is the paper's expectation over states. CleanRL's
//! `qdagger_dqn_*` sums its KL over the batch (a `torch.mean` of a scalar), which weighs the
//! term `batch` times as much; its KL differs from this cross-entropy by the teacher's
//! entropy, a constant of the student, so their gradients are the same up to that factor.

/// The distillation loss of `student` Q-values against `teacher`'s (`[batch, actions]`,
/// row-major, the same shape) at `temperature`, and its gradient with respect to
/// `student`. Each row's softmax is taken after subtracting its maximum, so large Q-values
/// cannot overflow.
///
/// # Panics
/// If the shapes differ, or `actions` does not divide them.
pub fn distillation_loss(
    student: &[f32],
    teacher: &[f32],
    actions: usize,
    temperature: f64,
) -> (f64, Vec<f32>) {
    assert_eq!(
        student.len(),
        teacher.len(),
        "one teacher row per student row"
    );
    assert!(actions > 0 && student.len().is_multiple_of(actions));
    let batch = student.len() / actions;
    let mut grad = vec![0.0f32; student.len()];
    let mut total = 0.0;
    let rows = student
        .chunks_exact(actions)
        .zip(teacher.chunks_exact(actions));
    for (b, (s, t)) in rows.enumerate() {
        let log_s = log_softmax(s, temperature);
        let log_t = log_softmax(t, temperature);
        for a in 0..actions {
            let p_t = log_t[a].exp();
            total -= p_t * log_s[a];
            let g = (log_s[a].exp() - p_t) / (temperature * batch as f64);
            grad[b * actions + a] = g as f32;
        }
    }
    (total / batch as f64, grad)
}

/// `log softmax(row / temperature)`, in f64.
fn log_softmax(row: &[f32], temperature: f64) -> Vec<f64> {
    let scaled: Vec<f64> = row.iter().map(|&q| f64::from(q) / temperature).collect();
    let max = scaled.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let log_sum = scaled.iter().map(|&x| (x - max).exp()).sum::<f64>().ln() + max;
    scaled.iter().map(|&x| x - log_sum).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The numbers PyTorch gives (autograd of `−(softmax(t/τ)·log_softmax(s/τ)).sum(-1).mean()`
    /// in f64): tests/fixtures/qdagger/distillation_reference.py prints them.
    #[test]
    fn loss_and_gradient_equal_pytorchs() {
        let student = [
            1.5, -0.25, 0.75, 10.0, 12.0, 11.0, -3.0, -3.5, -2.0, 0.0, 0.0, 0.0,
        ];
        let teacher = [
            0.5, 2.0, -1.0, 40.0, 39.0, 41.5, -1.0, -4.0, -2.5, 3.0, 1.0, 2.0,
        ];
        let expected: [(f64, f64, [f64; 12]); 3] = [
            (
                1.0,
                1.456369598474,
                [
                    0.108047792481,
                    -0.170008141994,
                    0.061960349514,
                    -0.020230551757,
                    0.150587735632,
                    -0.130357183875,
                    -0.138593284242,
                    0.025282952474,
                    0.113310331768,
                    -0.08297690561,
                    0.060825690041,
                    0.02215121557,
                ],
            ),
            (
                0.5,
                2.239025102590,
                [
                    0.375280935493,
                    -0.463118221705,
                    0.087837286213,
                    -0.015623588274,
                    0.430217935637,
                    -0.414594347363,
                    -0.418067506156,
                    0.019827216527,
                    0.39824028963,
                    -0.266739999432,
                    0.158728546678,
                    0.108011452754,
                ],
            ),
            (
                2.0,
                1.191622721591,
                [
                    0.024581288331,
                    -0.048960446709,
                    0.024379158379,
                    -0.010279823354,
                    0.042948639495,
                    -0.032668816142,
                    -0.037255212491,
                    0.011952265734,
                    0.025302946757,
                    -0.021643382215,
                    0.018376201263,
                    0.003267180952,
                ],
            ),
        ];
        for (temperature, loss, grad) in expected {
            let (got_loss, got_grad) = distillation_loss(&student, &teacher, 3, temperature);
            assert!(
                (got_loss - loss).abs() < 1e-9,
                "τ {temperature}: {got_loss} vs {loss}"
            );
            for (got, want) in got_grad.iter().zip(grad) {
                assert!(
                    (f64::from(*got) - want).abs() < 1e-7,
                    "τ {temperature}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn equal_q_values_cost_the_teachers_entropy_and_pull_nowhere() {
        // Two actions with equal values: softmax (½, ½), CE = ln 2, gradient 0.
        let (loss, grad) = distillation_loss(&[1.0, 1.0], &[3.0, 3.0], 2, 1.0);
        assert!((loss - 2f64.ln()).abs() < 1e-12);
        assert_eq!(grad, [0.0, 0.0]);
    }

    #[test]
    fn the_gradient_is_the_softmax_difference_over_temperature_and_batch() {
        // Student row (0, 0): p_S = (½, ½); teacher (ln 3, 0) at τ = 1: p_T = (¾, ¼).
        // CE = −(¾ ln ½ + ¼ ln ½) = ln 2; ∂/∂Q_S = (½ − ¾, ½ − ¼) / 1 = (−¼, ¼).
        let teacher = [3f32.ln(), 0.0];
        let (loss, grad) = distillation_loss(&[0.0, 0.0], &teacher, 2, 1.0);
        assert!((loss - 2f64.ln()).abs() < 1e-7);
        assert!((grad[0] + 0.25).abs() < 1e-7 && (grad[1] - 0.25).abs() < 1e-7);
        // Two rows halve each row's share; τ = 2 halves the gradient again and softens p_T
        // to (√3, 1)/(√3 + 1).
        let (_, grad) =
            distillation_loss(&[0.0, 0.0, 0.0, 0.0], &[teacher, teacher].concat(), 2, 2.0);
        let p_t0 = 3f64.sqrt() / (3f64.sqrt() + 1.0);
        assert!((f64::from(grad[0]) - (0.5 - p_t0) / 4.0).abs() < 1e-7);
        assert_eq!(grad[0], grad[2]);
    }
}
