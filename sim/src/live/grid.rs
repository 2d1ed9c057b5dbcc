//! The grid task live: a calibration session, then the scenario's runs,
//! the user's raw EEG streamed on the wall clock and each action decided by
//! a decoder outside the process.
//!
//! The calibration is the paper's protocol at the scenario's targeted
//! ErrP-to-noise ratio (400 actions unless told, 20 % erroneous, 3 to 3.5
//! s apart),
//! each action's label in a marker. After it the EEG goes on (rest) until
//! the decoder's stream appears. In the control phase each action's onset
//! is marked, never the user's verdict: the decoder must find it in the
//! EEG. The interval to the next action is the decoder's time; a decision
//! that comes later is not applied (the belief stays) and is counted.

use errp_bci::rng::derive_seed;
use errp_bci::{Assessment, AssessmentKind, CalibrationSetup, EegGenerator, Protocol, schedule};
use errp_robot::{Cell, Grid, GridControlParams, QTable};

use crate::error::{Result, SimError};
use crate::grid::{
    AssessmentDecoder, GridDecoding, GridEpisodeResult, GridScenario, LiveAction,
    grid_episode_seed, prepare_decoder, run_grid_episode_with,
};
use crate::live::contract::{CellXy, Marker, State};
use crate::live::sink::{Sink, check_rate};
use crate::live::streamer::{
    CalibrationMark, begin_control, end_session, stream_calibration, wait_for_decoder,
};
use crate::live::{DecisionTracker, GridLiveRun, LiveLink, LiveOptions, Streamer};

fn cell(c: Cell) -> CellXy {
    [c.x, c.y]
}

/// Runs the first `runs` episodes of `scenario` live on `link`, after the
/// calibration session; `decoder` names the decoder's stream in messages
/// ([`crate::live::LiveSession`] refused a scenario on own EEG).
pub(crate) fn run_grid_live(
    scenario: &GridScenario,
    link: &mut dyn LiveLink,
    options: LiveOptions,
    runs: usize,
    decoder: &str,
    sink: &mut Sink<'_>,
) -> Result<Vec<GridLiveRun>> {
    sink.note("calibrating the simulated user at the scenario's accuracy");
    let observer = sink.observer();
    let (prepared, report) = prepare_decoder(scenario, |step| observer.targeting(step))?;
    let (closed_loop, report) = match (&prepared, report) {
        (AssessmentDecoder::Eeg(d), Some(r)) => (d.generator.clone(), r),
        (AssessmentDecoder::EegBank(b), Some(r)) => (b.decoder.generator.clone(), r),
        _ => {
            return Err(SimError::Scenario(format!(
                "{}: errp stream needs the simulated user's EEG (decoder = \"eeg\"), not the \
                 oracle",
                scenario.path.display()
            )));
        }
    };
    let mut setup = crate::grid::run::grid_setup(scenario)?.at_ratio(report.targeting.ratio)?;
    if let Some(n) = options.calibration_actions {
        setup.calibration.n_actions = n;
    }
    let fs = setup.generator.sfreq_hz;
    check_rate(fs)?;
    let seed = scenario.seed;
    sink.note(&format!(
        "waiting up to {} s for a program to read the EEG",
        options.timeout_secs
    ));
    link.wait_for_readers(options.timeout_secs)?;
    let mut s = Streamer::new(
        link,
        fs,
        options.speed,
        DecisionTracker::new(decoder, options.timeout_secs),
    );

    stream_grid_calibration(&mut s, &setup, seed, sink)?;

    // Rest until the decoder's stream appears, from a generator of its
    // own: however long the wait, the control's EEG is the same.
    let mut rest = EegGenerator::new(
        &closed_loop,
        &setup.montage,
        derive_seed(seed, "live/rest", 0),
    )?;
    wait_for_decoder(&mut s, &mut rest, options, decoder, sink)?;
    let mut eeg = EegGenerator::new(
        &closed_loop,
        &setup.montage,
        derive_seed(seed, "live/control", 0),
    )?;
    begin_control(&mut s, runs)?;

    let table = QTable::compute(
        Grid::paper(),
        &scenario.params.control.part(GridControlParams::q),
    )?;
    let mut out = Vec::with_capacity(runs);
    for (k, &(start, goal)) in scenario.episodes.iter().take(runs).enumerate() {
        let run = live_run(
            &mut s,
            &mut eeg,
            scenario,
            &table,
            k,
            (start, goal),
            options,
        )?;
        sink.grid_run(k, &run)?;
        out.push(run);
    }
    end_session(&mut s, &mut eeg)?;
    Ok(out)
}

