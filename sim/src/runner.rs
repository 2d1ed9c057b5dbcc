//! One path from a loaded scenario to its result, for every front end
//! (`errp run`, the Python package's `errp.run`): the decoder prepared, the
//! episodes or runs, and the recording with its provenance. What a front
//! end shows along the way it sees through a [`RunObserver`]; `()` shows
//! nothing.

use std::path::{Path, PathBuf};

use errp_bci::{OnlineStep, TargetingStep};

use crate::calibration::CalibrationReport;
pub use crate::epuck::epuck_decoder_summary;
use crate::epuck::{
    ContinuousDecoder, ContinuousReport, EpuckEpisodeResult, EpuckScenario, WindowDecoder,
    prepare_continuous_decoder_with, run_epuck_runs,
};
use crate::error::SimError;
use crate::grid::{
    AssessmentDecoder, GridDecoding, GridEpisodeResult, GridRunReport, GridScenario,
    prepare_decoder, run_grid_scenario_with,
};
use crate::input::LoadedScenario;
use crate::names::Names;
use crate::scenario::AnyScenario;
use crate::task_kind::TaskKind;

/// The most e-puck runs one recording holds.
pub const MAX_RECORDED_RUNS: u64 = 100;

/// The most grid episodes one recording holds (each adds about 20 kB to
/// the file and 150 kB of memory while it is written: measured on 1000
/// episodes of `grid_fixed_goals.toml`).
pub const MAX_RECORDED_EPISODES: usize = 5_000;

/// What a front end sees of a run as it goes. Calls may come from several
/// threads (the e-puck's runs run in parallel when not recorded).
pub trait RunObserver: Sync {
    /// The run starts: its inputs are checked and its recording created.
    fn start(&self, _scenario: &AnyScenario) {}
    /// True once the front end can take no more (its output failed): the
    /// run stops before its next stage (the episodes, the recording) and
    /// records nothing.
    fn stopped(&self) -> bool {
        false
    }
    /// A step of the search for the ErrP-to-noise ratio of the accuracy.
    fn targeting(&self, _step: &TargetingStep) {}
    /// A step of the e-puck detector's calibration on a held-out session.
    fn online_step(&self, _step: &OnlineStep) {}
    /// The decoder is ready; `summary` says what its calibration found.
    fn decoder_ready(&self, _summary: &str) {}
    /// Grid episode `k` ended (in order).
    fn grid_episode(&self, _k: usize, _result: &GridEpisodeResult) {}
    /// The e-puck's `runs` start, in parallel unless recorded.
    fn epuck_runs_start(&self, _runs: u64, _parallel: bool) {}
    /// One more e-puck run ended (in no set order when in parallel).
    fn epuck_run_done(&self) {}
}

impl RunObserver for () {}

/// How a recording says it was made.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RunProvenance {
    /// The command or call, as its words.
    pub command: Vec<String>,
    /// The source commit of the program, if known.
    pub commit: Option<String>,
}

/// What [`run_scenario`] records, if anything.
#[derive(Debug, Clone, Copy)]
pub struct RunOptions<'a> {
    /// The `.rrd` file to record every episode into (created before any
    /// work, so that an unwritable path fails first).
    pub save: Option<&'a Path>,
    /// How the recording says it was made.
    pub provenance: &'a RunProvenance,
    /// How the front end names its inputs in errors.
    pub names: &'a Names,
}

/// An e-puck scenario's runs.
#[derive(Debug, Clone)]
pub struct EpuckRun {
    /// The scenario as run.
    pub scenario: EpuckScenario,
    /// The continuous decoder, calibrated.
    pub decoder: ContinuousDecoder,
    /// What its calibration found.
    pub report: ContinuousReport,
    /// One result per run, in run order.
    pub results: Vec<EpuckEpisodeResult>,
}

/// What a run of either task produced.
#[derive(Debug, Clone)]
pub enum RunOutcome {
    /// A grid scenario's episodes.
    Grid(Box<GridRunReport>),
    /// An e-puck scenario's runs.
    Epuck(Box<EpuckRun>),
}

impl RunOutcome {
    /// Its task.
    pub fn kind(&self) -> TaskKind {
        match self {
            RunOutcome::Grid(_) => TaskKind::Grid,
            RunOutcome::Epuck(_) => TaskKind::Epuck,
        }
    }
}

