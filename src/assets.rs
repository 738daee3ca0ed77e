//! Configs compiled into the binary, so that the app runs from any directory with no
//! set-up. The files in `assets/` are the same text, for reading and copying.

/// The paper's CartPole experiment: the app's default.
pub const CARTPOLE: &str = include_str!("../assets/cartpole.ron");
/// The paper's MountainCar experiment.
pub const MOUNTAIN_CAR: &str = include_str!("../assets/mountain_car.ron");
/// Acrobot with the paper's method and protocol.
pub const ACROBOT: &str = include_str!("../assets/acrobot.ron");
/// The paper's DQN baseline with one hidden layer of 100 on CartPole-v1: the default run
/// until the SAP-Net transfer loop lands.
pub const DQN_CARTPOLE: &str = include_str!("../assets/dqn_cartpole.ron");
