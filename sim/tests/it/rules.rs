//! Each rule on how a scenario's values combine (`errp_sim::rules`),
//! reached from each entry: a scenario file's key, a flag, a Python
//! keyword, a key set from outside (a sweep level, Python's `overrides=`)
//! and a live session; each refusal names the value as that entry names it.
//! (The sweep's own inputs, `--accuracy` and `--eeg` for every level, are
//! tested with the sweep.)

use std::path::{Path, PathBuf};

use errp_bci::RequestedAccuracy;
use errp_sim::grid::{DecoderChoice, EegMode};
use errp_sim::live::{LiveOptions, LiveRequest, LiveSession};
use errp_sim::{LoadedScenario, Names, RunProvenance, ScenarioInput, ScenarioSource};

const OWN_GRID: &str = "task = \"grid\"\nname = \"own\"\n[free_goals]\ncount = 2\n[eeg]\n\
                        recording = \"s01.edf\"\n";
const OWN_EPUCK: &str = "task = \"epuck\"\nstart = \"Mexico\"\ngoal = \"Pisa\"\n[eeg]\n\
                         recording = \"s01.edf\"\n";
const EPUCK: &str =
    "task = \"epuck\"\nstart = \"Mexico\"\ngoal = \"Pisa\"\n[user]\naccuracy = 0.9\n";
const GRID: &str = "task = \"grid\"\nname = \"sim\"\n[user]\naccuracy = 0.8\n[free_goals]\n\
                    count = 2\n";

