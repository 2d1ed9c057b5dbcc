//! Running a grid scenario: calibrate the decoder (EEG) or not (oracle), then
//! every episode, each from its own derived seed.

use std::collections::HashMap;
use std::sync::Arc;

use errp_bci::{
    Accuracy, CalibrationSetup, Classifier, LdaDecoder, MeanAccuracy, RequestedAccuracy,
    SessionParts, TargetingResult, TargetingStep, Valid, calibrate_session, rng::derive_seed,
    search_ratio,
};
use errp_robot::{Grid, GridControlParams, QTable};

use crate::calibration::{CalibrationReport, CalibrationRequest, NoCache, TargetingCache};
use crate::error::{Result, SimError};
use crate::grid::decoder::{AssessmentDecoder, EegDecoder, EegSource, EpochBankParts};
use crate::grid::episode::run_grid_episode_with;
use crate::grid::own_eeg::{OwnEegReport, prepare_own_eeg};
use crate::grid::plant::{GridDecoding, GridEpisodeResult};
use crate::grid::scenario::{DecoderChoice, EegMode, GridScenario};
use crate::key::StableKey;
use crate::rules::{self, Origin};
use crate::task::DecoderInfo;
use crate::task_kind::TaskKind;

/// Everything a grid run produced.
#[derive(Debug, Clone)]
pub struct GridRunReport {
    /// The scenario as run.
    pub scenario: GridScenario,
    /// The calibration behind the EEG decoder (none for the oracle and
    /// own EEG).
    pub calibration: Option<CalibrationReport>,
    /// What a person's own EEG gave (`[eeg] recording = ...`).
    pub own_eeg: Option<OwnEegReport>,
    /// One result per episode, in scenario order.
    pub episodes: Vec<GridEpisodeResult>,
}

impl GridRunReport {
    /// The decoder's accuracy pooled over every action of every episode.
    pub fn online_accuracy(&self) -> Accuracy {
        pooled_accuracy(&self.episodes)
    }
}

/// The decoder's accuracy pooled over every action of `episodes`.
pub fn pooled_accuracy(episodes: &[GridEpisodeResult]) -> Accuracy {
    Accuracy::pooled(episodes.iter().map(|r| &r.online))
}

/// The calibration setup of a grid scenario: the paper's protocol and the
/// default EEG model, with the scenario's user (`[realism]`).
pub(crate) fn grid_setup(s: &GridScenario) -> Result<Valid<CalibrationSetup>> {
    Ok(Valid::new(
        CalibrationSetup::default().with_realism(&s.realism)?,
    )?)
}

/// Builds the scenario's decoder: for the EEG decoder, a calibration session
/// targeted at the scenario's accuracy (`progress` sees the search). The
/// path of `errp run` and Table 1: [`prepare_grid_decoder`] with nothing
/// shared and no cache.
pub fn prepare_decoder(
    scenario: &GridScenario,
    progress: impl FnMut(&TargetingStep),
) -> Result<(AssessmentDecoder, Option<CalibrationReport>)> {
    let prepared = prepare_grid_decoder(scenario, &GridShared::default(), &NoCache, progress)?;
    Ok((prepared.decoder, prepared.calibration))
}

/// A grid decoder, ready for episodes.
#[derive(Debug, Clone)]
pub struct PreparedGrid {
    /// The decoder.
    pub decoder: AssessmentDecoder,
    /// Its calibration (none for the oracle).
    pub calibration: Option<CalibrationReport>,
    /// True if the targeting came from the cache.
    pub cached: bool,
}

