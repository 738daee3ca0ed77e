//! Dispatches a parsed command line to the part of the crate that does the work.

use std::io::Write;

use anyhow::{Context, Result};

use crate::cli::{Cli, Command, EnvArgs, TeachArgs};
use crate::config::Config;
use crate::{assets, env, random_episodes};

pub fn run(cli: Cli) -> Result<()> {
    match &cli.command {
        Some(Command::Env(args)) => run_env(&cli, args),
        Some(Command::Teach(args)) => run_teach(&cli, args),
        None => anyhow::bail!("not wired yet"),
    }
}

/// The config the user named, or the embedded default, with `--seed` applied.
fn load_config(cli: &Cli) -> Result<Config> {
    let mut config = match &cli.run.config {
        Some(path) => Config::from_file(path)?,
        None => Config::from_ron(assets::CARTPOLE, "embedded assets/cartpole.ron")?,
    };
    if let Some(seed) = cli.run.seed {
        config.seed = seed;
    }
    Ok(config)
}

fn run_env(cli: &Cli, args: &EnvArgs) -> Result<()> {
    let config = load_config(cli)?;
    let mut env = env::make(&config.env);
    let episodes = random_episodes::run(env.as_mut(), args.episodes, config.seed);
    let mut out = std::io::stdout().lock();
    random_episodes::print(&mut out, env.id(), &episodes)
        .and_then(|()| out.flush())
        .context("writing to stdout")
}

fn run_teach(cli: &Cli, args: &TeachArgs) -> Result<()> {
    if !args.headless {
        anyhow::bail!(
            "the interactive teach view comes with the TUI; for now use \
             `sapnet teach --headless --activate I`"
        );
    }
    crate::teach::headless::run(cli.run.config.as_deref(), args, &mut std::io::stdout().lock())
}
