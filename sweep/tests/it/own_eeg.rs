//! A sweep over people's recordings (`eeg.recording=a.edf,b.edf`): one
//! level per subject at the accuracy its recording gives, the files in the
//! manifest with their SHA-256, shards merged equal to the whole, and a
//! resume on a changed file refused.

use std::path::Path;

use errp_bci::stop::WindDown;
use errp_bci::{CalibrationParams, CalibrationSetup, Valid, export_session};
use errp_sim::Names;
use errp_sim::TaskKind;
use errp_sweep::{
    Manifest, Shard, SweepSpec, merge_sweeps, parse_accuracies, parse_axis, run_sweep,
};

use crate::{assert_same_files, complete, options, temp_dir};

/// A session of 160 actions at ErrP-to-noise `ratio` exported as EDF+ to
/// `path`, as `errp calibrate --export` writes it.
fn export(path: &Path, ratio: f64, seed: u64) {
    let setup = Valid::new(CalibrationSetup {
        calibration: CalibrationParams {
            n_actions: 160,
            ..CalibrationParams::default()
        },
        ..CalibrationSetup::with_ratio(ratio).unwrap()
    })
    .unwrap();
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    export_session(&setup, seed, file).unwrap();
}

const SCENARIO: &str = "task = \"grid\"\n[free_goals]\ncount = 4\n[eeg]\nrecording = \"a.edf\"\n";

fn recordings_spec(dir: &Path, accuracy: &str) -> SweepSpec {
    SweepSpec {
        task: TaskKind::Grid,
        scenario_path: dir.join("own.toml"),
        scenario_toml: SCENARIO.into(),
        accuracies: if accuracy.is_empty() {
            Vec::new()
        } else {
            parse_accuracies(accuracy, &Names::CLI).unwrap()
        },
        axes: vec![parse_axis(TaskKind::Grid, "eeg.recording=a.edf,b.edf", &Names::CLI).unwrap()],
        fixed: vec![],
        episodes: 8,
        seed: 3,
    }
}

#[test]
#[ignore = "slow (calibrates on two exports, 67 s): `cargo test --workspace -- --ignored` and CI run it"]
fn a_sweep_over_recordings_gives_one_level_per_subject_at_its_own_accuracy() {
    let d = temp_dir("recordings");
    std::fs::create_dir_all(&d).unwrap();
    export(&d.join("a.edf"), 0.8, 1);
    export(&d.join("b.edf"), 1.6, 2);
    let spec = recordings_spec(&d, "");
    assert!(spec.on_own_eeg());
    let out = d.join("whole");
    complete(&spec, &out, Shard::ALL, 2);

    // The manifest names each recording with its size and SHA-256; each
    // level's accuracy is its decoder's, cross-validated on its recording.
    let manifest = Manifest::read(&out).unwrap();
    let names: Vec<&str> = manifest
        .decoders
        .iter()
        .map(|i| i.own_eeg.as_ref().unwrap().name.as_str())
        .collect();
    assert_eq!(names, ["a.edf", "b.edf"]);
    for i in &manifest.decoders {
        let r = i.own_eeg.as_ref().unwrap();
        assert_eq!(r.bytes, std::fs::metadata(d.join(&r.name)).unwrap().len());
        assert_eq!(r.sha256.len(), 64);
        assert_eq!(Some(i.accuracy), i.cv_mean);
    }
    let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let rows: Vec<&str> = summary.lines().skip(1).collect();
    assert_eq!(rows.len(), 2, "{summary}");
    let accuracy = |row: &str| row.split(',').nth(1).unwrap().parse::<f64>().unwrap();
    for (row, info) in rows.iter().zip(&manifest.decoders) {
        assert!((accuracy(row) - info.accuracy).abs() < 1e-9, "{row}");
    }
    // The stronger ErrP gives the better decoder.
    assert!(accuracy(rows[1]) > accuracy(rows[0]) + 0.05, "{summary}");

    // Two shards merged are the whole sweep.
    let shards: Vec<_> = (1..=2)
        .map(|k| {
            let s = d.join(format!("shard{k}"));
            complete(&spec, &s, Shard { index: k, count: 2 }, 1);
            s
        })
        .collect();
    let merged = d.join("merged");
    merge_sweeps(&shards, &merged).unwrap();
    assert_same_files(&out, &merged);

    // No accuracy is targeted on recordings.
    let e = recordings_spec(&d, "0.8")
        .checked(&Names::CLI)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("--accuracy") && e.contains("eeg.recording") && e.contains("no accuracy"),
        "{e}"
    );

    // Resumed on another b.edf, the sweep is refused: its rows would mix
    // two subjects.
    export(&d.join("b.edf"), 1.6, 9);
    let sweep = spec.checked(&Names::CLI).unwrap();
    let e = run_sweep(&sweep, &options(&out, Shard::ALL, 7), &WindDown::new(), &())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("recording b.edf") && e.contains("SHA-256"),
        "{e}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}
