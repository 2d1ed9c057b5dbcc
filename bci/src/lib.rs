//! Synthetic EEG with error potentials, and the real ErrP decoder that reads it.
//!
//! The crate knows nothing of robots. It provides:
//!
//! * a [`Montage`] (the paper's 32 EEG channels + C1, C2, six EOG channels)
//!   with electrode positions from `assets/electrodes.csv`;
//! * an [`EegGenerator`]: assessment events in, continuous 256 Hz samples out
//!   (1/f background, alpha, sensor and line noise, blinks and saccades, and
//!   the ErrP of Fig. 1 of the paper on erroneous assessments);
//! * the paper's preprocessing ([`Preprocessor`]: notch, band-pass, CAR, EOG
//!   regression), temporal features ([`EpochWindow`]) and discrete decoder
//!   ([`LdaDecoder`]: z-score, PCA 95 %, shrinkage LDA, sigmoid);
//! * calibration sessions scored by cross-validation ([`calibrate`]) and
//!   accuracy targeting ([`target_accuracy`]): the ErrP-to-noise ratio at
//!   which the real decoder reaches a requested accuracy;
//! * the continuous decoder of sec. 2.2.2: temporal + theta PSD features of
//!   an 800 ms window ([`ContinuousFeatures`], [`ThetaPsd`]), an RBF SVM with
//!   Platt-scaled output ([`SvmDecoder`]), its trigger-locked calibration
//!   ([`calibrate_continuous`]) and accuracy targeting
//!   ([`target_continuous_accuracy`]), and its online side: the sliding
//!   window ([`SlidingWindow`]), the asynchronous [`Detector`] and its
//!   operating point on a held-out session ([`operating_point`]);
//! * the information one decoded action carries about the user's verdict
//!   ([`ActionInformation`]);
//! * the Gaussian classifier of the self-calibration papers
//!   ([`GaussianClassifier`]: soft labels, shrunk per-class covariances,
//!   Student-t densities) and its cross-validated confusion correction
//!   ([`confusion_matrix`]);
//! * the subjects of Table 1 ([`subject`]), EDF+ export ([`EdfWriter`]);
//! * a person's own EEG in place of the synthetic EEG: EDF, EDF+,
//!   BDF and BDF+ read and checked ([`EdfFile`]), matched to the montage
//!   ([`OwnEeg`]) and split into a calibration part and held-out epochs
//!   ([`split_own_eeg`]).
//!
//! ```
//! use errp_bci::{MeanAccuracy, RequestedAccuracy, subject};
//!
//! // An accuracy is checked where it enters: the mean of the two classes'
//! // rates, strictly between chance and 1 (1 only for the grid's oracle).
//! assert!(MeanAccuracy::new(0.7438).is_ok());
//! assert!(MeanAccuracy::new(0.5).is_err());
//! assert!(matches!(RequestedAccuracy::new(1.0), Ok(RequestedAccuracy::Perfect)));
//! // Table 1's subjects, with the accuracies the paper reports.
//! let s1 = subject("S1").unwrap();
//! assert_eq!(s1.fixed_goals_pct, 83.14);
//! ```

#![forbid(unsafe_code)]
#![warn(clippy::unwrap_used, clippy::print_stdout, clippy::iter_over_hash_type)]
// No function over 100 lines of code (clippy.toml) outside the tests.
#![cfg_attr(not(test), warn(clippy::too_many_lines))]

mod calibration;
mod classify;
mod continuous;
mod edf;
mod erp;
mod error;
mod features;
mod filter;
mod gaussian;
mod generator;
mod information;
mod lda;
mod montage;
mod noise;
mod online;
mod own_eeg;
mod platt;
mod preprocess;
mod psd;
pub mod rng;
mod smo;
mod special;
pub mod stop;
mod subjects;
mod svm;

pub use calibration::continuous::{
    ContinuousCalibrationParams, ContinuousSetup, calibrate_continuous, calibrate_continuous_with,
    continuous_schedule, simulate_continuous_session,
};
pub use calibration::targeting::{
    MeanAccuracy, RequestedAccuracy, SessionParts, TargetingResult, TargetingStep,
    inverse_normal_cdf, ratio_text, search_ratio, target_accuracy, target_accuracy_on,
    target_continuous_accuracy,
};
pub use calibration::{
    Accuracy, Calibrated, CalibratedModel, CalibrationParams, CalibrationSession, CalibrationSetup,
    GrandAverage, Protocol, RawSink, SessionOptions, Setup, TargetingParams, calibrate,
    calibrate_features, calibrate_session, cross_validate, cv_seed, eog_session, export_session,
    out_of_fold_decisions, schedule, simulate_session, simulate_session_with,
};
pub use classify::{Classifier, ErrorModel, Features, sigmoid, stratified_folds};
pub use continuous::ContinuousFeatures;
pub use edf::{
    EdfAnnotation, EdfFile, EdfFormat, EdfSignal, EdfWriter, MAX_EDF_SAMPLES, MAX_EDF_SIGNALS,
};
pub use erp::{AssessmentKind, Component, ErpTemplates};
pub use error::{BciError, Result};
pub use errp_valid::{Check, Valid, shown};
pub use features::{EpochWindow, FeatureExtractor};
pub use filter::{Biquad, FilterBank, FilterChain};
pub use gaussian::{
    ClassMoments, GaussianClassifier, PAPER_FOLDS, PAPER_SHRINK, SoftLabel, column_normalised,
    confusion_matrix, corrected, reference_folds,
};
pub use generator::{
    Assessment, BASELINE_SECS, Components, EegBlock, EegFeed, EegGenerator, ErrpTemplate,
    GeneratorParams, HybridEeg, HybridSource, MIN_HYBRID_PART_SECS, Realism, SFREQ_HZ,
    TEMPLATE_SECS,
};
pub use information::{
    ActionInformation, INFORMATION_BINS, binary_channel_bits, binary_entropy,
    binary_symmetric_bits, erasure_bits,
};
pub use lda::{LdaDecoder, LdaModel, Shrinkage, ledoit_wolf_shrinkage, pca_basis};
pub use montage::{Channel, ChannelKind, DECODING_CHANNELS, Montage};
pub use noise::{PinkNoise, Resonator};
pub use online::{
    Decision, Detector, DetectorMode, DetectorParams, HeldOutParams, HeldOutSession, OnlineStep,
    OnlineTarget, OnlineTargeting, OperatingPoint, ResponseSpan, SPAN_ALPHA, SlidingWindow,
    WARM_UP_SECS, WINDOW_STEP_SECS, binomial_upper_tail, detector_span, firings, operating_point,
    response_span, simulate_held_out, simulate_held_out_from, target_online,
    threshold_for_false_alarms,
};
pub use own_eeg::{
    CalibrationPart, EOG_CHANNELS, EventNames, MIN_CALIBRATION_PER_CLASS, OwnEeg, OwnEegEpoch,
    OwnEegSplit, calibration_events, split_own_eeg,
};
pub use platt::PlattScaling;
pub use preprocess::{PreprocessParams, Preprocessing, Preprocessor};
pub use psd::ThetaPsd;
pub use special::ln_gamma;
pub use subjects::{GoalSet, Subject, subject, subjects};
pub use svm::{SvmDecoder, SvmModel, SvmParts};
