//! Ctrl-C, SIGTERM and SIGHUP: what the program leaves behind when it is
//! stopped.
//!
//! Outside a sweep's episodes, a signal removes every file still being
//! written (the temporaries of `--save`, `--export` and the sweep's files,
//! and the sweep's lock) and exits at once with code 130. While a sweep
//! writes episodes, the first signal asks it to stop after the episodes in
//! flight (every row on disk is kept, and the same command resumes); a
//! second one exits at once, as above.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::out::errln;

/// Set by the first signal while a sweep writes episodes.
pub(crate) static WIND_DOWN: errp_bci::stop::WindDown = errp_bci::stop::WindDown::new();

/// True while a sweep writes episodes (a signal then stops it gracefully).
static GRACEFUL: AtomicBool = AtomicBool::new(false);

/// The exit code of an interrupted command.
pub(crate) const EXIT_INTERRUPTED: u8 = 130;

/// Installs the handler (once, at start-up).
pub(crate) fn install() {
    // Under a file-size limit (`ulimit -f`) a write that passes it kills
    // the process with SIGXFSZ, leaving its temporaries. With a handler the
    // write fails with EFBIG instead: an error, after which the temporaries
    // go, as for a full disk.
    #[cfg(unix)]
    let _ = signal_hook::flag::register(
        signal_hook::consts::SIGXFSZ,
        std::sync::Arc::new(AtomicBool::new(false)),
    );
    // Without a handler (an unusual platform) the default action stays:
    // the process ends, and the next run removes what it left.
    let _ = ctrlc::set_handler(|| {
        if GRACEFUL.load(Ordering::SeqCst) && !WIND_DOWN.requested() {
            WIND_DOWN.request();
            errln!(
                "\nStopping after the episodes in progress (every row on disk is kept; signal \
                 again to stop at once)"
            );
            return;
        }
        let removed = errp_sim::remove_unfinished();
        if removed > 0 {
            errln!("\nInterrupted: removed {removed} unfinished file(s)");
        } else {
            errln!("\nInterrupted");
        }
        std::process::exit(i32::from(EXIT_INTERRUPTED));
    });
}

/// From now on a signal stops the sweep between episodes (`true`), or at
/// once (`false`).
pub(crate) fn graceful(on: bool) {
    GRACEFUL.store(on, Ordering::SeqCst);
}
