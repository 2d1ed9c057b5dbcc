//! The integration tests of `errp_bci`, one binary: the synthetic EEG, the
//! discrete and continuous decoders, and the determinism contracts.

mod continuous;
mod decoder;
mod determinism;
mod eeg;
mod own_eeg;
mod realism;
