//! The integration tests of `errp_sim`, one binary: the grid task with the
//! EEG decoder, the e-puck task end to end, the determinism contracts, the
//! hooks for decoders and agents of the user's own (`hooks`), and
//! property tests of the scenario loaders (`scenario_fuzz`), and damaged
//! recordings read back (`recordings`).
mod determinism;
mod epuck;
mod grid;
mod hooks;
mod live;
mod own_eeg;
mod realism;
#[cfg(feature = "rerun")]
mod recordings;
mod rules;
mod scenario_fuzz;
