//! The grid on a person's own EEG: the decoder is calibrated on the
//! file's first part exactly as on a synthetic session (the same
//! preprocessing fitted on it, features, LDA, cross-validation and Platt
//! scaling), and each online action decodes an epoch of its class drawn
//! from the part after it, never from the part it was trained on.

use errp_bci::{
    Accuracy, CalibrationSetup, ErrorModel, LdaDecoder, LdaModel, Montage, OwnEeg, Preprocessing,
    Valid, calibrate_session, cross_validate, cv_seed, rng::derive_seed, split_own_eeg,
};
use errp_robot::GridControlParams;
use rand::Rng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::error::{Result, SimError};
use crate::grid::p_error::{PErrorChoice, PErrorMapping};
use crate::grid::params::GridTaskParams;
use crate::grid::scenario::GridScenario;
use crate::own_eeg::{BankDraw, FileDigest, OwnEegSpec, load_own_eeg, twice};

/// What the own EEG gave: the file, its split and the decoder's
/// accuracy, cross-validated on the calibration part and measured on the
/// held-out part.
#[derive(Debug, Clone, PartialEq)]
pub struct OwnEegReport {
    /// The file read: its name, size and SHA-256.
    pub file: FileDigest,
    /// Events in the calibration part.
    pub calibration_events: usize,
    /// Where the calibration part ends (its last epoch), s.
    pub calibration_end_secs: f64,
    /// The decoder's accuracy cross-validated on the calibration part,
    /// averaged over [`CV_REPEATS`] draws of the folds (the accuracy the
    /// shared control assumes).
    pub cross_validated: Accuracy,
    /// The decoder trained on the whole calibration part, on every held-out
    /// epoch: the accuracy the closed loop draws from.
    pub held_out: Accuracy,
    /// Events after the calibration part used by neither part (their
    /// epochs overlap it or run past the EEG's end).
    pub dropped: usize,
    /// Events annotated twice (the same class at the same sample), each
    /// kept once.
    pub merged: usize,
    /// How held-out epochs are drawn.
    pub draw: BankDraw,
    /// The EEG's length, s.
    pub duration_secs: f64,
    /// Its EOG channels: the six the regression reads, or none (no EOG
    /// regression).
    pub eog_channels: usize,
}

impl std::fmt::Display for OwnEegReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let cv = &self.cross_validated;
        let h = &self.held_out;
        writeln!(
            f,
            "EEG: recording {} ({} bytes, SHA-256 {}), {:.1} s{}{}",
            self.file.name,
            self.file.bytes,
            self.file.sha256,
            self.duration_secs,
            if self.eog_channels == 0 {
                "; no EOG channels: no EOG regression"
            } else {
                ""
            },
            twice(self.merged)
        )?;
        writeln!(
            f,
            "Decoder calibrated on its first {} events ({} error + {} correct, to {:.1} s): mean \
             accuracy {:.2} % cross-validated (over {CV_REPEATS} draws of the folds; correct \
             {:.2} %, error {:.2} %)",
            self.calibration_events,
            cv.n_error,
            cv.n_correct,
            self.calibration_end_secs,
            100.0 * cv.mean(),
            100.0 * cv.correct,
            100.0 * cv.error
        )?;
        writeln!(
            f,
            "Held out: {} error + {} correct epochs, mean accuracy {:.2} % (correct {:.2} %, \
             error {:.2} %), drawn {}{}",
            h.n_error,
            h.n_correct,
            100.0 * h.mean(),
            100.0 * h.correct,
            100.0 * h.error,
            match self.draw {
                BankDraw::WithReplacement => "with replacement",
                BankDraw::WithoutReplacement => "without replacement within an episode",
            },
            if self.dropped > 0 {
                format!(
                    "; {} events overlapping the calibration part dropped",
                    self.dropped
                )
            } else {
                String::new()
            }
        )
    }
}

/// One held-out epoch: its event in the own EEG, the decoder's features
/// and its preprocessed FCz.
#[derive(Debug, Clone)]
pub(crate) struct HeldOutEpoch {
    pub(crate) event: usize,
    pub(crate) features: Vec<f64>,
    pub(crate) fcz: Vec<f64>,
}

