//! The grid on a person's own EEG: the decoder calibrated on the first
//! part decodes epochs of the rest only (epochs marked by their event and
//! their FCz trace), drawn with or without replacement, and the shared
//! control assumes the accuracy the EEG gave; a file another tool wrote
//! (the shared fixtures of `tests/data/edf`) without the decoding
//! channels is refused naming them.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use errp_bci::{CalibrationParams, CalibrationSetup, Valid, export_session};
use errp_sim::grid::{AssessmentDecoder, GridScenario, prepare_decoder, run_grid_scenario};
use errp_sim::{AnyScenario, ScenarioInput, ScenarioSource};

/// A session of `n_actions` at ErrP-to-noise `ratio` exported as EDF+ to
/// `path`, as `errp calibrate --export` writes it.
fn export(path: &Path, n_actions: usize, ratio: f64, seed: u64) {
    let setup = Valid::new(CalibrationSetup {
        calibration: CalibrationParams {
            n_actions,
            ..CalibrationParams::default()
        },
        ..CalibrationSetup::with_ratio(ratio).unwrap()
    })
    .unwrap();
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    export_session(&setup, seed, file).unwrap();
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("errp-recorded-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The grid scenario at `dir/s.toml` whose EEG is `dir/s.edf`, with the
/// `[eeg]` table's other lines `extra`.
fn scenario(dir: &Path, extra: &str, episodes: usize) -> GridScenario {
    let text = format!(
        "task = \"grid\"\nseed = 5\n[free_goals]\ncount = {episodes}\n[eeg]\nrecording = \
         \"s.edf\"\n{extra}"
    );
    let path = dir.join("s.toml");
    std::fs::write(&path, text).unwrap();
    match ScenarioInput::load_as_written(ScenarioSource::File(path)).unwrap() {
        AnyScenario::Grid(s) => *s,
        AnyScenario::Epuck(_) => unreachable!("a grid scenario"),
    }
}

#[test]
#[ignore = "slow (8 s): `cargo test --workspace -- --ignored` and CI run it"]
fn no_epoch_of_the_calibration_part_is_ever_decoded_online() {
    let d = dir("leak");
    export(&d.join("s.edf"), 240, 1.0, 3);
    for (draw, repeats_within_episode) in
        [("with_replacement", true), ("without_replacement", false)]
    {
        let s = scenario(&d, &format!("draw = \"{draw}\"\ncalibration = 0.5"), 12);
        let (decoder, calibration) = prepare_decoder(&s, |_| {}).unwrap();
        assert!(calibration.is_none());
        let AssessmentDecoder::OwnEeg(bank) = &decoder else {
            panic!("a recording's decoder")
        };
        let k = bank.report.calibration_events;
        assert_eq!(k, 120);
        // Each held-out epoch, marked by its FCz trace.
        let mut marks: HashMap<Vec<u64>, (usize, bool)> = HashMap::new();
        for (event, error, fcz) in bank.epochs() {
            assert!(event >= k, "event {event} is in the calibration part");
            let mark = fcz.iter().map(|x| x.to_bits()).collect();
            assert!(marks.insert(mark, (event, error)).is_none());
        }
        let (n_error, n_correct) = (bank.report.held_out.n_error, bank.report.held_out.n_correct);
        assert_eq!(marks.len(), n_error + n_correct);
        assert!(n_error >= 10 && n_correct >= 60, "{n_error} {n_correct}");
        let episodes = run_grid_scenario(&s, &decoder, true, |_, _| {}).unwrap();
        let mut repeated = false;
        for e in &episodes {
            let mut seen = HashMap::new();
            let mut per_class = [0usize; 2];
            for step in &e.steps {
                let mark: Vec<u64> = step.fcz.iter().map(|x| x.to_bits()).collect();
                let &(event, error) = marks
                    .get(&mark)
                    .expect("every decoded epoch is a held-out one");
                assert_eq!(error, step.error, "an epoch of the action's class");
                per_class[usize::from(error)] += 1;
                if seen.insert(event, ()).is_some() {
                    repeated = true;
                    // Without replacement, an epoch repeats only once its
                    // class's pool is used up.
                    let pool = if error { n_error } else { n_correct };
                    assert!(
                        repeats_within_episode || per_class[usize::from(error)] > pool,
                        "{draw}: event {event} drawn twice in an episode"
                    );
                }
            }
        }
        // 12 episodes of about 25 actions from pools of ~20 errors: with
        // replacement, repeats are all but certain.
        assert_eq!(repeated, repeats_within_episode, "{draw}");
        // The control assumes the cross-validated accuracy.
        assert_eq!(bank.assumed_accuracy, bank.report.cross_validated.mean());
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_recording_gives_the_accuracy_of_the_session_it_was_exported_from() {
    // 400 actions at the ratio `errp calibrate --accuracy 0.78` finds.
    let d = dir("round");
    export(&d.join("s.edf"), 400, 0.94, 1);
    let s = scenario(&d, "", 30);
    let (decoder, _) = prepare_decoder(&s, |_| {}).unwrap();
    let AssessmentDecoder::OwnEeg(bank) = &decoder else {
        panic!("a recording's decoder")
    };
    let r = &bank.report;
    let cv = r.cross_validated.mean();
    assert!((cv - 0.78).abs() < 0.04, "cross-validated {cv}");
    assert!((r.held_out.mean() - 0.78).abs() < 0.05, "{r}");
    assert_eq!(r.file.name, "s.edf");
    assert_eq!(
        r.file.bytes,
        std::fs::metadata(d.join("s.edf")).unwrap().len()
    );
    let episodes = run_grid_scenario(&s, &decoder, false, |_, _| {}).unwrap();
    let reached = episodes.iter().filter(|e| e.reached()).count();
    assert!(reached >= 27, "{reached} of 30 goals reached");
    // The online accuracy is the held-out one, within its sampling error.
    let online = errp_sim::grid::pooled_accuracy(&episodes).mean();
    assert!((online - r.held_out.mean()).abs() < 0.06, "{online}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_file_another_tool_wrote_without_the_decoding_channels_is_refused_naming_them() {
    // MNE's export of the shared fixture (`tests/data/edf`): Fz, Cz and an
    // EOG channel, read as a recording; the decoder needs eight channels.
    let d = dir("fixture");
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/edf/mne_export.edf");
    std::fs::copy(fixture, d.join("s.edf")).unwrap();
    let s = scenario(&d, "", 1);
    let e = prepare_decoder(&s, |_| {}).unwrap_err().to_string();
    assert!(
        e.contains("s.edf: no channel \"FC1\"") && e.contains("the recording has \"Fz\", \"Cz\""),
        "{e}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_recordings_scenario_refuses_a_simulated_users_settings() {
    let d = dir("refuse");
    for (extra, field) in [
        ("[user]\naccuracy = 0.8\n", "user.accuracy"),
        ("[user]\nsubject = \"S1\"\n", "user.subject"),
        ("decoder = \"oracle\"\n", "decoder"),
        ("bank_per_class = 50\n", "bank_per_class"),
    ] {
        let text = format!(
            "task = \"grid\"\n{}[free_goals]\ncount = 2\n[eeg]\nrecording = \"s.edf\"\n{}",
            if extra.starts_with('[') { "" } else { extra },
            if extra.starts_with('[') { extra } else { "" },
        );
        let path = d.join("x.toml");
        std::fs::write(&path, text).unwrap();
        let e = ScenarioInput::load_as_written(ScenarioSource::File(path))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("field `{field}`")) && e.contains("recording"),
            "{field}: {e}"
        );
    }
    // The e-puck's T_e key is not the grid's.
    let path = d.join("fa.toml");
    std::fs::write(
        &path,
        "task = \"grid\"\n[free_goals]\ncount = 2\n[eeg]\nrecording = \"s.edf\"\nfalse_alarms_per_min = 2\n",
    )
    .unwrap();
    let e = ScenarioInput::load_as_written(ScenarioSource::File(path))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("field `eeg.false_alarms_per_min`") && e.contains("grid"),
        "{e}"
    );
    // A simulated user's [realism] is not used, and the user says so.
    let path = d.join("r.toml");
    std::fs::write(
        &path,
        "task = \"grid\"\n[free_goals]\ncount = 2\n[eeg]\nrecording = \"s.edf\"\n[realism]\nbackground_drift = 0.3\n",
    )
    .unwrap();
    let Some(s) = ScenarioInput::load_as_written(ScenarioSource::File(path))
        .unwrap()
        .into_grid()
    else {
        panic!("a grid scenario")
    };
    assert_eq!(s.user, "recording s.edf ([realism] not used)");
    assert_eq!(s.realism, errp_bci::Realism::default());
    std::fs::remove_dir_all(&d).unwrap();
}

/// The false-alarm rate an own-EEG hybrid's T_e is set for by default is the
/// paper-fitted user's, as its committed figure prints it.
#[test]
fn the_hybrids_false_alarm_rate_is_the_fitted_users() {
    let figure = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../docs/figures/epuck_mexico_default.txt"),
    )
    .unwrap();
    let line = figure
        .lines()
        .find(|l| {
            l.trim_start()
                .starts_with("detector: mean of 4 windows >= 0.8")
        })
        .expect("the detector's operating point in the figure");
    let rate: f64 = line
        .split("false alarms")
        .nth(1)
        .and_then(|r| r.trim().split('/').next())
        .and_then(|r| r.trim().parse().ok())
        .expect("a false-alarm rate");
    assert_eq!(rate, errp_sim::epuck::FITTED_FALSE_ALARMS_PER_MIN, "{line}");
}