impl PreparedGrid {
    /// What a sweep or a fit reports of the decoder of `s`: the requested
    /// accuracy, the ratio found and the session's cross-validated rates.
    pub fn info(&self, s: &GridScenario) -> DecoderInfo {
        let calibration = self.calibration.as_ref();
        let own_eeg = match &self.decoder {
            AssessmentDecoder::OwnEeg(bank) => Some(&bank.report),
            _ => None,
        };
        let accuracy = calibration
            .map(|c| c.calibrated.accuracy)
            .or(own_eeg.map(|r| r.cross_validated));
        DecoderInfo {
            // A recording's decoder has the accuracy it has: its
            // cross-validated one, which the control assumes.
            accuracy: decoder_accuracy(s, own_eeg),
            kind: if calibration.is_some() {
                "lda"
            } else if own_eeg.is_some() {
                "lda-recorded"
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
            own_eeg: own_eeg.map(|r| r.file.clone()),
            cached: self.cached,
        }
    }
}

/// The accuracy the decoder of `s` is known by: the one asked for, or
/// (on own EEG) the one cross-validated on its calibration part, which the
/// control assumes. Not a number for an own-EEG scenario without its
/// `own_eeg` report.
pub fn decoder_accuracy(s: &GridScenario, own_eeg: Option<&OwnEegReport>) -> f64 {
    match (s.accuracy.requested(), own_eeg) {
        (Some(a), _) => a.get(),
        (None, Some(r)) => r.cross_validated.mean(),
        (None, None) => f64::NAN,
    }
}

/// What the decoders of several grid scenarios can share, simulated once:
/// the calibration session of each seed (as its noise and ERP parts, so
/// that every accuracy mixes them at its own ratio) and the epoch banks.
/// Empty, [`prepare_grid_decoder`] simulates what a scenario needs itself.
#[derive(Debug, Default)]
pub struct GridShared {
    sessions: HashMap<String, Arc<SessionParts>>,
    banks: HashMap<String, Arc<EpochBankParts>>,
    held_out: HashMap<String, Arc<EpochBankParts>>,
}

/// Epochs per class on which the targeting scores a decoder online (sd of
/// the measured mean accuracy about 0.7 points at 75 %).
pub const HELD_OUT_PER_CLASS: usize = 2000;

/// The key of a grid scenario's calibration session: its user.
fn session_key(s: &GridScenario) -> String {
    StableKey::new("grid-session", 1)
        .int("seed", s.seed)
        .realism(&s.realism)
        .finish()
}

/// The key of a bank of `per_class` epochs of each class streamed for `s`
/// under `kind` (what they depend on).
fn epochs_key(kind: &str, s: &GridScenario, per_class: usize) -> String {
    StableKey::new(kind, 1)
        .int("seed", s.seed)
        .int("per_class", per_class as u64)
        .float("interval_min_secs", s.params.interval_min_secs)
        .float("interval_max_secs", s.params.interval_max_secs)
        .realism(&s.realism)
        .finish()
}

/// The key of a grid scenario's held-out epochs.
fn held_out_key(s: &GridScenario) -> String {
    epochs_key("grid-held-out", s, HELD_OUT_PER_CLASS)
}

/// The epochs on which the targeting of `s` scores its decoder: streamed as
/// the episodes stream theirs (same user, preprocessing and inter-action
/// intervals), from a seed of their own, so that no episode reads them.
fn build_held_out(
    s: &GridScenario,
    setup: &Valid<CalibrationSetup>,
    session: &SessionParts,
) -> Result<EpochBankParts> {
    synthesise_parts(
        s,
        setup,
        session,
        HELD_OUT_PER_CLASS,
        derive_seed(s.seed, "grid/targeting/held-out", 0),
    )
}

/// The key of a grid scenario's epoch bank: what its epochs depend on.
fn bank_key(s: &GridScenario) -> String {
    epochs_key("grid-bank", s, s.bank_per_class)
}

/// The calibration session of `setup` and `seed`, streamed as its noise and
/// ERP parts in parallel.
fn simulate_parts(setup: &Valid<CalibrationSetup>, seed: u64) -> Result<SessionParts> {
    let (noise, erp) = rayon::join(
        || SessionParts::simulate_part(setup, seed, false),
        || SessionParts::simulate_part(setup, seed, true),
    );
    Ok(SessionParts::from_parts(noise?, erp?)?)
}

/// The epoch bank parts of `s`, streamed through `session`'s preprocessing
/// with the user of `setup`.
fn build_bank(
    s: &GridScenario,
    setup: &Valid<CalibrationSetup>,
    session: &SessionParts,
) -> Result<EpochBankParts> {
    synthesise_parts(s, setup, session, s.bank_per_class, s.seed)
}

/// `per_class` epochs of each class from `seed`, streamed at `s`'s
/// inter-action intervals: the EEG of the user of `setup` in the closed
/// loop that follows the calibration ([`CalibrationSetup::closed_loop_generator`])
/// through `session`'s preprocessing.
fn synthesise_parts(
    s: &GridScenario,
    setup: &Valid<CalibrationSetup>,
    session: &SessionParts,
    per_class: usize,
    seed: u64,
) -> Result<EpochBankParts> {
    let generator = setup.closed_loop_generator(s.seed)?;
    let source = EegSource {
        generator: &generator,
        montage: &setup.montage,
        preprocessor: session.preprocessor(),
    };
    EpochBankParts::build(source, &s.params, per_class, seed)
}

impl GridShared {
    /// Simulates once what `scenarios` share: one calibration session per
    /// seed, one epoch bank per bank key (EEG decoders only), with the
    /// paper's protocol and the default EEG model with each scenario's
    /// user (`[realism]`), as every grid scenario is calibrated.
    pub fn build<'a>(scenarios: impl IntoIterator<Item = &'a GridScenario>) -> Result<Self> {
        let mut shared = Self::default();
        for s in scenarios {
            if s.decoder != DecoderChoice::Eeg {
                continue;
            }
            let setup = grid_setup(s)?;
            let session = session_key(s);
            if let std::collections::hash_map::Entry::Vacant(slot) =
                shared.sessions.entry(session.clone())
            {
                slot.insert(Arc::new(simulate_parts(&setup, s.seed)?));
            }
            let key = held_out_key(s);
            if !shared.held_out.contains_key(&key) {
                let held_out = build_held_out(s, &setup, &shared.sessions[&session])?;
                shared.held_out.insert(key, Arc::new(held_out));
            }
            let key = bank_key(s);
            if s.eeg == EegMode::Bank && !shared.banks.contains_key(&key) {
                let bank = build_bank(s, &setup, &shared.sessions[&session])?;
                shared.banks.insert(key, Arc::new(bank));
            }
        }
        Ok(shared)
    }
}

