//! Acrobot, after Gymnasium 1.x `gymnasium/envs/classic_control/acrobot.py`
//! (`AcrobotEnv.step`, `_dsdt` with `book_or_nips = "book"`, `rk4`, `wrap`, `bound`,
//! `reset`), with `TimeLimit`'s truncation built in.

use std::f64::consts::PI;
use std::hint::black_box;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::{AcrobotParams, EnvError, Environment, Step};

/// Half-width of the uniform distribution of every state variable at reset (Gymnasium's
/// default reset bounds, ±0.1).
const RESET_BOUND: f64 = 0.1;

/// Gymnasium's `_dsdt` hard-codes gravity rather than making it a class constant.
const GRAVITY: f64 = 9.8;

/// Two links joined by an actuated joint, hanging from a fixed one; swing the tip above the
/// bar. Actions 0, 1, 2 apply the torques `available_torque[action]` (−1, 0, +1).
///
/// State `[theta1, theta2, dtheta1, dtheta2]`; the observation is
/// `[cos θ1, sin θ1, cos θ2, sin θ2, dθ1, dθ2]`, computed in `f64` and cast to `f32`.
/// Reward −1 per step and 0 on the terminating step. Until the first reset the state is all
/// zeros and the generator is seeded with 0.
#[derive(Debug, Clone)]
pub struct Acrobot {
    params: AcrobotParams,
    /// Parts of `_dsdt` that depend only on the parameters, each computed exactly as its
    /// sub-expression in Gymnasium so that the result is the same to the bit.
    derived: Derived,
    state: [f64; 4],
    /// `sin_cos(state[1])`: the observation and the next step's first evaluation of the
    /// dynamics both need it, and libm calls are most of the cost of a step.
    sin_cos_theta2: (f64, f64),
    /// Gymnasium's `_get_ob` of the state.
    obs: [f32; 6],
    rng: StdRng,
    elapsed: u32,
}

/// Sub-expressions of Gymnasium's `_dsdt` that do not depend on the state.
#[derive(Debug, Clone)]
struct Derived {
    /// `m1 * lc1**2`
    m1_lc1_sq: f64,
    /// `l1**2 + lc2**2`
    l1_sq_plus_lc2_sq: f64,
    /// `2 * l1 * lc2`
    two_l1_lc2: f64,
    /// `l1 * lc2`
    l1_lc2: f64,
    /// `lc2**2`
    lc2_sq: f64,
    /// `m2 * lc2 * g`
    m2_lc2_g: f64,
    /// `-m2 * l1 * lc2`
    neg_m2_l1_lc2: f64,
    /// `2 * m2 * l1 * lc2`
    two_m2_l1_lc2: f64,
    /// `(m1 * lc1 + m2 * l1) * g`
    phi1_gravity: f64,
    /// `m2 * l1 * lc2`
    m2_l1_lc2: f64,
    /// `m2 * lc2**2 + I2`
    m2_lc2_sq_plus_i2: f64,
}

impl Derived {
    fn new(p: &AcrobotParams) -> Self {
        let (m1, m2) = (p.link_mass_1, p.link_mass_2);
        let (l1, lc1, lc2) = (p.link_length_1, p.link_com_pos_1, p.link_com_pos_2);
        let i2 = p.link_moi;
        let lc2_sq = py_square(lc2);
        Self {
            m1_lc1_sq: m1 * py_square(lc1),
            l1_sq_plus_lc2_sq: py_square(l1) + lc2_sq,
            two_l1_lc2: 2.0 * l1 * lc2,
            l1_lc2: l1 * lc2,
            lc2_sq,
            m2_lc2_g: m2 * lc2 * GRAVITY,
            neg_m2_l1_lc2: -m2 * l1 * lc2,
            two_m2_l1_lc2: 2.0 * m2 * l1 * lc2,
            phi1_gravity: (m1 * lc1 + m2 * l1) * GRAVITY,
            m2_l1_lc2: m2 * l1 * lc2,
            m2_lc2_sq_plus_i2: m2 * lc2_sq + i2,
        }
    }
}

