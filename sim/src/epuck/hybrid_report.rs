//! What an e-puck hybrid was made of, as the output and a recording's
//! provenance say it ([`crate::epuck::prepare_hybrid`]).

use crate::own_eeg::{FITTED_FALSE_ALARMS_PER_MIN, FileDigest, twice};

/// What the hybrid was made of, as the output and the recording's
/// provenance say it.
#[derive(Debug, Clone, PartialEq)]
pub struct HybridReport {
    /// The own EEG file's name, size and SHA-256.
    pub file: FileDigest,
    /// Events of the calibration part (the subject's response).
    pub calibration_events: usize,
    /// Error and correct epochs averaged into the response.
    pub template_counts: (usize, usize),
    /// Seconds of background in the calibration part and in the rest.
    pub background_secs: (f64, f64),
    /// EOG channels found (0: no EOG regression).
    pub eog_channels: usize,
    /// Events annotated twice (the same class at the same sample), each
    /// kept once.
    pub merged: usize,
    /// The false alarms a minute T_e was set for.
    pub false_alarms_per_min: f64,
    /// The T_e found.
    pub t_e: f64,
    /// The SVM's cross-validated mean accuracy: the accuracy the shared
    /// control assumes.
    pub accuracy: f64,
}

/// The label every output of a hybrid run carries.
pub const HYBRID_LABEL: &str = "hybrid: recorded background, recorded ErrP template";

impl std::fmt::Display for HybridReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (errors, correct) = self.template_counts;
        let (calibration, online) = self.background_secs;
        writeln!(
            f,
            "EEG: {HYBRID_LABEL}, from recording {} ({} bytes, SHA-256 {}){}",
            self.file.name,
            self.file.bytes,
            self.file.sha256,
            twice(self.merged)
        )?;
        writeln!(
            f,
            "  the subject's error-minus-correct response from the first {} events ({errors} \
             error, {correct} correct epochs); background {calibration:.1} s for the \
             calibration, the other {online:.1} s online (looped){}",
            self.calibration_events,
            if self.eog_channels == 0 {
                "; no EOG channels: no EOG regression"
            } else {
                ""
            }
        )?;
        write!(
            f,
            "  T_e = {:.3}: {} false alarms a minute on the held-out hybrid (the paper-fitted \
             user's at T_e = 0.8 is {FITTED_FALSE_ALARMS_PER_MIN})",
            self.t_e, self.false_alarms_per_min
        )
    }
}
