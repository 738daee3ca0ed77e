//! stderr held aside while a screen is up: what a protocol's code says there (a library
//! trained on first use, a warning) would be drawn over the screen. It goes to a private
//! file, and is said on the real stderr, in order, once the screen has closed.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::os::fd::AsRawFd;

/// stderr redirected to a temporary file until dropped.
pub struct StderrCapture {
    file: File,
    /// The real stderr, duplicated before it was replaced.
    saved: libc::c_int,
}

impl StderrCapture {
    /// Redirects stderr; `None` (stderr left as it is) if it cannot.
    pub fn start() -> Option<Self> {
        let file = tempfile::tempfile().ok()?;
        let _ = std::io::stderr().flush();
        // SAFETY: dup and dup2 on descriptors this process owns; a failure is checked
        // and leaves stderr as it was.
        let saved = unsafe { libc::dup(2) };
        if saved < 0 {
            return None;
        }
        if unsafe { libc::dup2(file.as_raw_fd(), 2) } < 0 {
            unsafe { libc::close(saved) };
            return None;
        }
        Some(Self { file, saved })
    }
}

impl Drop for StderrCapture {
    fn drop(&mut self) {
        let _ = std::io::stderr().flush();
        // SAFETY: puts back the descriptor saved in `start`, then closes the copy.
        unsafe {
            libc::dup2(self.saved, 2);
            libc::close(self.saved);
        }
        let mut said = Vec::new();
        if self.file.seek(SeekFrom::Start(0)).is_ok() && self.file.read_to_end(&mut said).is_ok() {
            let _ = std::io::stderr().write_all(&said);
        }
    }
}
