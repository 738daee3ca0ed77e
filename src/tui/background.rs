//! Work a view hands to a thread of its own so that its screen never waits for it (the
//! Curves view's curves of a large folder: seconds of reading and bootstrapping). The one
//! event loop ([`super::event_loop`]) draws every frame while any such work runs, so that
//! the view can show that it works, and once more when a piece ends, so that its result
//! is drawn without a key.

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::mpsc;

static RUNNING: AtomicUsize = AtomicUsize::new(0);
static ENDED: AtomicU64 = AtomicU64::new(0);

/// Counts a piece of work from its start to its end (dropped however the work ends).
struct Running;

impl Running {
    fn start() -> Self {
        RUNNING.fetch_add(1, Ordering::SeqCst);
        Running
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        RUNNING.fetch_sub(1, Ordering::SeqCst);
        ENDED.fetch_add(1, Ordering::SeqCst);
    }
}

/// Runs `work` on a thread named `name` at the lowest priority; its result comes on the
/// receiver (sent before the work counts as ended). Where no thread can be started, the
/// work is done here.
pub fn spawn<T: Send + 'static>(
    name: &str,
    work: impl FnOnce() -> T + Send + 'static,
) -> mpsc::Receiver<T> {
    let (tx, rx) = mpsc::channel();
    let running = Running::start();
    let work = std::sync::Arc::new(std::sync::Mutex::new(Some((work, tx, running))));
    let on_thread = work.clone();
    let started = std::thread::Builder::new()
        .name(name.to_string())
        .spawn(move || {
            crate::tui::workbench::folder::lowest_priority();
            if let Some((work, tx, running)) = on_thread.lock().ok().and_then(|mut w| w.take()) {
                let _ = tx.send(work());
                drop(running);
            }
        });
    if started.is_err() {
        if let Some((work, tx, running)) = work.lock().ok().and_then(|mut w| w.take()) {
            let _ = tx.send(work());
            drop(running);
        }
    }
    rx
}

/// Whether some work runs now.
pub fn busy() -> bool {
    RUNNING.load(Ordering::SeqCst) > 0
}

/// How many pieces of work have ended so far: when this changes, a result waits.
pub fn ended() -> u64 {
    ENDED.load(Ordering::SeqCst)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_result_is_there_when_the_work_counts_as_ended() {
        let before = ended();
        let rx = spawn("test", || 6 * 7);
        assert_eq!(rx.recv().unwrap(), 42);
        // The count moves just after the send.
        while ended() == before {
            std::thread::yield_now();
        }
    }
}
