//! Signalling a child process as a user would, with kill(1).

use std::process::{Child, Command};
use std::time::{Duration, Instant};

/// Waits until `ready` holds (at most 120 s), then sends `signal` (`TERM`, `KILL`, …).
pub fn signal_when(child: &Child, signal: &str, ready: impl Fn() -> bool) {
    let started = Instant::now();
    while !ready() {
        assert!(started.elapsed() < Duration::from_secs(120), "never ready");
        std::thread::sleep(Duration::from_millis(5));
    }
    let status = Command::new("kill")
        .arg(format!("-{signal}"))
        .arg(child.id().to_string())
        .status()
        .unwrap();
    assert!(status.success());
}
