//! EDF+ export of raw EEG with event annotations ([`EdfWriter`]), and the
//! reading of EDF, EDF+, BDF and BDF+ files ([`EdfFile`]) for a person's own
//! EEG.

mod read;
mod write;

pub use read::{EdfAnnotation, EdfFile, EdfFormat, EdfSignal, MAX_EDF_SAMPLES, MAX_EDF_SIGNALS};
pub use write::EdfWriter;
