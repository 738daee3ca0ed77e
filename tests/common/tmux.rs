//! A tmux pane to drive the binary in as a user would: keys in (`send-keys`), the screen
//! back (`capture-pane`).

use std::process::Command;
use std::thread::sleep;
use std::time::{Duration, Instant};

/// Whether tmux is here; the tests that need it say they are skipped when it is not.
pub fn available() -> bool {
    Command::new("tmux").arg("-V").output().is_ok()
}

pub struct Session(String);

impl Session {
    pub fn start(width: u16, height: u16, command: &str) -> Self {
        // One session per test, the tests running side by side in one process.
        static SESSIONS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let k = SESSIONS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let name = format!("sapnet-e2e-{}-{k}", std::process::id());
        // Two tests starting the first sessions at once race to start the tmux server, and
        // the loser's new-session fails: try again once the server is up.
        for attempt in 1..=5 {
            let status = Command::new("tmux")
                .args(["new-session", "-d", "-s", &name])
                .args(["-x", &width.to_string(), "-y", &height.to_string()])
                .arg(command)
                .status()
                .expect("running tmux");
            if status.success() {
                return Session(name);
            }
            assert!(attempt < 5, "tmux new-session failed 5 times");
            sleep(Duration::from_millis(200));
        }
        unreachable!("the loop returns or fails")
    }

    pub fn keys(&self, keys: &str) {
        let status = Command::new("tmux")
            .args(["send-keys", "-t", &self.0, keys])
            .status()
            .expect("running tmux");
        assert!(status.success());
    }

    /// The pane's text, a line wrapped by the terminal joined back into one (`-J`), so a
    /// message is found whatever the pane's width.
    pub fn screen(&self) -> String {
        let out = Command::new("tmux")
            .args(["capture-pane", "-p", "-J", "-t", &self.0])
            .output()
            .expect("running tmux");
        String::from_utf8_lossy(&out.stdout).into_owned()
    }

    /// The pane's rows as the terminal shows them, its scrollback first, a wrapped line as
    /// two rows.
    pub fn rows(&self) -> Vec<String> {
        let out = Command::new("tmux")
            .args(["capture-pane", "-p", "-S", "-", "-t", &self.0])
            .output()
            .expect("running tmux");
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .map(str::to_string)
            .collect()
    }

    /// Waits until every one of `needles` is on the screen.
    pub fn wait_for(&self, needles: &[&str]) -> String {
        let deadline = Instant::now() + Duration::from_secs(120);
        loop {
            let screen = self.screen();
            if needles.iter().all(|n| screen.contains(n)) {
                return screen;
            }
            assert!(
                Instant::now() < deadline,
                "waited 120 s for {needles:?}; the screen:\n{screen}"
            );
            sleep(Duration::from_millis(200));
        }
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        let _ = Command::new("tmux")
            .args(["kill-session", "-t", &self.0])
            .status();
    }
}
