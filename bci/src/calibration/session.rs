//! Simulating a calibration session: the schedule of assessments, the EEG
//! streamed through it, preprocessed and cut into features.

use std::io::{Seek, Write};

use errp_valid::Valid;
use nalgebra::DMatrix;
use rand::Rng;

use super::{CalibrationParams, CalibrationSetup, GrandAverage, preprocessing};
use crate::classify::Features;
use crate::edf::EdfWriter;
use crate::erp::AssessmentKind;
use crate::error::{Result, check};
use crate::features::{EpochWindow, FeatureExtractor};
use crate::generator::{
    Assessment, Components, EegBlock, EegFeed, EegGenerator, GeneratorParams, HybridSource,
};
use crate::montage::Montage;
use crate::preprocess::Preprocessor;
use crate::rng::{derive_seed, labelled};

/// A simulated calibration session, preprocessed and cut into features.
#[derive(Debug, Clone)]
pub struct CalibrationSession {
    /// Features, `(n_actions, n_features)`: 312 temporal ones for the
    /// discrete decoder.
    pub features: Features,
    /// `true` where the action was erroneous.
    pub labels: Vec<bool>,
    /// The assessments, on the session clock.
    pub assessments: Vec<Assessment>,
    /// The preprocessor fitted on the EOG session.
    pub preprocessor: Preprocessor,
    /// Grand averages over every EEG channel, when asked for.
    pub grand_average: Option<GrandAverage>,
}

/// A consumer of raw blocks (all channels) and the assessments whose onsets
/// fall in each, e.g. an EDF writer.
pub type RawSink<'a> = &'a mut dyn FnMut(&EegBlock, &[Assessment]) -> Result<()>;

/// What else to produce while the session is simulated.
#[derive(Default)]
pub struct SessionOptions<'a> {
    /// Which parts of the signal to generate (all, by default).
    pub components: Components,
    /// Compute grand averages over all EEG channels in [-200, 800] ms.
    pub grand_average: bool,
    /// Called with each raw block (all channels) and the assessments whose
    /// onsets fall in it, e.g. to export the raw EEG.
    pub raw_sink: Option<RawSink<'a>>,
    /// A person's own EEG in place of the synthetic user's EEG: its
    /// background looped, the subject's response at the errors, the
    /// preprocessing fitted on its calibration part (no EOG session).
    pub hybrid: Option<&'a HybridSource>,
}

/// The EOG session that precedes a calibration: the same user and montage,
/// asked to blink and look around (2 blinks and 1 saccade per second on
/// average), no actions.
pub fn eog_session(
    params: &Valid<GeneratorParams>,
    calib: &CalibrationParams,
    montage: &Montage,
    seed: u64,
) -> Result<EegBlock> {
    let eye = params.with(|p| {
        p.blink_rate_hz = p.blink_rate_hz.max(0.5);
        p.saccade_rate_hz = p.saccade_rate_hz.max(1.0);
    })?;
    let mut g = EegGenerator::new(&eye, montage, derive_seed(seed, "calibration/eog", 0))?;
    Ok(g.generate((calib.eog_session_secs * params.sfreq_hz) as usize))
}

/// The action schedule of a session: onsets at U[min, max] s intervals, each
/// erroneous with probability `error_rate`.
pub fn schedule(calib: &CalibrationParams, seed: u64) -> Vec<Assessment> {
    let mut rng = labelled(seed, "calibration/schedule");
    let mut t = 2.0;
    (0..calib.n_actions)
        .map(|_| {
            let kind = if rng.random_bool(calib.error_rate) {
                AssessmentKind::Error
            } else {
                AssessmentKind::Correct
            };
            let a = Assessment {
                onset_secs: t,
                kind,
            };
            t += rng.random_range(calib.interval_min_secs..=calib.interval_max_secs);
            a
        })
        .collect()
}

/// Simulates a calibration session: EOG session, preprocessor fit, then
/// `n_actions` assessed actions streamed through the generator and the
/// preprocessor in 1 s blocks, and the paper's temporal features.
pub fn simulate_session(
    setup: &Valid<CalibrationSetup>,
    seed: u64,
    options: SessionOptions<'_>,
) -> Result<CalibrationSession> {
    let assessments = schedule(&setup.calibration, seed);
    let onsets: Vec<f64> = assessments.iter().map(|a| a.onset_secs).collect();
    let window = EpochWindow::paper(setup.generator.sfreq_hz);
    simulate_session_with(setup, seed, &assessments, &onsets, &window, options)
}