/// A finished run.
#[derive(Debug, Clone)]
pub struct ScenarioRun {
    /// Its results.
    pub outcome: RunOutcome,
    /// What the decoder's calibration found, as text (printed, and kept in
    /// a recording's provenance).
    pub decoder_summary: String,
    /// The recording written, if one was asked for.
    pub recording: Option<PathBuf>,
}

/// A run that failed, with what it was doing when that is worth saying
/// (`calibrating the decoder`, the save flag).
#[derive(Debug, thiserror::Error)]
#[error("{}", match context { Some(c) => format!("{c}: {error}"), None => error.to_string() })]
pub struct RunError {
    /// What the run was doing.
    pub context: Option<String>,
    /// Why it failed.
    #[source]
    pub error: SimError,
}

fn at(context: &str) -> impl FnOnce(SimError) -> RunError + '_ {
    move |error| RunError {
        context: Some(context.to_string()),
        error,
    }
}

fn plain(error: SimError) -> RunError {
    RunError {
        context: None,
        error,
    }
}

/// Runs a loaded scenario of either task: prepares its decoder on the one
/// path of every command, runs its episodes (grid) or runs (e-puck) from
/// their derived seeds, and records them with their provenance when asked.
pub fn run_scenario(
    loaded: LoadedScenario,
    options: RunOptions<'_>,
    observer: &impl RunObserver,
) -> Result<ScenarioRun, RunError> {
    let LoadedScenario { scenario, text } = loaded;
    check_recordable(&scenario, &options)?;
    let recording =
        PendingRecording::open(options.save, scenario.kind()).map_err(at(options.names.save))?;
    observer.start(&scenario);
    match scenario {
        AnyScenario::Grid(s) => run_grid(*s, recording, text, options, observer),
        AnyScenario::Epuck(s) => run_epuck(*s, recording, text, options, observer),
    }
}

/// The error of a run its observer stopped.
fn check_going(observer: &impl RunObserver) -> Result<(), RunError> {
    if observer.stopped() {
        return Err(plain(SimError::OutputFailed));
    }
    Ok(())
}

/// What `errp run` says it is about to run: the scenario, its episodes or
/// runs, its decoder and its seed.
pub struct RunHeadline<'a>(pub &'a AnyScenario);

impl std::fmt::Display for RunHeadline<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            AnyScenario::Grid(s) => {
                let decoder = match (s.accuracy.requested(), s.decoder) {
                    (Some(a), crate::grid::DecoderChoice::Eeg) => {
                        format!("EEG decoder at {:.2} % (", 100.0 * a.get())
                    }
                    (Some(a), _) => format!("oracle decoder at {:.2} % (", 100.0 * a.get()),
                    (None, _) => "EEG decoder on the ".into(),
                };
                let close = if s.accuracy.requested().is_some() {
                    ")"
                } else {
                    ""
                };
                let (name, n, user, seed) = (&s.name, s.episodes.len(), &s.user, s.seed);
                write!(
                    f,
                    "{name}: {n} episodes, {decoder}{user}{close}, seed {seed}"
                )
            }
            AnyScenario::Epuck(s) => {
                let start = &s.episode.start;
                write!(
                    f,
                    "{}: e-puck from ({:.0}, {:.0}) cm to {}, {} run(s), {}, seed {}{}",
                    s.name,
                    100.0 * start.x_m,
                    100.0 * start.y_m,
                    s.layout.goals()[s.episode.goal].name,
                    s.runs,
                    s.decoder_text(),
                    s.seed,
                    if s.user_seed == s.seed {
                        String::new()
                    } else {
                        format!(" (user seed {})", s.user_seed)
                    }
                )
            }
        }
    }
}

/// Refuses a recording too large to write.
fn check_recordable(scenario: &AnyScenario, options: &RunOptions<'_>) -> Result<(), RunError> {
    if options.save.is_none() {
        return Ok(());
    }
    match scenario {
        AnyScenario::Epuck(s) => check_recordable_runs(s.runs as u64, options.names),
        AnyScenario::Grid(s) => check_recordable_episodes(s, options.names),
    }
    .map_err(plain)
}

