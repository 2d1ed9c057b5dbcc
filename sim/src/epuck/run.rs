//! Running an e-puck scenario: calibrate the continuous decoder at the
//! scenario's accuracy, then every run of the episode, each from its own
//! derived seed (in parallel when no recording watches).

use errp_bci::{Accuracy, OnlineStep, TargetingResult, TargetingStep, Valid, rng::derive_seed};
use rayon::prelude::*;

use crate::calibration::{NoCache, TargetingCache};
use crate::epuck::decoder::{
    ContinuousDecoder, ContinuousReport, ContinuousRequest, calibrate_continuous_at,
    run_online_calibration, target_continuous,
};
use crate::epuck::episode::{EpuckEpisodeResult, run_epuck_episode, run_epuck_episode_with};
use crate::epuck::observer::EpuckObserver;
use crate::epuck::plant::WindowDecoder;
use crate::epuck::scenario::EpuckScenario;
use crate::error::Result;

/// Calibrates the scenario's continuous decoder (`progress` sees the search)
/// and measures its online operating point with the scenario's detector.
///
/// With an online target (`[user] hit_rate`), `online_progress` sees that
/// search instead, and the decoder's T_e is the one it calibrated
/// ([`ContinuousDecoder::detector_t_e`]).
pub fn prepare_continuous_decoder(
    scenario: &EpuckScenario,
    progress: impl FnMut(&TargetingStep),
) -> Result<(ContinuousDecoder, ContinuousReport)> {
    prepare_continuous_decoder_with(scenario, progress, |_| {})
}

/// [`prepare_continuous_decoder`] with a progress callback for each kind of
/// search.
pub fn prepare_continuous_decoder_with(
    scenario: &EpuckScenario,
    progress: impl FnMut(&TargetingStep),
    online_progress: impl FnMut(&OnlineStep),
) -> Result<(ContinuousDecoder, ContinuousReport)> {
    let prepared = prepare_epuck_decoder(scenario, &NoCache, progress, online_progress)?;
    Ok((prepared.decoder, prepared.report))
}

/// An e-puck decoder, ready for runs.
#[derive(Debug, Clone)]
pub struct PreparedEpuck {
    /// The decoder, with its online operating point measured.
    pub decoder: ContinuousDecoder,
    /// Its calibration.
    pub report: ContinuousReport,
    /// True if the targeting came from the cache.
    pub cached: bool,
}

/// The calibration of a scenario's continuous decoder: the paper's
/// protocol and EEG model, with the scenario's user (`[realism]`).
pub(crate) fn continuous_request(scenario: &EpuckScenario) -> Result<ContinuousRequest> {
    let base = ContinuousRequest::new(scenario.accuracy, scenario.user_seed);
    Ok(ContinuousRequest {
        setup: Valid::new(base.setup.with_realism(&scenario.realism)?)?,
        ..base
    })
}

/// Builds the scenario's continuous decoder, the one path of every e-puck
/// command. With an accuracy target: the ratio from `cache` (or searched;
/// `progress` sees the search), the calibration session at it, then the
/// operating point measured on a held-out session. With an online target
/// (`[user] hit_rate`), the search that `online_progress` sees, which
/// measures the operating point at every step and is not cached. With a
/// person's own EEG, the hybrid ([`crate::epuck::prepare_hybrid`]).
pub fn prepare_epuck_decoder(
    scenario: &EpuckScenario,
    cache: &dyn TargetingCache,
    mut progress: impl FnMut(&TargetingStep),
    online_progress: impl FnMut(&OnlineStep),
) -> Result<PreparedEpuck> {
    if let Some(eeg) = &scenario.own_eeg {
        let (decoder, report) = crate::epuck::hybrid::prepare_hybrid(scenario, eeg)?;
        return Ok(PreparedEpuck {
            decoder,
            report,
            cached: false,
        });
    }
    let request = continuous_request(scenario)?;
    match scenario.online_target {
        None => {
            let mut find = || target_continuous(&request, &mut progress);
            // A cached ratio is checked by the calibration it leads to (its
            // cross-validated accuracy is the figure the search found), which
            // is kept for use.
            let mut checked = None;
            let mut verify = |t: &TargetingResult| {
                let report = calibrate_continuous_at(&request, t.clone())?;
                let why = t.inconsistency(report.calibrated.accuracy, &request.search);
                checked = Some(report);
                Ok(why)
            };
            let (targeting, cached) = cache.get_or_search(
                "epuck-svm",
                &request.targeting_key(),
                &mut find,
                &mut verify,
            )?;
            let report = match checked.filter(|_| cached) {
                Some(report) => report,
                None => calibrate_continuous_at(&request, targeting)?,
            };
            let decoder = finish_continuous_decoder(scenario, &report)?;
            Ok(PreparedEpuck {
                decoder,
                report,
                cached,
            })
        }
        Some(target) => {
            let (decoder, report, _) = run_online_calibration(
                &request,
                target,
                scenario.params.detector,
                scenario.params.control.t_e,
                online_progress,
            )?;
            Ok(PreparedEpuck {
                decoder,
                report,
                cached: false,
            })
        }
    }
}

