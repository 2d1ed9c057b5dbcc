//! The integration tests of `errp_robot`, one binary: closed loops of the
//! grid and the continuous controller, and the determinism contracts.

mod determinism;
mod epuck_closed_loop;
mod grid_strategies;
