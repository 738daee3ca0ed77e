//! A round of many updates that a stop can end between two of them, shared by every
//! learner: a run told to stop (its command channel's flag) does not wait out a round of
//! thousands of updates (`gradient_steps` up to 10,000, QDagger's offline phase), and what
//! the round learned before the stop is kept.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use super::DqnError;

/// The run's stop flag as a learner hears it; none for a learner outside a run.
#[derive(Debug, Clone, Default)]
pub(super) struct Interrupt(Option<Arc<AtomicBool>>);

impl Interrupt {
    pub fn new(flag: Arc<AtomicBool>) -> Self {
        Self(Some(flag))
    }

    pub fn raised(&self) -> bool {
        self.0.as_ref().is_some_and(|f| f.load(Ordering::Relaxed))
    }
}

/// `count` updates by `update`, each told its index from 0, `interrupt` heard between two
/// of them (and before the first too when `before_first`): the last update's loss, none if
/// none ran.
pub(super) fn round(
    count: u64,
    before_first: bool,
    interrupt: &Interrupt,
    mut update: impl FnMut(u64) -> Result<f64, DqnError>,
) -> Result<Option<f64>, DqnError> {
    let mut loss = None;
    for k in 0..count {
        if (k > 0 || before_first) && interrupt.raised() {
            break;
        }
        loss = Some(update(k)?);
    }
    Ok(loss)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_raised_stop_ends_the_round_between_two_updates() {
        let flag = Arc::new(AtomicBool::new(false));
        let interrupt = Interrupt::new(Arc::clone(&flag));
        let mut made = Vec::new();
        let loss = round(5, false, &interrupt, |k| {
            made.push(k);
            if k == 2 {
                flag.store(true, Ordering::SeqCst);
            }
            Ok(k as f64)
        })
        .unwrap();
        assert_eq!((made, loss), (vec![0, 1, 2], Some(2.0)));
        // Raised before the round: the first update still runs, unless heard before it.
        assert_eq!(
            round(3, false, &interrupt, |k| Ok(k as f64)).unwrap(),
            Some(0.0)
        );
        assert_eq!(round(3, true, &interrupt, |k| Ok(k as f64)).unwrap(), None);
        assert_eq!(
            round(2, true, &Interrupt::default(), |k| Ok(k as f64)).unwrap(),
            Some(1.0)
        );
    }
}