/// Refuses to record `runs` e-puck runs into one file: more than
/// [`MAX_RECORDED_RUNS`]. The error names the inputs as `names` says.
pub fn check_recordable_runs(runs: u64, names: &Names) -> Result<(), SimError> {
    if runs <= MAX_RECORDED_RUNS {
        return Ok(());
    }
    let save = names.save;
    Err(SimError::Scenario(format!(
        "{save} with {runs} runs: a recording holds at most {MAX_RECORDED_RUNS} runs (each adds \
         about 2.5 MB to the file and 9 MB of memory while it is written); record at most \
         {MAX_RECORDED_RUNS} ({}), or run them all without {save}",
        names.runs
    )))
}

/// Refuses to record the episodes of `scenario` into one file: more than
/// [`MAX_RECORDED_EPISODES`]. The error names the inputs as `names` says.
pub fn check_recordable_episodes(scenario: &GridScenario, names: &Names) -> Result<(), SimError> {
    let n = scenario.episodes.len();
    if n <= MAX_RECORDED_EPISODES {
        return Ok(());
    }
    let save = names.save;
    Err(SimError::Scenario(format!(
        "{save} with {n} episodes: a recording holds at most {MAX_RECORDED_EPISODES} grid \
         episodes (each adds about 20 kB to the file and 150 kB of memory while it is \
         written, so {:.1} GB here); record fewer (lower `repeats` in {}), or run them \
         all without {save}",
        n as f64 * 150e3 / 1e9,
        scenario.path.display()
    )))
}

/// What the grid decoder's calibration found, as `errp run` prints it:
/// the synthetic session's (`calibration`) or the own EEG's (nothing for
/// the oracle).
pub fn grid_decoder_summary(
    decoder: &AssessmentDecoder,
    calibration: Option<&CalibrationReport>,
) -> String {
    if let AssessmentDecoder::OwnEeg(bank) = decoder {
        return bank.report.to_string();
    }
    match calibration {
        Some(c) => format!(
            "Decoder calibrated on 400 actions: mean accuracy {:.2} % on held-out epochs (the \
             target; correct {:.2} %, error {:.2} %), {:.2} % cross-validated\n",
            100.0 * c.targeting.accuracy.mean(),
            100.0 * c.targeting.accuracy.correct,
            100.0 * c.targeting.accuracy.error,
            100.0 * c.calibrated.accuracy.mean()
        ),
        None => String::new(),
    }
}

/// A batch's recording, created before its work so that an unwritable
/// path fails first; nothing without a path.
pub struct PendingRecording {
    file: Option<recording::File>,
}

impl PendingRecording {
    /// The `.rrd` at `save` of a batch of `task`, created now (refused by
    /// a build without the `rerun` feature).
    pub fn open(save: Option<&Path>, task: TaskKind) -> Result<Self, SimError> {
        Ok(Self {
            file: recording::open(save, task)?,
        })
    }

    /// True if there is one.
    pub fn is_some(&self) -> bool {
        self.file.is_some()
    }
}

/// What a batch's recording says of how it was made, and how errors name
/// it.
#[derive(Debug, Clone, Copy)]
pub struct BatchRecord<'a> {
    /// How the front end names the recording (`--save`, `save`).
    pub flag: &'a str,
    /// The scenario's text as run.
    pub text: &'a str,
    /// What the decoder's calibration found, as text (empty if nothing).
    pub decoder_summary: &'a str,
    /// The command or call.
    pub made_by: &'a RunProvenance,
}

/// The episodes of a grid scenario decoded by `decoding` (the built-in
/// decoder, or one of the caller's own), episode `k` from
/// [`grid_episode_seed`](crate::grid::grid_episode_seed), each shown to
/// `observer`, then recorded into `recording` as `record` says unless the
/// observer stopped: the episode stage of [`run_scenario`], for callers
/// with their decoder prepared.
pub fn run_grid_batch(
    scenario: GridScenario,
    calibration: Option<CalibrationReport>,
    decoding: GridDecoding<'_>,
    recording: PendingRecording,
    record: BatchRecord<'_>,
    observer: &impl RunObserver,
) -> Result<(GridRunReport, Option<PathBuf>), RunError> {
    let recorded = match &decoding {
        GridDecoding::Builtin(AssessmentDecoder::OwnEeg(bank)) => Some(bank.report.clone()),
        _ => None,
    };
    let episodes = run_grid_scenario_with(&scenario, decoding, recording.is_some(), |k, r| {
        observer.grid_episode(k, r)
    })
    .map_err(plain)?;
    check_going(observer)?;
    let report = GridRunReport {
        scenario,
        calibration,
        own_eeg: recorded,
        episodes,
    };
    let path = recording::grid(recording.file, &report, &record).map_err(at(record.flag))?;
    Ok((report, path))
}

