//! Sources from other agents: a policy whose observation or action space differs from the
//! target's, reused through a declared inter-task mapping (Taylor, Stone & Liu, "Transfer
//! Learning via Inter-Task Mappings for Temporal Difference Learning", JMLR 8, 2007).
//!
//! - χ_X maps the target's state variables to the source's: the source's j-th input is the
//!   target's `state[j]`-th observation value;
//! - χ_A maps the source's actions to the target's: the source's a-th action is the
//!   target's `actions[a]`, or `None` when the target has nothing like it (a three-action
//!   CartPole's "no push").
//!
//! As the paper's transfer functional ρ does, the mapping is applied once, to the network:
//! [`InterTaskMapping::translate`] writes the source's Q-network as a network of the
//! target's spaces whose Q-values are the source's through the mapping,
//! `Q_target(s, χ_A(a)) = Q_source(χ_X(s), a)`. From there the policy acts, learns from
//! the shared replay buffer of the target's transitions, is judged and tested as any other
//! source: nothing downstream knows it came from another agent.
//!
//! A target action that no source action maps to (a two-action MountainCar source's "no
//! push") has no value in the source: its row starts as the mean of the mapped actions'
//! rows, so its Q-value is the mean of theirs. It is never above their largest (the source's
//! greedy choice stays its own) and is learned from the target's transitions that took it.

use candle_core::{Device, Tensor};

use crate::dqn::{Architecture, DqnError, QNet};

use crate::env::mapping::{InterTaskMapping, Spaces};

impl InterTaskMapping {
    /// The source's network `net` written in the target's spaces (module docs): the first
    /// layer's column of each source input moves to the target variable χ_X reads (a target
    /// variable no source input reads gets zeros, one read twice the sum), the last layer's
    /// row of each source action to its image under χ_A (a source action without one is
    /// dropped; a target action without a preimage gets the mapped rows' mean).
    ///
    /// The mapping must fit (`check`): `net`'s spaces are the source's.
    pub fn translate(&self, net: &QNet, target: Spaces) -> Result<QNet, DqnError> {
        let source = net.architecture();
        let hidden = source.hidden.clone();
        let mut values: Vec<Tensor> = net.named_parameters().into_iter().map(|(_, t)| t).collect();
        let layers = values.len() / 2;

        // χ_X on the first layer's weight [units, source inputs].
        let first = values[0].to_vec2::<f32>()?;
        let widened: Vec<Vec<f32>> = first
            .iter()
            .map(|row| {
                let mut out = vec![0.0; target.observation_size];
                for (j, &w) in row.iter().enumerate() {
                    out[self.state[j]] += w;
                }
                out
            })
            .collect();
        values[0] = matrix(widened)?;

        // χ_A on the last layer's weight [source actions, units] and bias.
        let (w, b) = (2 * (layers - 1), 2 * (layers - 1) + 1);
        let weights = values[w].to_vec2::<f32>()?;
        let biases = values[b].to_vec1::<f32>()?;
        // A target action without preimage starts as the mapped rows' mean (module docs).
        let mapped: Vec<usize> = (0..self.actions.len())
            .filter(|&a| self.actions[a].is_some())
            .collect();
        let n = mapped.len() as f32;
        // Summed, then divided: the study's runs were made with this order.
        let mut mean_row = vec![0.0; weights[mapped[0]].len()];
        for &a in &mapped {
            for (m, &v) in mean_row.iter_mut().zip(&weights[a]) {
                *m += v;
            }
        }
        mean_row.iter_mut().for_each(|m| *m /= n);
        let mean_bias = mapped.iter().fold(0.0, |sum, &a| sum + biases[a]) / n;
        let preimage = |t: usize| self.actions.iter().position(|&i| i == Some(t));
        let (rows, bias): (Vec<Vec<f32>>, Vec<f32>) = (0..target.action_count)
            .map(|t| match preimage(t) {
                Some(a) => (weights[a].clone(), biases[a]),
                None => (mean_row.clone(), mean_bias),
            })
            .unzip();
        values[w] = matrix(rows)?;
        values[b] = Tensor::from_vec(bias, target.action_count, &Device::Cpu)?;

        QNet::from_parameters(
            Architecture::new(target.observation_size, &hidden, target.action_count),
            values,
        )
    }
}

