//! sapnet: policy reuse in reinforcement learning with a spreading activation model
//! (SAP-Net), after "Autonomous Reusing Policy Selection using Spreading Activation Model
//! in Deep Reinforcement Learning".
//!
//! - [`sapnet`]: the paper's section II — categories, the policy graph, selection,
//!   activation and spreading. Pure maths.
//! - [`env`](mod@env): native CartPole, MountainCar and Acrobot, with Gymnasium's dynamics
//!   to the bit.
//! - [`dqn`]: the DQN on candle; [`policy_store`]: policies on disk; [`checkpoints`]:
//!   Q-networks trained elsewhere (Stable-Baselines3, PyTorch, safetensors) read as ours.
//! - [`trainer`]: training runs on their own thread, reporting through events;
//!   [`experiment`]: planning and scheduling a protocol's runs.
//! - [`stats`]: interval estimates over runs' scores; [`report`]: the methods side by side
//!   and the plots; [`results`]: a results directory on disk. Below both front ends.
//! - [`tensorboard`]: TensorBoard's event files, written (scalars, hyper-parameters) and
//!   read; [`outside_runs`]: runs made by other tools (Stable-Baselines3's monitor files,
//!   CSV exports, event files) read as episodes and scored as sapnet scores its own.
//! - [`headless`]: the scripted front end over the trainer's events; [`compare`]: runs that
//!   already exist (other tools' or sapnet's) through the same report.
//! - [`teach`]: stepping activation and spreading by hand on a small graph.
//! - [`tui`]: the terminal dashboard over the trainer's events, and interactive teach mode.
//! - [`config`]: the RON run configuration, with the paper's values as defaults.

pub mod app;
pub mod assets;
pub mod checkpoints;
pub mod cli;
pub mod compare;
pub mod config;
pub mod dqn;
pub mod env;
pub mod env_command;
pub mod experiment;
pub mod failpoint;
pub mod folder_lock;
pub mod headless;
pub mod limits;
pub mod outside_runs;
pub mod policy_store;
pub mod progress;
pub mod report;
pub mod results;
pub mod reuse;
pub mod ron_file;
pub mod safe_io;
pub mod sapnet;
pub mod seeds;
pub mod shown_text;
pub mod signals;
pub mod sources;
pub mod stats;
pub mod sweep;
pub mod teach;
pub mod tensorboard;
pub mod trainer;
pub mod tui;