/// Simulates the calibration session of `setup` from `seed`, as
/// [`simulate_session`] does, and writes its raw EEG and its events to
/// `out` as EDF+ (one-second records, `error` and `correct` annotations),
/// as `errp calibrate --export` does: the session, and `out` once written.
/// A person's own EEG in the tests and benchmarks is such a file.
pub fn export_session<W: Write + Seek>(
    setup: &Valid<CalibrationSetup>,
    seed: u64,
    out: W,
) -> Result<(CalibrationSession, W)> {
    let mut writer = EdfWriter::new(out, &setup.montage, setup.generator.sfreq_hz)?;
    let mut sink = |b: &EegBlock, e: &[Assessment]| writer.write(b, e);
    let session = simulate_session(
        setup,
        seed,
        SessionOptions {
            raw_sink: Some(&mut sink),
            ..SessionOptions::default()
        },
    )?;
    Ok((session, writer.finish()?))
}

/// Checks that there is one window per assessment and that the onsets are
/// finite, non-negative and sorted.
fn check_schedule(assessments: &[Assessment], window_onsets_secs: &[f64]) -> Result<()> {
    check(
        window_onsets_secs.len() == assessments.len(),
        "window_onsets_secs",
        window_onsets_secs.len(),
        &format!("one window per assessment ({})", assessments.len()),
    )?;
    check(
        assessments
            .windows(2)
            .all(|w| w[0].onset_secs <= w[1].onset_secs)
            && assessments
                .iter()
                .all(|a| a.onset_secs.is_finite() && a.onset_secs >= 0.0),
        "assessments",
        "unsorted",
        "onsets (s) finite, >= 0 and sorted",
    )?;
    check(
        window_onsets_secs.iter().all(|w| w.is_finite()),
        "window_onsets_secs",
        "not finite",
        "finite onsets (s)",
    )
}

/// The grand averages' window at `fs`: the samples before the onset
/// (200 ms), and in all (1 s).
fn ga_window(fs: f64) -> (usize, usize) {
    let before = (0.2 * fs).round() as usize;
    (before, before + (0.8 * fs).round() as usize)
}

/// The grand averages of Fig. 1 over every EEG channel (`full_chunks`,
/// spatially preprocessed), from `onsets` (samples) with their `labels`.
/// Offline analysis, as for Fig. 1: zero-phase filtering, so that the
/// latencies are not delayed by the causal online filter.
fn grand_average(
    full_chunks: Vec<EegBlock>,
    pre: &Preprocessor,
    onsets: &[usize],
    labels: &[bool],
    montage: &Montage,
    fs: f64,
) -> GrandAverage {
    let n_eeg = montage.n_eeg();
    let (ga_before, ga_len) = ga_window(fs);
    let mut full = EegBlock::zeros(n_eeg, 0);
    concat_into(&mut full, &full_chunks);
    drop(full_chunks);
    let filter = pre.filter();
    for ch in 0..full.n_channels {
        filter.filtfilt(full.channel_mut(ch));
    }
    let mut sums = [DMatrix::zeros(n_eeg, ga_len), DMatrix::zeros(n_eeg, ga_len)];
    let mut counts = [0usize; 2];
    for (&o, &l) in onsets.iter().zip(labels) {
        if o < ga_before {
            continue;
        }
        counts[usize::from(l)] += 1;
        for ch in 0..n_eeg {
            let x = &full.channel(ch)[o - ga_before..o - ga_before + ga_len];
            for (t, v) in x.iter().enumerate() {
                sums[usize::from(l)][(ch, t)] += v;
            }
        }
    }
    let [c, e] = sums;
    GrandAverage {
        channels: (0..n_eeg)
            .map(|i| montage.channels()[i].name.clone())
            .collect(),
        times_ms: (0..ga_len)
            .map(|t| (t as f64 - ga_before as f64) / fs * 1000.0)
            .collect(),
        error: e / counts[1].max(1) as f64,
        correct: c / counts[0].max(1) as f64,
    }
}

