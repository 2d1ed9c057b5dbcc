//! Preparing every level's decoder, on the path `errp run` takes, each distinct one once.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use errp_robot::QTable;

use errp_sim::epuck::{ContinuousDecoder, EpuckScenario, prepare_epuck_decoder};
use errp_sim::grid::{AssessmentDecoder, GridScenario, GridShared, prepare_grid_decoder};
use errp_sim::{AnyScenario, Result};

use crate::cache::TargetCache;
use crate::manifest::DecoderInfo;
use crate::observer::SweepObserver;
use crate::spec::Level;

/// One level, ready to run episodes.
pub(crate) enum Runner {
    Grid {
        scenario: Box<GridScenario>,
        decoder: Arc<AssessmentDecoder>,
        table: Arc<QTable>,
    },
    Epuck {
        scenario: Box<EpuckScenario>,
        decoder: Arc<ContinuousDecoder>,
    },
}

/// The decoder a level needs, before calibration; equal keys share one.
pub(crate) fn decoder_key(level: &Level) -> String {
    match &level.scenario {
        AnyScenario::Grid(s) => format!(
            "{:?}",
            (
                s.accuracy,
                s.seed,
                s.decoder,
                s.p_error,
                s.eeg,
                s.bank_per_class,
                s.params.interval_min_secs,
                s.params.interval_max_secs
            )
        ),
        // The held-out operating point, and with an online target the
        // calibration itself, depend on the detector and T_e too.
        AnyScenario::Epuck(s) => format!(
            "{:?}",
            (
                s.accuracy,
                s.seed,
                s.online_target,
                s.params.detector,
                s.params.control.t_e
            )
        ),
    }
}

pub(crate) enum Prepared {
    Grid(Arc<AssessmentDecoder>),
    Epuck(Arc<ContinuousDecoder>),
}

/// Calibrates the decoder `level` needs on the path `errp run` takes, with
/// the cache for the targeting and `shared` for the grid's sessions and
/// banks.
pub(crate) fn prepare(
    level: &Level,
    cache: &TargetCache,
    shared: &GridShared,
) -> Result<(Prepared, DecoderInfo)> {
    match &level.scenario {
        AnyScenario::Grid(s) => {
            let prepared = prepare_grid_decoder(s, shared, cache, |_| {})?;
            let calibration = prepared.calibration.as_ref();
            let accuracy = calibration.map(|c| c.calibrated.accuracy);
            let info = DecoderInfo {
                accuracy: s.accuracy,
                kind: if calibration.is_some() {
                    "lda"
                } else {
                    "oracle"
                }
                .into(),
                calibration_seed: s.seed,
                errp_to_noise: calibration.map(|c| c.targeting.ratio),
                cv_correct: accuracy.map(|a| a.correct),
                cv_error: accuracy.map(|a| a.error),
                cv_mean: accuracy.map(|a| a.mean()),
                online_hit_rate: None,
                online_false_alarms_per_min: None,
                cached: prepared.cached,
            };
            Ok((Prepared::Grid(Arc::new(prepared.decoder)), info))
        }
        AnyScenario::Epuck(s) => {
            let prepared = prepare_epuck_decoder(s, cache, |_| {}, |_| {})?;
            let a = prepared.report.calibrated.accuracy;
            let point = prepared.decoder.online.as_ref().map(|o| o.point);
            let info = DecoderInfo {
                accuracy: s.accuracy,
                kind: "svm".into(),
                calibration_seed: s.seed,
                errp_to_noise: Some(prepared.report.targeting.ratio),
                cv_correct: Some(a.correct),
                cv_error: Some(a.error),
                cv_mean: Some(a.mean()),
                online_hit_rate: point.map(|p| p.hit_rate),
                online_false_alarms_per_min: point.map(|p| p.false_alarms_per_min),
                cached: prepared.cached,
            };
            Ok((Prepared::Epuck(Arc::new(prepared.decoder)), info))
        }
    }
}

/// Prepares the decoders of `first_level` (level indices) on every thread of
/// the current pool, the likely slowest first: targeting far from 75 % takes
/// the most search steps. Results are in `first_level` order, whatever the
/// thread count.
pub(crate) fn prepare_all(
    levels: &[Level],
    first_level: &[usize],
    cache: &TargetCache,
    shared: &GridShared,
    observer: &dyn SweepObserver,
) -> Result<Vec<(Prepared, DecoderInfo)>> {
    let n = first_level.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| {
        let cost = |i: usize| (levels[first_level[i]].accuracy - 0.75).abs();
        cost(b).total_cmp(&cost(a)).then(a.cmp(&b))
    });
    let next = AtomicUsize::new(0);
    let ready = AtomicUsize::new(0);
    type Slot = Mutex<Option<Result<(Prepared, DecoderInfo)>>>;
    let slots: Vec<Slot> = (0..n).map(|_| Mutex::new(None)).collect();
    rayon::scope(|scope| {
        for _ in 0..rayon::current_num_threads().min(n) {
            scope.spawn(|_| {
                loop {
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(&k) = order.get(i) else { break };
                    let result = prepare(&levels[first_level[k]], cache, shared);
                    if let Ok((_, info)) = &result {
                        let done = ready.fetch_add(1, Ordering::SeqCst) + 1;
                        observer.decoder_ready(info, done, n);
                    }
                    *slots[k].lock().expect("no panic while holding the slot") = Some(result);
                }
            });
        }
    });
    slots
        .into_iter()
        .map(|slot| {
            slot.into_inner()
                .expect("no panic while holding the slot")
                .expect("every decoder was prepared")
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::{SweepSpec, SweepTask, parse_accuracies, parse_axis};

    fn epuck_levels(param: &str) -> Vec<Level> {
        SweepSpec {
            task: SweepTask::Epuck,
            scenario_path: "mexico_to_pisa.toml".into(),
            scenario_toml: include_str!("../../scenarios/mexico_to_pisa.toml").into(),
            accuracies: parse_accuracies("0.9").unwrap(),
            axes: vec![parse_axis(SweepTask::Epuck, param).unwrap()],
            fixed: vec![],
            episodes: 1,
            seed: 1,
        }
        .levels()
        .unwrap()
    }

    #[test]
    fn levels_share_a_decoder_only_when_it_would_be_the_same() {
        // T_e sets the held-out operating point the decoder carries.
        let t_e = epuck_levels("t_e=0.7,0.8");
        assert_ne!(decoder_key(&t_e[0]), decoder_key(&t_e[1]));
        // The user's field of view does not touch the decoder.
        let fov = epuck_levels("fov_deg=60,90");
        assert_eq!(decoder_key(&fov[0]), decoder_key(&fov[1]));
    }
}
