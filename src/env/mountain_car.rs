//! MountainCar, after Gymnasium 1.x `gymnasium/envs/classic_control/mountain_car.py`
//! (`MountainCarEnv.step` and `MountainCarEnv.reset`), with `TimeLimit`'s truncation built
//! in.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::{EnvError, Environment, MountainCarParams, Step};

/// Range of the starting position (Gymnasium's default reset bounds); velocity starts at 0.
const RESET_POSITION: std::ops::Range<f64> = -0.6..-0.4;

/// An underpowered car in a valley that must rock back and forth to reach the flag on the
/// right hill. Actions: 0 accelerate left, 1 do nothing, 2 accelerate right (a two-action
/// agent: 0 left, 1 right).
///
/// State `[position, velocity]`; the observation is the state cast to `f32`. Reward −1 on
/// every step. Until the first reset the state is all zeros and the generator is seeded
/// with 0.
#[derive(Debug, Clone)]
pub struct MountainCar {
    params: MountainCarParams,
    state: [f64; 2],
    /// The observation: the state cast to `f32`.
    obs: [f32; 2],
    rng: StdRng,
    elapsed: u32,
}

impl MountainCar {
    pub fn new(params: MountainCarParams) -> Self {
        Self {
            params,
            state: [0.0; 2],
            obs: [0.0; 2],
            rng: StdRng::seed_from_u64(0),
            elapsed: 0,
        }
    }
}

impl Environment for MountainCar {
    fn id(&self) -> &str {
        "MountainCar-v0"
    }

    fn observation_size(&self) -> usize {
        2
    }

    fn action_count(&self) -> usize {
        self.params.actions.count()
    }

    fn reset(&mut self, seed: Option<u64>) -> Result<&[f32], EnvError> {
        if let Some(seed) = seed {
            self.rng = StdRng::seed_from_u64(seed);
        }
        self.state = [self.rng.random_range(RESET_POSITION), 0.0];
        self.obs = self.state.map(|v| v as f32);
        self.elapsed = 0;
        Ok(&self.obs)
    }

    /// Gymnasium's `MountainCarEnv.step`, operation for operation, so the state matches its
    /// `float64` state bit for bit.
    ///
    /// # Panics
    /// If `action` is not one of the agent's (0, 1 or 2; 0 or 1 with two actions).
    #[inline]
    fn step(&mut self, action: usize) -> Result<Step<'_>, EnvError> {
        let actions = self.params.actions.count();
        assert!(
            action < actions,
            "MountainCar: action {action} is not one of the agent's {actions}"
        );
        let p = &self.params;
        let [mut position, mut velocity] = self.state;
        // Gymnasium's `(action - 1) * force`: −1, 0 or +1 times the force.
        velocity += p.actions.direction(action) * p.force + (3.0 * position).cos() * -p.gravity;
        velocity = velocity.clamp(-p.max_speed, p.max_speed);
        position += velocity;
        position = position.clamp(p.min_position, p.max_position);
        // The left wall is inelastic.
        if position == p.min_position && velocity < 0.0 {
            velocity = 0.0;
        }
        self.state = [position, velocity];
        self.obs = self.state.map(|v| v as f32);

        let terminated = position >= p.goal_position && velocity >= p.goal_velocity;
        self.elapsed += 1;
        Ok(Step {
            obs: &self.obs,
            reward: -1.0,
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
        self.state = EnvError::check_length("MountainCar", state)?;
        self.obs = self.state.map(|v| v as f32);
        Ok(())
    }

    fn elapsed_steps(&self) -> u32 {
        self.elapsed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env() -> MountainCar {
        let mut env = MountainCar::new(MountainCarParams::default());
        env.reset(Some(3)).unwrap();
        env
    }

    #[test]
    fn left_wall_clips_position_and_stops_the_car() {
        let mut env = env();
        env.set_state(&[-1.19, -0.05]).unwrap();
        let step = env.step(0).unwrap();
        assert_eq!(*step.obs, [-1.2f32, 0.0]);
        assert!(!step.terminated);
        assert_eq!(step.reward, -1.0);
        assert_eq!(env.state(), &[-1.2, 0.0]);
    }

    #[test]
    fn velocity_is_clipped_to_max_speed() {
        let mut env = env();
        env.set_state(&[-0.5, 0.07]).unwrap();
        env.step(2).unwrap();
        assert_eq!(env.state()[1], 0.07);
        env.set_state(&[-0.5, -0.07]).unwrap();
        env.step(0).unwrap();
        assert_eq!(env.state()[1], -0.07);
    }

    #[test]
    fn reaching_the_goal_terminates() {
        let mut env = env();
        env.set_state(&[0.49, 0.02]).unwrap();
        let step = env.step(2).unwrap();
        assert!(step.terminated);
        assert!(!step.truncated);
        assert_eq!(step.reward, -1.0);
        assert!(env.state()[0] >= 0.5);
    }

    #[test]
    fn moving_away_from_the_goal_does_not_terminate() {
        let mut env = env();
        env.set_state(&[0.45, 0.01]).unwrap();
        assert!(!env.step(1).unwrap().terminated);
    }

    #[test]
    fn truncates_at_the_time_limit_even_when_terminated() {
        let mut env = env();
        for _ in 0..199 {
            env.set_state(&[-0.5, 0.0]).unwrap();
            let step = env.step(1).unwrap();
            assert!(!step.truncated && !step.terminated);
        }
        env.set_state(&[0.55, 0.03]).unwrap();
        let step = env.step(2).unwrap();
        assert!(step.terminated && step.truncated);
        env.reset(None).unwrap();
        assert_eq!(env.elapsed_steps(), 0);
    }

    #[test]
    fn same_seed_same_reset_and_resets_in_range() {
        let mut a = MountainCar::new(MountainCarParams::default());
        let mut b = MountainCar::new(MountainCarParams::default());
        assert_eq!(a.reset(Some(9)).unwrap(), b.reset(Some(9)).unwrap());
        assert_eq!(a.reset(None).unwrap(), b.reset(None).unwrap());
        for _ in 0..1000 {
            a.reset(None).unwrap();
            let [position, velocity] = a.state() else {
                unreachable!()
            };
            assert!((-0.6..-0.4).contains(position));
            assert_eq!(*velocity, 0.0);
        }
    }

    #[test]
    fn set_state_checks_length() {
        assert!(matches!(
            env().set_state(&[0.0; 3]),
            Err(EnvError::WrongLength { got: 3, .. })
        ));
    }

    #[test]
    #[should_panic(expected = "action 3")]
    fn out_of_range_action_panics() {
        env().step(3).unwrap();
    }

    #[test]
    fn a_two_action_agent_pushes_left_or_right() {
        let two = MountainCarParams {
            actions: crate::env::ActionSet::LeftRight,
            ..MountainCarParams::default()
        };
        let after = |params: &MountainCarParams, action| {
            let mut env = MountainCar::new(params.clone());
            env.set_state(&[-0.5, 0.01]).unwrap();
            env.step(action).unwrap();
            env.state().to_vec()
        };
        let three = MountainCarParams::default();
        assert_eq!(after(&two, 0), after(&three, 0));
        assert_eq!(after(&two, 1), after(&three, 2));
        assert_eq!(MountainCar::new(two).action_count(), 2);
    }
}
