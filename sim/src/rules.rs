//! How a scenario's values combine: each rule stated once, in one function
//! that every entry reaches (a scenario file's loader, the builder,
//! `errp run`'s flags and Python's keywords through
//! [`ScenarioInput`](crate::ScenarioInput), a sweep's levels, `errp
//! stream`, Python's own EEG given in memory). A refusal names the value as
//! the entry it came through names it ([`Origin`], [`Names`]).
//!
//! - [`task_takes`]: the runs are the e-puck's; the decoder and the EEG
//!   mode are the grid's.
//! - [`own_eeg_is_the_user`]: a scenario on a person's own EEG takes
//!   nothing that describes a simulated user or a decoder of its own.
//! - [`accuracy_for`]: a decoder is asked for a mean accuracy strictly
//!   between 0.5 and 1; only the grid's oracle may be perfect.

use std::path::Path;

use errp_bci::RequestedAccuracy;

use crate::error::{Result, SimError};
use crate::names::Names;
use crate::scenario_file::field_error;
use crate::task_kind::TaskKind;

/// Where a value was given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin<'a> {
    /// In the scenario named `path`, written in it or set as one of its
    /// keys: named by the key (`{path}: field `user.accuracy``).
    Scenario(&'a Path),
    /// By an input of a run outside the scenario (a flag, a keyword):
    /// named as that front end names it.
    Input(&'a Names),
    /// By an input of a sweep, for every level: named as that front end
    /// names it.
    Sweep(&'a Names),
}

/// Where a person's own EEG came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OwnEegFrom<'a> {
    /// `[eeg] recording = "..."` in the scenario at `path`.
    Scenario {
        /// The scenario.
        path: &'a Path,
        /// The file, as written.
        recording: &'a str,
    },
    /// A sweep's levels (`--param eeg.recording=a.edf,b.edf`).
    Swept,
    /// Given in memory to a task of `task` (Python's `eeg=`).
    Supplied(TaskKind),
}

/// A value that only one task takes ([`task_takes`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TaskValue {
    /// The number of runs (the e-puck's).
    Runs,
    /// The decoder: the EEG decoder or the oracle (the grid's).
    Decoder,
    /// The EEG mode: per action or a bank (the grid's).
    EegMode,
}

