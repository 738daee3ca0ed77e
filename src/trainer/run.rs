//! One run, whatever the method: its loop over episodes and steps. Who acts and who learns
//! is the method's [`Selector`](crate::reuse::Selector); what a step, an episode's end and
//! the run's end do (the shared replay buffer, learning, the events, the greedy tests) is
//! [`Run`]'s, once.
//!
//! For SAP-Net this is Algorithm 3 as `DESIGN.md` reads it:
//!
//! ```text
//! load the N source policies, each with its own target network and Adam state
//! one shared replay buffer D for the target task
//! warm-up: the first N × replay_start_size steps of the run, π_0, π_1, … act in turn,
//!          replay_start_size steps each, storing transitions, without learning
//! every later step:
//!     i  ~ P(π_i) = softmax(A / τ)                       # eq. 6
//!     a  = π_i's ε-greedy action; store (s, a, r, s') in D
//!     π_i does one gradient update on a minibatch of D; T_a = E_{t+1} − E_t   # eq. 7
//!     activate(i, 𝒜) if T_a ≤ 0 else activate(i, 0)    # eq. 8–11
//! the chosen policy is argmax_i A_i; it is tested greedily
//! ```
//!
//! A method whose sources learn
//! ([`Learning::ActingSource`](crate::reuse::Learning::ActingSource)) has that warm-up; a
//! method with a learner of its own ([`Learning::Learner`](crate::reuse::Learning::Learner):
//! DQN from scratch, PRQ-learning) has none, and its learner waits for `replay_start_size`
//! transitions as any DQN does.

use std::sync::mpsc::Sender;

use super::events::Event;
use super::run_state::{EpisodeReturn, Run};
use super::spec::RunSpec;
use super::{CommandReceiver, RunOutcome, TrainerError};

/// Trains `spec` for its budget of episodes or environment steps, then tests the result
/// greedily: the chosen source, or the method's own learner. Sends the
/// events of `spec.stream` and obeys `commands` (see [`Command`]); a [`Command::Stop`] (or
/// a closed command channel) ends training early, and the run is then reported as
/// stopped, untested.
///
/// On a non-finite loss the error carries the network with its last good weights.
///
/// [`Command`]: super::Command
/// [`Command::Stop`]: super::Command::Stop
pub fn train(
    spec: &RunSpec,
    events: &Sender<Event>,
    commands: &CommandReceiver,
) -> Result<RunOutcome, TrainerError> {
    let mut run = Run::start(spec, events, commands)?;
    let step_budget = spec.budget.steps().unwrap_or(u64::MAX);
    'episodes: for episode in 1..=spec.budget.episodes() {
        let mut sums = EpisodeReturn::new();
        loop {
            if run.steps() >= step_budget {
                // The budget truncates the episode in progress: it never ends, so neither
                // the selector nor the curve hears a return cut short; the record keeps it.
                run.cut_episode(&sums);
                break 'episodes;
            }
            if !run.may_step() {
                break 'episodes;
            }
            let step = run.step(episode)?;
            sums.add(step.reward, spec.dqn.gamma);
            if step.done {
                break;
            }
        }
        run.end_episode(episode, &sums);
    }
    run.finish()
}
