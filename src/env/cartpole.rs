//! CartPole, after Gymnasium 1.x `gymnasium/envs/classic_control/cartpole.py`
//! (`CartPoleEnv.step` and `CartPoleEnv.reset`), with `TimeLimit`'s truncation built in.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::{CartPoleParams, EnvError, Environment, Integrator, Step};

/// Half-width of the uniform distribution of every state variable at reset (Gymnasium's
/// default reset bounds, ±0.05).
const RESET_BOUND: f64 = 0.05;

/// A pole hinged on a cart; push the cart left (action 0) or right (action 1) to keep the
/// pole upright (a three-action agent: 0 left, 1 no push, 2 right).
///
/// State `[x, x_dot, theta, theta_dot]`; the observation is the state cast to `f32`, in
/// `observation_order`.
/// Reward 1 on every step, the terminating one included. Until the first reset the state is
/// all zeros and the generator is seeded with 0.
#[derive(Debug, Clone)]
pub struct CartPole {
    params: CartPoleParams,
    /// `params.observation_order`, or `None` for the state's own order.
    order: Option<[usize; 4]>,
    /// The push of each action, N: `[−F, F]`, or `[−F, 0, F]` for a three-action agent.
    /// Looked up, not computed, on every step: the step is CartPole's whole cost.
    forces: [f64; 3],
    /// Gymnasium's `total_mass`, computed once as it does in `__init__`.
    total_mass: f64,
    /// Gymnasium's `polemass_length`.
    polemass_length: f64,
    state: [f64; 4],
    /// The observation: the state cast to `f32`.
    obs: [f32; 4],
    /// `(sin θ, cos θ)` of the state, computed as soon as θ is known so that the libm call
    /// overlaps the divisions of the step that sets θ.
    sin_cos_theta: (f64, f64),
    rng: StdRng,
    elapsed: u32,
    /// Gymnasium's `steps_beyond_terminated is not None`: steps taken after the pole fell
    /// earn 0.
    fell: bool,
}

impl CartPole {
    /// # Panics
    /// If `params.observation_order` is not a permutation of 0..4 (a validated config's is).
    pub fn new(params: CartPoleParams) -> Self {
        let order: [usize; 4] = params
            .observation_order
            .as_slice()
            .try_into()
            .ok()
            .filter(|o: &[usize; 4]| {
                let mut sorted = *o;
                sorted.sort_unstable();
                sorted == super::params::CARTPOLE_ORDER
            })
            .expect("observation_order is a permutation of 0..4");
        let f = params.force_mag;
        // ±force_mag exactly, as Gymnasium's `force_mag if action == 1 else -force_mag`.
        let forces = match params.actions {
            crate::env::ActionSet::LeftRight => [-f, f, f],
            crate::env::ActionSet::LeftNoneRight => [-f, 0.0, f],
        };
        Self {
            order: (order != super::params::CARTPOLE_ORDER).then_some(order),
            forces,
            total_mass: params.masspole + params.masscart,
            polemass_length: params.masspole * params.length,
            params,
            state: [0.0; 4],
            obs: [0.0; 4],
            sin_cos_theta: (0.0, 1.0),
            rng: StdRng::seed_from_u64(0),
            elapsed: 0,
            fell: false,
        }
    }

    fn observe(&mut self) {
        self.obs = observation(self.order, &self.state);
    }
}

/// The observation of `state`, in the agent's order.
#[inline]
fn observation(order: Option<[usize; 4]>, state: &[f64; 4]) -> [f32; 4] {
    match order {
        None => state.map(|v| v as f32),
        Some(order) => order.map(|i| state[i] as f32),
    }
}

impl Environment for CartPole {
    fn id(&self) -> &str {
        if self.params.max_episode_steps == 200 {
            "CartPole-v0"
        } else {
            "CartPole-v1"
        }
    }

    fn observation_size(&self) -> usize {
        4
    }

    fn action_count(&self) -> usize {
        self.params.actions.count()
    }

    fn reset(&mut self, seed: Option<u64>) -> Result<&[f32], EnvError> {
        if let Some(seed) = seed {
            self.rng = StdRng::seed_from_u64(seed);
        }
        for v in &mut self.state {
            *v = self.rng.random_range(-RESET_BOUND..RESET_BOUND);
        }
        self.sin_cos_theta = self.state[2].sin_cos();
        self.observe();
        self.elapsed = 0;
        self.fell = false;
        Ok(&self.obs)
    }