/// Rule: each task takes its own values. The runs are the e-puck's (a grid
/// scenario lists its episodes); the decoder and the EEG mode are the
/// grid's (the e-puck always decodes its EEG with the sliding-window SVM).
/// `given` are the values an entry set, with where; the first the task of
/// the scenario at `path` does not take is refused.
pub fn task_takes(task: TaskKind, path: &Path, given: &[(TaskValue, Origin<'_>)]) -> Result<()> {
    for &(value, origin) in given {
        match (task, value, origin) {
            (TaskKind::Grid, TaskValue::Runs, Origin::Input(n) | Origin::Sweep(n)) => {
                return Err(SimError::Scenario(format!(
                    "{}: applies to e-puck scenarios; a grid scenario lists its episodes (set \
                     `repeats` in {})",
                    n.runs,
                    path.display()
                )));
            }
            (TaskKind::Epuck, TaskValue::Decoder | TaskValue::EegMode, Origin::Input(n)) => {
                return Err(SimError::Scenario(format!(
                    "{} and {} apply to grid scenarios; the e-puck task always runs the streamed \
                     EEG through the sliding-window SVM",
                    n.decoder, n.eeg
                )));
            }
            (TaskKind::Epuck, TaskValue::Decoder | TaskValue::EegMode, Origin::Sweep(n)) => {
                return Err(SimError::Sweep(format!(
                    "{} applies to the grid; the e-puck always streams its EEG",
                    n.sweep_eeg
                )));
            }
            // A scenario's own keys are the loader's: one the task does
            // not have is an unknown field there.
            _ => {}
        }
    }
    Ok(())
}

/// A value a scenario on a person's own EEG cannot also have
/// ([`own_eeg_is_the_user`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Claim<'a> {
    /// A decoder accuracy to target (`user.accuracy`).
    Accuracy(f64),
    /// A subject of Table 1 (`user.subject`).
    Subject(&'a str),
    /// A goal set (`user.goals`), as written.
    Goals(&'a str),
    /// An online hit rate to target (`user.hit_rate`).
    HitRate(f64),
    /// A false-alarm rate to target (`user.false_alarms_per_min`).
    FalseAlarmsPerMin(f64),
    /// A detector threshold (`control.t_e`).
    DetectorThreshold,
    /// An EEG mode, as written (`eeg = "bank"`).
    EegMode(&'a str),
    /// A bank's size (`bank_per_class`).
    BankPerClass(&'a str),
    /// The oracle decoder (`decoder = "oracle"`).
    Oracle,
    /// A decoder of the caller's own (Python's `decoder=`).
    OwnDecoder,
    /// The user's EEG streamed over Lab Streaming Layer (`errp stream`).
    Streamed,
}

/// Why a scenario on own EEG takes no accuracy, in a field's words.
const NO_ACCURACY: &str = "nothing, with a recording (eeg.recording): the decoder is calibrated \
                           on the recording's first part and has the accuracy the recording \
                           gives; no accuracy is targeted";

/// Rule: a person's own EEG is the user. A scenario on own EEG takes
/// nothing that describes a simulated user or targets its decoder (an
/// accuracy, a subject, a goal set, an online target, T_e), no EEG mode or
/// bank (the EEG is the file's held-out epochs), no oracle (it reads
/// no EEG), no decoder of the caller's own, and cannot be streamed (`errp
/// stream` streams the simulated user). `claims` are what the entry was
/// also given, in the order it reports them; with own EEG, the first is
/// refused.
pub fn own_eeg_is_the_user(
    own: Option<OwnEegFrom<'_>>,
    claims: &[(Claim<'_>, Origin<'_>)],
) -> Result<()> {
    match (own, claims.first()) {
        (Some(own), Some(&(claim, origin))) => Err(own_eeg_refusal(own, claim, origin)),
        _ => Ok(()),
    }
}

/// The refusal of `claim`, given at `origin`, on the own EEG `own`.
fn own_eeg_refusal(own: OwnEegFrom<'_>, claim: Claim<'_>, origin: Origin<'_>) -> SimError {
    match (origin, own) {
        (Origin::Scenario(path), own) => scenario_refusal(path, own, claim),
        (Origin::Input(n), OwnEegFrom::Scenario { path, recording }) => {
            input_refusal(n, path, recording, claim)
        }
        (Origin::Input(_), OwnEegFrom::Supplied(TaskKind::Grid)) => match claim {
            Claim::OwnDecoder => own_decoder(),
            _ => SimError::Scenario(
                "accuracy: with eeg=..., the decoder is calibrated on the recording's first part \
                 and has the accuracy the recording gives (GridTask.calibration); no accuracy is \
                 targeted: leave out accuracy"
                    .into(),
            ),
        },
        (Origin::Input(_), OwnEegFrom::Supplied(TaskKind::Epuck)) => SimError::Scenario(
            "accuracy and decoder: with eeg=..., the runs stream a hybrid of the recording, \
             decoded by the SVM calibrated on its first part, which has the accuracy the \
             recording gives (EpuckTask.calibration); no accuracy is targeted: leave out \
             accuracy and decoder"
                .into(),
        ),
        (Origin::Sweep(n) | Origin::Input(n), own) => {
            let what = match own {
                OwnEegFrom::Scenario { path, .. } => {
                    format!("{}: its EEG is a recording (eeg.recording)", path.display())
                }
                OwnEegFrom::Swept | OwnEegFrom::Supplied(_) => "the swept eeg.recording".into(),
            };
            SimError::Sweep(match claim {
                Claim::EegMode(mode) => format!(
                    "{} {mode} with {what}: the recording is the EEG; leave it out",
                    n.sweep_eeg
                ),
                _ => format!(
                    "{} with {what}: a recording's decoder is calibrated on its first part and \
                     has the accuracy the recording gives (the sweep reports it per level); no \
                     accuracy is targeted: leave out {}",
                    n.accuracy, n.accuracy
                ),
            })
        }
    }
}

/// The refusal of `claim`, a key of the scenario at `path`, on own EEG.
fn scenario_refusal(path: &Path, own: OwnEegFrom<'_>, claim: Claim<'_>) -> SimError {
    use Claim as C;
    let field =
        |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
    match claim {
        C::Accuracy(a) => field("user.accuracy", a.to_string(), NO_ACCURACY),
        C::Subject(s) => field("user.subject", format!("{s:?}"), NO_ACCURACY),
        C::Goals(g) => field("user.goals", g.to_string(), NO_ACCURACY),
        C::HitRate(h) => field("user.hit_rate", h.to_string(), NO_ACCURACY),
        C::FalseAlarmsPerMin(f) => field("user.false_alarms_per_min", f.to_string(), NO_ACCURACY),
        C::DetectorThreshold => field(
            "control.t_e",
            "given".into(),
            "no t_e with a recording (eeg.recording): T_e is set on the recording for \
             eeg.false_alarms_per_min",
        ),
        C::BankPerClass(n) => field(
            "bank_per_class",
            n.to_string(),
            "nothing, with a recording (eeg.recording): the bank is the recording's held-out \
             epochs",
        ),
        C::Oracle => field(
            "decoder",
            "\"oracle\"".into(),
            if matches!(own, OwnEegFrom::Supplied(_)) {
                "\"eeg\" with a recording: the oracle reads no EEG"
            } else {
                "\"eeg\" with a recording (eeg.recording): the oracle reads no EEG"
            },
        ),
        C::EegMode(mode) => field(
            "eeg",
            format!("{mode:?}"),
            "nothing, with a recording (eeg.recording): the EEG is the recording's held-out \
             epochs",
        ),
        C::OwnDecoder => own_decoder(),
        C::Streamed => streamed(path),
    }
}

/// The refusal of `claim`, set by an input named as `n` names it, on the
/// own EEG `recording` of the scenario at `path`.
fn input_refusal(n: &Names, path: &Path, recording: &str, claim: Claim<'_>) -> SimError {
    let why = format!(
        "the EEG of {} is a recording (eeg.recording = {recording:?})",
        path.display()
    );
    SimError::Scenario(match claim {
        Claim::Oracle => format!(
            "{} oracle: {why}, which only the EEG decoder reads",
            n.decoder
        ),
        Claim::EegMode(mode) => format!(
            "{} {mode}: {why}, whose held-out epochs the decoder reads; remove the [eeg] table to \
             simulate a user",
            n.eeg
        ),
        Claim::OwnDecoder => return own_decoder(),
        Claim::Streamed => return streamed(path),
        _ => format!(
            "{}: {why}: its decoder is calibrated on the recording's first part and has the \
             accuracy the recording gives (reported when it is read); no accuracy is targeted. \
             Leave out {}, or remove the [eeg] table to simulate a user",
            n.accuracy, n.accuracy
        ),
    })
}

/// A decoder of the caller's own on own EEG.
fn own_decoder() -> SimError {
    SimError::Scenario(
        "decoder: the scenario's EEG is a recording, decoded by a decoder calibrated on its \
         first part; a decoder of your own reads the synthetic user's EEG (remove the [eeg] \
         table, or fit your decoder on the recording yourself)"
            .into(),
    )
}

/// Own EEG to be streamed.
fn streamed(path: &Path) -> SimError {
    SimError::Scenario(format!(
        "{}: errp stream streams the simulated user's EEG; a scenario on a recording ([eeg] \
         recording) cannot be streamed",
        path.display()
    ))
}

/// The grid's accuracies, in words.
const GRID_ACCURACIES: &str =
    "a mean accuracy in (0.5, 1) for the EEG decoder, (0.5, 1] for the oracle";

/// Rule: a decoder is asked for a mean accuracy strictly between 0.5
/// (chance) and 1; only the grid's oracle, which flips assessments with
/// probability 1 - accuracy, may be perfect. `accuracy` was asked of the
/// decoder of a `task` scenario (`oracle`: the grid's oracle) at `origin`.
pub fn accuracy_for(
    task: TaskKind,
    oracle: bool,
    accuracy: f64,
    origin: Origin<'_>,
) -> Result<RequestedAccuracy> {
    match (RequestedAccuracy::new(accuracy), task) {
        (Ok(a @ RequestedAccuracy::Targeted(_)), _) => return Ok(a),
        (Ok(a @ RequestedAccuracy::Perfect), TaskKind::Grid) if oracle => return Ok(a),
        _ => {}
    }
    Err(match (origin, task) {
        (Origin::Input(n) | Origin::Sweep(n), _) if accuracy == 1.0 => SimError::Scenario(format!(
            "{} 1: only the grid's oracle decoder may be perfect (with {} oracle, or decoder \
                 = \"oracle\" in the scenario); the EEG decoders take a mean accuracy strictly \
                 between 0.5 and 1, e.g. 0.95",
            n.accuracy, n.decoder
        )),
        (Origin::Input(n) | Origin::Sweep(n), _) => SimError::Scenario(format!(
            "{} = {} is invalid: expected {GRID_ACCURACIES}",
            n.accuracy,
            errp_bci::shown(accuracy.to_string())
        )),
        (Origin::Scenario(path), TaskKind::Grid) => {
            field_error(path, "user.accuracy", accuracy.to_string(), GRID_ACCURACIES)
        }
        (Origin::Scenario(path), TaskKind::Epuck) => field_error(
            path,
            "user.accuracy",
            accuracy.to_string(),
            "a mean accuracy strictly between 0.5 (chance) and 1, e.g. 0.95 (the mean of the \
             decoder's two cross-validated class rates)",
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const PATH: &str = "s.toml";

    fn text(r: Result<impl std::fmt::Debug>) -> String {
        r.unwrap_err().to_string()
    }

    #[test]
    fn a_task_refuses_the_other_tasks_values_naming_the_entry() {
        let path = Path::new(PATH);
        let cli = Origin::Input(&Names::CLI);
        let e = text(task_takes(TaskKind::Grid, path, &[(TaskValue::Runs, cli)]));
        assert!(e.starts_with("--runs: applies to e-puck scenarios"), "{e}");
        let e = text(task_takes(
            TaskKind::Epuck,
            path,
            &[(TaskValue::EegMode, cli)],
        ));
        assert!(
            e.starts_with("--decoder and --eeg apply to grid scenarios"),
            "{e}"
        );
        let py = Origin::Sweep(&Names::PYTHON);
        let e = text(task_takes(
            TaskKind::Epuck,
            path,
            &[(TaskValue::EegMode, py)],
        ));
        assert!(e.starts_with("per_action= applies to the grid"), "{e}");
        // Each task takes its own, and the scenario's keys are the loader's.
        assert!(task_takes(TaskKind::Epuck, path, &[(TaskValue::Runs, cli)]).is_ok());
        let file = Origin::Scenario(path);
        assert!(task_takes(TaskKind::Grid, path, &[(TaskValue::Runs, file)]).is_ok());
    }

    #[test]
    fn own_eeg_refuses_the_first_claim_in_the_words_of_its_origin() {
        let path = Path::new(PATH);
        let own = OwnEegFrom::Scenario {
            path,
            recording: "s01.edf",
        };
        let claims = [
            (Claim::Accuracy(0.8), Origin::Input(&Names::CLI)),
            (Claim::Oracle, Origin::Input(&Names::CLI)),
        ];
        let e = text(own_eeg_is_the_user(Some(own), &claims));
        assert!(
            e.starts_with(
                "--accuracy: the EEG of s.toml is a recording (eeg.recording = \"s01.edf\")"
            ) && e.contains("Leave out --accuracy"),
            "{e}"
        );
        let e = text(own_eeg_is_the_user(
            Some(own),
            &[(Claim::Subject("S1"), Origin::Scenario(path))],
        ));
        assert!(
            e.starts_with("s.toml: field `user.subject` = \"S1\" is invalid"),
            "{e}"
        );
        let e = text(own_eeg_is_the_user(
            Some(OwnEegFrom::Swept),
            &[(Claim::Accuracy(0.8), Origin::Sweep(&Names::PYTHON))],
        ));
        assert!(
            e.starts_with("accuracy with the swept eeg.recording"),
            "{e}"
        );
        let e = text(own_eeg_is_the_user(
            Some(own),
            &[(Claim::Streamed, Origin::Input(&Names::CLI))],
        ));
        assert!(e.contains("cannot be streamed"), "{e}");
        // Without own EEG, or without a claim, nothing is refused.
        assert!(own_eeg_is_the_user(None, &claims).is_ok());
        assert!(own_eeg_is_the_user(Some(own), &[]).is_ok());
    }

    #[test]
    fn only_the_grids_oracle_may_be_perfect() {
        let path = Path::new(PATH);
        let file = Origin::Scenario(path);
        assert_eq!(
            accuracy_for(TaskKind::Grid, true, 1.0, file).unwrap(),
            RequestedAccuracy::Perfect
        );
        for (task, oracle) in [(TaskKind::Grid, false), (TaskKind::Epuck, false)] {
            assert!(accuracy_for(task, oracle, 0.9, file).is_ok());
            let e = text(accuracy_for(task, oracle, 1.0, file));
            assert!(
                e.starts_with("s.toml: field `user.accuracy` = 1 is invalid"),
                "{e}"
            );
            let e = text(accuracy_for(
                task,
                oracle,
                1.0,
                Origin::Input(&Names::PYTHON),
            ));
            assert!(
                e.starts_with(
                    "accuracy 1: only the grid's oracle decoder may be perfect (with \
                               overrides[\"decoder\"] oracle"
                ),
                "{e}"
            );
        }
        for bad in [0.5, 1.7, f64::NAN] {
            assert!(accuracy_for(TaskKind::Grid, true, bad, file).is_err());
        }
    }
}
