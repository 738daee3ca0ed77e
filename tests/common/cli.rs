//! The binary under test, the test configs and what a run said on stderr: shared by the
//! command-line tests.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `sapnet` binary cargo built for these tests.
pub fn sapnet() -> Command {
    Command::new(env!("CARGO_BIN_EXE_sapnet"))
}

/// A config of `tests/configs/`.
pub fn configs(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/configs")
        .join(name)
}

/// What a finished command said on stderr.
pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// `output`, once it is sure the command succeeded (else its stderr, as the failure).
pub fn ok(output: Output) -> Output {
    assert!(output.status.success(), "{}", stderr(&output));
    output
}