/// Builds the scenario's decoder, the one path of every grid command. For
/// the EEG decoder: the calibration session (from `shared`, or simulated),
/// the ErrP-to-noise ratio targeted for the scenario's accuracy (from
/// `cache`, or searched; `progress` sees the search), the session at that
/// ratio scored by cross-validation and trained on, then the online
/// decoder, streamed or with its epoch bank (from `shared`, or built).
pub fn prepare_grid_decoder(
    scenario: &GridScenario,
    shared: &GridShared,
    cache: &dyn TargetingCache,
    mut progress: impl FnMut(&TargetingStep),
) -> Result<PreparedGrid> {
    if let Some(eeg) = scenario.accuracy.own_eeg() {
        let bank = prepare_own_eeg(scenario, eeg, &grid_setup(scenario)?)?;
        return Ok(PreparedGrid {
            decoder: AssessmentDecoder::OwnEeg(Box::new(bank)),
            calibration: None,
            cached: false,
        });
    }
    if scenario.decoder == DecoderChoice::Oracle {
        return Ok(PreparedGrid {
            decoder: AssessmentDecoder::Oracle {
                accuracy: requested(scenario)?.get(),
            },
            calibration: None,
            cached: false,
        });
    }
    let request = CalibrationRequest {
        setup: grid_setup(scenario)?,
        ..CalibrationRequest::new(targeted(scenario)?, scenario.seed)
    };
    let simulated;
    let parts = match shared.sessions.get(&session_key(scenario)) {
        Some(parts) => parts.as_ref(),
        None => {
            simulated = simulate_parts(&request.setup, scenario.seed)?;
            &simulated
        }
    };
    let lda = LdaDecoder::default();
    let key = format!(
        "{} held_out={}",
        request.targeting_key(),
        held_out_key(scenario)
    );
    // The held-out epochs, from `shared` or built once (by the search or
    // by the check of a cached ratio, whichever needs them first).
    let built = std::cell::OnceCell::new();
    let held_out = || -> Result<&EpochBankParts> {
        if let Some(h) = shared.held_out.get(&held_out_key(scenario)) {
            return Ok(h.as_ref());
        }
        if let Some(b) = built.get() {
            return Ok(b);
        }
        let b = build_held_out(scenario, &request.setup, parts)?;
        Ok(built.get_or_init(|| b))
    };
    let (targeting, cached) = cache.get_or_search(
        "grid-lda-online",
        &key,
        &mut || target_online_accuracy(parts, held_out()?, &lda, &request, &mut progress),
        &mut |t| {
            let again = online_accuracy_at(parts, held_out()?, &lda, &request, t.ratio)?;
            Ok(t.inconsistency(again, &request.search))
        },
    )?;
    let calibrated = calibrate_session(
        &lda,
        parts.session_at(targeting.ratio),
        request.setup.calibration.folds,
        request.seed,
    )?;
    let report = CalibrationReport {
        generator: request.setup.at_ratio(targeting.ratio)?.generator,
        targeting,
        calibrated,
    };
    let mut eeg = EegDecoder::from_report(&report, scenario.p_error);
    eeg.generator = request
        .setup
        .at_ratio(report.targeting.ratio)?
        .closed_loop_generator(scenario.seed)?;
    let decoder = match scenario.eeg {
        EegMode::PerAction => AssessmentDecoder::Eeg(Box::new(eeg)),
        EegMode::Bank => {
            let bank = match shared.banks.get(&bank_key(scenario)) {
                Some(bank) => bank.bank(eeg),
                None => build_bank(scenario, &request.setup, parts)?.bank(eeg),
            };
            AssessmentDecoder::EegBank(Box::new(bank))
        }
    };
    Ok(PreparedGrid {
        decoder,
        calibration: Some(report),
        cached,
    })
}