/// `x**2` as Python and NumPy evaluate it: the C library's `pow(x, 2.0)`.
///
/// glibc's `pow` (Arm's optimized-routines, also in musl) is not correctly rounded: its
/// documented worst case is 0.54 ulp, and `pow(x, 2.0)` differs from `x * x` for about one
/// input in a thousand, where the exact square lies near the midpoint between two doubles.
/// Elsewhere the only double within 0.54 ulp of the exact square is the correctly rounded
/// `x * x`, so `pow` is called only near a midpoint: bit-exact, and most calls are saved
/// (`pow` was a third of Acrobot's step).
#[inline]
fn py_square(x: f64) -> f64 {
    /// Below this the rounding error of `x * x` could be subnormal and inexact.
    const SMALLEST_CHECKED: f64 = 1e-290;
    const EXPONENT_BITS: u64 = 0x7ff0_0000_0000_0000;
    const MANTISSA_BITS: u64 = 0x000f_ffff_ffff_ffff;
    let p = x * x;
    if p.is_finite() && p > SMALLEST_CHECKED {
        let e = square_error(x, p);
        // Spacing of the doubles on the side of `p` where x² lies (halved below a power
        // of two).
        let mut ulp = f64::from_bits(p.to_bits() & EXPONENT_BITS) * f64::EPSILON;
        if e < 0.0 && p.to_bits() & MANTISSA_BITS == 0 {
            ulp *= 0.5;
        }
        // The nearest other double is at least 0.55 ulp from x², beyond pow's 0.54.
        if e.abs() <= 0.45 * ulp {
            return p;
        }
    }
    libm_square(x)
}

/// The rounding error `e` of `p = x * x`, so that x² = p + e exactly (Dekker's product).
///
/// `x.mul_add(x, -p)` gives the same, but without FMA in the target (x86-64's baseline) it
/// is a slow software routine. Exact while `p` is finite and `e` is not subnormal.
#[inline]
fn square_error(x: f64, p: f64) -> f64 {
    // Veltkamp's split of x into 26 + 27 significant bits, whose products are exact.
    const SPLITTER: f64 = 134_217_729.0; // 2^27 + 1
    let c = SPLITTER * x;
    let hi = c - (c - x);
    let lo = x - hi;
    ((hi * hi - p) + 2.0 * hi * lo) + lo * lo
}

/// The C library's `pow(x, 2.0)`. LLVM rewrites `pow(x, 2.0)` into `x * x`; hiding the
/// exponent keeps the call.
#[inline]
fn libm_square(x: f64) -> f64 {
    x.powf(black_box(2.0))
}

/// `(x.sin(), x.cos())` in one `sincos` call, which gives the same bits.
///
/// Inlined, the branches of [`py_square`] let LLVM move the sine away from the cosine and
/// miss the fusion, which costs a libm call per evaluation of the dynamics.
#[inline(never)]
fn sin_cos(x: f64) -> (f64, f64) {
    x.sin_cos()
}

/// Gymnasium's `wrap`: shifts `x` by whole turns until it lies in `[lo, hi]`.
#[inline]
fn wrap(mut x: f64, lo: f64, hi: f64) -> f64 {
    let diff = hi - lo;
    while x > hi {
        x -= diff;
    }
    while x < lo {
        x += diff;
    }
    x
}

/// Gymnasium's `bound`: Python's `min(max(x, lo), hi)`, whose ties (±0) and NaN keep `x`.
#[inline]
fn bound(x: f64, lo: f64, hi: f64) -> f64 {
    let x = if lo > x { lo } else { x };
    if hi < x {
        hi
    } else {
        x
    }
}

impl Acrobot {
    pub fn new(params: AcrobotParams) -> Self {
        let mut acrobot = Self {
            derived: Derived::new(&params),
            params,
            state: [0.0; 4],
            sin_cos_theta2: sin_cos(0.0),
            obs: [0.0; 6],
            rng: StdRng::seed_from_u64(0),
            elapsed: 0,
        };
        acrobot.observe(sin_cos(0.0));
        acrobot
    }

    fn set(&mut self, state: [f64; 4]) {
        self.state = state;
        self.sin_cos_theta2 = sin_cos(state[1]);
    }

    /// Keeps Gymnasium's `_get_ob` of the state, given `sin_cos(state[0])`.
    #[inline]
    fn observe(&mut self, (sin_theta1, cos_theta1): (f64, f64)) {
        let (sin_theta2, cos_theta2) = self.sin_cos_theta2;
        let [_, _, dtheta1, dtheta2] = self.state;
        self.obs = [
            cos_theta1 as f32,
            sin_theta1 as f32,
            cos_theta2 as f32,
            sin_theta2 as f32,
            dtheta1 as f32,
            dtheta2 as f32,
        ];
    }

