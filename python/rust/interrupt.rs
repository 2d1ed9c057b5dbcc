//! Long calls that Ctrl-C stops. The work runs on a thread of its own; the
//! calling thread (Python's main thread, where signal handlers run) waits
//! with the GIL released and checks Python's signals every 50 ms. When a
//! handler raises (Ctrl-C's `KeyboardInterrupt`), the work is asked to stop
//! ([`errp_bci::stop`]: it checks between EEG blocks, targeting steps and
//! episodes, a fraction of a second apart), the call waits for it and
//! raises the handler's exception. What the work was writing is dropped
//! unfinished, and a file that was not finished is removed, as when the
//! command-line program is interrupted.

use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::Duration;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

/// How often the calling thread looks for a signal.
const POLL: Duration = Duration::from_millis(50);

/// `work` run as the module says, its result once it is done.
pub(crate) fn long<T: Send>(py: Python<'_>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    long_or(py, || {}, work)
}

/// [`long`], with `on_stop` also run when a signal stops the work (a
/// sweep's own cancel flag, which it polls between episodes).
pub(crate) fn long_or<T: Send>(
    py: Python<'_>,
    on_stop: impl Fn(),
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    errp_bci::stop::clear();
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
                Ok(value) => return Ok(value),
                Err(RecvTimeoutError::Disconnected) => {
                    // The worker panicked; the scope re-raises its panic
                    // when it ends, which PyO3 turns into an exception.
                    return Err(PyRuntimeError::new_err("the work stopped without a result"));
                }
                Err(RecvTimeoutError::Timeout) => {
                    if let Err(e) = py.check_signals() {
                        errp_bci::stop::request();
                        on_stop();
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
