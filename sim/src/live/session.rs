//! A live session from a loaded scenario, the way [`crate::run_scenario`]
//! runs one offline: the rules checked, the recording created before any
//! work, the task's live loop over a [`LiveLink`], each run shown to the
//! front end's observer and recorded. `errp stream` opens the link between
//! [`LiveSession::new`] and [`LiveSession::run`], from
//! [`LiveSession::header`].

use std::path::{Path, PathBuf};

use errp_bci::SFREQ_HZ;

use crate::error::Result;
use crate::input::LoadedScenario;
use crate::live::contract::EegHeader;
use crate::live::epuck::run_epuck_live;
use crate::live::grid::run_grid_live;
use crate::live::sink::{Sink, recording};
use crate::live::{LiveLink, LiveObserver, LiveOptions, LiveRunStats};
use crate::names::Names;
use crate::rules::{self, Claim, Origin};
use crate::runner::RunProvenance;
use crate::scenario::AnyScenario;
use crate::task_kind::TaskKind;

/// What a front end asks of a live session.
#[derive(Debug, Clone, Copy)]
pub struct LiveRequest<'a> {
    /// The pace, the waits and the calibration's length.
    pub options: LiveOptions,
    /// The runs to stream: the grid scenario's first N, or N runs of the
    /// e-puck's; none for the scenario's.
    pub runs: Option<u64>,
    /// The decoder's stream, as the link looks for it (`name=errp-decoder`):
    /// the recording says it, messages name it by its value.
    pub decoder: &'a str,
    /// The `.rrd` to record the session into (created before any work).
    pub save: Option<&'a Path>,
    /// How the recording says it was made.
    pub provenance: &'a RunProvenance,
    /// How the front end names its inputs in errors.
    pub names: &'a Names,
}

/// A live session ready to run.
pub struct LiveSession {
    scenario: AnyScenario,
    runs: usize,
    options: LiveOptions,
    /// The decoder's stream, as messages name it.
    decoder: String,
    recording: Option<recording::File>,
}

/// What a live session did.
#[derive(Debug, Clone)]
pub struct LiveOutcome {
    /// The task.
    pub task: TaskKind,
    /// Whether each run reached its goal.
    pub reached: Vec<bool>,
    /// Each run's decisions and their timing.
    pub stats: Vec<LiveRunStats>,
    /// The recording written, if asked for.
    pub recording: Option<PathBuf>,
}

impl LiveSession {
    /// The session of `loaded` as `request` asks: refused if the
    /// scenario's EEG is a person's own (the session streams the simulated
    /// user's), its recording created now so that an unwritable path
    /// fails first.
    pub fn new(loaded: LoadedScenario, request: LiveRequest<'_>) -> Result<Self> {
        let LoadedScenario { scenario, text } = loaded;
        let own = match &scenario {
            AnyScenario::Grid(s) => s
                .accuracy
                .own_eeg()
                .map(|e| e.origin(&s.path, TaskKind::Grid)),
            AnyScenario::Epuck(s) => {
                (s.own_eeg.as_deref()).map(|e| e.origin(&s.path, TaskKind::Epuck))
            }
        };
        rules::own_eeg_is_the_user(own, &[(Claim::Streamed, Origin::Input(request.names))])?;
        // The grid streams its first runs; the e-puck any number, each
        // seeded as `errp run` seeds it.
        let runs = match (&scenario, request.runs) {
            (AnyScenario::Grid(s), None) => s.episodes.len(),
            (AnyScenario::Epuck(s), None) => s.runs,
            (AnyScenario::Grid(s), Some(n)) => (n as usize).min(s.episodes.len()),
            (AnyScenario::Epuck(_), Some(n)) => n as usize,
        };
        let recording = request
            .save
            .map(|path| {
                let live = (request.options.speed, request.decoder);
                recording::open(path, (&scenario, &text), request.provenance, live)
            })
            .transpose()?;
        let decoder = request
            .decoder
            .split_once('=')
            .map_or(request.decoder, |(_, v)| v);
        Ok(Self {
            scenario,
            runs,
            options: request.options,
            decoder: decoder.to_string(),
            recording,
        })
    }

    /// The task.
    pub fn task(&self) -> TaskKind {
        self.scenario.kind()
    }

    /// What the EEG stream says of itself: the true rate, the speed, the
    /// scenario's seed and the task.
    pub fn header(&self) -> EegHeader {
        let seed = match &self.scenario {
            AnyScenario::Grid(s) => s.seed,
            AnyScenario::Epuck(s) => s.seed,
        };
        EegHeader {
            fs_hz: SFREQ_HZ,
            speed: self.options.speed,
            seed,
            task: self.task(),
            session: self.options.session,
        }
    }

    /// Runs the session on `link`: the calibration, then the runs, each
    /// shown to `observer` and recorded; the recording is moved into
    /// place at the end.
    pub fn run(
        mut self,
        link: &mut dyn LiveLink,
        observer: &mut dyn LiveObserver,
    ) -> Result<LiveOutcome> {
        let task = self.task();
        let mut sink = Sink::new(observer, self.recording.as_mut());
        let (reached, stats): (Vec<bool>, Vec<LiveRunStats>) = match &self.scenario {
            AnyScenario::Grid(s) => {
                run_grid_live(s, link, self.options, self.runs, &self.decoder, &mut sink)?
                    .into_iter()
                    .map(|r| (r.result.reached(), r.stats))
                    .unzip()
            }
            AnyScenario::Epuck(s) => {
                run_epuck_live(s, link, self.options, self.runs, &self.decoder, &mut sink)?
                    .into_iter()
                    .map(|r| (r.result.reached(), r.stats))
                    .unzip()
            }
        };
        let recording = self.recording.take().map(recording::finish).transpose()?;
        Ok(LiveOutcome {
            task,
            reached,
            stats,
            recording,
        })
    }
}
