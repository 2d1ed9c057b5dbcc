//! A person's own EEG in place of the synthetic EEG: its channels
//! matched by name to the montage, its events read from annotations, and
//! its split into a calibration part, on which the discrete decoder is
//! trained as on a synthetic session, and a held-out part, whose epochs the
//! closed loop draws.
//!
//! The split is by time. The calibration part holds the first events; it
//! ends where the last of their epochs ends. Held-out epochs start after
//! that, so no sample a decoder was trained on (nor the preprocessing
//! fitted on) is ever decoded online. The EOG regression, which a synthetic
//! session fits on a separate EOG session, is fitted on the calibration
//! part itself: a person's file rarely comes with one.

use errp_valid::Valid;
use nalgebra::DMatrix;

use crate::calibration::CalibrationSession;
use crate::edf::{EdfFile, EdfSignal};
use crate::erp::AssessmentKind;
use crate::error::{BciError, Result};
use crate::features::EpochWindow;
use crate::generator::{Assessment, EegBlock};
use crate::montage::{ChannelKind, DECODING_CHANNELS, Montage};
use crate::preprocess::{Preprocessing, Preprocessor};

/// The row of `labels` that montage channel `name` matches
/// ([`crate::montage`]'s rule), or an error naming two that both do.
fn find(labels: &[&str], name: &str) -> Result<Option<usize>> {
    crate::montage::find_label(labels, name).map_err(BciError::Format)
}

/// Events of each class a calibration part needs at least (the
/// cross-validation's five folds each hold one).
pub const MIN_CALIBRATION_PER_CLASS: usize = 5;

/// The most labelled events own EEG may hold (ten times the paper's
/// sessions of 400 and more actions; each held-out one keeps an epoch).
pub const MAX_OWN_EEG_EVENTS: usize = 20_000;

/// The EOG channels the preprocessing's regression needs.
pub const EOG_CHANNELS: [&str; 6] = ["EOG LA", "EOG LB", "EOG RA", "EOG RB", "EOG LO", "EOG RO"];

/// Which annotation texts mark each class of event (compared trimmed,
/// ignoring case).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EventNames {
    /// The text of an erroneous action's onset.
    pub error: String,
    /// The text of a correct action's onset.
    pub correct: String,
}

impl Default for EventNames {
    /// `error` and `correct`, as `errp calibrate --export` writes them.
    fn default() -> Self {
        Self {
            error: "error".into(),
            correct: "correct".into(),
        }
    }
}

/// Own EEG matched to the montage: the channels the decoder needs, in
/// the montage's order, in µV, and its labelled events.
#[derive(Debug, Clone)]
pub struct OwnEeg {
    /// The standard montage's channels found in the file (EEG first).
    pub montage: Montage,
    /// The samples, `(montage.len(), n)`, in µV.
    pub raw: EegBlock,
    /// The sampling rate.
    pub sfreq_hz: f64,
    /// The labelled events, by onset.
    pub events: Vec<Assessment>,
    /// Events given twice (the same class at the same sample, a common
    /// export bug), each kept once: a repeat would put one epoch into both
    /// a training and a test fold.
    pub merged: usize,
}

/// A short list of names, for messages.
fn listed(names: &[&str]) -> String {
    let mut s: Vec<String> = names.iter().take(48).map(|n| format!("{n:?}")).collect();
    if names.len() > 48 {
        s.push(format!("... ({} in all)", names.len()));
    }
    s.join(", ")
}