    /// Gymnasium's `_dsdt` ("book" dynamics): the time derivative of `s` under torque `a`,
    /// given `sin_cos(s[1])`.
    #[inline]
    fn dsdt(&self, s: [f64; 4], a: f64, (sin_theta2, cos_theta2): (f64, f64)) -> [f64; 4] {
        let d = &self.derived;
        let i1 = self.params.link_moi;
        let i2 = self.params.link_moi;
        let m2 = self.params.link_mass_2;
        let [theta1, theta2, dtheta1, dtheta2] = s;
        let dtheta1_sq = py_square(dtheta1);
        let dtheta2_sq = py_square(dtheta2);

        let d1 = d.m1_lc1_sq + m2 * (d.l1_sq_plus_lc2_sq + d.two_l1_lc2 * cos_theta2) + i1 + i2;
        let d2 = m2 * (d.lc2_sq + d.l1_lc2 * cos_theta2) + i2;
        let phi2 = d.m2_lc2_g * (theta1 + theta2 - PI / 2.0).cos();
        let phi1 = d.neg_m2_l1_lc2 * dtheta2_sq * sin_theta2
            - d.two_m2_l1_lc2 * dtheta2 * dtheta1 * sin_theta2
            + d.phi1_gravity * (theta1 - PI / 2.0).cos()
            + phi2;
        let numerator = a + d2 / d1 * phi1 - d.m2_l1_lc2 * dtheta1_sq * sin_theta2 - phi2;
        let ddtheta2 = numerator / (d.m2_lc2_sq_plus_i2 - py_square(d2) / d1);
        let ddtheta1 = -(d2 * ddtheta2 + phi1) / d1;
        [dtheta1, dtheta2, ddtheta1, ddtheta2]
    }

    /// Gymnasium's `rk4` from the current state over the single interval `[0, dt]`. The
    /// torque rides along as a fifth state variable with derivative 0 there, so it is passed
    /// unchanged here.
    #[inline]
    fn rk4(&self, torque: f64) -> [f64; 4] {
        let y0 = self.state;
        let dt = self.params.dt;
        let dt2 = dt / 2.0;
        let derivative_at = |k: [f64; 4], h: f64| {
            let y: [f64; 4] = std::array::from_fn(|i| y0[i] + h * k[i]);
            self.dsdt(y, torque, sin_cos(y[1]))
        };
        let k1 = self.dsdt(y0, torque, self.sin_cos_theta2);
        let k2 = derivative_at(k1, dt2);
        let k3 = derivative_at(k2, dt2);
        let k4 = derivative_at(k3, dt);
        let sixth = dt / 6.0;
        std::array::from_fn(|i| y0[i] + sixth * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
    }
}

impl Environment for Acrobot {
    fn id(&self) -> &str {
        "Acrobot-v1"
    }

    fn observation_size(&self) -> usize {
        6
    }

    fn action_count(&self) -> usize {
        3
    }

    /// Draws every state variable from U(−0.1, 0.1) and rounds it to `f32`, as Gymnasium's
    /// `reset` does (`.astype(np.float32)`); the state is then held in `f64`.
    ///
    /// Gymnasium computes this first observation's sines and cosines in `float32` (NumPy's
    /// own routines); here they are computed in `f64` and rounded, which differs by one ulp
    /// in about one reset in a thousand. Every later observation is computed as Gymnasium
    /// does.
    fn reset(&mut self, seed: Option<u64>) -> Result<&[f32], EnvError> {
        if let Some(seed) = seed {
            self.rng = StdRng::seed_from_u64(seed);
        }
        let state = std::array::from_fn(|_| {
            f64::from(self.rng.random_range(-RESET_BOUND..RESET_BOUND) as f32)
        });
        self.set(state);
        self.observe(sin_cos(self.state[0]));
        self.elapsed = 0;
        Ok(&self.obs)
    }

