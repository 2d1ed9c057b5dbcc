//! Own EEG in place of the synthetic session: an EDF+ export read
//! back gives the decoder the accuracy the synthetic session gave, no
//! held-out epoch overlaps the calibration part, and what own EEG lacks
//! is named.

use std::io::Cursor;

use errp_bci::{
    Assessment, AssessmentKind, CalibrationPart, EdfFile, EegBlock, ErrorModel, EventNames,
    LdaDecoder, Preprocessing, Valid, calibrate_session, export_session, split_own_eeg,
};

use crate::decoder::sized;

/// A simulated session of `n_actions` at ErrP-to-noise `ratio`, its
/// synthetic cross-validated accuracy, and its EDF+ export.
fn exported(n_actions: usize, ratio: f64, seed: u64) -> (f64, Vec<u8>) {
    let setup = sized(n_actions, ratio);
    let (session, bytes) = export_session(&setup, seed, Cursor::new(Vec::new())).unwrap();
    let synthetic = calibrate_session(&LdaDecoder::default(), session, 5, seed).unwrap();
    (synthetic.accuracy.mean(), bytes.into_inner())
}

fn preprocessing() -> Valid<Preprocessing> {
    Valid::new(Preprocessing {
        params: Default::default(),
        sfreq_hz: 256.0,
    })
    .unwrap()
}

fn read(bytes: &[u8]) -> errp_bci::OwnEeg {
    let file = EdfFile::read(Cursor::new(bytes), Some(bytes.len() as u64)).unwrap();
    errp_bci::OwnEeg::from_edf(&file, &EventNames::default(), 256.0).unwrap()
}

#[test]
fn an_exported_session_decodes_as_the_synthetic_one_did() {
    let (synthetic, bytes) = exported(400, 0.55, 11);
    let rec = read(&bytes);
    assert_eq!(rec.montage.len(), 40);
    assert_eq!(rec.events.len(), 400);
    let split = split_own_eeg(&rec, CalibrationPart::Fraction(0.5), &preprocessing()).unwrap();
    assert_eq!(split.calibration.labels.len(), 200);
    assert_eq!(split.held_out.len() + split.dropped, 200);
    assert!(split.dropped <= 1, "{} dropped", split.dropped);
    // Leakage: every held-out epoch starts after the calibration part ends.
    for h in &split.held_out {
        assert!(h.event >= 200 && h.onset_secs >= split.calibration_end_secs);
    }
    let calibrated =
        calibrate_session(&LdaDecoder::default(), split.calibration.clone(), 5, 11).unwrap();
    let cv = calibrated.accuracy.mean();
    let right: Vec<(bool, bool)> = split
        .held_out
        .iter()
        .map(|h| (h.error, calibrated.model.decision(&h.features) >= 0.0))
        .collect();
    let rate = |class: bool| {
        let of: Vec<_> = right.iter().filter(|(e, _)| *e == class).collect();
        of.iter().filter(|(e, p)| e == p).count() as f64 / of.len() as f64
    };
    let held_out = (rate(true) + rate(false)) / 2.0;
    // The synthetic session's cross-validation trains on 400 trials, the
    // recording's on 200: a little lower, as a shorter calibration gives.
    // Shuffled labels or misplaced onsets give chance (0.5).
    assert!(
        synthetic > 0.65 && (cv - synthetic).abs() < 0.07 && (held_out - synthetic).abs() < 0.07,
        "synthetic {synthetic:.3}, recorded: cross-validated {cv:.3}, held out {held_out:.3}"
    );
}

