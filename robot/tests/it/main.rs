//! The integration tests of `errp_robot`, one binary: closed loops of the
//! grid and the continuous controller, and the determinism contracts.

mod continuous_closed_loop;
mod determinism;
mod grid_strategies;