/// `runs` runs of an e-puck scenario with its calibrated `decoder`, or
/// `window_decoder` of the caller's own in its place, run `k` from
/// [`epuck_run_seed`](crate::epuck::epuck_run_seed), each told to
/// `observer`, recorded into `recording` as `record` says (one after
/// another) or not (in parallel with the built-in decoder): the run stage
/// of [`run_scenario`], for callers with their decoder prepared.
pub fn run_epuck_batch_recorded(
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    runs: usize,
    window_decoder: Option<WindowDecoder<'_>>,
    recording: PendingRecording,
    record: BatchRecord<'_>,
    observer: &impl RunObserver,
) -> Result<(Vec<EpuckEpisodeResult>, Option<PathBuf>), RunError> {
    let on_run = |_: usize| observer.epuck_run_done();
    match recording.file {
        Some(file) => {
            let results = recording::epuck(
                &file,
                scenario,
                decoder,
                runs,
                window_decoder,
                &record,
                &on_run,
            )
            .map_err(plain)?;
            let path = recording::finish(file).map_err(at(record.flag))?;
            Ok((results, path))
        }
        None => Ok((
            run_epuck_runs(scenario, decoder, runs, window_decoder, &mut (), &on_run)
                .map_err(plain)?,
            None,
        )),
    }
}

fn run_grid(
    scenario: GridScenario,
    recording: PendingRecording,
    text: String,
    options: RunOptions<'_>,
    observer: &impl RunObserver,
) -> Result<ScenarioRun, RunError> {
    let (decoder, calibration) = prepare_decoder(&scenario, |s| observer.targeting(s))
        .map_err(at("calibrating the decoder"))?;
    let decoder_summary = grid_decoder_summary(&decoder, calibration.as_ref());
    observer.decoder_ready(&decoder_summary);
    check_going(observer)?;
    let record = BatchRecord {
        flag: options.names.save,
        text: &text,
        decoder_summary: &decoder_summary,
        made_by: options.provenance,
    };
    let (report, recording) = run_grid_batch(
        scenario,
        calibration,
        GridDecoding::Builtin(&decoder),
        recording,
        record,
        observer,
    )?;
    Ok(ScenarioRun {
        outcome: RunOutcome::Grid(Box::new(report)),
        decoder_summary,
        recording,
    })
}

fn run_epuck(
    scenario: EpuckScenario,
    recording: PendingRecording,
    text: String,
    options: RunOptions<'_>,
    observer: &impl RunObserver,
) -> Result<ScenarioRun, RunError> {
    let (decoder, report) = prepare_continuous_decoder_with(
        &scenario,
        |s| observer.targeting(s),
        |s| observer.online_step(s),
    )
    .map_err(at("calibrating the continuous decoder"))?;
    let decoder_summary = epuck_decoder_summary(&decoder, &report);
    observer.decoder_ready(&decoder_summary);
    check_going(observer)?;
    observer.epuck_runs_start(scenario.runs as u64, !recording.is_some());
    let record = BatchRecord {
        flag: options.names.save,
        text: &text,
        decoder_summary: &decoder_summary,
        made_by: options.provenance,
    };
    let (results, recording) = run_epuck_batch_recorded(
        &scenario,
        &decoder,
        scenario.runs,
        None,
        recording,
        record,
        observer,
    )?;
    Ok(ScenarioRun {
        outcome: RunOutcome::Epuck(Box::new(EpuckRun {
            scenario,
            decoder,
            report,
            results,
        })),
        decoder_summary,
        recording,
    })
}

/// The recording, when the crate records (the `rerun` feature).
#[cfg(feature = "rerun")]
mod recording {
    use std::path::{Path, PathBuf};