/// A scenario file of this test process holding `text`.
fn file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("errp-rules-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

fn input(path: &Path) -> ScenarioInput {
    ScenarioInput::new(ScenarioSource::File(path.to_path_buf()))
}

fn refused(input: &ScenarioInput, names: &Names) -> String {
    input.load(names).unwrap_err().to_string()
}

fn accuracy(a: f64) -> Option<RequestedAccuracy> {
    Some(RequestedAccuracy::new(a).unwrap())
}

#[test]
fn own_eeg_refuses_an_accuracy_named_as_each_entry_gave_it() {
    // A file's key.
    let with_key = file("own-key", &format!("{OWN_GRID}[user]\naccuracy = 0.8\n"));
    let e = refused(&input(&with_key), &Names::CLI);
    assert!(
        e.contains("field `user.accuracy` = 0.8") && e.contains("no accuracy"),
        "{e}"
    );
    // A flag, a keyword: the same value, named by the front end.
    let own = file("own", OWN_GRID);
    let set = ScenarioInput {
        accuracy: accuracy(0.8),
        ..input(&own)
    };
    let e = refused(&set, &Names::CLI);
    assert!(
        e.starts_with("--accuracy: the EEG of ") && e.contains("Leave out --accuracy"),
        "{e}"
    );
    let e = refused(&set, &Names::PYTHON);
    assert!(
        e.starts_with("accuracy: the EEG of ") && !e.contains("--"),
        "{e}"
    );
    // A key set from outside (a sweep level): named as the file's key.
    let key = ScenarioInput {
        keys: vec![("user.accuracy".into(), toml::Value::Float(0.8))],
        ..input(&own)
    };
    let e = refused(&key, &Names::FILE);
    assert!(e.contains("field `user.accuracy` = 0.8"), "{e}");
    // The e-puck's file takes none either, nor a T_e.
    let e = refused(
        &input(&file(
            "own-te",
            &format!("{OWN_EPUCK}[control]\nt_e = 0.7\n"),
        )),
        &Names::CLI,
    );
    assert!(e.contains("field `control.t_e`"), "{e}");
}

#[test]
fn own_eeg_refuses_an_eeg_mode_and_the_oracle_from_any_entry() {
    let own = file("own-mode", OWN_GRID);
    let mode = ScenarioInput {
        eeg: Some(EegMode::Bank),
        ..input(&own)
    };
    assert!(refused(&mode, &Names::CLI).starts_with("--eeg bank: the EEG of "));
    // Set as a key it would replace the table naming the recording.
    let key = ScenarioInput {
        keys: vec![("eeg".into(), toml::Value::String("bank".into()))],
        ..input(&own)
    };
    let e = refused(&key, &Names::PYTHON);
    assert!(e.starts_with("overrides[\"eeg\"] bank: the EEG of "), "{e}");
    let oracle = ScenarioInput {
        decoder: Some(DecoderChoice::Oracle),
        ..input(&own)
    };
    assert!(refused(&oracle, &Names::CLI).starts_with("--decoder oracle: the EEG of "));
    let written = file("own-oracle", &format!("decoder = \"oracle\"\n{OWN_GRID}"));
    let e = refused(&input(&written), &Names::CLI);
    assert!(e.contains("field `decoder` = \"oracle\""), "{e}");
}

#[test]
fn only_the_grids_oracle_is_perfect_whatever_the_entry() {
    let grid = file("grid", GRID);
    let perfect = ScenarioInput {
        accuracy: accuracy(1.0),
        ..input(&grid)
    };
    let e = refused(&perfect, &Names::CLI);
    assert!(
        e.starts_with("--accuracy 1: only the grid's oracle") && e.contains("--decoder"),
        "{e}"
    );
    let e = refused(&perfect, &Names::PYTHON);
    assert!(
        e.starts_with("accuracy 1: only") && e.contains("overrides[\"decoder\"]"),
        "{e}"
    );
    // The oracle may be, set as a flag or as a key (Python's overrides=).
    let oracle = ScenarioInput {
        decoder: Some(DecoderChoice::Oracle),
        ..perfect.clone()
    };
    assert!(oracle.load(&Names::CLI).is_ok());
    let oracle_key = ScenarioInput {
        keys: vec![("decoder".into(), toml::Value::String("oracle".into()))],
        ..perfect.clone()
    };
    assert!(oracle_key.load(&Names::PYTHON).is_ok());
    // A file's key, a sweep level's.
    let written = file("perfect", &GRID.replace("0.8", "1.0"));
    let e = refused(&input(&written), &Names::CLI);
    assert!(e.contains("field `user.accuracy` = 1 is invalid"), "{e}");
    let level = ScenarioInput {
        keys: vec![("user.accuracy".into(), toml::Value::Float(1.0))],
        ..input(&grid)
    };
    assert!(refused(&level, &Names::FILE).contains("field `user.accuracy` = 1"));
    // The e-puck has no oracle.
    let epuck = file("epuck", EPUCK);
    let e = refused(
        &ScenarioInput {
            accuracy: accuracy(1.0),
            ..input(&epuck)
        },
        &Names::CLI,
    );
    assert!(e.starts_with("--accuracy 1: only the grid's oracle"), "{e}");
}

#[test]
fn a_value_of_the_other_task_is_refused_naming_the_entry() {
    let grid = file("grid-runs", GRID);
    let runs = ScenarioInput {
        runs: Some(3),
        ..input(&grid)
    };
    assert!(refused(&runs, &Names::CLI).starts_with("--runs: applies to e-puck scenarios"));
    assert!(refused(&runs, &Names::PYTHON).starts_with("runs: applies to e-puck scenarios"));
    let epuck = file("epuck-eeg", EPUCK);
    let eeg = ScenarioInput {
        eeg: Some(EegMode::Bank),
        ..input(&epuck)
    };
    assert!(refused(&eeg, &Names::CLI).starts_with("--decoder and --eeg apply to grid"));
}

/// A live session of `loaded` as `errp stream` asks for it.
fn live(loaded: LoadedScenario) -> errp_sim::Result<LiveSession> {
    LiveSession::new(
        loaded,
        LiveRequest {
            options: LiveOptions::default(),
            runs: None,
            decoder: "name=errp-decoder",
            save: None,
            provenance: &RunProvenance::default(),
            names: &Names::CLI,
        },
    )
}

#[test]
fn a_live_session_streams_the_simulated_user_only_and_names_its_options() {
    let own = input(&file("own-live", OWN_EPUCK))
        .load(&Names::CLI)
        .unwrap();
    let e = live(own).err().expect("refused").to_string();
    assert!(
        e.contains("errp stream streams the simulated user's EEG"),
        "{e}"
    );
    let grid = input(&file("grid-live", GRID)).load(&Names::CLI).unwrap();
    assert!(live(grid).is_ok());
    let e = LiveOptions::new(1000.0, 30.0, None, &Names::CLI)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("--speed: 1000 is not a speed"), "{e}");
    let e = LiveOptions::new(2.0, 0.0, None, &Names::PYTHON)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("timeout: 0 is not a timeout"), "{e}");
}
