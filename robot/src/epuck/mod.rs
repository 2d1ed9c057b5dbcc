//! The e-puck task (sec. 5, the paper's continuous task): the e-puck's constants and kinematics, its
//! pose, the arena's goals, the potentials of eq. (5), the likelihoods of
//! eq. (6) and (7), the obstacle reflex and the controller that turns,
//! drives and stops the robot.

pub(crate) mod avoidance;
pub(crate) mod control;
pub(crate) mod drive;
pub(crate) mod layout;
pub(crate) mod likelihood;
pub(crate) mod pose;
pub(crate) mod potential;
