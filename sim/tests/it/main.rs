//! The integration tests of `errp_sim`, one binary: the grid task with the
//! EEG decoder, the e-puck task end to end, and the determinism contracts.

mod determinism;
mod epuck;
mod grid;