/// Streams the grid's calibration session of `setup` (seed `seed`), each
/// action's label in its marker.
fn stream_grid_calibration(
    s: &mut Streamer<'_, DecisionTracker>,
    setup: &CalibrationSetup,
    seed: u64,
    sink: &mut Sink<'_>,
) -> Result<()> {
    let protocol = &setup.calibration;
    let actions = schedule(protocol, seed);
    // No EOG session is streamed: the decoder regresses the EOG on the
    // calibration itself.
    let secs = protocol.duration_secs() - protocol.eog_session_secs;
    let speed = s.pace().speed();
    sink.note(&format!(
        "calibration: {} actions, {secs:.0} s of EEG ({:.0} s at speed {speed})",
        actions.len(),
        speed.to_link(secs),
    ));
    let mut eeg = EegGenerator::new(
        &setup.generator,
        &setup.montage,
        derive_seed(seed, "live/calibration", 0),
    )?;
    stream_calibration(s, &mut eeg, &actions, CalibrationMark::Action, |_| 0.0)
}

/// Run `k` of `scenario`, from `start` to `goal`, live on `s`, the EEG
/// from `eeg`.
fn live_run(
    s: &mut Streamer<'_, DecisionTracker>,
    eeg: &mut EegGenerator,
    scenario: &GridScenario,
    table: &QTable,
    k: usize,
    (start, goal): (Cell, Cell),
    options: LiveOptions,
) -> Result<GridLiveRun> {
    let fs = eeg.params().sfreq_hz;
    s.marker(&Marker::GridRunStart {
        run: k,
        start: cell(start),
        goal: cell(goal),
    })?;
    s.stream(&eeg.generate((options.rest_secs * fs).round() as usize))?;
    let mut decisions = Vec::new();
    let mut decide = |a: &LiveAction<'_>| -> Result<Option<f64>> {
        s.state(&State::Grid {
            run: k,
            cursor: cell(a.from),
            goal: cell(goal),
            belief: a.belief,
        })?;
        let onset = s.now_stamp();
        let id = s.tracker.announce(onset);
        s.marker(&Marker::Action {
            run: k,
            action: id,
            name: a.action.name(),
            from: cell(a.from),
            to: cell(a.to),
        })?;
        eeg.schedule(Assessment {
            onset_secs: eeg.now_secs(),
            kind: if a.error {
                AssessmentKind::Error
            } else {
                AssessmentKind::Correct
            },
        });
        s.stream(&eeg.generate((a.interval_secs * fs).round() as usize))?;
        let d = s.tracker.settle();
        decisions.push(d);
        Ok(d)
    };
    let result = run_grid_episode_with(
        start,
        goal,
        table,
        &scenario.params,
        GridDecoding::Live(&mut decide),
        grid_episode_seed(scenario.seed, k),
        true,
    )?;
    s.marker(&Marker::GridRunEnd {
        run: k,
        reached: result.reached(),
        committed: result.committed.map(cell),
        actions: result.actions,
    })?;
    Ok(GridLiveRun {
        result,
        stats: s.tracker.take_run(),
        decisions,
    })
}

/// The first runs of `scenario` again, offline, each action decided as
/// `decisions` says (per run, per action: p(error) or none, as a live
/// session applied them): the same episodes, for a recorded session's
/// table.
pub fn replay_grid(
    scenario: &GridScenario,
    decisions: &[Vec<Option<f64>>],
) -> Result<Vec<GridEpisodeResult>> {
    let table = QTable::compute(
        Grid::paper(),
        &scenario.params.control.part(GridControlParams::q),
    )?;
    if decisions.len() > scenario.episodes.len() {
        return Err(SimError::Scenario(format!(
            "{} runs of decisions for a scenario of {}",
            decisions.len(),
            scenario.episodes.len()
        )));
    }
    let mut out = Vec::with_capacity(decisions.len());
    for (k, run) in decisions.iter().enumerate() {
        let (start, goal) = scenario.episodes[k];
        let mut next = run.iter();
        let mut decide = |_: &LiveAction<'_>| -> Result<Option<f64>> {
            next.next().copied().ok_or_else(|| {
                SimError::Scenario(format!(
                    "run {k}: the replay needs more decisions than the {} recorded",
                    run.len()
                ))
            })
        };
        out.push(run_grid_episode_with(
            start,
            goal,
            &table,
            &scenario.params,
            GridDecoding::Live(&mut decide),
            grid_episode_seed(scenario.seed, k),
            true,
        )?);
    }
    Ok(out)
}
