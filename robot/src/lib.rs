//! The shared-control agent: beliefs over goals updated from a probability of error.
//!
//! `errp_robot` knows nothing of EEG or physics: shared control consumes a
//! probability of error, never an EEG sample. It holds the [`Belief`] over
//! candidate goals that both the grid and the e-puck strategies update, and
//! the grid task's policy matching (sec. 4.2): the 5x5 [`Grid`], optimal
//! Q-values ([`QTable`]), their soft-max (eq. 3), the likelihood of eq. (4)
//! and the epsilon-greedy [`GridController`].
//!
//! For the continuous task (sec. 5) it holds the e-puck's constants and
//! differential-drive kinematics ([`EpuckParams`], [`WheelSpeeds`],
//! [`Twist`], [`integrate`]), the arena's goals ([`GoalLayout::cities`]),
//! the potentials of eq. (5) ([`QuadraticPotential`]), the likelihoods of
//! eq. (6) and (7) ([`turn_likelihood`], [`linear_likelihood`]) and the
//! [`EpuckController`] that turns, drives and stops the robot, with
//! the obstacle reflex under it ([`AvoidanceParams`]).
//!
//! Both controllers choose their actions by a [`Strategy`]: the paper's
//! greedy one, or the [`expected_information_gain`] of the decoder's next
//! assessment; the grid controller also by Thompson sampling (greedy towards
//! a goal drawn from the belief, kept until the user objects or the belief
//! moves away from it).
//!
//! ```
//! use errp_robot::Belief;
//!
//! // Two goals; the device's last action was an error for the first goal
//! // and correct for the second, and the decoder said "error" with p = 0.8:
//! // the likelihood of each goal is what the decoder's output makes of it.
//! let mut belief = Belief::uniform(2);
//! belief.update(&[0.8, 0.2]).unwrap();
//! let p = belief.probabilities();
//! assert!((p[0] - 0.8).abs() < 1e-12 && (p[1] - 0.2).abs() < 1e-12);
//! ```

#![forbid(unsafe_code)]
#![warn(clippy::unwrap_used, clippy::print_stdout, clippy::iter_over_hash_type)]
// No function over 100 lines of code (clippy.toml) outside the tests.
#![cfg_attr(not(test), warn(clippy::too_many_lines))]

mod belief;
mod epuck;
mod error;
mod grid;
mod strategy;

pub use belief::{Belief, log_sum_exp};
pub use epuck::avoidance::AvoidanceParams;
pub use epuck::control::{EpuckController, Observation, Phase, StepKind, StopReason};
pub use epuck::drive::{EpuckParams, Twist, WheelSpeeds, integrate};
pub use epuck::layout::{Goal, GoalLayout, LAYOUT_GRID_CELLS};
pub use epuck::likelihood::{EpuckControlParams, linear_likelihood, turn_likelihood};
pub use epuck::pose::{Pose, wrap_angle};
pub use epuck::potential::QuadraticPotential;
pub use error::{Result, RobotError};
pub use errp_valid::{Check, Valid};
pub use grid::control::{GridControlParams, GridController};
pub use grid::policy::policy_likelihood;
pub use grid::qvalues::{QParams, QTable, softmax};
pub use grid::{Cell, Grid, GridAction};
pub use strategy::{Strategy, entropy_nats, expected_information_gain};
