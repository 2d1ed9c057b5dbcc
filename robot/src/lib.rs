//! The shared-control agent: beliefs over goals updated from a probability of error.
//!
//! `errp_robot` knows nothing of EEG or physics: shared control consumes a
//! probability of error, never an EEG sample. It holds the [`Belief`] over
//! candidate goals that both the grid and the e-puck strategies update.

mod belief;
mod error;

pub use belief::{Belief, log_sum_exp};
pub use error::{Result, RobotError};