    /// Gymnasium's `CartPoleEnv.step`, operation for operation, so the state matches its
    /// `float64` state bit for bit.
    ///
    /// # Panics
    /// If `action` is not one of the agent's (0 or 1; 0, 1 or 2 with three actions).
    #[inline]
    fn step(&mut self, action: usize) -> Result<Step<'_>, EnvError> {
        let actions = self.params.actions.count();
        assert!(
            action < actions,
            "CartPole: action {action} is not one of the agent's {actions}"
        );
        let p = &self.params;
        let [mut x, mut x_dot, mut theta, mut theta_dot] = self.state;
        let force = self.forces[action];
        let (sintheta, costheta) = self.sin_cos_theta;

        let temp =
            (force + self.polemass_length * (theta_dot * theta_dot) * sintheta) / self.total_mass;
        let thetaacc = (p.gravity * sintheta - costheta * temp)
            / (p.length * (4.0 / 3.0 - p.masspole * (costheta * costheta) / self.total_mass));
        let xacc = temp - self.polemass_length * thetaacc * costheta / self.total_mass;

        match p.integrator {
            Integrator::Euler => {
                x += p.tau * x_dot;
                x_dot += p.tau * xacc;
                theta += p.tau * theta_dot;
                theta_dot += p.tau * thetaacc;
            }
            Integrator::SemiImplicitEuler => {
                x_dot += p.tau * xacc;
                x += p.tau * x_dot;
                theta_dot += p.tau * thetaacc;
                theta += p.tau * theta_dot;
            }
        }
        self.state = [x, x_dot, theta, theta_dot];
        self.obs = observation(self.order, &self.state);
        self.sin_cos_theta = theta.sin_cos();