/// The online decoder of a finished calibration, with the operating point
/// of the scenario's detector measured on a held-out session (seeded by
/// the scenario's seed): the last step of every path that prepares an
/// e-puck decoder.
pub fn finish_continuous_decoder(
    scenario: &EpuckScenario,
    report: &ContinuousReport,
) -> Result<ContinuousDecoder> {
    let setup = continuous_request(scenario)?.setup;
    let mut decoder =
        ContinuousDecoder::from_report(report).with_closed_loop(&setup, scenario.user_seed)?;
    decoder.measure_online(
        scenario.params.detector,
        scenario.params.control.t_e,
        scenario.user_seed,
    )?;
    Ok(decoder)
}

/// The seed of run `k` of a scenario with base seed `seed`.
pub fn epuck_run_seed(seed: u64, k: usize) -> u64 {
    derive_seed(seed, "epuck/run", k as u64)
}

/// Runs run `k` of `scenario` with `observer` watching.
pub fn run_epuck_once(
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    k: usize,
    observer: &mut impl EpuckObserver,
) -> Result<EpuckEpisodeResult> {
    run_epuck_episode(
        scenario,
        decoder,
        epuck_run_seed(scenario.seed, k),
        observer,
    )
}

/// What watches a scenario's runs one after another (a recording): told
/// when each starts, then each run's steps as an [`EpuckObserver`].
pub trait EpuckRunsObserver: EpuckObserver {
    /// Run `k` (from 0) starts, from `seed`.
    fn start_run(&mut self, k: usize, seed: u64);
}

/// `()` watches nothing ([`EpuckObserver::watches`]), so the runs may go
/// in parallel.
impl EpuckRunsObserver for () {
    fn start_run(&mut self, _k: usize, _seed: u64) {}
}

/// Runs `runs` runs of `scenario` without recording, in parallel. Results
/// are in run order and do not depend on the number of threads.
pub fn run_epuck_batch(
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    runs: usize,
) -> Result<Vec<EpuckEpisodeResult>> {
    run_epuck_runs(scenario, decoder, runs, None, &mut (), &|_| {})
}

/// [`run_epuck_batch`], calling `on_run` after each run ends (on the
/// thread that ran it, in no set order), e.g. to count them for a progress
/// bar.
pub fn run_epuck_batch_counted(
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    runs: usize,
    on_run: &(dyn Fn() + Sync),
) -> Result<Vec<EpuckEpisodeResult>> {
    run_epuck_runs(scenario, decoder, runs, None, &mut (), &|_| on_run())
}

