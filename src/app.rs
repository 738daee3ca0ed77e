//! Dispatches a parsed command line to the part of the crate that does the work.

use anyhow::Result;

use crate::cli::{Cli, Command};

pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Some(Command::Teach(args)) => {
            if !args.headless {
                anyhow::bail!(
                    "the interactive teach view comes with the TUI; for now use \
                     `sapnet teach --headless --activate I`"
                );
            }
            crate::teach::headless::run(
                cli.run.config.as_deref(),
                &args,
                &mut std::io::stdout().lock(),
            )
        }
        Some(Command::Env(_)) | None => {
            anyhow::bail!("not wired yet")
        }
    }
}
