use std::path::PathBuf;
use std::process::{Command, Stdio};

/// The Python to test the Gymnasium bridge with (`SAPNET_TEST_PYTHON`, else the active
/// virtualenv's), if it has Gymnasium with Box2D; `None` (said on stderr) otherwise.
pub fn with_gymnasium() -> Option<PathBuf> {
    let python = std::env::var_os("SAPNET_TEST_PYTHON")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("VIRTUAL_ENV").map(|v| PathBuf::from(v).join("bin/python")))?;
    let ok = Command::new(&python)
        .args(["-c", "import gymnasium, Box2D"])
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        eprintln!(
            "{} has no gymnasium[box2d]: the bridge tests are skipped",
            python.display()
        );
        return None;
    }
    Some(python)
}

/// The Python with Gymnasium, or the test returns, saying it is skipped.
macro_rules! python_or_skip {
    () => {
        match $crate::common::python::with_gymnasium() {
            Some(p) => p,
            None => {
                eprintln!("no Python with Gymnasium (SAPNET_TEST_PYTHON): skipped");
                return;
            }
        }
    };
}

// Imported by path (`use crate::common::python::python_or_skip;`) as any item is.
pub(crate) use python_or_skip;
