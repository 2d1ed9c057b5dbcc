//! What a sweep reports as it goes: decoders calibrated, episodes done, notes.

use errp_sim::task::DecoderInfo;

/// What a sweep reports as it goes. Every method defaults to nothing;
/// `()` watches nothing.
pub trait SweepObserver: Sync {
    /// A decoder is calibrated (`done` of `total`).
    fn decoder_ready(&self, _info: &DecoderInfo, _done: usize, _total: usize) {}
    /// `done` of this run's `total` episodes are on disk.
    fn episodes_done(&self, _done: usize, _total: usize) {}
    /// Something the user should know that is not an error (rows dropped
    /// by `--repair`).
    fn note(&self, _text: &str) {}
    /// Something found wrong that the sweep worked around (a cache entry
    /// that did not verify, searched again).
    fn warning(&self, _text: &str) {}
}

impl SweepObserver for () {}