#[test]
fn what_a_recording_lacks_is_named() {
    let (_, bytes) = exported(40, 1.0, 3);
    let file = EdfFile::read(Cursor::new(&bytes), Some(bytes.len() as u64)).unwrap();
    let names = EventNames::default();
    let err = |f: &EdfFile, n: &EventNames| {
        errp_bci::OwnEeg::from_edf(f, n, 256.0)
            .unwrap_err()
            .to_string()
    };
    // No FCz.
    let mut f = file.clone();
    f.signals.retain(|s| s.label != "FCz");
    let e = err(&f, &names);
    assert!(e.contains("no channel \"FCz\""), "{e}");
    // No EOG LA; MNE's "LA" is taken for it.
    let mut f = file.clone();
    f.signals.retain(|s| s.label != "EOG LA");
    assert!(err(&f, &names).contains("no channel \"EOG LA\""));
    // No EOG channel at all: no regression, CAR and the filters only.
    let mut f = file.clone();
    f.signals.retain(|s| !s.label.starts_with("EOG"));
    let rec = errp_bci::OwnEeg::from_edf(&f, &names, 256.0).unwrap();
    assert_eq!((rec.montage.n_eog(), rec.montage.n_eeg()), (0, 34));
    let split = split_own_eeg(&rec, CalibrationPart::Fraction(0.5), &preprocessing()).unwrap();
    let w = split.calibration.preprocessor.eog_weights();
    assert!(w.iter().all(|&x| x == 0.0));
    let mut f = file.clone();
    for s in &mut f.signals {
        s.label = s.label.trim_start_matches("EOG ").to_string();
    }
    f.signals.reverse();
    assert!(errp_bci::OwnEeg::from_edf(&f, &names, 256.0).is_ok());
    // Two channels that match one name: AF3 relabelled FCz, before the
    // real FCz, is refused naming both (never decoded as FCz).
    let mut f = file.clone();
    let af3 = f.signals.iter().position(|s| s.label == "AF3").unwrap();
    let fcz = f.signals.iter().position(|s| s.label == "FCz").unwrap();
    assert!(af3 < fcz);
    f.signals[af3].label = "EEG FCz".into();
    let e = err(&f, &names);
    assert!(
        e.contains(&format!(
            "two channels match \"FCz\": \"EEG FCz\" (channel {}) and \"FCz\" (channel {})",
            af3 + 1,
            fcz + 1
        )),
        "{e}"
    );
    // Another rate.
    let e = errp_bci::OwnEeg::from_edf(&file, &names, 512.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("256 Hz") && e.contains("512 Hz"), "{e}");
    // No events of a class.
    let renamed = EventNames {
        error: "S 96".into(),
        ..EventNames::default()
    };
    let e = err(&file, &renamed);
    assert!(
        e.contains("no events of class error") && e.contains("\"correct\", \"error\""),
        "{e}"
    );
    // Too short for a calibration: 40 actions hold about 8 errors.
    let rec = read(&bytes);
    let e = split_own_eeg(&rec, CalibrationPart::Events(6), &preprocessing())
        .unwrap_err()
        .to_string();
    assert!(e.contains("calibration part holds"), "{e}");
    let e = split_own_eeg(&rec, CalibrationPart::Fraction(1.0), &preprocessing())
        .unwrap_err()
        .to_string();
    assert!(e.contains("calibration"), "{e}");
}

#[test]
fn arrays_are_matched_and_checked_as_files_are() {
    let montage = errp_bci::Montage::standard();
    let labels: Vec<&str> = montage.channels().iter().map(|c| c.name.as_str()).collect();
    let data = EegBlock::zeros(labels.len(), 256);
    let event = |onset_secs| Assessment {
        onset_secs,
        kind: AssessmentKind::Error,
    };
    let new = |labels: &[&str], events| errp_bci::OwnEeg::new(labels, &data, 256.0, events);
    assert!(new(&labels, vec![event(0.5)]).is_ok());
    let e = new(&labels, vec![event(1.5)]).unwrap_err().to_string();
    assert!(e.contains("event at 1.5 s lies outside"), "{e}");
    let e = new(&labels[1..], vec![]).unwrap_err().to_string();
    assert!(e.contains("names for 40 rows"), "{e}");
    let mut twice = labels.clone();
    twice[0] = "eeg cz";
    let e = new(&twice, vec![]).unwrap_err().to_string();
    assert!(
        e.contains("two channels match \"Cz\": \"eeg cz\" (channel 1)"),
        "{e}"
    );
}