/// The decoder calibrated on own EEG and the held-out epochs it
/// decodes online, one pool per class.
#[derive(Debug, Clone)]
pub struct OwnEegBank {
    /// The own EEG's channels.
    pub montage: Montage,
    /// The decoder trained on the calibration part.
    pub model: LdaModel,
    /// How decision values become p(error).
    pub p_error: PErrorMapping,
    /// The accuracy the shared control assumes: the cross-validated one,
    /// above 0.5 (checked).
    pub assumed_accuracy: f64,
    /// What the own EEG gave.
    pub report: OwnEegReport,
    pub(crate) error: Vec<HeldOutEpoch>,
    pub(crate) correct: Vec<HeldOutEpoch>,
}

impl OwnEegBank {
    /// Every epoch the closed loop may draw: its event's index in the
    /// own EEG (none in the calibration part), its class (true for
    /// error) and its preprocessed FCz, as a step records it.
    pub fn epochs(&self) -> impl Iterator<Item = (usize, bool, &[f64])> {
        let error = self.error.iter().map(|e| (e.event, true, e.fcz.as_slice()));
        let correct = self
            .correct
            .iter()
            .map(|e| (e.event, false, e.fcz.as_slice()));
        error.chain(correct)
    }

    /// The decoder's p(error) and class for `features`.
    pub(crate) fn decide(&self, features: &[f64]) -> (f64, bool) {
        self.p_error.decide(&self.model, features)
    }

    /// Every held-out epoch's (p(error), says error), by class.
    pub(crate) fn decisions(&self) -> [Vec<(f64, bool)>; 2] {
        let all = |pool: &[HeldOutEpoch]| pool.iter().map(|e| self.decide(&e.features)).collect();
        [all(&self.error), all(&self.correct)]
    }
}

/// Draws held-out epochs of a class, as the scenario says: uniformly each
/// time, or each epoch once (in a seeded order) before any repeats.
#[derive(Debug)]
pub(crate) struct OwnEegDraw {
    decks: [Vec<usize>; 2],
}

impl OwnEegDraw {
    pub(crate) fn new() -> Self {
        Self {
            decks: [Vec::new(), Vec::new()],
        }
    }

    /// The next epoch of class `error` from `bank`.
    pub(crate) fn draw<'a>(
        &mut self,
        bank: &'a OwnEegBank,
        error: bool,
        rng: &mut ChaCha8Rng,
    ) -> &'a HeldOutEpoch {
        let pool = if error { &bank.error } else { &bank.correct };
        let i = match bank.report.draw {
            BankDraw::WithReplacement => rng.random_range(0..pool.len()),
            BankDraw::WithoutReplacement => {
                let deck = &mut self.decks[usize::from(error)];
                if deck.is_empty() {
                    deck.extend(0..pool.len());
                    deck.shuffle(rng);
                }
                deck.pop().expect("refilled when empty")
            }
        };
        &pool[i]
    }
}

