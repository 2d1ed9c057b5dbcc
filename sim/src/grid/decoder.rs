//! The grid task's decoders: the oracle, the EEG decoder on a live stream or
//! on a bank of pre-streamed epochs, and the mapping of LDA scores to
//! p(error).

use errp_bci::{
    Accuracy, ActionInformation, Assessment, AssessmentKind, Components, EegBlock, EegGenerator,
    EpochWindow, ErrorModel, GeneratorParams, LdaModel, Montage, Preprocessor, Valid,
    rng::derive_seed, rng::labelled,
};
use rand::Rng;

use crate::calibration::CalibrationReport;
use crate::error::{Result, SimError};
use crate::grid::own_eeg::OwnEegBank;
use crate::grid::p_error::{PErrorChoice, PErrorMapping};
use crate::grid::params::GridTaskParams;

/// What turns the user's assessment into p(error).
#[derive(Debug, Clone)]
pub enum AssessmentDecoder {
    /// No EEG: the assessment is reported flipped with probability
    /// 1 - accuracy, as p(error) = accuracy (decoded error) or 1 - accuracy
    /// (decoded correct), the calibrated output of such a decoder.
    Oracle {
        /// Probability of reporting the assessment right.
        accuracy: f64,
    },
    /// Synthetic EEG through the real preprocessing and decoder, as trained
    /// on a calibration session; each action's EEG is streamed (the whole
    /// inter-action interval) when the action happens.
    Eeg(Box<EegDecoder>),
    /// The same decoder applied to epochs drawn from a bank of synthetic
    /// epochs streamed and preprocessed in advance (one per class of
    /// assessment): the decoder still reads real synthetic EEG for every
    /// action, but no EEG is synthesised during the episode. For Monte Carlo
    /// speed; epochs are reused across episodes.
    EegBank(Box<EpochBank>),
    /// A decoder calibrated on a person's own EEG, decoding held-out
    /// epochs of the same file (`[eeg] recording = ...`).
    OwnEeg(Box<OwnEegBank>),
}

/// Epochs per class on which [`AssessmentDecoder::information`] measures an
/// EEG decoder: about 110 minutes of closed-loop EEG, so that the plug-in
/// estimate's bias (about 0.007 bits) and spread stay below 0.01 bits.
pub const INFORMATION_PER_CLASS: usize = 1000;

impl AssessmentDecoder {
    /// What one action's p(error) tells of the user's verdict, at equal
    /// priors ([`ActionInformation`]): measured on `per_class` fresh
    /// actions of each class, streamed as the closed loop streams them (the
    /// same user, preprocessing and inter-action intervals, a seed of their
    /// own), or drawn from the oracle.
    pub fn information(
        &self,
        params: &GridTaskParams,
        per_class: usize,
        seed: u64,
    ) -> Result<ActionInformation> {
        let d = match self {
            Self::Oracle { accuracy } => {
                let mut rng = labelled(seed, "grid/information/oracle");
                let mut draw = |error: bool| -> Vec<(f64, bool)> {
                    (0..per_class)
                        .map(|_| oracle_report(*accuracy, error, &mut rng))
                        .collect()
                };
                let error = draw(true);
                let correct = draw(false);
                return measured(&error, &correct);
            }
            Self::Eeg(d) => d.as_ref(),
            Self::EegBank(bank) => &bank.decoder,
            // The recording's epochs are what there is: every held-out one.
            Self::OwnEeg(bank) => {
                let [error, correct] = bank.decisions();
                return measured(&error, &correct);
            }
        };
        let (error, correct) = synthesise_classes(
            d.source(),
            params,
            per_class,
            derive_seed(seed, "grid/information", 0),
            Components::default(),
            |eeg, error, interval| decide(d, &eeg.epoch(error, interval, false).0),
        )?;
        measured(&error, &correct)
    }
}

/// What the oracle reports of a verdict (`error`): the verdict, flipped
/// with probability 1 - `accuracy`, as (p(error), says error), p(error)
/// being `accuracy` or 1 - `accuracy`.
pub(crate) fn oracle_report(accuracy: f64, error: bool, rng: &mut impl Rng) -> (f64, bool) {
    let right = rng.random::<f64>() < accuracy;
    let says_error = if right { error } else { !error };
    (
        if says_error { accuracy } else { 1.0 - accuracy },
        says_error,
    )
}

