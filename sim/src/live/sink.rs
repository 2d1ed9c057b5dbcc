//! Where a live session's runs go as they end: the front end's observer
//! and the session's recording (`errp stream --save`).

use errp_bci::SFREQ_HZ;

use crate::epuck::EpuckObserver;
use crate::error::{Result, SimError};
use crate::live::LiveObserver;
use crate::live::runs::{EpuckLiveRun, GridLiveRun};

/// Where a live loop's runs go: the front end's observer and the
/// recording.
pub(crate) struct Sink<'a> {
    observer: &'a mut dyn LiveObserver,
    recording: Option<&'a mut recording::File>,
}

impl<'a> Sink<'a> {
    /// Runs to `observer` and into `recording`.
    pub(crate) fn new(
        observer: &'a mut dyn LiveObserver,
        recording: Option<&'a mut recording::File>,
    ) -> Self {
        Self {
            observer,
            recording,
        }
    }

    /// A line about the session.
    pub(crate) fn note(&mut self, text: &str) {
        self.observer.note(text);
    }

    /// The front end's observer (for what a run shows offline too: the
    /// calibration's steps).
    pub(crate) fn observer(&self) -> &dyn LiveObserver {
        &*self.observer
    }

    /// Grid run `k` ended.
    pub(crate) fn grid_run(&mut self, k: usize, run: &GridLiveRun) -> Result<()> {
        self.observer.grid_run(k, run);
        match &mut self.recording {
            Some(r) => recording::grid_run(r, k, run),
            None => Ok(()),
        }
    }

    /// E-puck run `k` ended.
    pub(crate) fn epuck_run(&mut self, k: usize, run: &EpuckLiveRun) -> Result<()> {
        self.observer.epuck_run(k, run);
        match &mut self.recording {
            Some(r) => recording::epuck_run(r, k, run),
            None => Ok(()),
        }
    }

    /// What watches e-puck run `k` (seed `seed`) step by step: the
    /// recording, if any.
    pub(crate) fn watch(&mut self, k: usize, seed: u64) -> Option<&mut dyn EpuckObserver> {
        recording::watch(self.recording.as_deref_mut()?, k, seed)
    }
}

/// The session's recording: each run through the task's own recorder,
/// and the decisions as received ([`crate::live::save`]).
#[cfg(feature = "rerun")]
pub(crate) mod recording {
    use std::path::{Path, PathBuf};

    use crate::epuck::EpuckObserver;
    use crate::error::Result;
    use crate::live::runs::{EpuckLiveRun, GridLiveRun};
    use crate::live::save::LiveRecording;
    use crate::pace::Speed;
    use crate::record::data::{LiveProvenance, Provenance};
    use crate::runner::RunProvenance;
    use crate::scenario::AnyScenario;

    pub(crate) type File = LiveRecording;

    /// The recording at `path` of `scenario` (run as `text`) made as
    /// `made_by` says, live at `speed` with decisions from `decoder`
    /// (`name=errp-decoder`), made now.
    pub(crate) fn open(
        path: &Path,
        (scenario, text): (&AnyScenario, &str),
        made_by: &RunProvenance,
        (speed, decoder): (Speed, &str),
    ) -> Result<File> {
        let (name, seed) = match scenario {
            AnyScenario::Grid(s) => (&s.name, s.seed),
            AnyScenario::Epuck(s) => (&s.name, s.seed),
        };
        let mut p = Provenance::new(scenario.kind(), name, text.to_string(), seed);
        p.command.clone_from(&made_by.command);
        if let Some(commit) = &made_by.commit {
            p.commit.clone_from(commit);
        }
        let live = LiveProvenance {
            speed,
            decoder: decoder.to_string(),
        };
        p.decoder_summary = format!(
            "decoder: outside the process, over Lab Streaming Layer ({}), live at speed {}\n",
            live.decoder, live.speed
        );
        match scenario {
            AnyScenario::Grid(s) => LiveRecording::grid(path, s, p, live),
            AnyScenario::Epuck(s) => LiveRecording::epuck(path, s, p, live),
        }
    }

    pub(super) fn grid_run(file: &mut File, k: usize, run: &GridLiveRun) -> Result<()> {
        file.grid_run(k, run)
    }

    pub(super) fn epuck_run(file: &mut File, k: usize, run: &EpuckLiveRun) -> Result<()> {
        file.epuck_run(k, run)
    }

    pub(super) fn watch(file: &mut File, k: usize, seed: u64) -> Option<&mut dyn EpuckObserver> {
        file.epuck_watch(k, seed)
    }

    /// Moves the file into place.
    pub(crate) fn finish(file: File) -> Result<PathBuf> {
        file.finish()
    }
}

/// Without the `rerun` feature nothing records: asking to is an error.
#[cfg(not(feature = "rerun"))]
pub(crate) mod recording {
    use std::path::{Path, PathBuf};

    use crate::epuck::EpuckObserver;
    use crate::error::{Result, SimError};
    use crate::live::runs::{EpuckLiveRun, GridLiveRun};
    use crate::pace::Speed;
    use crate::runner::RunProvenance;
    use crate::scenario::AnyScenario;

    /// No file is ever open.
    pub(crate) enum File {}

    pub(crate) fn open(
        path: &Path,
        _scenario: (&AnyScenario, &str),
        _made_by: &RunProvenance,
        _live: (Speed, &str),
    ) -> Result<File> {
        Err(SimError::NoRecorder {
            path: path.to_path_buf(),
        })
    }

    pub(super) fn grid_run(file: &mut File, _k: usize, _run: &GridLiveRun) -> Result<()> {
        match *file {}
    }

    pub(super) fn epuck_run(file: &mut File, _k: usize, _run: &EpuckLiveRun) -> Result<()> {
        match *file {}
    }

    pub(super) fn watch(file: &mut File, _k: usize, _seed: u64) -> Option<&mut dyn EpuckObserver> {
        match *file {}
    }

    pub(crate) fn finish(file: File) -> Result<PathBuf> {
        match file {}
    }
}

/// The error of a generator whose rate is not the contract's.
pub(crate) fn check_rate(fs_hz: f64) -> Result<()> {
    if fs_hz != SFREQ_HZ {
        return Err(SimError::Live(format!(
            "the EEG is sampled at {fs_hz} Hz, not the {SFREQ_HZ} Hz the stream announces"
        )));
    }
    Ok(())
}
