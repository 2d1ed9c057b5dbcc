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

/// A request to wind down, held by the caller of work that runs in units
/// (a sweep's episodes, a fit's users): the units in flight finish and no
/// more start, so that everything written is whole and the same call
/// resumes. A stop [`request`]ed process-wide winds down too, so a caller
/// that sets only that (the Python package on Ctrl-C) needs nothing else.
#[derive(Debug, Default)]
pub struct WindDown(AtomicBool);

impl WindDown {
    /// No request yet.
    pub const fn new() -> Self {
        Self(AtomicBool::new(false))
    }

    /// Asks the work to finish its units in flight and start no more.
    pub fn request(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    /// Whether to start no more units: this was requested, or a stop was,
    /// process-wide.
    pub fn requested(&self) -> bool {
        self.0.load(Ordering::SeqCst) || requested()
    }
}