/// [`ActionInformation::measure`], or an error naming what was wrong.
fn measured(error: &[(f64, bool)], correct: &[(f64, bool)]) -> Result<ActionInformation> {
    ActionInformation::measure(error, correct).ok_or_else(|| {
        SimError::Scenario(
            "the information per action needs at least one p(error) in [0, 1] of each class".into(),
        )
    })
}

/// Preprocessed epochs of each assessment class, ready to be decoded.
#[derive(Debug, Clone)]
pub struct EpochBank {
    /// The decoder that reads them.
    pub decoder: EegDecoder,
    pub(crate) error: Vec<(Vec<f64>, Vec<f64>)>,
    pub(crate) correct: Vec<(Vec<f64>, Vec<f64>)>,
}

impl EpochBank {
    /// Streams `per_class` error and `per_class` correct assessments (in a
    /// seeded random order, at the task's inter-action intervals) through the
    /// generator and the preprocessor and keeps each epoch's features and
    /// its FCz trace.
    pub fn build(
        decoder: EegDecoder,
        params: &GridTaskParams,
        per_class: usize,
        seed: u64,
    ) -> Result<Self> {
        let (error, correct) = synthesise_pools(
            decoder.source(),
            params,
            per_class,
            seed,
            Components::default(),
        )?;
        Ok(Self {
            decoder,
            error,
            correct,
        })
    }

    /// Epochs per class.
    /// Epoch `i` of a class: its features and its FCz trace.
    pub fn epoch(&self, error: bool, i: usize) -> (&[f64], &[f64]) {
        let (x, fcz) = if error {
            &self.error[i]
        } else {
            &self.correct[i]
        };
        (x, fcz)
    }

    /// Epochs per class.
    pub fn len(&self) -> usize {
        self.error.len().min(self.correct.len())
    }

    /// True if the bank holds no epochs.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The epochs of [`EpochBank::build`] streamed once in two parts that add up
/// to the bank at any ErrP-to-noise ratio r: background + artifacts, and the
/// ERPs at ratio 1 (the preprocessing and the features are linear). For
/// sweeps, whose levels share a calibration session and so the preprocessor,
/// and differ only in r.
#[derive(Debug, Clone)]
pub struct EpochBankParts {
    noise: Pools,
    erp: Pools,
}

impl EpochBankParts {
    /// Streams both parts from `source` (its ratio is not used).
    pub fn build(
        source: EegSource<'_>,
        params: &GridTaskParams,
        per_class: usize,
        seed: u64,
    ) -> Result<Self> {
        let generator = source.generator.with(|g| g.errp_to_noise = 1.0)?;
        let unit = EegSource {
            generator: &generator,
            ..source
        };
        let part = |erp: bool| {
            let components = Components {
                background: !erp,
                artifacts: !erp,
                erp,
            };
            synthesise_pools(unit, params, per_class, seed, components)
        };
        let (noise, erp) = rayon::join(|| part(false), || part(true));
        Ok(Self {
            noise: noise?,
            erp: erp?,
        })
    }