#[test]
fn events_annotated_twice_are_kept_once_and_two_outcomes_are_refused() {
    // Every event written twice, as some exporters do: the same events,
    // so no epoch lands in both a training and a test fold.
    let (_, bytes) = exported(60, 1.0, 4);
    let file = EdfFile::read(Cursor::new(&bytes), Some(bytes.len() as u64)).unwrap();
    let names = EventNames::default();
    let once = errp_bci::OwnEeg::from_edf(&file, &names, 256.0).unwrap();
    assert_eq!(once.merged, 0);
    let mut doubled = file.clone();
    doubled.annotations = file
        .annotations
        .iter()
        .flat_map(|a| [a.clone(), a.clone()])
        .collect();
    let twice = errp_bci::OwnEeg::from_edf(&doubled, &names, 256.0).unwrap();
    assert_eq!(twice.events, once.events);
    assert_eq!(twice.merged, once.events.len());
    // Within half a sample is the same sample.
    let mut near = file.clone();
    let mut again = file.annotations[3].clone();
    again.onset_secs += 0.3 / 256.0;
    near.annotations.push(again);
    let rec = errp_bci::OwnEeg::from_edf(&near, &names, 256.0).unwrap();
    assert_eq!((rec.events.len(), rec.merged), (once.events.len(), 1));
    // One action with both outcomes.
    let mut both = file.clone();
    let mut other = file.annotations[3].clone();
    other.text = if other.text == "error" {
        "correct"
    } else {
        "error"
    }
    .into();
    let at = other.onset_secs;
    both.annotations.push(other);
    let e = errp_bci::OwnEeg::from_edf(&both, &names, 256.0)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!(
            "the event at {at} s is annotated both error and correct"
        )),
        "{e}"
    );
}

#[test]
fn a_hybrid_continuous_calibration_decodes_the_subjects_own_response() {
    use errp_bci::{
        ContinuousSetup, ErrpTemplate, HybridSource, SessionOptions, SvmDecoder,
        calibrate_continuous_with,
    };
    let (_, bytes) = exported(400, 0.94, 1);
    let rec = read(&bytes);
    let k = 200;
    let end = ((rec.events[k - 1].onset_secs + 1.0) * 256.0) as usize;
    let template = ErrpTemplate::from_raw(&rec.raw, 256.0, &rec.events[..k]).unwrap();
    let fcz = rec.montage.index("FCz").unwrap();
    // The subject's response at FCz: the ErrP's negativity and positivity.
    let r = template.response.channel(fcz);
    let (min, max) = r
        .iter()
        .fold((0.0f64, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
    assert!(min < -1.0 && max > 1.0, "{min} {max}");
    let hybrid = HybridSource::from_own_eeg(&rec.montage, &rec.raw, 256.0, &rec.events, k).unwrap();
    // The calibration part and the rest: the recording, split where the
    // part's last epoch ends, nothing shared.
    assert_eq!(hybrid.calibration.n_samples, end);
    assert_eq!(
        hybrid.calibration.n_samples + hybrid.held_out.n_samples,
        rec.raw.n_samples
    );
    let setup = Valid::new(ContinuousSetup::default()).unwrap();
    let options = SessionOptions {
        hybrid: Some(&hybrid),
        ..SessionOptions::default()
    };
    let c = calibrate_continuous_with(&SvmDecoder::default(), &setup, 3, options).unwrap();
    let acc = c.accuracy.mean();
    eprintln!("hybrid continuous calibration: {acc:.4} (template peak {min:.2} / {max:.2} uV)");
    assert!(acc > 0.6, "hybrid continuous calibration at {acc}");
}
