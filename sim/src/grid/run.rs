//! Running a grid scenario: calibrate the decoder (EEG) or not (oracle), then
//! every episode, each from its own derived seed.

use errp_bci::{Accuracy, TargetingStep, rng::derive_seed};
use errp_robot::{Grid, QTable};

use crate::calibration::{CalibrationReport, CalibrationRequest, run_calibration};
use crate::error::{Result, SimError};
use crate::grid::episode::{
    AssessmentDecoder, EegDecoder, EpochBank, GridEpisodeResult, run_grid_episode,
};
use crate::grid::scenario::{DecoderChoice, EegMode, GridScenario};

/// Everything a grid run produced.
#[derive(Debug, Clone)]
pub struct GridRunReport {
    /// The scenario as run.
    pub scenario: GridScenario,
    /// The calibration behind the EEG decoder (none for the oracle).
    pub calibration: Option<CalibrationReport>,
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

/// Builds the scenario's decoder: for the EEG decoder, a calibration session
/// targeted at the scenario's accuracy (`progress` sees the search).
pub fn prepare_decoder(
    scenario: &GridScenario,
    progress: impl FnMut(&TargetingStep),
) -> Result<(AssessmentDecoder, Option<CalibrationReport>)> {
    match scenario.decoder {
        DecoderChoice::Oracle => Ok((decoder_from_calibration(scenario, None)?, None)),
        DecoderChoice::Eeg => {
            let request = CalibrationRequest::new(scenario.accuracy, scenario.seed);
            let report = run_calibration(&request, progress, None)?;
            Ok((
                decoder_from_calibration(scenario, Some(&report))?,
                Some(report),
            ))
        }
    }
}

/// The scenario's decoder from its calibration (none for the oracle): the
/// online EEG decoder, streamed or with its epoch bank built.
pub fn decoder_from_calibration(
    scenario: &GridScenario,
    report: Option<&CalibrationReport>,
) -> Result<AssessmentDecoder> {
    let report = match (scenario.decoder, report) {
        (DecoderChoice::Oracle, _) => {
            return Ok(AssessmentDecoder::Oracle {
                accuracy: scenario.accuracy,
            });
        }
        (DecoderChoice::Eeg, Some(report)) => report,
        (DecoderChoice::Eeg, None) => {
            return Err(SimError::Scenario(
                "the EEG decoder needs a calibration".into(),
            ));
        }
    };
    let eeg = EegDecoder::from_report(report, scenario.p_error);
    Ok(match scenario.eeg {
        EegMode::Stream => AssessmentDecoder::Eeg(Box::new(eeg)),
        EegMode::Bank => AssessmentDecoder::EegBank(Box::new(EpochBank::build(
            eeg,
            &scenario.params,
            scenario.bank_per_class,
            scenario.seed,
        )?)),
    })
}

/// Runs every episode of `scenario` with `decoder`. Episode k uses the seed
/// derived from (scenario seed, k); `record_steps` keeps every action.
pub fn run_grid_scenario(
    scenario: &GridScenario,
    decoder: &AssessmentDecoder,
    record_steps: bool,
    mut on_episode: impl FnMut(usize, &GridEpisodeResult),
) -> Result<Vec<GridEpisodeResult>> {
    let table = QTable::compute(Grid::paper(), &scenario.params.control.q)?;
    let mut out = Vec::with_capacity(scenario.episodes.len());
    for (k, &(start, goal)) in scenario.episodes.iter().enumerate() {
        let seed = derive_seed(scenario.seed, "grid/episode", k as u64);
        let r = run_grid_episode(
            start,
            goal,
            &table,
            &scenario.params,
            decoder,
            seed,
            record_steps,
        )?;
        on_episode(k, &r);
        out.push(r);
    }
    Ok(out)
}
