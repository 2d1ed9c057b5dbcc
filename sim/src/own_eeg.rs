//! A person's own EEG as a scenario's EEG: the `[eeg]` table that
//! names it, checked when the scenario loads, and the file's loading when
//! the decoder is prepared (a regular file within [`MAX_OWN_EEG_BYTES`],
//! hashed as it is read, checked as EDF or BDF and matched to the montage).
//!
//! Loading a scenario never opens the EEG file: a recording's stored
//! scenario is read back (`errp inspect`, a sweep's finished scenario) far
//! from the file it names.

use std::io::{self, BufReader, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use errp_bci::{CalibrationPart, EdfFile, EventNames, OwnEeg};
use serde::{Deserialize, Serialize};

use crate::error::{Result, SimError};
pub use crate::files::FileDigest;
use crate::files::{Hashing, open_regular};
use crate::rules::OwnEegFrom;
use crate::scenario_file::field_error;
use crate::task_kind::TaskKind;

/// The largest own EEG file read (1 GiB).
pub const MAX_OWN_EEG_BYTES: u64 = 1 << 30;

/// The calibration part when a scenario sets none: the first half of the
/// events.
pub const DEFAULT_CALIBRATION: f64 = 0.5;

/// The false alarms a minute of the shipped e-puck user (accuracy 95 %,
/// fitted to the paper's two runs by `errp fit epuck`) at the paper's
/// T_e = 0.8 with the default detector, on its held-out session:
/// `docs/figures/epuck_mexico_default.txt` (a test reads it there). An
/// e-puck hybrid's T_e is set to give this rate unless its `[eeg]` table
/// says `false_alarms_per_min`.
pub const FITTED_FALSE_ALARMS_PER_MIN: f64 = 5.37;

/// The largest false-alarm rate an e-puck hybrid's T_e may be set for.
pub const MAX_FALSE_ALARMS_PER_MIN: f64 = 60.0;

/// How the closed loop draws held-out epochs of a class.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BankDraw {
    /// Any epoch of the class, each time (the default; epochs repeat).
    #[default]
    WithReplacement,
    /// Each epoch of the class once before any repeats.
    WithoutReplacement,
}

/// The `[eeg]` table of a scenario, as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct OwnEegFields {
    recording: String,
    #[serde(default)]
    calibration: Option<f64>,
    #[serde(default)]
    calibration_events: Option<f64>,
    #[serde(default)]
    error: Option<String>,
    #[serde(default)]
    correct: Option<String>,
    #[serde(default)]
    draw: Option<BankDraw>,
    #[serde(default)]
    false_alarms_per_min: Option<f64>,
}

/// The `[eeg]` table of an e-puck scenario: a table naming an EEG file
/// (a grid's `eeg` may also be a mode).
#[derive(Debug, Clone)]
pub(crate) struct OwnEegTable(pub(crate) OwnEegFields);

impl<'de> Deserialize<'de> for OwnEegTable {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = OwnEegTable;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a table naming a recording ([eeg] recording = \"s01.edf\")")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                map: A,
            ) -> std::result::Result<OwnEegTable, A::Error> {
                OwnEegFields::deserialize(serde::de::value::MapAccessDeserializer::new(map))
                    .map(OwnEegTable)
            }
        }
        d.deserialize_map(Visitor)
    }
}

/// A scenario's own EEG, checked (the file itself is read when the
/// decoder is prepared).
#[derive(Debug, Clone, PartialEq)]
pub struct OwnEegSpec {
    /// The path as the scenario writes it.
    pub written: String,
    /// The path, relative ones resolved against the scenario's directory.
    pub file: PathBuf,
    /// How much of the EEG calibrates the decoder.
    pub part: CalibrationPart,
    /// The annotations that mark each class.
    pub names: EventNames,
    /// How held-out epochs are drawn (the grid).
    pub draw: BankDraw,
    /// The false alarms a minute the hybrid's T_e is set for (the e-puck;
    /// none: [`FITTED_FALSE_ALARMS_PER_MIN`]).
    pub false_alarms_per_min: Option<f64>,
    /// The EEG itself, when it was given in memory (Python's MNE
    /// objects) rather than as a file: used in place of reading `file`.
    pub supplied: Option<Arc<SuppliedOwnEeg>>,
}

