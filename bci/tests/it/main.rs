//! The integration tests of `errp_bci`, one binary: the synthetic EEG, the
//! discrete and continuous decoders, the self-calibration papers' Gaussian
//! classifier, the determinism contracts, and the
//! EDF reader on files other tools wrote.

mod continuous;
mod decoder;
mod determinism;
mod edf_fixtures;
mod eeg;
mod gaussian;
mod own_eeg;
mod realism;