    /// Gymnasium's `AcrobotEnv.step`, operation for operation, so the state matches its
    /// `float64` state bit for bit. The torque noise is drawn from the environment's
    /// generator only when `torque_noise_max > 0`, as in Gymnasium.
    ///
    /// # Panics
    /// If `action` is not 0, 1 or 2.
    #[inline]
    fn step(&mut self, action: usize) -> Result<Step<'_>, EnvError> {
        assert!(action < 3, "Acrobot: action {action} is not 0, 1 or 2");
        let p = &self.params;
        let mut torque = p.available_torque[action];
        if p.torque_noise_max > 0.0 {
            torque += self
                .rng
                .random_range(-p.torque_noise_max..p.torque_noise_max);
        }
        let ns = self.rk4(torque);
        let p = &self.params;
        let (theta1, theta2) = (wrap(ns[0], -PI, PI), wrap(ns[1], -PI, PI));
        self.set([
            theta1,
            theta2,
            bound(ns[2], -p.max_vel_1, p.max_vel_1),
            bound(ns[3], -p.max_vel_2, p.max_vel_2),
        ]);

        let sin_cos_theta1 = sin_cos(theta1);
        let terminated = -sin_cos_theta1.1 - (theta2 + theta1).cos() > 1.0;
        self.observe(sin_cos_theta1);
        self.elapsed += 1;
        Ok(Step {
            obs: &self.obs,
            reward: if terminated { 0.0 } else { -1.0 },
            terminated,
            truncated: self.elapsed >= self.params.max_episode_steps,
        })
    }

    /// Gymnasium's `_get_ob`.
    fn observation(&self) -> &[f32] {
        &self.obs
    }

    fn state(&self) -> &[f64] {
        &self.state
    }

    fn set_state(&mut self, state: &[f64]) -> Result<(), EnvError> {
        let state = EnvError::check_length("Acrobot", state)?;
        self.set(state);
        self.observe(sin_cos(self.state[0]));
        Ok(())
    }