    /// The bank `decoder` reads, at its generator's ratio: what
    /// [`EpochBank::build`] gives (to rounding) if `decoder`'s preprocessor is
    /// the one the parts were streamed with.
    pub fn bank(&self, decoder: EegDecoder) -> EpochBank {
        let r = decoder.generator.errp_to_noise;
        let mix = |noise: &[(Vec<f64>, Vec<f64>)], erp: &[(Vec<f64>, Vec<f64>)]| {
            noise
                .iter()
                .zip(erp)
                .map(|((xn, fn_), (xe, fe))| {
                    (
                        xn.iter().zip(xe).map(|(a, b)| a + r * b).collect(),
                        fn_.iter().zip(fe).map(|(a, b)| a + r * b).collect(),
                    )
                })
                .collect()
        };
        EpochBank {
            error: mix(&self.noise.0, &self.erp.0),
            correct: mix(&self.noise.1, &self.erp.1),
            decoder,
        }
    }
}

impl EpochBankParts {
    /// The accuracy of `model` (decision >= 0 is "error", as online) on
    /// every epoch of the bank mixed at ErrP-to-noise `ratio`: the online
    /// accuracy of a decoder reading this user's EEG at that ratio, measured
    /// on epochs it was not trained on.
    pub fn score(&self, model: &impl ErrorModel, ratio: f64) -> Accuracy {
        let mut labels = Vec::new();
        let mut predicted = Vec::new();
        let mut row = Vec::new();
        for (error, (noise, erp)) in [
            (true, (&self.noise.0, &self.erp.0)),
            (false, (&self.noise.1, &self.erp.1)),
        ] {
            for ((xn, _), (xe, _)) in noise.iter().zip(erp) {
                row.clear();
                row.extend(xn.iter().zip(xe).map(|(a, b)| a + ratio * b));
                labels.push(error);
                predicted.push(model.decision(&row) >= 0.0);
            }
        }
        Accuracy::score(&labels, &predicted)
    }
}

/// Streams the epochs of a bank with the generator's `components`.
fn synthesise_pools(
    source: EegSource<'_>,
    params: &GridTaskParams,
    per_class: usize,
    seed: u64,
    components: Components,
) -> Result<Pools> {
    synthesise_classes(
        source,
        params,
        per_class,
        seed,
        components,
        |eeg, error, interval| eeg.epoch(error, interval, true),
    )
}

/// Streams `per_class` epochs of each class in a seeded random order and
/// keeps what `keep` makes of each.
fn synthesise_classes<T>(
    source: EegSource<'_>,
    params: &GridTaskParams,
    per_class: usize,
    seed: u64,
    components: Components,
    mut keep: impl FnMut(&mut OnlineEeg, bool, f64) -> T,
) -> Result<(Vec<T>, Vec<T>)> {
    if per_class == 0 {
        return Err(SimError::Scenario(
            "an epoch bank needs at least one epoch per class".into(),
        ));
    }
    let mut stream_eeg = OnlineEeg::start(source, derive_seed(seed, "grid/bank", 0), components)?;
    let mut rng = labelled(seed, "grid/bank/order");
    let mut error = Vec::with_capacity(per_class);
    let mut correct = Vec::with_capacity(per_class);
    while error.len() < per_class || correct.len() < per_class {
        // A bank is thousands of epochs: a stop request is seen between
        // two of them.
        errp_bci::stop::check()?;
        let want_error = if error.len() == per_class {
            false
        } else if correct.len() == per_class {
            true
        } else {
            rng.random_bool(0.5)
        };
        let interval = rng.random_range(params.interval_min_secs..=params.interval_max_secs);
        let epoch = keep(&mut stream_eeg, want_error, interval);
        if want_error {
            error.push(epoch);
        } else {
            correct.push(epoch);
        }
    }
    Ok((error, correct))
}

/// The calibrated EEG pipeline used online.
#[derive(Debug, Clone)]
pub struct EegDecoder {
    /// The synthetic user's EEG model (at the calibrated ErrP-to-noise ratio).
    pub generator: Valid<GeneratorParams>,
    /// The montage.
    pub montage: Montage,
    /// Preprocessing fitted on the EOG session before the calibration.
    pub preprocessor: Preprocessor,
    /// The decoder trained on the calibration session.
    pub model: LdaModel,
    /// How decision values become p(error).
    pub p_error: PErrorMapping,
}

impl EegDecoder {
    /// The online decoder a calibration produced, with p(error) mapped as
    /// `choice` says.
    pub fn from_report(report: &CalibrationReport, choice: PErrorChoice) -> Self {
        Self {
            generator: report.generator.clone(),
            montage: Montage::standard(),
            preprocessor: report.calibrated.session.preprocessor.clone(),
            model: report.calibrated.model.clone(),
            p_error: match choice {
                PErrorChoice::Sigmoid => PErrorMapping::Sigmoid,
                PErrorChoice::Platt => PErrorMapping::Platt(report.calibrated.platt),
            },
        }
    }
}

/// The decoder's p(error) and class for one epoch's features.
pub(crate) fn decide(d: &EegDecoder, features: &[f64]) -> (f64, bool) {
    d.p_error.decide(&d.model, features)
}

/// What an EEG stream needs: the user's EEG model, the montage and the
/// decoder's preprocessing.
#[derive(Debug, Clone, Copy)]
pub struct EegSource<'a> {
    /// The synthetic user's EEG model.
    pub generator: &'a Valid<GeneratorParams>,
    /// The montage.
    pub montage: &'a Montage,
    /// The preprocessing fitted at calibration.
    pub preprocessor: &'a Preprocessor,
}

/// A continuous EEG stream through the decoder's preprocessing.
pub(crate) struct OnlineEeg {
    generator: EegGenerator,
    preprocessor: Preprocessor,
    window: EpochWindow,
    fcz_row: usize,
}

