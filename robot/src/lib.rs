//! The shared-control agent: beliefs over goals updated from a probability of error.
//!
//! `errp_robot` knows nothing of EEG or physics: shared control consumes a
//! probability of error, never an EEG sample. It holds the [`Belief`] over
//! candidate goals that both the grid and the e-puck strategies update, and
//! the grid task's policy matching (sec. 4.2): the 5x5 [`Grid`], optimal
//! Q-values ([`QTable`]), their soft-max (eq. 3), the likelihood of eq. (4)
//! and the epsilon-greedy [`GridController`].

mod belief;
mod error;
mod grid;
mod grid_control;
mod qvalues;

pub use belief::{Belief, log_sum_exp};
pub use error::{Result, RobotError};
pub use grid::{Cell, Grid, GridAction};
pub use grid_control::{GridControlParams, GridController, policy_likelihood};
pub use qvalues::{QParams, QTable, softmax};
