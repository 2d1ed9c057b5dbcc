//! The e-puck on a person's own EEG, as a labelled hybrid: the file's
//! EEG as the background (its calibration part
//! for the calibration, the rest online), and the subject's
//! error-minus-correct response, from the calibration part, added at the
//! simulated user's assessments with the generator's single-trial
//! variability ([`errp_bci::HybridSource`]).
//!
//! The decoder is calibrated as the synthetic user's is (the same
//! button-locked protocol, preprocessing, features, SVM and Platt), with no
//! targeting: the subject's response has the amplitude it has. T_e cannot
//! be the paper's 0.8 as it stands, since one person's Platt probability is
//! not another's: it is set on the hybrid's held-out session to give the
//! false alarms a minute that the paper-fitted user makes at 0.8
//! ([`FITTED_FALSE_ALARMS_PER_MIN`]), the paper's "a high value, to
//! minimise false positives" kept as a rate.

use std::sync::Arc;

use errp_bci::{
    HybridSource, SessionOptions, SvmDecoder, TargetingResult, calibrate_continuous_with,
    threshold_for_false_alarms,
};

use crate::epuck::decoder::{ContinuousDecoder, ContinuousReport, ContinuousRequest, OnlineReport};
use crate::epuck::hybrid_report::HybridReport;
use crate::epuck::scenario::EpuckScenario;
use crate::error::{Result, SimError};
use crate::own_eeg::{FITTED_FALSE_ALARMS_PER_MIN, OwnEegSpec, load_own_eeg};

/// Calibrates the continuous decoder of `scenario` on the own EEG `eeg`
/// (a hybrid), sets T_e for the false-alarm rate, and measures the
/// detector there. Errors name the file.
pub fn prepare_hybrid(
    scenario: &EpuckScenario,
    eeg: &OwnEegSpec,
) -> Result<(ContinuousDecoder, ContinuousReport)> {
    let request = ContinuousRequest::new(scenario.accuracy, scenario.user_seed);
    let fs = request.setup.generator.sfreq_hz;
    let (recording, file) = load_own_eeg(eeg, fs)?;
    let named = |e: errp_bci::BciError| SimError::Scenario(format!("{}: {e}", file.name));
    let k = errp_bci::calibration_events(eeg.part, recording.events.len()).map_err(named)?;
    let hybrid =
        HybridSource::from_own_eeg(&recording.montage, &recording.raw, fs, &recording.events, k)
            .map_err(named)?;
    let background_secs = (
        hybrid.calibration.n_samples as f64 / fs,
        hybrid.held_out.n_samples as f64 / fs,
    );
    let template_counts = hybrid.template.counts;
    let (mut decoder, report) = calibrate_on_own_eeg(&request, Arc::new(hybrid))?;
    let accuracy = report.calibrated.accuracy.mean();
    if accuracy <= 0.5 {
        return Err(SimError::Scenario(format!(
            "{}: the continuous decoder calibrated on this recording decodes at chance \
             ({:.2} % cross-validated): its error and correct epochs do not differ",
            file.name,
            100.0 * accuracy
        )));
    }
    let detector = scenario.params.detector;
    let held_out = decoder.record_held_out(request.seed)?;
    let fa = eeg
        .false_alarms_per_min
        .unwrap_or(FITTED_FALSE_ALARMS_PER_MIN);
    let (t_e, _) = threshold_for_false_alarms(&held_out, detector, fa).map_err(named)?;
    decoder.online = Some(OnlineReport::from_held_out(&held_out, detector, t_e)?);
    decoder.own_eeg = Some(Box::new(HybridReport {
        file,
        calibration_events: k,
        template_counts,
        background_secs,
        eog_channels: recording.montage.n_eog(),
        merged: recording.merged,
        false_alarms_per_min: fa,
        t_e,
        accuracy,
    }));
    Ok((decoder, report))
}

/// Calibrates the continuous decoder on `hybrid` as the synthetic one is
/// calibrated, with no targeting (the subject's response has the amplitude
/// it has); not yet measured online.
pub fn calibrate_on_own_eeg(
    request: &ContinuousRequest,
    hybrid: Arc<HybridSource>,
) -> Result<(ContinuousDecoder, ContinuousReport)> {
    let options = SessionOptions {
        hybrid: Some(&hybrid),
        ..SessionOptions::default()
    };
    let calibrated = calibrate_continuous_with(
        &SvmDecoder::default(),
        &request.setup,
        request.seed,
        options,
    )?;
    let report = ContinuousReport {
        targeting: TargetingResult {
            requested: calibrated.accuracy.mean(),
            ratio: request.setup.generator.errp_to_noise,
            accuracy: calibrated.accuracy,
            steps: Vec::new(),
        },
        generator: request.setup.generator.clone(),
        calibrated,
    };
    let mut decoder = ContinuousDecoder::from_report(&report);
    decoder.montage = hybrid.montage.clone();
    decoder.hybrid = Some(hybrid);
    Ok((decoder, report))
}

/// What the continuous decoder's calibration found, as `errp run` prints
/// it, with its operating point on the held-out session.
pub fn epuck_decoder_summary(decoder: &ContinuousDecoder, report: &ContinuousReport) -> String {
    let acc = report.calibrated.accuracy;
    let mut text = decoder
        .own_eeg
        .as_ref()
        .map(|r| format!("{r}\n"))
        .unwrap_or_default();
    text += &format!(
        "SVM decoder calibrated on {} error + {} correct button-locked examples: correct {:.2} %, \
         error {:.2} %, mean {:.2} % (cross-validated); {} support vectors\n",
        acc.n_error,
        acc.n_correct,
        100.0 * acc.correct,
        100.0 * acc.error,
        100.0 * acc.mean(),
        decoder.model.n_support()
    );
    if let Some(online) = &decoder.online {
        text.push_str(&online.to_string());
    }
    text
}