        let terminated = x < -p.x_threshold
            || x > p.x_threshold
            || theta < -p.theta_threshold_radians
            || theta > p.theta_threshold_radians;
        let reward = if self.fell { 0.0 } else { 1.0 };
        self.fell |= terminated;
        self.elapsed += 1;
        Ok(Step {
            obs: &self.obs,
            reward,
            terminated,
            truncated: self.elapsed >= p.max_episode_steps,
        })
    }

    #[inline]
    fn observation(&self) -> &[f32] {
        &self.obs
    }

    fn state(&self) -> &[f64] {
        &self.state
    }

    fn set_state(&mut self, state: &[f64]) -> Result<(), EnvError> {
        self.state = EnvError::check_length("CartPole", state)?;
        self.observe();
        self.sin_cos_theta = self.state[2].sin_cos();
        Ok(())
    }

    fn elapsed_steps(&self) -> u32 {
        self.elapsed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env() -> CartPole {
        let mut env = CartPole::new(CartPoleParams::default());
        env.reset(Some(7)).unwrap();
        env
    }

    #[test]
    fn cart_beyond_x_threshold_terminates_with_reward_one() {
        for (x, x_dot, action) in [(2.39, 1.0, 1), (-2.39, -1.0, 0)] {
            let mut env = env();
            env.set_state(&[x, x_dot, 0.0, 0.0]).unwrap();
            let step = env.step(action).unwrap();
            let (terminated, truncated, reward) = (step.terminated, step.truncated, step.reward);
            assert!(env.state()[0].abs() > 2.4);
            assert!(terminated, "x = {} should terminate", env.state()[0]);
            assert!(!truncated);
            assert_eq!(reward, 1.0);
        }
    }

    #[test]
    fn pole_beyond_twelve_degrees_terminates_with_reward_one() {
        let limit = 12f64.to_radians();
        for sign in [1.0, -1.0] {
            let mut env = env();
            env.set_state(&[0.0, 0.0, sign * (limit - 1e-4), sign * 0.5])
                .unwrap();
            let step = env.step(0).unwrap();
            let (terminated, reward) = (step.terminated, step.reward);
            assert!(env.state()[2].abs() > limit);
            assert!(terminated);
            assert_eq!(reward, 1.0);
        }
    }

    #[test]
    fn inside_thresholds_does_not_terminate() {
        let mut env = env();
        env.set_state(&[2.3, 0.0, 0.2, 0.0]).unwrap();
        let step = env.step(1).unwrap();
        assert!(!step.terminated && !step.truncated);
        assert_eq!(step.reward, 1.0);
    }

    #[test]
    fn steps_after_the_fall_earn_nothing_until_reset() {
        let mut env = env();
        env.set_state(&[0.0, 0.0, 0.3, 0.0]).unwrap();
        assert_eq!(env.step(0).unwrap().reward, 1.0);
        assert_eq!(env.step(0).unwrap().reward, 0.0);
        env.reset(None).unwrap();
        assert_eq!(env.step(0).unwrap().reward, 1.0);
    }

    #[test]
    fn truncates_at_the_time_limit_even_when_terminated() {
        let mut env = CartPole::new(CartPoleParams {
            max_episode_steps: 3,
            ..CartPoleParams::default()
        });
        env.reset(Some(1)).unwrap();
        env.set_state(&[0.0; 4]).unwrap();
        assert!(!env.step(0).unwrap().truncated);
        assert!(!env.step(1).unwrap().truncated);
        env.set_state(&[3.0, 0.0, 0.0, 0.0]).unwrap();
        let step = env.step(0).unwrap();
        assert!(step.terminated && step.truncated);
        assert_eq!(env.elapsed_steps(), 3);
    }

    #[test]
    fn same_seed_same_reset_and_resets_in_range() {
        let mut a = CartPole::new(CartPoleParams::default());
        let mut b = CartPole::new(CartPoleParams::default());
        assert_eq!(a.reset(Some(42)).unwrap(), b.reset(Some(42)).unwrap());
        assert_eq!(a.reset(None).unwrap(), b.reset(None).unwrap());
        let one = a.reset(Some(1)).unwrap().to_vec();
        assert_ne!(one, a.reset(Some(2)).unwrap());
        for _ in 0..1000 {
            let obs = a.reset(None).unwrap().to_vec();
            assert!(a.state().iter().all(|v| (-0.05..0.05).contains(v)));
            assert!(obs.iter().zip(a.state()).all(|(&o, &s)| o == s as f32));
        }
    }

    #[test]
    fn unseeded_fresh_env_is_deterministic() {
        let mut a = CartPole::new(CartPoleParams::default());
        let mut b = CartPole::new(CartPoleParams::default());
        assert_eq!(a.reset(None).unwrap(), b.reset(Some(0)).unwrap());
    }

    #[test]
    fn set_state_checks_length() {
        let mut env = env();
        assert_eq!(
            env.set_state(&[0.0; 3]),
            Err(EnvError::WrongLength {
                env: "CartPole".into(),
                expected: 4,
                got: 3
            })
        );
    }

    #[test]
    #[should_panic(expected = "action 2")]
    fn out_of_range_action_panics() {
        env().step(2).unwrap();
    }

    #[test]
    fn a_three_action_agent_pushes_left_not_at_all_or_right() {
        let three = CartPoleParams {
            actions: crate::env::ActionSet::LeftNoneRight,
            ..CartPoleParams::default()
        };
        let start = [0.01, 0.02, 0.03, 0.04];
        let after = |params: &CartPoleParams, action| {
            let mut env = CartPole::new(params.clone());
            env.set_state(&start).unwrap();
            env.step(action).unwrap();
            env.state().to_vec()
        };
        let two = CartPoleParams::default();
        assert_eq!(after(&three, 0), after(&two, 0));
        assert_eq!(after(&three, 2), after(&two, 1));
        let coast = CartPoleParams {
            force_mag: 0.0,
            ..two
        };
        assert_eq!(after(&three, 1), after(&coast, 0));
        assert_eq!(CartPole::new(three).action_count(), 3);
    }

    #[test]
    fn a_permuted_agent_sees_the_state_in_its_order() {
        let mut env = CartPole::new(CartPoleParams {
            observation_order: vec![2, 3, 0, 1],
            ..CartPoleParams::default()
        });
        let mut plain = CartPole::new(CartPoleParams::default());
        let first = env.reset(Some(5)).unwrap().to_vec();
        let own = plain.reset(Some(5)).unwrap().to_vec();
        assert_eq!(first, [own[2], own[3], own[0], own[1]]);
        let obs = env.step(1).unwrap().obs.to_vec();
        let own = plain.step(1).unwrap().obs.to_vec();
        assert_eq!(obs, [own[2], own[3], own[0], own[1]]);
        assert_eq!(env.state(), plain.state(), "the physics is the same");
    }
}
