//! The e-puck live: the button-locked calibration, then the scenario's
//! runs, the user's raw EEG streamed on the wall clock and the windows'
//! p(error) taken from a decoder outside the process.
//!
//! The calibration is the paper's protocol (sec. 5.1) for the scenario's
//! user: 70 erroneous then 70 correct robot actions, 1 to 2 s apart, each
//! marked at the button press (the example window: 800 ms from the press)
//! with its label. In the control phase the markers say when a run starts
//! and ends and when the robot's movement phase changes (turning, driving,
//! stopped); the user's ErrPs are never marked. The decoder sends p(error)
//! of its windows, each named by its last sample's timestamp; the
//! detector reads them at the scenario's `control.t_e`
//! ([`crate::live::WindowTracker`] says which apply).

use errp_bci::rng::derive_seed;
use errp_bci::{ContinuousCalibrationParams, EegGenerator, Protocol, continuous_schedule};

use crate::epuck::{
    ContinuousDecoder, EpuckEpisodeResult, EpuckScenario, LiveWindow, PHASE_NAMES, epuck_run_seed,
    prepare_continuous_decoder_with, run_epuck_episode_live,
};
use crate::error::{Result, SimError};
use crate::live::contract::{Marker, State};
use crate::live::sink::{Sink, check_rate};
use crate::live::streamer::{
    CalibrationMark, begin_control, end_session, stream_calibration, wait_for_decoder,
};
use crate::live::{EpuckLiveRun, LiveLink, LiveObserver, LiveOptions, Streamer, WindowTracker};

/// Prepares the decoder of `scenario` (the simulated user's EEG model at
/// the scenario's accuracy), each step of its calibration shown to
/// `observer`.
pub fn prepare_live_epuck(
    scenario: &EpuckScenario,
    observer: &dyn LiveObserver,
) -> Result<ContinuousDecoder> {
    let decoder = prepare_continuous_decoder_with(
        scenario,
        |step| observer.targeting(step),
        |step| observer.online_step(step),
    )?;
    Ok(decoder.0)
}

/// Runs the first `runs` runs of `scenario` live on `link`, after the
/// calibration session; `decoder` names the decoder's stream in messages.
pub(crate) fn run_epuck_live(
    scenario: &EpuckScenario,
    link: &mut dyn LiveLink,
    options: LiveOptions,
    runs: usize,
    decoder: &str,
    sink: &mut Sink<'_>,
) -> Result<Vec<EpuckLiveRun>> {
    sink.note("calibrating the simulated user at the scenario's accuracy");
    let prepared = prepare_live_epuck(scenario, sink.observer())?;
    let mut protocol = crate::epuck::run::continuous_request(scenario)?
        .setup
        .calibration
        .clone();
    if let Some(n) = options.calibration_actions {
        protocol.per_class = n / 2;
    }
    let fs = prepared.generator.sfreq_hz;
    check_rate(fs)?;
    let seed = scenario.user_seed;
    sink.note(&format!(
        "waiting up to {} s for a program to read the EEG",
        options.timeout_secs
    ));
    link.wait_for_readers(options.timeout_secs)?;
    let mut s = Streamer::new(
        link,
        fs,
        options.speed,
        WindowTracker::new(decoder, options.timeout_secs),
    );

    stream_epuck_calibration(&mut s, &prepared, &protocol, seed, sink)?;

    let mut rest = EegGenerator::new(
        &prepared.closed_loop,
        &prepared.montage,
        derive_seed(seed, "live/rest", 0),
    )?;
    wait_for_decoder(&mut s, &mut rest, options, decoder, sink)?;
    begin_control(&mut s, runs)?;

    let mut out = Vec::with_capacity(runs);
    for k in 0..runs {
        let run = live_run(&mut s, scenario, &prepared, k, sink)?;
        sink.epuck_run(k, &run)?;
        out.push(run);
    }
    end_session(&mut s, &mut rest)?;
    Ok(out)
}

