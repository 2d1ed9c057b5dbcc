//! The simulated subjects: each Table 1 subject's decoders calibrated
//! online at its accuracy, several calibrations per subject.

use std::sync::atomic::{AtomicUsize, Ordering};

use errp_bci::GoalSet;
use errp_bci::rng::derive_seed;
use errp_bci::stop::WindDown;
use errp_sim::Result;
use errp_sim::grid::{
    AssessmentDecoder, DecoderChoice, EegMode, GridScenario, GridShared, GridTaskParams,
    prepare_grid_decoder,
};
use rayon::prelude::*;

use super::paper::paper_rows;
use super::spec::GridFitSpec;
use crate::cache::TargetCache;
use crate::observer::SweepObserver;

/// Epochs per class in each calibration's bank.
pub const GRID_FIT_BANK: usize = 1000;

/// One calibration of one subject on one goal set.
pub(super) struct Calibration {
    pub(super) subject: usize,
    pub(super) goals: GoalSet,
    pub(super) index: usize,
    pub(super) seed: u64,
    pub(super) decoder: AssessmentDecoder,
}

/// The scenario of one calibration: the subject's accuracy, the paper's
/// task with `params`, epochs from a bank.
pub(super) fn scenario(
    accuracy: f64,
    seed: u64,
    subject: &str,
    params: GridTaskParams,
    realism: &errp_bci::Realism,
) -> errp_sim::Result<GridScenario> {
    GridScenario::builder("fit grid", DecoderChoice::Eeg, accuracy, seed)
        .name(&format!("{subject} (fit grid)"))
        .eeg(EegMode::Bank)
        .bank_per_class(GRID_FIT_BANK)
        .user(subject)
        .params(params)
        .realism(realism.clone())
        .build()
}

/// Every subject's decoders on either goal set, `spec.calibrations` each,
/// calibrated in parallel through the cache; `None` if cancelled.
pub(super) fn calibrate_users(
    spec: &GridFitSpec,
    cache: &TargetCache,
    wind_down: &WindDown,
    observer: &dyn SweepObserver,
    base: GridTaskParams,
) -> Result<Option<Vec<Calibration>>> {
    let fixed = paper_rows(GoalSet::Fixed);
    let free = paper_rows(GoalSet::Free);
    let mut jobs = Vec::new();
    for goals in [GoalSet::Fixed, GoalSet::Free] {
        for subject in 0..fixed.len() {
            for index in 0..spec.calibrations {
                let k = (goals as usize * fixed.len() + subject) * spec.calibrations + index;
                jobs.push((
                    subject,
                    goals,
                    index,
                    derive_seed(spec.seed, "fit/grid/calibration", k as u64),
                ));
            }
        }
    }
    let done = AtomicUsize::new(0);
    let calibrations: Vec<Calibration> = jobs
        .par_iter()
        .map(|&(subject, goals, index, seed)| {
            if wind_down.requested() {
                return Ok(None);
            }
            let rows = if goals == GoalSet::Fixed {
                &fixed
            } else {
                &free
            };
            let row = &rows[subject];
            let s = scenario(row.accuracy, seed, &row.subject, base, &spec.realism)?;
            let warn = |w: &str| observer.warning(w);
            let cache = cache.reporting(&warn);
            let prepared = prepare_grid_decoder(&s, &GridShared::default(), &cache, |_| {})?;
            observer.decoder_ready(
                &prepared.info(&s),
                done.fetch_add(1, Ordering::Relaxed) + 1,
                jobs.len(),
            );
            Ok(Some(Calibration {
                subject,
                goals,
                index,
                seed,
                decoder: prepared.decoder,
            }))
        })
        .collect::<Result<Vec<Option<Calibration>>>>()?
        .into_iter()
        .collect::<Option<Vec<_>>>()
        .unwrap_or_default();
    Ok((calibrations.len() == jobs.len()).then_some(calibrations))
}
