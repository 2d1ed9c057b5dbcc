//! Python bindings of the ErrP testbed (`errp._core`): a thin layer over
//! the Rust crates, which stay the one implementation.
//!
//! Every function here converts arguments, releases the GIL for the Rust
//! work, and converts results to numpy arrays, dictionaries or CSV text that
//! the pure-Python package (`python/src/errp`) turns into pandas frames and
//! MNE objects. Errors in what the caller gave are `ValueError`s that name
//! the field and the accepted range (the messages of the scenario loaders);
//! files that cannot be read or written are `OSError`s; an exception raised
//! by a decoder of the caller's own propagates unchanged.

// No function over 100 lines of code (clippy.toml) outside the tests.
#![forbid(unsafe_code)]
#![cfg_attr(not(test), warn(clippy::too_many_lines))]

mod convert;
mod decoders;
mod env;
#[cfg(feature = "rerun")]
mod inspect;
mod interrupt;
mod own_eeg;
mod run;
mod session;
mod tasks;

use pyo3::prelude::*;

/// The compiled core of the `errp` package.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(session::simulate_session, m)?)?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(run::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(run::episode_columns, m)?)?;
    #[cfg(feature = "rerun")]
    m.add_function(wrap_pyfunction!(inspect::read_recording, m)?)?;
    m.add_function(wrap_pyfunction!(decoders::temporal_features, m)?)?;
    m.add_function(wrap_pyfunction!(decoders::continuous_features, m)?)?;
    m.add_function(wrap_pyfunction!(decoders::lda_fit, m)?)?;
    m.add_function(wrap_pyfunction!(decoders::svm_fit, m)?)?;
    m.add_function(wrap_pyfunction!(decoders::svm_decision, m)?)?;
    m.add_class::<session::EegGenerator>()?;
    m.add_class::<tasks::GridTask>()?;
    m.add_class::<tasks::EpuckTask>()?;
    m.add_class::<env::GridEnvCore>()?;
    m.add_class::<env::EpuckEnvCore>()?;
    m.add("HAS_RERUN", cfg!(feature = "rerun"))?;
    // The limits the package checks its whole-number arguments against
    // (errp/_args.py), the program's own.
    m.add("MAX_RUNS", errp_sim::epuck::MAX_RUNS)?;
    m.add("MAX_EPISODES", errp_sweep::MAX_EPISODES)?;
    m.add("MAX_THREADS", run::MAX_THREADS)?;
    m.add("MAX_GENERATE_SAMPLES", session::MAX_GENERATE_SAMPLES)?;
    m.add("MAX_LDA_TRIALS", decoders::MAX_LDA_TRIALS)?;
    m.add("MAX_LDA_FEATURES", decoders::MAX_LDA_FEATURES)?;
    m.add("MAX_SVM_TRIALS", decoders::MAX_SVM_TRIALS)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