    use super::BatchRecord;
    use crate::epuck::{ContinuousDecoder, EpuckEpisodeResult, EpuckScenario, WindowDecoder};
    use crate::error::Result;
    use crate::grid::GridRunReport;
    use crate::record::RrdFile;
    use crate::record::data::Provenance;
    use crate::task_kind::TaskKind;

    pub(super) type File = RrdFile;

    /// The `.rrd` at `save`, created now.
    pub(super) fn open(save: Option<&Path>, task: TaskKind) -> Result<Option<File>> {
        save.map(|p| match task {
            TaskKind::Epuck => crate::epuck::epuck_recording(p),
            TaskKind::Grid => crate::grid::grid_recording(p),
        })
        .transpose()
    }

    fn provenance(task: TaskKind, name: &str, seed: u64, of: &BatchRecord<'_>) -> Provenance {
        let mut p = Provenance::new(task, name, of.text.to_string(), seed);
        if let Some(commit) = &of.made_by.commit {
            p.commit.clone_from(commit);
        }
        p.command.clone_from(&of.made_by.command);
        p.decoder_summary = of.decoder_summary.to_string();
        p
    }

    /// Writes a grid run into `file` and finishes it.
    pub(super) fn grid(
        file: Option<File>,
        report: &GridRunReport,
        of: &BatchRecord<'_>,
    ) -> Result<Option<PathBuf>> {
        let Some(file) = file else { return Ok(None) };
        let s = &report.scenario;
        let mut p = provenance(TaskKind::Grid, &s.name, s.seed, of);
        p.own_eeg = report.own_eeg.as_ref().map(|r| r.file.clone());
        crate::grid::record_grid_run(file, report, &p).map(Some)
    }

    /// Runs and records the e-puck's runs one after another.
    pub(super) fn epuck(
        file: &File,
        scenario: &EpuckScenario,
        decoder: &ContinuousDecoder,
        runs: usize,
        window_decoder: Option<WindowDecoder<'_>>,
        of: &BatchRecord<'_>,
        on_run: &(dyn Fn(usize) + Sync),
    ) -> Result<Vec<EpuckEpisodeResult>> {
        let mut p = provenance(TaskKind::Epuck, &scenario.name, scenario.seed, of);
        p.own_eeg = decoder.own_eeg.as_ref().map(|r| r.file.clone());
        crate::epuck::record_epuck_runs_with(
            file,
            scenario,
            decoder,
            &p,
            runs,
            window_decoder,
            on_run,
        )
    }

    /// Finishes the file.
    pub(super) fn finish(file: File) -> Result<Option<PathBuf>> {
        file.finish().map(Some)
    }
}

/// Without the `rerun` feature nothing records: asking to is an error.
#[cfg(not(feature = "rerun"))]
mod recording {
    use std::path::{Path, PathBuf};

    use super::BatchRecord;
    use crate::epuck::{ContinuousDecoder, EpuckEpisodeResult, EpuckScenario, WindowDecoder};
    use crate::error::{Result, SimError};
    use crate::grid::GridRunReport;
    use crate::task_kind::TaskKind;

    /// No file is ever open.
    pub(super) enum File {}

    pub(super) fn open(save: Option<&Path>, _task: TaskKind) -> Result<Option<File>> {
        match save {
            None => Ok(None),
            Some(p) => Err(SimError::NoRecorder {
                path: p.to_path_buf(),
            }),
        }
    }

    pub(super) fn grid(
        file: Option<File>,
        _report: &GridRunReport,
        _of: &BatchRecord<'_>,
    ) -> Result<Option<PathBuf>> {
        match file {
            None => Ok(None),
            Some(f) => match f {},
        }
    }

    pub(super) fn epuck(
        file: &File,
        _scenario: &EpuckScenario,
        _decoder: &ContinuousDecoder,
        _runs: usize,
        _window_decoder: Option<WindowDecoder<'_>>,
        _of: &BatchRecord<'_>,
        _on_run: &(dyn Fn(usize) + Sync),
    ) -> Result<Vec<EpuckEpisodeResult>> {
        match *file {}
    }

    pub(super) fn finish(file: File) -> Result<Option<PathBuf>> {
        match file {}
    }
}