/// The targeting of the grid's decoder: the ErrP-to-noise ratio at which
/// the LDA trained on the whole calibration session (as it is used online)
/// scores the requested mean accuracy on `held_out`, epochs streamed as the
/// episodes stream theirs. This is the accuracy Table 1 reports (sec. 4.3:
/// online, "the percentage of detection of correct and erroneous
/// signals"); the session's cross-validated accuracy, which trains on 4/5
/// of the trials, is lower by a few points and is reported beside it.
pub fn target_online_accuracy(
    parts: &SessionParts,
    held_out: &EpochBankParts,
    lda: &LdaDecoder,
    request: &CalibrationRequest,
    progress: impl FnMut(&TargetingStep),
) -> Result<TargetingResult> {
    Ok(search_ratio(
        request.accuracy,
        &request.search,
        |ratio| online_accuracy_at(parts, held_out, lda, request, ratio),
        progress,
    )?)
}

/// What [`target_online_accuracy`] evaluates at one ratio: the LDA trained
/// on the whole session at `ratio`, scored on `held_out`. A ratio that
/// gives features the LDA cannot take (not finite) is an error.
pub fn online_accuracy_at(
    parts: &SessionParts,
    held_out: &EpochBankParts,
    lda: &LdaDecoder,
    request: &CalibrationRequest,
    ratio: f64,
) -> errp_bci::Result<Accuracy> {
    let labels = parts.session_at(0.0).labels;
    let fit_seed = derive_seed(request.seed, "calibration/fit", 0);
    let model = lda.fit(&parts.features_at(ratio), &labels, fit_seed)?;
    Ok(held_out.score(&model, ratio))
}

