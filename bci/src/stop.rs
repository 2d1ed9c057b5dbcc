//! A request to stop long work early, process-wide as a signal is: the
//! Python package sets it when Ctrl-C arrives during a call that runs in
//! Rust, and the long loops (a session's EEG blocks, the targeting's steps,
//! the episodes of a run) return [`BciError::Interrupted`] at their next
//! check, within a fraction of a second. The command-line program handles
//! its signals itself and never sets it.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::error::{BciError, Result};

static STOP: AtomicBool = AtomicBool::new(false);

/// Asks every long loop to stop at its next check.
pub fn request() {
    STOP.store(true, Ordering::SeqCst);
}

/// Withdraws the request (before the next call starts).
pub fn clear() {
    STOP.store(false, Ordering::SeqCst);
}

/// Whether a stop is requested.
pub fn requested() -> bool {
    STOP.load(Ordering::Relaxed)
}

/// `Err(Interrupted)` if a stop is requested: the check of a long loop.
pub fn check() -> Result<()> {
    if requested() {
        Err(BciError::Interrupted)
    } else {
        Ok(())
    }
}
