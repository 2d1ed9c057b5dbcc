//! Standard output and standard error, written without panics.
//!
//! `println!` panics when standard output cannot be written (exit code
//! 101); these do not:
//!
//! - A reader that has gone (a closed pipe, `errp run ... | head -1`) is
//!   not an error. The rest of the output is dropped, the work goes on, so
//!   every file the command was asked to write (`--save`, `--export`,
//!   `--out`) is written, and the command exits as it would have (0 when
//!   it succeeds), as `ripgrep` does.
//! - Any other failure of standard output (a full disk: `> /dev/full`) is
//!   an error naming standard output and its cause: the command stops,
//!   removes what it had not finished, and exits with code 2.
//! - Standard error is where such errors are reported, so its own failures
//!   cannot be: they are ignored (the exit code still tells).

use std::io::{self, Write};
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Result, anyhow};

/// Set once a write found the reader gone.
static STDOUT_GONE: AtomicBool = AtomicBool::new(false);

/// Writes `args` to standard output: see the module's rules.
pub(crate) fn stdout(args: std::fmt::Arguments) -> Result<()> {
    if STDOUT_GONE.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut out = io::stdout().lock();
    outcome(out.write_fmt(args))
}

/// Flushes standard output (at the end of a command): a failure to write
/// what was buffered is an error as any other.
pub(crate) fn flush() -> Result<()> {
    if STDOUT_GONE.load(Ordering::Relaxed) {
        return Ok(());
    }
    outcome(io::stdout().lock().flush())
}

fn outcome(result: io::Result<()>) -> Result<()> {
    match result {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == io::ErrorKind::BrokenPipe => {
            STDOUT_GONE.store(true, Ordering::Relaxed);
            Ok(())
        }
        Err(e) => Err(anyhow!("cannot write to standard output: {e}")),
    }
}

/// Writes `args` to standard error, ignoring its failures.
pub(crate) fn stderr(args: std::fmt::Arguments) {
    let _ = io::stderr().lock().write_fmt(args);
}

/// `print!` that returns an error instead of panicking (use with `?`).
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::out::stdout(format_args!($($arg)*))
    };
}

/// `println!` that returns an error instead of panicking (use with `?`).
macro_rules! outln {
    () => {
        $crate::out::stdout(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::out::stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprintln!` that ignores a standard error that cannot be written.
macro_rules! errln {
    () => {
        $crate::out::stderr(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::out::stderr(format_args!("{}\n", format_args!($($arg)*)))
    };
}

pub(crate) use {errln, out, outln};