/// The accuracy the EEG decoder of `scenario` is targeted at (a scenario
/// changed after it was checked may ask a perfect one, which the rule
/// refuses).
fn targeted(scenario: &GridScenario) -> Result<MeanAccuracy> {
    let asked = requested(scenario)?;
    let origin = Origin::Scenario(&scenario.path);
    match rules::accuracy_for(TaskKind::Grid, false, asked.get(), origin)? {
        RequestedAccuracy::Targeted(a) => Ok(a),
        RequestedAccuracy::Perfect => unreachable!("the rule refuses a perfect EEG decoder"),
    }
}

/// The accuracy `scenario` asks for (none when its EEG is own EEG).
fn requested(scenario: &GridScenario) -> Result<RequestedAccuracy> {
    scenario.accuracy.requested().ok_or_else(|| {
        SimError::Scenario(format!(
            "{}: a recording's decoder has the accuracy the recording gives; none is asked for",
            scenario.path.display()
        ))
    })
}

/// The streamed EEG decoder of a synthetic user calibrated at `accuracy`
/// (online, as every grid decoder: [`target_online_accuracy`]; seed
/// `seed`), with Platt-scaled p(error): for benches, examples and tests that
/// need one decoder without a scenario file.
pub fn eeg_decoder(accuracy: f64, seed: u64) -> Result<AssessmentDecoder> {
    let scenario = GridScenario::builder("eeg_decoder", DecoderChoice::Eeg, accuracy, seed)
        .bank_per_class(1)
        .build()?;
    Ok(prepare_decoder(&scenario, |_| {})?.0)
}

/// Runs every episode of `scenario` with `decoder`. Episode k uses the seed
/// derived from (scenario seed, k); `record_steps` keeps every action.
pub fn run_grid_scenario(
    scenario: &GridScenario,
    decoder: &AssessmentDecoder,
    record_steps: bool,
    on_episode: impl FnMut(usize, &GridEpisodeResult),
) -> Result<Vec<GridEpisodeResult>> {
    run_grid_scenario_with(
        scenario,
        GridDecoding::Builtin(decoder),
        record_steps,
        on_episode,
    )
}

/// [`run_grid_scenario`] with any [`GridDecoding`], e.g. a decoder of the
/// user's own: the same episodes from the same seeds.
pub fn run_grid_scenario_with(
    scenario: &GridScenario,
    mut decoding: GridDecoding<'_>,
    record_steps: bool,
    mut on_episode: impl FnMut(usize, &GridEpisodeResult),
) -> Result<Vec<GridEpisodeResult>> {
    let table = QTable::compute(
        Grid::paper(),
        &scenario.params.control.part(GridControlParams::q),
    )?;
    let mut out = Vec::with_capacity(scenario.episodes.len());
    for (k, &(start, goal)) in scenario.episodes.iter().enumerate() {
        errp_bci::stop::check()?;
        let seed = crate::grid::grid_episode_seed(scenario.seed, k);
        let r = run_grid_episode_with(
            start,
            goal,
            &table,
            &scenario.params,
            decoding.reborrow(),
            seed,
            record_steps,
        )?;
        on_episode(k, &r);
        out.push(r);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The keys of what grid decoders share are stable, versioned keys:
    /// written field by field, floats by their bits, pinned here so that a
    /// change of what they hold is made on purpose (with a new version).
    #[test]
    fn the_shared_parts_have_stable_keys() {
        let text = include_str!("../../../scenarios/variants/grid_fixed_goals_ideal.toml");
        let s = GridScenario::parse(text, std::path::Path::new("ideal.toml")).unwrap();
        assert_eq!(session_key(&s), "grid-session/v1;seed=1");
        let intervals = "interval_min_secs=f:4008000000000000;interval_max_secs=f:400c000000000000";
        assert_eq!(
            held_out_key(&s),
            format!("grid-held-out/v1;seed=1;per_class=2000;{intervals}")
        );
        assert_eq!(
            bank_key(&s),
            format!("grid-bank/v1;seed=1;per_class=1000;{intervals}")
        );
        let mut real = s.clone();
        real.realism.background_drift = 0.3;
        assert!(session_key(&real).starts_with("grid-session/v1;seed=1;realism="));
        assert_ne!(held_out_key(&real), held_out_key(&s));
    }
}