/// The one loop over a scenario's runs: run `k` from
/// [`epuck_run_seed`]`(scenario.seed, k)`, with `window_decoder` (a decoder
/// of the user's own, as in [`crate::epuck::run_epuck_episode_with`]) in
/// place of the calibrated SVM when given, `observer` watching, and
/// `on_run(k)` called after run `k` ends. With neither a decoder of the user's
/// own nor an observer that watches, the runs go in parallel; otherwise
/// one after another. Either way the results are in run order and the
/// same.
pub fn run_epuck_runs(
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    runs: usize,
    mut window_decoder: Option<WindowDecoder<'_>>,
    observer: &mut impl EpuckRunsObserver,
    on_run: &(dyn Fn(usize) + Sync),
) -> Result<Vec<EpuckEpisodeResult>> {
    if window_decoder.is_none() && !observer.watches() {
        return (0..runs)
            .into_par_iter()
            .map(|k| {
                errp_bci::stop::check()?;
                let r = run_epuck_once(scenario, decoder, k, &mut ());
                on_run(k);
                r
            })
            .collect();
    }
    let mut out = Vec::with_capacity(runs);
    for k in 0..runs {
        errp_bci::stop::check()?;
        let seed = epuck_run_seed(scenario.seed, k);
        observer.start_run(k, seed);
        let decode = window_decoder
            .as_mut()
            .map(|d| &mut **d as WindowDecoder<'_>);
        out.push(run_epuck_episode_with(
            scenario, decoder, seed, observer, decode,
        )?);
        on_run(k);
    }
    Ok(out)
}

/// Summary of many runs of one e-puck scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct EpuckSummary {
    /// Runs.
    pub runs: usize,
    /// Runs that converged on the user's goal.
    pub reached: usize,
    /// Runs that converged on another goal.
    pub wrong: usize,
    /// Median time to convergence over the runs that reached the goal (s).
    pub median_secs: f64,
    /// Median detected errors over those runs.
    pub median_detected: f64,
    /// Median false detections over those runs.
    pub median_false: f64,
    /// Times of the runs that reached the goal (s), sorted.
    pub reached_secs: Vec<f64>,
    /// Detections of those runs, sorted.
    pub reached_detected: Vec<f64>,
    /// Median time to the goal over every run, a run that converged on
    /// another goal or timed out counting as never reaching it (infinite
    /// when fewer than half the runs reach it). Unlike the median over the
    /// runs that reached the goal, it cannot improve when a worse decoder
    /// lets the slow runs end on a wrong goal instead.
    pub median_secs_to_goal: f64,
    /// Window accuracy pooled over every run.
    pub online: Accuracy,
    /// Detections per second of run, pooled over every run.
    pub detections_per_sec: f64,
    /// Shares of all detections made while turning, driving and stopped on
    /// a goal.
    pub phase_shares: [f64; 3],
    /// Shares of the true detections whose ErrP judged a turn, a drive and
    /// a stop.
    pub judged_shares: [f64; 3],
    /// Hit rate per ErrP, pooled over every run.
    pub hit_rate: f64,
    /// False detections per minute of error-free time, pooled.
    pub false_alarms_per_min: f64,
}

fn sorted(mut v: Vec<f64>) -> Vec<f64> {
    v.sort_by(f64::total_cmp);
    v
}

/// Summarises `results`.
pub fn summarise(results: &[EpuckEpisodeResult]) -> EpuckSummary {
    let ok: Vec<&EpuckEpisodeResult> = results.iter().filter(|r| r.reached()).collect();
    let col = |f: &dyn Fn(&EpuckEpisodeResult) -> f64| ok.iter().map(|r| f(r)).collect::<Vec<_>>();
    let sum = |f: &dyn Fn(&EpuckEpisodeResult) -> f64| results.iter().map(f).sum::<f64>();
    EpuckSummary {
        runs: results.len(),
        reached: ok.len(),
        wrong: results
            .iter()
            .filter(|r| r.committed.is_some() && !r.reached())
            .count(),
        median_secs: crate::stats::median(&col(&|r| r.time_secs)),
        median_detected: crate::stats::median(&col(&|r| r.detected_errors as f64)),
        median_false: crate::stats::median(&col(&|r| r.false_detections as f64)),
        reached_secs: sorted(col(&|r| r.time_secs)),
        reached_detected: sorted(col(&|r| r.detected_errors as f64)),
        median_secs_to_goal: {
            let t = sorted(
                results
                    .iter()
                    .map(|r| {
                        if r.reached() {
                            r.time_secs
                        } else {
                            f64::INFINITY
                        }
                    })
                    .collect(),
            );
            t.get(t.len() / 2).copied().unwrap_or(f64::NAN)
        },
        online: Accuracy::pooled(results.iter().map(|r| &r.online)),
        detections_per_sec: sum(&|r| r.detected_errors as f64) / sum(&|r| r.time_secs),
        // Shares of no detection are undefined (NaN), not 0 %.
        phase_shares: {
            let total = sum(&|r| r.detected_errors as f64);
            [0, 1, 2].map(|k| sum(&|r| r.detected_by_phase[k] as f64) / total)
        },
        judged_shares: {
            let total = sum(&|r| r.true_by_judged_phase.iter().sum::<usize>() as f64);
            [0, 1, 2].map(|k| sum(&|r| r.true_by_judged_phase[k] as f64) / total)
        },
        hit_rate: 1.0 - sum(&|r| r.missed_errors as f64) / sum(&|r| r.errps_scored as f64),
        false_alarms_per_min: sum(&|r| r.false_detections as f64) / (sum(&|r| r.clean_secs) / 60.0),
    }
}