/// Simulates a session with a given schedule and feature extractor: EOG
/// session, preprocessor fit, then `assessments` (sorted by onset) streamed
/// through the generator and the preprocessor in 1 s blocks, and one feature
/// vector per assessment from the window that starts at the matching entry of
/// `window_onsets_secs` (rounded to samples), labelled by the assessment.
///
/// Only `eog_session_secs` of `setup.calibration` is used (and checked with
/// the rest); the schedule is the one given. Grand averages are locked to the
/// assessment onsets.
pub fn simulate_session_with(
    setup: &Valid<CalibrationSetup>,
    seed: u64,
    assessments: &[Assessment],
    window_onsets_secs: &[f64],
    features: &dyn FeatureExtractor,
    mut options: SessionOptions<'_>,
) -> Result<CalibrationSession> {
    check_schedule(assessments, window_onsets_secs)?;
    let (params, calib) = (&setup.generator, &setup.calibration);
    let montage = options.hybrid.map_or(&setup.montage, |h| &h.montage);
    let preprocess = &preprocessing(setup);
    let fs = params.sfreq_hz;
    let eog = match options.hybrid {
        Some(h) => (*h.calibration).clone(),
        None => eog_session(params, calib, montage, seed)?,
    };
    let decoding = montage.decoding_indices();
    let mut pre = Preprocessor::fit(montage, preprocess, &eog, &decoding)?;
    let preprocessor = pre.clone();
    let all_eeg: Vec<usize> = (0..montage.n_eeg()).collect();
    let pre_all = if options.grand_average {
        Some(Preprocessor::fit(montage, preprocess, &eog, &all_eeg)?)
    } else {
        None
    };

    let (_, ga_len) = ga_window(fs);
    let last_onset = assessments
        .iter()
        .map(|a| a.onset_secs)
        .chain(window_onsets_secs.iter().copied())
        .fold(0.0, f64::max);
    let total = ((last_onset * fs).ceil() as usize + features.span().max(ga_len) + 1).max(1);

    let mut generator: EegFeed = match options.hybrid {
        Some(h) => h.calibration_feed(params, seed)?.into(),
        None => EegGenerator::new(params, montage, seed)?
            .with_components(options.components)
            .into(),
    };
    for a in assessments {
        generator.schedule(*a);
    }
    let block_len = fs as usize;
    let mut decoded = EegBlock::zeros(decoding.len(), 0);
    let mut decoded_chunks = Vec::new();
    let mut full_chunks = Vec::new();
    let mut done = 0;
    let mut next_event = 0;
    while done < total {
        crate::stop::check()?;
        let n = block_len.min(total - done);
        let raw = generator.generate(n);
        if let Some(sink) = options.raw_sink.as_mut() {
            let end = (done + n) as f64 / fs;
            let first = next_event;
            while next_event < assessments.len() && assessments[next_event].onset_secs < end {
                next_event += 1;
            }
            sink(&raw, &assessments[first..next_event])?;
        }
        decoded_chunks.push(pre.process(&raw));
        if let Some(p) = pre_all.as_ref() {
            full_chunks.push(p.apply_spatial(&raw));
        }
        done += n;
    }
    concat_into(&mut decoded, &decoded_chunks);

    let onsets: Vec<usize> = assessments
        .iter()
        .map(|a| (a.onset_secs * fs).round() as usize)
        .collect();
    let n_features = features.n_features(decoding.len());
    let mut flat = Vec::with_capacity(onsets.len() * n_features);
    for &w in window_onsets_secs {
        features.extract_into(&decoded, (w * fs).round().max(0.0) as usize, &mut flat);
    }
    let features = DMatrix::from_row_slice(onsets.len(), n_features, &flat);
    let labels: Vec<bool> = assessments
        .iter()
        .map(|a| a.kind == AssessmentKind::Error)
        .collect();

    let grand_average = options
        .grand_average
        .then(|| grand_average(full_chunks, &pre, &onsets, &labels, montage, fs));

    Ok(CalibrationSession {
        features,
        labels,
        assessments: assessments.to_vec(),
        preprocessor,
        grand_average,
    })
}

fn concat_into(dst: &mut EegBlock, chunks: &[EegBlock]) {
    let n: usize = chunks.iter().map(|c| c.n_samples).sum();
    let mut out = EegBlock::zeros(dst.n_channels, n);
    for ch in 0..dst.n_channels {
        let row = out.channel_mut(ch);
        let mut at = 0;
        for c in chunks {
            row[at..at + c.n_samples].copy_from_slice(c.channel(ch));
            at += c.n_samples;
        }
    }
    *dst = out;
}