/// Streams the button-locked calibration of `protocol` for the user of
/// `prepared` (seed `seed`), labelled at each press.
fn stream_epuck_calibration(
    s: &mut Streamer<'_, WindowTracker>,
    prepared: &ContinuousDecoder,
    protocol: &ContinuousCalibrationParams,
    seed: u64,
    sink: &mut Sink<'_>,
) -> Result<()> {
    let (actions, presses) = continuous_schedule(protocol, seed);
    let secs = protocol.duration_secs() - protocol.eog_session_secs;
    let speed = s.pace().speed();
    sink.note(&format!(
        "calibration: {} examples, {secs:.0} s of EEG ({:.0} s at speed {})",
        actions.len(),
        speed.to_link(secs),
        speed
    ));
    let mut eeg = EegGenerator::new(
        &prepared.generator,
        &prepared.montage,
        derive_seed(seed, "live/calibration", 0),
    )?;
    stream_calibration(s, &mut eeg, &actions, CalibrationMark::Example, |i| {
        presses[i] - actions[i].onset_secs
    })
}

/// Run `k` of `scenario` live on `s`, with the decoder `prepared` (its
/// detection spans and the user's EEG model), watched as `observer` asks.
fn live_run(
    s: &mut Streamer<'_, WindowTracker>,
    scenario: &EpuckScenario,
    prepared: &ContinuousDecoder,
    k: usize,
    sink: &mut Sink<'_>,
) -> Result<EpuckLiveRun> {
    let names = scenario.layout.goals();
    let goal = scenario.episode.goal;
    s.marker(&Marker::EpuckRunStart {
        run: k,
        goal: &names[goal].name,
    })?;
    let mut decisions = Vec::new();
    let mut phase = None;
    let mut decide = |w: &LiveWindow<'_>| -> Result<Vec<f64>> {
        if let Some(warm_up) = w.warm_up {
            s.tracker.warm_up_began();
            s.stream(warm_up)?;
            let origin = s.now_stamp();
            s.tracker.run_began(origin);
        }
        if phase != Some(w.phase) {
            phase = Some(w.phase);
            let stamp = s.now_stamp();
            s.tracker.phase_began(stamp);
            s.marker(&Marker::Phase {
                run: k,
                phase: PHASE_NAMES[w.phase],
                target: &names[w.target].name,
            })?;
        }
        let p = &w.tracked;
        s.state(&State::Epuck {
            run: k,
            time: w.time_secs,
            pose: [p.x_m, p.y_m, p.heading_rad],
            target: w.target,
            goal,
            belief: w.belief,
        })?;
        s.stream(w.raw)?;
        let got = s.tracker.take();
        decisions.push(got.clone());
        Ok(got)
    };
    let seed = epuck_run_seed(scenario.seed, k);
    let mut watch = sink.watch(k, seed);
    let result = run_epuck_episode_live(scenario, prepared, seed, &mut decide, &mut watch)?;
    s.marker(&Marker::EpuckRunEnd {
        run: k,
        reached: result.reached(),
        committed: result.committed.map(|j| names[j].name.as_str()),
        time: result.time_secs,
    })?;
    Ok(EpuckLiveRun {
        result,
        stats: s.tracker.take_run(),
        decisions,
    })
}

/// The first runs of `scenario` again, offline, with the decoder
/// [`prepare_live_epuck`] gives and each window's p(error)s as `decisions`
/// says (per run, per window, as a live session applied them): the same
/// runs, for a recorded session's table.
pub fn replay_epuck(
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    decisions: &[Vec<Vec<f64>>],
) -> Result<Vec<EpuckEpisodeResult>> {
    let mut out = Vec::with_capacity(decisions.len());
    for (k, run) in decisions.iter().enumerate() {
        let mut next = run.iter();
        let mut decide = |_: &LiveWindow<'_>| -> Result<Vec<f64>> {
            next.next().cloned().ok_or_else(|| {
                SimError::Scenario(format!(
                    "run {k}: the replay needs more windows than the {} recorded",
                    run.len()
                ))
            })
        };
        out.push(run_epuck_episode_live(
            scenario,
            decoder,
            epuck_run_seed(scenario.seed, k),
            &mut decide,
            &mut (),
        )?);
    }
    Ok(out)
}