impl OwnEeg {
    /// Matches `labels` (one per row of `data`, `(labels.len(), n)` in µV,
    /// at `sfreq_hz`) to the standard montage: the eight decoding channels
    /// and the six EOG ones must be there, every other EEG channel found
    /// joins the common average reference; two labels that match one
    /// channel are refused. `events` are sorted by onset and must lie
    /// inside the data; an event given twice is kept once
    /// ([`OwnEeg::merged`]), one sample labelled both error and correct is
    /// refused.
    pub fn new(
        labels: &[&str],
        data: &EegBlock,
        sfreq_hz: f64,
        mut events: Vec<Assessment>,
    ) -> Result<Self> {
        if data.n_channels != labels.len() {
            return Err(BciError::Format(format!(
                "{} channel names for {} rows of data",
                labels.len(),
                data.n_channels
            )));
        }
        let standard = Montage::standard();
        // The EOG regression's six channels, all of them or none.
        let mut has_eog = false;
        for name in EOG_CHANNELS {
            has_eog |= find(labels, name)?.is_some();
        }
        let mut keep = Vec::new();
        let mut rows = Vec::new();
        for (i, c) in standard.channels().iter().enumerate() {
            match find(labels, &c.name)? {
                Some(row) => {
                    keep.push(i);
                    rows.push(row);
                }
                None if DECODING_CHANNELS.contains(&c.name.as_str())
                    || (has_eog && c.kind == ChannelKind::Eog) =>
                {
                    return Err(BciError::Format(format!(
                        "no channel {:?}: the decoder needs {} and the EOG regression all of {} \
                         (or none: no regression); the recording has {}",
                        c.name,
                        DECODING_CHANNELS.join(" "),
                        EOG_CHANNELS.join(", "),
                        listed(labels)
                    )));
                }
                None => {}
            }
        }
        let montage = standard.subset(&keep)?;
        let mut raw = EegBlock::zeros(rows.len(), data.n_samples);
        for (ch, &row) in rows.iter().enumerate() {
            raw.channel_mut(ch).copy_from_slice(data.channel(row));
        }
        if let Some(bad) = raw.data.iter().position(|v| !v.is_finite()) {
            return Err(BciError::Format(format!(
                "channel {:?} holds a sample that is not a finite number",
                montage.channels()[bad / data.n_samples.max(1)].name
            )));
        }
        if events.len() > MAX_OWN_EEG_EVENTS {
            return Err(BciError::Format(format!(
                "{} labelled events; own EEG may hold at most {MAX_OWN_EEG_EVENTS}",
                events.len()
            )));
        }
        events.sort_by(|a, b| a.onset_secs.total_cmp(&b.onset_secs));
        let duration = data.n_samples as f64 / sfreq_hz;
        if let Some(e) = events
            .iter()
            .find(|e| !(e.onset_secs >= 0.0 && e.onset_secs < duration))
        {
            return Err(BciError::Format(format!(
                "an event at {} s lies outside the recording (0 to {duration} s)",
                e.onset_secs
            )));
        }
        let (events, merged) = merge_repeats(events, sfreq_hz)?;
        Ok(Self {
            montage,
            raw,
            sfreq_hz,
            events,
            merged,
        })
    }

    /// Own EEG from an EDF or BDF file, at the decoder's `sfreq_hz`:
    /// its channels matched as [`OwnEeg::new`] matches them (each a
    /// voltage, at `sfreq_hz`), its events the annotations `names` gives.
    pub fn from_edf(file: &EdfFile, names: &EventNames, sfreq_hz: f64) -> Result<Self> {
        let labels: Vec<&str> = file.signals.iter().map(|s| s.label.as_str()).collect();
        let standard = Montage::standard();
        // Only the channels that will be used must be usable.
        let mut used: Vec<&EdfSignal> = Vec::new();
        for c in standard.channels() {
            if let Some(i) = find(&labels, &c.name)? {
                used.push(&file.signals[i]);
            }
        }
        for s in &used {
            if s.sfreq_hz != sfreq_hz {
                return Err(BciError::Format(format!(
                    "channel {:?} is sampled at {} Hz; the decoder runs at {sfreq_hz} Hz: \
                     resample the recording to {sfreq_hz} Hz (e.g. MNE's raw.resample({sfreq_hz}))",
                    s.label, s.sfreq_hz
                )));
            }
            if s.to_microvolts().is_none() {
                return Err(BciError::Format(format!(
                    "channel {:?} is in {:?}, not a voltage (uV, mV, V)",
                    s.label, s.unit
                )));
            }
        }
        let n = used.iter().map(|s| s.samples.len()).min().unwrap_or(0);
        let mut data = EegBlock::zeros(used.len(), n);
        let mut used_labels = Vec::with_capacity(used.len());
        for (ch, s) in used.iter().enumerate() {
            let k = s.to_microvolts().unwrap_or(1.0);
            for (o, v) in data.channel_mut(ch).iter_mut().zip(&s.samples) {
                *o = v * k;
            }
            used_labels.push(s.label.as_str());
        }
        let events = events_of(file, names)?;
        Self::new(&used_labels, &data, sfreq_hz, events)
    }

