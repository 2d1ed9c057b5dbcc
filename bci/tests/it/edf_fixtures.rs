//! errp's EDF+/BDF+ reader on files other tools wrote (`tests/data/edf`,
//! made by `scripts/edf_fixtures.py` with the versions its `fixtures.json`
//! names): each file reads to what MNE reads from it, the channels, the
//! rate, the samples and the events' onsets from the first sample (edfio's
//! file starts half a second past its header's second).

use std::io::Cursor;
use std::path::PathBuf;

use errp_bci::{EdfFile, EdfFormat};
use serde_json::Value;

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/data/edf")
}

fn read(name: &str) -> EdfFile {
    let bytes = std::fs::read(fixtures().join(name)).unwrap();
    EdfFile::read(Cursor::new(&bytes), Some(bytes.len() as u64))
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn files_other_tools_wrote_read_as_mne_reads_them() {
    let meta: Value =
        serde_json::from_str(&std::fs::read_to_string(fixtures().join("fixtures.json")).unwrap())
            .unwrap();
    let files = meta["read_by_mne"].as_object().unwrap();
    assert_eq!(files.len(), 4, "{files:?}");
    for (name, mne) in files {
        let f = read(name);
        let bdf = name.ends_with(".bdf");
        assert_eq!(
            f.format,
            if bdf {
                EdfFormat::BdfPlus
            } else {
                EdfFormat::EdfPlus
            },
            "{name}"
        );
        let labels: Vec<&str> = f.signals.iter().map(|s| s.label.as_str()).collect();
        let channels: Vec<&str> = mne["channels"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_str().unwrap())
            .collect();
        assert_eq!(labels, channels, "{name}");
        let fz = &f.signals[0];
        assert_eq!(fz.sfreq_hz, mne["sfreq_hz"].as_f64().unwrap(), "{name}");
        assert_eq!(
            fz.samples.len() as u64,
            mne["samples"].as_u64().unwrap(),
            "{name}"
        );
        // The same physical values (MNE's rounded to 1e-6 uV in the file).
        let factor = fz.to_microvolts().unwrap();
        for (k, want) in mne["fz_first_uv"].as_array().unwrap().iter().enumerate() {
            let got = fz.samples[k] * factor;
            assert!(
                (got - want.as_f64().unwrap()).abs() < 2e-6,
                "{name}: Fz sample {k} is {got} uV, MNE reads {want}"
            );
        }
        // The events, from the first sample, as MNE reads them.
        let events: Vec<(f64, &str)> = mne["events"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| (e[0].as_f64().unwrap(), e[1].as_str().unwrap()))
            .collect();
        assert_eq!(
            f.annotations.len(),
            events.len(),
            "{name}: {:?}",
            f.annotations
        );
        for (a, (onset, text)) in f.annotations.iter().zip(&events) {
            assert_eq!(a.text, *text, "{name}");
            assert!(
                (a.onset_secs - onset).abs() < 1e-6,
                "{name}: {} at {} s, MNE reads {onset} s",
                a.text,
                a.onset_secs
            );
        }
    }
    // edfio's file starts 0.5 s after its header's second, and its events
    // are where they were written, from the first sample.
    let f = read("edfio_subsecond.edf");
    assert_eq!(f.start_secs, 0.5);
    assert_eq!(f.annotations[0].onset_secs, 1.25);
}
