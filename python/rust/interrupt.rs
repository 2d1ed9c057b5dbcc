//! Long calls that Ctrl-C stops. The work runs on a thread of its own; the
//! calling thread (Python's main thread, where signal handlers run) waits
//! with the GIL released and checks Python's signals every 50 ms. When a
//! handler raises (Ctrl-C's `KeyboardInterrupt`), the work is asked to stop
//! ([`errp_bci::stop`]: it checks between EEG blocks, targeting steps and
//! episodes, a fraction of a second apart), the call waits for it and
//! raises the handler's exception. What the work was writing is dropped
//! unfinished, and a file that was not finished is removed, as when the
//! command-line program is interrupted.
//!
//! The same loop shows progress: the work counts what it has done on a
//! [`Meter`], and the calling thread passes each change to the caller's
//! `progress` callable (`errp/_progress.py`: a tqdm bar, or lines on
//! stderr) with the GIL held.

use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Mutex, PoisonError};
use std::time::Duration;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

/// How often the calling thread looks for a signal.
const POLL: Duration = Duration::from_millis(50);

/// The stages a long call reports (`progress=`): a targeting search, then
/// grid episodes or e-puck runs.
pub(crate) const CALIBRATING: &str = "calibrating";
pub(crate) const EPISODES: &str = "episodes";
pub(crate) const RUNS: &str = "runs";

/// What a long call has done: its stage ("calibrating", "episodes",
/// "runs", "levels"), how many of its steps are done, and of how many (0:
/// not known beforehand, as the steps of a targeting search).
#[derive(Debug, Default)]
pub(crate) struct Meter {
    state: Mutex<(&'static str, usize, usize)>,
}

impl Meter {
    /// `done` of `total` steps of `stage` are done.
    pub(crate) fn set(&self, stage: &'static str, done: usize, total: usize) {
        *self.state.lock().unwrap_or_else(PoisonError::into_inner) = (stage, done, total);
    }

    /// One more step of `stage` (of `total`) is done; the count restarts
    /// when the stage changes.
    pub(crate) fn step(&self, stage: &'static str, total: usize) {
        let mut s = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        let done = if s.0 == stage { s.1 + 1 } else { 1 };
        *s = (stage, done, total);
    }

    fn read(&self) -> (&'static str, usize, usize) {
        *self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// A [`Meter`] and the callable that shows it: `progress(stage, done,
/// total)`.
pub(crate) type Shown<'a, 'py> = Option<(&'a Meter, &'a Bound<'py, PyAny>)>;

/// `work` run as the module says, its result once it is done.
pub(crate) fn long<T: Send>(py: Python<'_>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    long_or(py, None, work)
}

/// [`long`], its progress shown by `progress` when given.
pub(crate) fn long_shown<T: Send>(
    py: Python<'_>,
    meter: &Meter,
    progress: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    long_or(py, progress.map(|p| (meter, p)), work)
}

/// [`long`], with the progress `shown`. An exception the progress
/// callable raises stops the work as a signal does. A signal stops every
/// kind of work one way ([`errp_bci::stop::request`]): a sweep sees it as a
/// [`errp_bci::stop::WindDown`] too, so the rows it wrote are kept and the
/// same call later resumes.
pub(crate) fn long_or<T: Send>(
    py: Python<'_>,
    shown: Shown<'_, '_>,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    errp_bci::stop::clear();
    let mut last = ("", 0, 0);
    let mut show = move || -> PyResult<()> {
        if let Some((meter, progress)) = shown {
            let now = meter.read();
            if now != last && !now.0.is_empty() {
                last = now;
                progress.call1(now)?;
            }
        }
        Ok(())
    };
    std::thread::scope(|scope| {
        let (tx, rx) = mpsc::channel();
        scope.spawn(move || {
            // The receiver is gone only if the caller is: nothing to tell.
            let _ = tx.send(work());
        });
        let mut rx = rx;
        loop {
            let (got, back) = py.detach(move || (rx.recv_timeout(POLL), rx));
            rx = back;
            match got {
                Ok(value) => {
                    show()?;
                    return Ok(value);
                }
                Err(RecvTimeoutError::Disconnected) => {
                    // The worker panicked; the scope re-raises its panic
                    // when it ends, which PyO3 turns into an exception.
                    return Err(PyRuntimeError::new_err("the work stopped without a result"));
                }
                Err(RecvTimeoutError::Timeout) => {
                    if let Err(e) = py.check_signals().and_then(|()| show()) {
                        errp_bci::stop::request();
                        // Wait for the work to see it, the GIL released
                        // (a decoder of the caller's own may need it).
                        let _ = py.detach(move || rx.recv());
                        errp_bci::stop::clear();
                        return Err(e);
                    }
                }
            }
        }
    })
}