/// Own EEG given in memory, with what identifies it.
#[derive(Debug)]
pub struct SuppliedOwnEeg {
    /// The EEG, matched to the montage.
    pub eeg: OwnEeg,
    /// Its name, size and SHA-256 (of the file it was read from, or of the
    /// data as given).
    pub digest: FileDigest,
}

/// Two own EEGs are the same if their digests are.
impl PartialEq for SuppliedOwnEeg {
    fn eq(&self, other: &Self) -> bool {
        self.digest == other.digest
    }
}

impl OwnEegSpec {
    /// Where it came from, for the rules ([`crate::rules`]): the scenario
    /// at `scenario` (of `task`) names it, or it was given in memory.
    pub fn origin<'a>(&'a self, scenario: &'a Path, task: TaskKind) -> OwnEegFrom<'a> {
        match self.supplied {
            Some(_) => OwnEegFrom::Supplied(task),
            None => OwnEegFrom::Scenario {
                path: scenario,
                recording: &self.written,
            },
        }
    }

    /// The own EEG `supplied` in memory, split and drawn as `options` (an
    /// `[eeg]` table's keys but `recording`) say; errors name the field
    /// (`eeg.calibration`) of `who`.
    pub fn supplied(
        options: &toml::Table,
        supplied: SuppliedOwnEeg,
        who: &Path,
        task: TaskKind,
    ) -> Result<Self> {
        if options.contains_key("recording") {
            return Err(field_error(
                who,
                "eeg.recording",
                "set".into(),
                "nothing: the recording is the one given",
            ));
        }
        let mut table = options.clone();
        table.insert(
            "recording".into(),
            toml::Value::String(supplied.digest.name.clone()),
        );
        let file: OwnEegFields = table
            .try_into()
            .map_err(|e| SimError::Scenario(format!("{}: eeg: {e}", who.display())))?;
        let mut eeg = file.check(who, task)?;
        eeg.file = PathBuf::from(&supplied.digest.name);
        eeg.supplied = Some(Arc::new(supplied));
        Ok(eeg)
    }
}

impl OwnEegFields {
    /// Checks the table of the scenario at `scenario`; errors name the
    /// field (`eeg.calibration`).
    pub(crate) fn check(self, scenario: &Path, task: TaskKind) -> Result<OwnEegSpec> {
        let bad = |field: &str, value: String, expected: &str| {
            field_error(scenario, &format!("eeg.{field}"), value, expected)
        };
        self.check_task_keys(scenario, task)?;
        if self.recording.trim().is_empty() {
            return Err(bad(
                "recording",
                format!("{:?}", self.recording),
                "the path of an EDF or BDF file, relative to the scenario's directory",
            ));
        }
        let part = match (self.calibration, self.calibration_events) {
            (Some(_), Some(_)) => {
                return Err(bad(
                    "calibration_events",
                    "set with eeg.calibration".into(),
                    "one of eeg.calibration (a fraction of the events) and \
                     eeg.calibration_events (a count)",
                ));
            }
            (Some(f), None) if f > 0.0 && f < 1.0 => CalibrationPart::Fraction(f),
            (Some(f), None) => {
                return Err(bad(
                    "calibration",
                    f.to_string(),
                    "a fraction of the events strictly between 0 and 1, e.g. 0.5",
                ));
            }
            (None, Some(n)) if n.fract() == 0.0 && (1.0..=1e6).contains(&n) => {
                CalibrationPart::Events(n as usize)
            }
            (None, Some(n)) => {
                return Err(bad(
                    "calibration_events",
                    n.to_string(),
                    "a whole number of events from 1 to 1000000",
                ));
            }
            (None, None) => CalibrationPart::Fraction(DEFAULT_CALIBRATION),
        };
        let defaults = EventNames::default();
        let names = EventNames {
            error: self.error.unwrap_or(defaults.error),
            correct: self.correct.unwrap_or(defaults.correct),
        };
        for (field, name) in [("error", &names.error), ("correct", &names.correct)] {
            if name.trim().is_empty() || name.len() > 256 {
                return Err(bad(
                    field,
                    format!("{name:?}"),
                    "the annotation text of the class, 1 to 256 bytes",
                ));
            }
        }
        if names
            .error
            .trim()
            .eq_ignore_ascii_case(names.correct.trim())
        {
            return Err(bad(
                "correct",
                format!("{:?}", names.correct),
                "an annotation text other than eeg.error's",
            ));
        }
        let written = self.recording;
        let file = match scenario.parent() {
            Some(dir) if Path::new(&written).is_relative() => dir.join(&written),
            _ => PathBuf::from(&written),
        };
        Ok(OwnEegSpec {
            written,
            file,
            part,
            names,
            draw: self.draw.unwrap_or_default(),
            false_alarms_per_min: self.false_alarms_per_min,
            supplied: None,
        })
    }

