//! The scratch memory of gradient updates, kept per thread and per network shape.
//!
//! In the transfer loop a library's learners take turns (one learns at each step), so
//! scratch memory owned by each learner would grow with the library, each piece allocated
//! and zeroed once per learner and idle the rest of the time. Kept per thread and per shape
//! instead, it grows with the shapes a library holds (three in Table II), and a learner
//! picks up the buffers its shape used last. The passes overwrite everything they read, so
//! whose buffers they were changes no number.

use std::cell::RefCell;

use super::backprop::Workspace;
use super::Architecture;

/// The buffers of one update: the online network's passes and the target network's.
#[derive(Debug, Default)]
pub(crate) struct UpdateWork {
    pub online: Workspace,
    pub target: Workspace,
}

/// A thread's [`UpdateWork`]s, the most recently used last.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    kept: Vec<UpdateWork>,
}

/// Shapes a thread keeps buffers for; the least recently used goes past that (a run that
/// meets more shapes than this only allocates more often).
const SHAPES_KEPT: usize = 8;

impl Scratch {
    /// The buffers for `architecture` at `batch`: the ones that shape used last, or new ones.
    pub(crate) fn for_shape(
        &mut self,
        architecture: &Architecture,
        batch: usize,
    ) -> &mut UpdateWork {
        let found = self
            .kept
            .iter()
            .rposition(|work| work.online.is_for(architecture, batch));
        let last = self.kept.len().wrapping_sub(1);
        let work = match found {
            // The common case (one learner, or learners of one shape): nothing moves.
            Some(at) if at == last => return &mut self.kept[last],
            Some(at) => self.kept.remove(at),
            None => {
                if self.kept.len() == SHAPES_KEPT {
                    self.kept.remove(0);
                }
                UpdateWork::default()
            }
        };
        self.kept.push(work);
        self.kept.last_mut().expect("just pushed")
    }
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::default();
}

/// Calls `f` with this thread's scratch memory.
///
/// # Panics
/// If `f` calls `with_scratch` again (an update never runs inside another).
pub(crate) fn with_scratch<R>(f: impl FnOnce(&mut Scratch) -> R) -> R {
    SCRATCH.with_borrow_mut(f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dqn::kernels::Isa;
    use crate::dqn::QNet;
    use rand::{rngs::StdRng, SeedableRng};

    #[test]
    fn each_shape_gets_its_own_buffers_and_finds_them_again() {
        let mut rng = StdRng::seed_from_u64(3);
        let small = QNet::new(Architecture::new(4, &[8], 2), &mut rng).unwrap();
        let deep = QNet::new(Architecture::new(4, &[8, 8], 2), &mut rng).unwrap();
        let mut scratch = Scratch::default();
        let obs = [0.5f32; 4 * 3];
        for net in [&small, &deep, &small] {
            let work = scratch.for_shape(net.architecture(), 3);
            net.forward_with(Isa::Portable, &obs, 3, &mut work.online)
                .unwrap();
        }
        assert_eq!(scratch.kept.len(), 2);
        assert!(scratch.kept[1].online.is_for(small.architecture(), 3));
        // Another batch size is another shape.
        scratch.for_shape(small.architecture(), 4);
        assert_eq!(scratch.kept.len(), 3);
    }

    #[test]
    fn past_the_limit_the_least_recently_used_shape_goes() {
        let mut rng = StdRng::seed_from_u64(4);
        let mut scratch = Scratch::default();
        let obs = [0.5f32; 4];
        let nets: Vec<QNet> = (1..=SHAPES_KEPT + 1)
            .map(|units| QNet::new(Architecture::new(4, &[units], 2), &mut rng).unwrap())
            .collect();
        for net in &nets {
            let work = scratch.for_shape(net.architecture(), 1);
            net.forward_with(Isa::Portable, &obs, 1, &mut work.online)
                .unwrap();
        }
        assert_eq!(scratch.kept.len(), SHAPES_KEPT);
        assert!(!scratch
            .kept
            .iter()
            .any(|w| w.online.is_for(nets[0].architecture(), 1)));
    }
}