    /// The EEG's duration, in seconds.
    pub fn duration_secs(&self) -> f64 {
        self.raw.n_samples as f64 / self.sfreq_hz
    }
}

/// `events` (sorted by onset) with each repeat (the same class at the same
/// sample) left out, and how many were; one sample of both classes is an
/// error.
fn merge_repeats(events: Vec<Assessment>, sfreq_hz: f64) -> Result<(Vec<Assessment>, usize)> {
    let sample = |e: &Assessment| (e.onset_secs * sfreq_hz).round();
    let mut kept: Vec<Assessment> = Vec::with_capacity(events.len());
    let mut merged = 0;
    for e in events {
        // Events at one sample are adjacent once sorted, and only the first
        // of them is kept.
        match kept.last() {
            Some(k) if sample(k) == sample(&e) && k.kind == e.kind => merged += 1,
            Some(k) if sample(k) == sample(&e) => {
                return Err(BciError::Format(format!(
                    "the event at {} s is annotated both error and correct: one action has \
                     one outcome",
                    errp_valid::shown(e.onset_secs)
                )));
            }
            _ => kept.push(e),
        }
    }
    Ok((kept, merged))
}

/// The annotations of `file` that `names` marks as events, with a message
/// naming what is there when a class has none.
fn events_of(file: &EdfFile, names: &EventNames) -> Result<Vec<Assessment>> {
    let is = |text: &str, name: &str| text.trim().eq_ignore_ascii_case(name.trim());
    let events: Vec<Assessment> = file
        .annotations
        .iter()
        .filter_map(|a| {
            let kind = if is(&a.text, &names.error) {
                AssessmentKind::Error
            } else if is(&a.text, &names.correct) {
                AssessmentKind::Correct
            } else {
                return None;
            };
            Some(Assessment {
                onset_secs: a.onset_secs,
                kind,
            })
        })
        .collect();
    for (kind, name) in [
        (AssessmentKind::Error, &names.error),
        (AssessmentKind::Correct, &names.correct),
    ] {
        if !events.iter().any(|e| e.kind == kind) {
            let mut texts: Vec<&str> = file.annotations.iter().map(|a| a.text.as_str()).collect();
            texts.sort_unstable();
            texts.dedup();
            return Err(BciError::Format(format!(
                "no events of class {} (annotations {name:?}); the recording's annotations \
                 are: {}",
                if kind == AssessmentKind::Error {
                    "error"
                } else {
                    "correct"
                },
                if texts.is_empty() {
                    "none".to_string()
                } else {
                    listed(&texts)
                }
            )));
        }
    }
    Ok(events)
}

/// How much of own EEG calibrates the decoder.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CalibrationPart {
    /// This fraction of the events, the first ones, in (0, 1).
    Fraction(f64),
    /// This many events, the first ones.
    Events(usize),
}

/// One held-out epoch of own EEG, preprocessed.
#[derive(Debug, Clone)]
pub struct OwnEegEpoch {
    /// The event's index in [`OwnEeg::events`].
    pub event: usize,
    /// Its onset, in seconds.
    pub onset_secs: f64,
    /// True for an erroneous action.
    pub error: bool,
    /// The decoder's features.
    pub features: Vec<f64>,
    /// The preprocessed decoding channels from the onset, `(8, span)`.
    pub block: EegBlock,
}

/// Own EEG split for the discrete decoder.
#[derive(Debug, Clone)]
pub struct OwnEegSplit {
    /// The calibration part's epochs, as a synthetic session gives them.
    pub calibration: CalibrationSession,
    /// Where the calibration part ends, in seconds.
    pub calibration_end_secs: f64,
    /// The held-out epochs, by onset.
    pub held_out: Vec<OwnEegEpoch>,
    /// Events after the calibration's first whose epochs overlap the
    /// calibration part or run past the EEG's end: used by neither.
    pub dropped: usize,
}