    /// Refuses the other task's key: the grid's `draw`, the e-puck's
    /// `false_alarms_per_min`; checks the latter's range.
    fn check_task_keys(&self, scenario: &Path, task: TaskKind) -> Result<()> {
        let bad = |field: &str, value: String, expected: &str| {
            field_error(scenario, &format!("eeg.{field}"), value, expected)
        };
        match (task, self.draw, self.false_alarms_per_min) {
            (TaskKind::Epuck, Some(d), _) => {
                return Err(bad(
                    "draw",
                    match d {
                        BankDraw::WithReplacement => "\"with_replacement\"".into(),
                        BankDraw::WithoutReplacement => "\"without_replacement\"".into(),
                    },
                    "nothing in an e-puck scenario: its ErrPs are the subject's response added \
                     to the recording's background, not drawn epochs",
                ));
            }
            (TaskKind::Grid, _, Some(f)) => {
                return Err(bad(
                    "false_alarms_per_min",
                    f.to_string(),
                    "nothing in a grid scenario: its decoder reads one epoch per action, with \
                     no threshold to set (the e-puck's T_e)",
                ));
            }
            (_, _, Some(f)) if !(f > 0.0 && f <= MAX_FALSE_ALARMS_PER_MIN) => {
                return Err(bad(
                    "false_alarms_per_min",
                    f.to_string(),
                    &format!(
                        "false alarms a minute in (0, {}] (default {}, the paper-fitted user's)",
                        MAX_FALSE_ALARMS_PER_MIN, FITTED_FALSE_ALARMS_PER_MIN
                    ),
                ));
            }
            _ => {}
        }
        Ok(())
    }
}

/// What a report says of `merged` events annotated twice: nothing when
/// there are none.
pub(crate) fn twice(merged: usize) -> String {
    match merged {
        0 => String::new(),
        n => format!(
            "; {n} event{} annotated twice (the same class at the same sample), each kept once",
            if n == 1 { "" } else { "s" }
        ),
    }
}