    fn elapsed_steps(&self) -> u32 {
        self.elapsed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env() -> Acrobot {
        let mut env = Acrobot::new(AcrobotParams::default());
        env.reset(Some(11)).unwrap();
        env
    }

    #[test]
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    fn square_is_glibc_pow_not_the_product() {
        // An input where glibc's pow(x, 2) and x * x round differently (found with Python:
        // `x**2 != x*x`).
        let x = f64::from_bits(0xc010_db07_b8dd_0d73);
        assert_eq!(py_square(x).to_bits(), 0x4031_c1c5_d522_784f);
        assert_eq!((x * x).to_bits(), 0x4031_c1c5_d522_7850);
    }

    #[test]
    fn square_shortcut_agrees_with_pow() {
        let mut rng = StdRng::seed_from_u64(0);
        let mut differs_from_product = 0;
        let specials = [
            0.0,
            -0.0,
            1.0,
            2.0,
            0.5,
            1e-300,
            1e-150,
            1e200,
            f64::MAX,
            f64::NAN,
        ];
        let randoms = (0..1_000_000).map(|i| {
            let magnitude = [1e-3, 1.0, 30.0, 1e8][i % 4];
            rng.random_range(-magnitude..magnitude)
        });
        for x in specials.into_iter().chain(randoms) {
            let (got, want) = (py_square(x), libm_square(x));
            assert!(
                got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                "x = {x:e}: {got:e} but pow gives {want:e}"
            );
            differs_from_product += usize::from(want != x * x);
        }
        // The slow path must have been exercised where glibc's pow is not x * x.
        if cfg!(all(target_os = "linux", target_env = "gnu")) {
            assert!(differs_from_product > 100, "{differs_from_product}");
        }
    }

    #[test]
    fn wrap_shifts_by_whole_turns() {
        assert_eq!(wrap(0.5, -PI, PI), 0.5);
        assert_eq!(wrap(PI, -PI, PI), PI);
        assert_eq!(wrap(-PI, -PI, PI), -PI);
        assert_eq!(wrap(3.5, -PI, PI), 3.5 - 2.0 * PI);
        assert_eq!(wrap(-3.5, -PI, PI), -3.5 + 2.0 * PI);
        assert_eq!(wrap(10.0, -PI, PI), 10.0 - 2.0 * PI - 2.0 * PI);
    }

    #[test]
    fn bound_clips_and_keeps_ties() {
        assert_eq!(bound(20.0, -4.0, 4.0), 4.0);
        assert_eq!(bound(-20.0, -4.0, 4.0), -4.0);
        assert_eq!(bound(1.5, -4.0, 4.0), 1.5);
        assert!(bound(-0.0, 0.0, 1.0).is_sign_negative());
    }

    #[test]
    fn theta1_wraps_across_pi_in_both_directions() {
        let mut env = env();
        env.set_state(&[3.1, 0.0, 3.0, 0.0]).unwrap();
        env.step(1).unwrap();
        let theta1 = env.state()[0];
        assert!((-PI..0.0).contains(&theta1), "theta1 = {theta1}");

        env.set_state(&[-3.1, 0.0, -3.0, 0.0]).unwrap();
        env.step(1).unwrap();
        let theta1 = env.state()[0];
        assert!((0.0..=PI).contains(&theta1), "theta1 = {theta1}");
    }

    #[test]
    fn velocities_are_bounded() {
        let p = AcrobotParams::default();
        let mut env = env();
        for sign in [1.0, -1.0] {
            env.set_state(&[0.0, 0.0, sign * 2.0 * p.max_vel_1, sign * 2.0 * p.max_vel_2])
                .unwrap();
            env.step(1).unwrap();
            let [.., dtheta1, dtheta2] = env.state() else {
                unreachable!()
            };
            // The dynamics may turn a velocity round; whichever way it ends, it is clipped.
            assert_eq!((dtheta1.abs(), dtheta2.abs()), (p.max_vel_1, p.max_vel_2));
        }
    }

    #[test]
    fn tip_above_the_bar_terminates_with_reward_zero() {
        let mut env = env();
        // Both links pointing up: the tip is 2 above the pivot.
        env.set_state(&[PI - 0.01, 0.0, 0.0, 0.0]).unwrap();
        let step = env.step(1).unwrap();
        assert!(step.terminated);
        assert_eq!(step.reward, 0.0);

        env.set_state(&[0.0; 4]).unwrap();
        let step = env.step(1).unwrap();
        assert!(!step.terminated);
        assert_eq!(step.reward, -1.0);
    }

    #[test]
    fn observation_is_trigonometry_of_the_state() {
        let mut env = env();
        env.set_state(&[0.3, -0.2, 0.1, -0.4]).unwrap();
        let obs = env.step(2).unwrap().obs.to_vec();
        let [t1, t2, d1, d2] = env.state().try_into().unwrap();
        let expected = [t1.cos(), t1.sin(), t2.cos(), t2.sin(), d1, d2].map(|v| v as f32);
        assert_eq!(obs, expected);
    }

    #[test]
    fn truncates_at_the_time_limit_even_when_terminated() {
        let mut env = Acrobot::new(AcrobotParams {
            max_episode_steps: 2,
            ..AcrobotParams::default()
        });
        env.reset(Some(0)).unwrap();
        assert!(!env.step(1).unwrap().truncated);
        env.set_state(&[PI - 0.01, 0.0, 0.0, 0.0]).unwrap();
        let step = env.step(1).unwrap();
        assert!(step.terminated && step.truncated);
    }

    #[test]
    fn same_seed_same_reset_and_resets_in_range_in_f32() {
        let mut a = Acrobot::new(AcrobotParams::default());
        let mut b = Acrobot::new(AcrobotParams::default());
        assert_eq!(a.reset(Some(5)).unwrap(), b.reset(Some(5)).unwrap());
        assert_eq!(a.state(), b.state());
        assert_eq!(a.reset(None).unwrap(), b.reset(None).unwrap());
        for _ in 0..1000 {
            a.reset(None).unwrap();
            for &v in a.state() {
                assert!((-0.1..=0.1).contains(&v));
                assert_eq!(f64::from(v as f32), v);
            }
        }
    }

    #[test]
    fn torque_noise_is_drawn_only_when_enabled() {
        let mut quiet = env();
        let mut reference = env();
        quiet.step(0).unwrap();
        assert_eq!(quiet.reset(None).unwrap(), reference.reset(None).unwrap());

        let noisy_params = AcrobotParams {
            torque_noise_max: 0.5,
            ..AcrobotParams::default()
        };
        let mut noisy = Acrobot::new(noisy_params.clone());
        let mut reference = Acrobot::new(noisy_params);
        noisy.reset(Some(1)).unwrap();
        reference.reset(Some(1)).unwrap();
        noisy.step(1).unwrap();
        assert_ne!(noisy.reset(None).unwrap(), reference.reset(None).unwrap());
    }

    #[test]
    fn set_state_checks_length() {
        assert!(matches!(
            env().set_state(&[0.0; 6]),
            Err(EnvError::WrongLength { got: 6, .. })
        ));
    }

    #[test]
    #[should_panic(expected = "action 3")]
    fn out_of_range_action_panics() {
        env().step(3).unwrap();
    }
}
