//! Dispatches a parsed command line to the part of the crate that does the work.

use anyhow::Result;

use crate::cli::{Cli, Command};

pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Some(Command::Env(_)) | Some(Command::Teach(_)) | None => {
            anyhow::bail!("not wired yet")
        }
    }
}