/// Reads the EEG file `eeg` names, at the decoder's `sfreq_hz`: opened as
/// a regular file (never waiting on a FIFO or a device), at most
/// [`MAX_OWN_EEG_BYTES`], read as EDF or BDF, every byte hashed, and
/// matched to the montage. Errors name the file.
pub fn load_own_eeg(eeg: &OwnEegSpec, sfreq_hz: f64) -> Result<(OwnEeg, FileDigest)> {
    if let Some(s) = &eeg.supplied {
        if s.eeg.sfreq_hz != sfreq_hz {
            return Err(SimError::Scenario(format!(
                "{}: sampled at {} Hz; the decoder reads {sfreq_hz} Hz (resample it first)",
                s.digest.name, s.eeg.sfreq_hz
            )));
        }
        return Ok((s.eeg.clone(), s.digest.clone()));
    }
    let path = &eeg.file;
    let input = |source| SimError::Input {
        path: path.clone(),
        source,
    };
    let file = open_regular(path).map_err(input)?;
    let len = file.metadata().map_err(input)?.len();
    if len > MAX_OWN_EEG_BYTES {
        return Err(SimError::Scenario(format!(
            "{}: {len} bytes; a recording may have at most {MAX_OWN_EEG_BYTES} bytes (1 GiB)",
            path.display()
        )));
    }
    let named = |e: errp_bci::BciError| SimError::Scenario(format!("{}: {e}", path.display()));
    let mut reader = Hashing::new(BufReader::new(file.take(MAX_OWN_EEG_BYTES)));
    let edf = EdfFile::read(&mut reader, Some(len)).map_err(named)?;
    // What the records did not cover (nothing, in a well-formed file) is
    // part of the file all the same.
    io::copy(&mut reader, &mut io::sink()).map_err(input)?;
    let recording = OwnEeg::from_edf(&edf, &eeg.names, sfreq_hz).map_err(named)?;
    let digest = reader.digest(&eeg.written);
    Ok((recording, digest))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checked(text: &str) -> Result<OwnEegSpec> {
        let f: OwnEegFields = toml::from_str(text).expect("a table");
        f.check(Path::new("scenarios/s.toml"), TaskKind::Grid)
    }

    #[test]
    fn the_table_is_checked_naming_its_fields() {
        let r = checked("recording = \"s01.edf\"").unwrap();
        assert_eq!(r.file, Path::new("scenarios/s01.edf"));
        assert_eq!(r.part, CalibrationPart::Fraction(0.5));
        assert_eq!(
            (r.names, r.draw),
            (EventNames::default(), BankDraw::WithReplacement)
        );
        let r = checked("recording = \"/data/s01.bdf\"\ncalibration_events = 120\ndraw = \"without_replacement\"\nerror = \"S 96\"").unwrap();
        assert_eq!(r.file, Path::new("/data/s01.bdf"));
        assert_eq!(r.part, CalibrationPart::Events(120));
        assert_eq!(
            (r.names.error.as_str(), r.draw),
            ("S 96", BankDraw::WithoutReplacement)
        );
        for (text, field) in [
            ("recording = \"\"", "eeg.recording"),
            ("recording = \"a\"\ncalibration = 1.0", "eeg.calibration"),
            (
                "recording = \"a\"\ncalibration_events = 2.5",
                "eeg.calibration_events",
            ),
            (
                "recording = \"a\"\ncalibration = 0.5\ncalibration_events = 9",
                "eeg.calibration_events",
            ),
            ("recording = \"a\"\ncorrect = \"ERROR\"", "eeg.correct"),
        ] {
            let e = checked(text).unwrap_err().to_string();
            assert!(
                e.starts_with("scenarios/s.toml: field `") && e.contains(field),
                "{e}"
            );
        }
    }

    #[test]
    fn a_file_is_hashed_whole_and_refused_naming_it() {
        let dir = std::env::temp_dir().join(format!("errp-recorded-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let eeg = |name: &str| OwnEegSpec {
            false_alarms_per_min: None,
            written: name.into(),
            file: dir.join(name),
            part: CalibrationPart::Fraction(0.5),
            names: EventNames::default(),
            draw: BankDraw::WithReplacement,
            supplied: None,
        };
        std::fs::write(dir.join("text.edf"), "not EEG at all").unwrap();
        let e = load_own_eeg(&eeg("text.edf"), 256.0)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("text.edf") && e.contains("not an EDF or BDF file"),
            "{e}"
        );
        let e = load_own_eeg(&eeg("missing.edf"), 256.0)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("cannot read") && e.contains("missing.edf"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
