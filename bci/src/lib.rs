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
//! * the subjects of Table 1 ([`subject`]) and EDF+ export ([`EdfWriter`]).

mod calibration;
mod classify;
mod edf;
mod erp;
mod error;
mod features;
mod filter;
mod generator;
mod lda;
mod montage;
mod noise;
mod platt;
mod preprocess;
pub mod rng;
mod subjects;
mod targeting;

pub use calibration::{
    Accuracy, Calibrated, CalibrationParams, CalibrationSession, CalibrationSetup, GrandAverage,
    RawSink, SessionOptions, calibrate, cross_validate, cv_seed, eog_session,
    out_of_fold_decisions, schedule, simulate_session, stratified_folds,
};
pub use classify::{Classifier, ErrorModel, Features, sigmoid};
pub use edf::EdfWriter;
pub use erp::{AssessmentKind, Component, ErpTemplates};
pub use error::{BciError, Result};
pub use features::EpochWindow;
pub use filter::{Biquad, FilterBank, FilterChain};
pub use generator::{Assessment, Components, EegBlock, EegGenerator, GeneratorParams};
pub use lda::{LdaDecoder, LdaModel, Shrinkage, ledoit_wolf_shrinkage, pca_basis};
pub use montage::{Channel, ChannelKind, DECODING_CHANNELS, Montage};
pub use noise::{PinkNoise, Resonator};
pub use platt::PlattScaling;
pub use preprocess::{PreprocessParams, Preprocessor};
pub use subjects::{GoalSet, Subject, subject, subjects};
pub use targeting::{
    TargetingParams, TargetingResult, TargetingStep, check_requested_accuracy, inverse_normal_cdf,
    target_accuracy,
};