impl OnlineEeg {
    /// Starts a stream and lets the filters settle.
    pub(crate) fn start(d: EegSource<'_>, seed: u64, components: Components) -> Result<Self> {
        let fs = d.generator.sfreq_hz;
        let mut generator =
            EegGenerator::new(d.generator, d.montage, seed)?.with_components(components);
        let mut preprocessor = d.preprocessor.clone();
        preprocessor.reset();
        preprocessor.process(&generator.generate((errp_bci::WARM_UP_SECS * fs) as usize));
        let fcz = d.montage.index("FCz")?;
        let fcz_row = preprocessor
            .outputs()
            .iter()
            .position(|&o| o == fcz)
            .unwrap_or(0);
        Ok(Self {
            generator,
            preprocessor,
            window: EpochWindow::paper(fs),
            fcz_row,
        })
    }

    /// Schedules an assessment now, streams the EEG up to the next action
    /// (the whole inter-action interval, so filters see continuous EEG) and
    /// returns the epoch's features and, if asked, its preprocessed FCz.
    pub(crate) fn epoch(
        &mut self,
        error: bool,
        interval_secs: f64,
        keep_fcz: bool,
    ) -> (Vec<f64>, Vec<f64>) {
        let clean = self.interval(error, interval_secs);
        let features = self.window.extract(&clean, 0);
        let fcz = if keep_fcz {
            clean.channel(self.fcz_row)[..self.window.span()].to_vec()
        } else {
            Vec::new()
        };
        (features, fcz)
    }

    /// Like [`epoch`](Self::epoch), but returns the preprocessed epoch itself,
    /// `(n_channels, span)` from the onset, and its FCz trace, for a decoder
    /// of the user's own.
    pub(crate) fn epoch_block(&mut self, error: bool, interval_secs: f64) -> (EegBlock, Vec<f64>) {
        let clean = self.interval(error, interval_secs);
        let span = self.window.span();
        let epoch = clean.samples(0..span);
        let fcz = epoch.channel(self.fcz_row).to_vec();
        (epoch, fcz)
    }

    /// The built-in decoder's features of an epoch from
    /// [`epoch_block`](Self::epoch_block).
    pub(crate) fn features(&self, epoch: &EegBlock) -> Vec<f64> {
        self.window.extract(epoch, 0)
    }

    /// Schedules an assessment now and streams the preprocessed EEG up to
    /// the next action.
    fn interval(&mut self, error: bool, interval_secs: f64) -> EegBlock {
        let fs = self.generator.params().sfreq_hz;
        let onset = self.generator.now_secs();
        self.generator.schedule(Assessment {
            onset_secs: onset,
            kind: if error {
                AssessmentKind::Error
            } else {
                AssessmentKind::Correct
            },
        });
        let n = ((interval_secs * fs).round() as usize).max(self.window.span());
        let raw = self.generator.generate(n);
        self.preprocessor.process(&raw)
    }
}

/// Preprocessed epochs of each assessment class for a decoder of the user's
/// own: streamed as [`EpochBank::build`] streams its epochs (the same
/// schedule and EEG for the same seed), but kept whole, `(n_channels,
/// n_samples)` from the onset, instead of as the built-in decoder's
/// features. [`GridDecoding::Scores`](crate::grid::GridDecoding::Scores)
/// runs episodes on what a decoder makes of them.
#[derive(Debug, Clone)]
pub struct EpochBlocks {
    /// Error epochs.
    pub error: Vec<EegBlock>,
    /// Correct epochs.
    pub correct: Vec<EegBlock>,
}

impl EpochBlocks {
    /// Streams `per_class` epochs of each class from `source`.
    pub fn build(
        source: EegSource<'_>,
        params: &GridTaskParams,
        per_class: usize,
        seed: u64,
    ) -> Result<Self> {
        let (error, correct) = synthesise_classes(
            source,
            params,
            per_class,
            seed,
            Components::default(),
            |eeg, error, interval| eeg.epoch_block(error, interval).0,
        )?;
        Ok(Self { error, correct })
    }
}

impl EegDecoder {
    /// The stream this decoder reads.
    pub fn source(&self) -> EegSource<'_> {
        EegSource {
            generator: &self.generator,
            montage: &self.montage,
            preprocessor: &self.preprocessor,
        }
    }
}

/// Preprocessed epochs of both classes.
type Pools = (Vec<(Vec<f64>, Vec<f64>)>, Vec<(Vec<f64>, Vec<f64>)>);