/// Reads the own EEG of `scenario`, calibrates the decoder on its first
/// part as a synthetic session is calibrated (`setup`'s preprocessing and
/// folds, an LDA, Platt scaling) and keeps the held-out epochs. Errors
/// name the file.
pub(crate) fn prepare_own_eeg(
    scenario: &GridScenario,
    eeg: &OwnEegSpec,
    setup: &Valid<CalibrationSetup>,
) -> Result<OwnEegBank> {
    let sfreq_hz = setup.generator.sfreq_hz;
    let (recording, file) = load_own_eeg(eeg, sfreq_hz)?;
    let named = |e: errp_bci::BciError| SimError::Scenario(format!("{}: {e}", eeg.file.display()));
    let preprocessing = Valid::new(Preprocessing {
        params: setup.preprocess.clone(),
        sfreq_hz,
    })?;
    let split = split_own_eeg(&recording, eeg.part, &preprocessing).map_err(named)?;
    let lda = LdaDecoder::default();
    let calibration_events = split.calibration.labels.len();
    let fcz_row = fcz_row(&recording, &split.calibration.preprocessor)?;
    let folds = setup.calibration.folds;
    let calibrated =
        calibrate_session(&lda, split.calibration, folds, scenario.seed).map_err(named)?;
    let cv = repeated_cv(
        &lda,
        &calibrated.session.features,
        &calibrated.session.labels,
        folds,
        scenario.seed,
        calibrated.accuracy,
    )
    .map_err(named)?;
    scenario
        .params
        .control
        .with(|c| c.assumed_accuracy = cv.mean())
        .map_err(|_| {
            SimError::Scenario(format!(
                "{}: the decoder calibrated on its first {calibration_events} events is at chance \
             (mean accuracy {:.2} % cross-validated): the shared control needs a decoder above \
             50 %; check the event names (eeg.error, eeg.correct) and the channels, or \
             calibrate on more events (eeg.calibration)",
                eeg.file.display(),
                100.0 * cv.mean()
            ))
        })?;
    let (mut error, mut correct) = (Vec::new(), Vec::new());
    let (mut labels, mut predicted) = (Vec::new(), Vec::new());
    for e in split.held_out {
        labels.push(e.error);
        predicted.push(calibrated.model.decision(&e.features) >= 0.0);
        let epoch = HeldOutEpoch {
            event: e.event,
            fcz: e.block.channel(fcz_row).to_vec(),
            features: e.features,
        };
        if e.error {
            error.push(epoch);
        } else {
            correct.push(epoch);
        }
    }
    Ok(OwnEegBank {
        montage: recording.montage.clone(),
        p_error: match scenario.p_error {
            PErrorChoice::Sigmoid => PErrorMapping::Sigmoid,
            PErrorChoice::Platt => PErrorMapping::Platt(calibrated.platt),
        },
        model: calibrated.model,
        assumed_accuracy: cv.mean(),
        report: OwnEegReport {
            file,
            calibration_events,
            calibration_end_secs: split.calibration_end_secs,
            cross_validated: cv,
            held_out: Accuracy::score(&labels, &predicted),
            dropped: split.dropped,
            merged: recording.merged,
            draw: eeg.draw,
            duration_secs: recording.duration_secs(),
            eog_channels: recording.montage.n_eog(),
        },
        error,
        correct,
    })
}

/// Draws of the folds the cross-validated accuracy is averaged over.
pub const CV_REPEATS: u64 = 10;

/// The cross-validated accuracy averaged over [`CV_REPEATS`] draws of the
/// folds (`first` is the draw of `seed` itself, the one the decoder's Platt
/// scaling comes from): own EEG's calibration part is short (200
/// events, 30 to 40 errors, in a 400-action session), and one draw's
/// accuracy moves by about 2 points with the folds alone.
fn repeated_cv(
    lda: &LdaDecoder,
    features: &errp_bci::Features,
    labels: &[bool],
    folds: usize,
    seed: u64,
    first: Accuracy,
) -> errp_bci::Result<Accuracy> {
    // In parallel; summed in the draws' order, whatever the thread count.
    let draws: Vec<Accuracy> = (1..CV_REPEATS)
        .into_par_iter()
        .map(|r| {
            let folds_seed = cv_seed(derive_seed(seed, "recorded/cv", r));
            cross_validate(lda, features, labels, folds, folds_seed)
        })
        .collect::<errp_bci::Result<_>>()?;
    let mut sum = (first.correct, first.error);
    for a in &draws {
        sum.0 += a.correct;
        sum.1 += a.error;
    }
    Ok(Accuracy {
        correct: sum.0 / CV_REPEATS as f64,
        error: sum.1 / CV_REPEATS as f64,
        ..first
    })
}

/// The row of FCz among the preprocessor's outputs.
fn fcz_row(recording: &OwnEeg, preprocessor: &errp_bci::Preprocessor) -> Result<usize> {
    let fcz = recording.montage.index("FCz")?;
    Ok(preprocessor
        .outputs()
        .iter()
        .position(|&o| o == fcz)
        .unwrap_or(0))
}

/// `params` as the shared control uses them with `bank`: the accuracy it
/// assumes is the own EEG's.
pub(crate) fn own_eeg_control(
    params: &GridTaskParams,
    bank: &OwnEegBank,
) -> Result<Valid<GridControlParams>> {
    Ok(params
        .control
        .with(|c| c.assumed_accuracy = bank.assumed_accuracy)?)
}