fn matrix(rows: Vec<Vec<f32>>) -> Result<Tensor, DqnError> {
    let (n, m) = (rows.len(), rows.first().map_or(0, Vec::len));
    let flat: Vec<f32> = rows.into_iter().flatten().collect();
    Ok(Tensor::from_vec(flat, (n, m), &Device::Cpu)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    fn spaces(observation_size: usize, action_count: usize) -> Spaces {
        Spaces {
            observation_size,
            action_count,
        }
    }

    #[test]
    fn a_mapping_that_does_not_fit_is_refused_at_its_field() {
        let field = "sources.tasks[0].mapping";
        let (source, target) = (spaces(4, 3), spaces(4, 2));
        let ok = InterTaskMapping {
            state: vec![0, 1, 2, 3],
            actions: vec![Some(0), None, Some(1)],
        };
        assert_eq!(ok.check(field, source, target), Ok(()));
        let cases = [
            (
                InterTaskMapping {
                    state: vec![0, 1, 4, 3],
                    ..ok.clone()
                },
                "`sources.tasks[0].mapping.state[2]`: expected one of the target's state \
                 variables 0 to 3, got 4",
            ),
            (
                InterTaskMapping {
                    state: vec![0, 1, 2],
                    ..ok.clone()
                },
                "`sources.tasks[0].mapping.state`: expected 4 entries",
            ),
            (
                InterTaskMapping {
                    actions: vec![Some(0), None],
                    ..ok.clone()
                },
                "`sources.tasks[0].mapping.actions`: source action 2 has no image",
            ),
            (
                InterTaskMapping {
                    actions: vec![Some(0), None, Some(2)],
                    ..ok.clone()
                },
                "`sources.tasks[0].mapping.actions[2]`: expected one of the target's actions \
                 0 to 1 or None, got Some(2)",
            ),
            (
                InterTaskMapping {
                    actions: vec![Some(0), Some(0), Some(1)],
                    ..ok.clone()
                },
                "`sources.tasks[0].mapping.actions[1]`: target action 0 is already the image \
                 of source action 0",
            ),
            (
                InterTaskMapping {
                    actions: vec![None, None, None],
                    ..ok.clone()
                },
                "at least one source action mapped",
            ),
        ];
        for (mapping, expected) in cases {
            let error = mapping.check(field, source, target).unwrap_err();
            assert!(error.contains(expected), "{error}\nwanted: {expected}");
        }
    }

    /// A random source net of `source` spaces.
    fn net(source: Spaces, hidden: &[usize], seed: u64) -> QNet {
        let arch = Architecture::new(source.observation_size, hidden, source.action_count);
        QNet::new(arch, &mut StdRng::seed_from_u64(seed)).unwrap()
    }

    fn observations(n: usize, size: usize) -> Vec<Vec<f32>> {
        let mut rng = StdRng::seed_from_u64(9);
        (0..n)
            .map(|_| (0..size).map(|_| rng.random_range(-2.0..2.0)).collect())
            .collect()
    }

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() <= 1e-5 * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn a_permutation_maps_the_state_and_keeps_every_q_value() {
        // The source sees [θ, θ̇, x, ẋ]: its j-th input is the target's state[j]-th.
        let mapping = InterTaskMapping {
            state: vec![2, 3, 0, 1],
            actions: vec![Some(0), Some(1)],
        };
        let source = net(spaces(4, 2), &[7, 5], 1);
        let target = mapping.translate(&source, spaces(4, 2)).unwrap();
        for obs in observations(200, 4) {
            let seen: Vec<f32> = mapping.state.iter().map(|&i| obs[i]).collect();
            let (q, q_source) = (
                target.q_values(&obs).unwrap(),
                source.q_values(&seen).unwrap(),
            );
            assert!(
                q.iter().zip(&q_source).all(|(&a, &b)| close(a, b)),
                "{q:?} {q_source:?}"
            );
        }
    }

    #[test]
    fn a_source_action_without_image_is_dropped_and_the_greedy_choice_is_among_the_rest() {
        // A three-action CartPole source (left, none, right) on the two-action target.
        let mapping = InterTaskMapping {
            state: vec![0, 1, 2, 3],
            actions: vec![Some(0), None, Some(1)],
        };
        let source = net(spaces(4, 3), &[6], 2);
        let target = mapping.translate(&source, spaces(4, 2)).unwrap();
        assert_eq!(target.architecture().action_count, 2);
        for obs in observations(200, 4) {
            let (q, q_source) = (
                target.q_values(&obs).unwrap(),
                source.q_values(&obs).unwrap(),
            );
            assert!(close(q[0], q_source[0]) && close(q[1], q_source[2]));
            let greedy = if q_source[2] > q_source[0] { 1 } else { 0 };
            assert_eq!(target.greedy_action(&obs).unwrap(), greedy);
        }
    }

    #[test]
    fn a_target_action_without_preimage_starts_at_the_mean_of_the_mapped_ones() {
        // A two-action MountainCar source (left, right) on the three-action target, and a
        // source that reads velocity first: Q(s, none) = (Q(s, left) + Q(s, right)) / 2.
        let mapping = InterTaskMapping {
            state: vec![1, 0],
            actions: vec![Some(0), Some(2)],
        };
        let source = net(spaces(2, 2), &[5, 4, 3], 3);
        let target = mapping.translate(&source, spaces(2, 3)).unwrap();
        for obs in observations(200, 2) {
            let q = target.q_values(&obs).unwrap();
            let q_source = source.q_values(&[obs[1], obs[0]]).unwrap();
            assert!(close(q[0], q_source[0]) && close(q[2], q_source[1]));
            assert!(close(q[1], (q_source[0] + q_source[1]) / 2.0), "{q:?}");
            assert_ne!(target.greedy_action(&obs).unwrap(), 1, "{q:?}");
        }
    }

    #[test]
    fn a_target_variable_read_twice_or_never_is_summed_or_ignored() {
        // A one-layer source reading the target's variable 0 twice, never 1 or 2.
        let mapping = InterTaskMapping {
            state: vec![0, 0],
            actions: vec![Some(0)],
        };
        let w = Tensor::from_vec(vec![2.0f32, 3.0], (1, 2), &Device::Cpu).unwrap();
        let b = Tensor::from_vec(vec![0.5f32], 1, &Device::Cpu).unwrap();
        let source = QNet::from_parameters(Architecture::new(2, &[], 1), vec![w, b]).unwrap();
        let target = mapping.translate(&source, spaces(3, 1)).unwrap();
        // Q = 2·x0 + 3·x0 + 0.5, whatever x1 and x2 are.
        assert_eq!(target.q_values(&[1.0, 7.0, -9.0]).unwrap(), vec![5.5]);
    }
}