/// Splits `recording` (own EEG) by time: the first events (`part`)
/// calibrate, the later ones are held out. The preprocessing
/// (`preprocessing`, at the EEG's rate) is fitted on the calibration part,
/// then run causally over the whole of it; every event's epoch becomes the
/// paper's temporal features.
pub fn split_own_eeg(
    recording: &OwnEeg,
    part: CalibrationPart,
    preprocessing: &Valid<Preprocessing>,
) -> Result<OwnEegSplit> {
    let fs = recording.sfreq_hz;
    let n_events = recording.events.len();
    let k = calibration_events(part, n_events)?;
    let window = EpochWindow::paper(fs);
    let span = window.span();
    let onset = |e: &Assessment| (e.onset_secs * fs).round() as usize;
    let end = onset(&recording.events[k - 1]) + span;
    if end > recording.raw.n_samples {
        return Err(BciError::Format(format!(
            "the recording ends {:.3} s after its last calibration event, inside its epoch",
            recording.duration_secs() - recording.events[k - 1].onset_secs
        )));
    }
    let calibration = &recording.events[..k];
    count_classes(calibration, "calibration part", MIN_CALIBRATION_PER_CLASS)?;
    let fit_on = recording.raw.samples(0..end);
    let decoding = recording.montage.decoding_indices();
    let preprocessor = Preprocessor::fit(&recording.montage, preprocessing, &fit_on, &decoding)
        .map_err(|e| match e {
            BciError::Training(m) => BciError::Format(format!(
                "the calibration part ({:.1} s) is too short to fit the preprocessing: {m}",
                end as f64 / fs
            )),
            other => other,
        })?;
    let decoded = preprocessor.clone().process(&recording.raw);
    let n_features = window.n_features(decoding.len());
    let mut flat = Vec::with_capacity(k * n_features);
    for e in calibration {
        window.extract_into(&decoded, onset(e), &mut flat);
    }
    let mut held_out = Vec::new();
    let mut dropped = 0;
    for (i, e) in recording.events.iter().enumerate().skip(k) {
        let at = onset(e);
        if at < end || at + span > decoded.n_samples {
            dropped += 1;
            continue;
        }
        let block = decoded.samples(at..at + span);
        held_out.push(OwnEegEpoch {
            event: i,
            onset_secs: e.onset_secs,
            error: e.kind == AssessmentKind::Error,
            features: window.extract(&decoded, at),
            block,
        });
    }
    let held: Vec<Assessment> = held_out.iter().map(|h| recording.events[h.event]).collect();
    count_classes(&held, "held-out part", 1)?;
    Ok(OwnEegSplit {
        calibration: CalibrationSession {
            features: DMatrix::from_row_slice(k, n_features, &flat),
            labels: calibration
                .iter()
                .map(|e| e.kind == AssessmentKind::Error)
                .collect(),
            assessments: calibration.to_vec(),
            preprocessor,
            grand_average: None,
        },
        calibration_end_secs: end as f64 / fs,
        held_out,
        dropped,
    })
}

/// The number of calibration events `part` asks of `n`: at least one, and
/// one fewer than all.
pub fn calibration_events(part: CalibrationPart, n: usize) -> Result<usize> {
    let k = match part {
        CalibrationPart::Fraction(f) if f > 0.0 && f < 1.0 => (f * n as f64).round() as usize,
        CalibrationPart::Fraction(f) => {
            return Err(BciError::InvalidParameter {
                name: "calibration",
                value: errp_valid::shown(f),
                expected: "a fraction of the events strictly between 0 and 1, e.g. 0.5".into(),
            });
        }
        CalibrationPart::Events(k) => k,
    };
    if k == 0 || k >= n {
        return Err(BciError::Format(format!(
            "a calibration part of {k} of the recording's {n} events: it needs at least one, \
             and leaves at least one held out"
        )));
    }
    Ok(k)
}

/// Checks that `events` (of `what`) hold at least `min` of each class.
fn count_classes(events: &[Assessment], what: &str, min: usize) -> Result<()> {
    let errors = events
        .iter()
        .filter(|e| e.kind == AssessmentKind::Error)
        .count();
    let correct = events.len() - errors;
    if errors < min || correct < min {
        return Err(BciError::Format(format!(
            "the {what} holds {errors} error and {correct} correct events; it needs at least \
             {min} of each (a longer recording, or another split)"
        )));
    }
    Ok(())
}
