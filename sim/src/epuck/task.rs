//! The e-puck task as a [`Task`]: what a sweep runs at one level.

use std::sync::Arc;

use crate::calibration::TargetingCache;
use crate::epuck::decoder::ContinuousDecoder;
use errp_robot::GoalLayout;

use crate::epuck::episode::{EpuckEpisodeResult, run_epuck_episode};
use crate::epuck::run::prepare_epuck_decoder;
use crate::epuck::scenario::EpuckScenario;
use crate::error::Result;
use crate::key::StableKey;
use crate::paper::PAPER_EPUCK;
use crate::task::{
    ColumnKind, DecoderInfo, EpisodeColumn, EpisodeRow, FieldError, FigureText, PaperPoint, Task,
    TaskInfo, format_number, rate_field,
};
use crate::task_kind::TaskKind;

/// One e-puck run as the task's row of `episodes.csv`: its
/// [`TaskInfo::columns`] (cities named from `layout`), success and online
/// accuracy.
pub fn epuck_row(layout: &GoalLayout, r: &EpuckEpisodeResult) -> EpisodeRow {
    let names = layout.names();
    let fields = vec![
        names[r.goal].to_string(),
        r.committed.map_or(String::new(), |c| names[c].to_string()),
        format_number(r.time_secs),
        format_number(r.path_m),
        r.errps.to_string(),
        r.detected_errors.to_string(),
        r.false_detections.to_string(),
        r.missed_errors.to_string(),
        r.detected_by_phase[0].to_string(),
        r.detected_by_phase[1].to_string(),
        r.detected_by_phase[2].to_string(),
        rate_field(r.hit_rate()),
        rate_field(r.false_alarms_per_min()),
    ];
    EpisodeRow {
        success: r.reached(),
        fields,
        online: r.online,
    }
}

/// The continuous e-puck (sec. 5): the cost is seconds to convergence.
#[derive(Debug, Clone, Copy)]
pub struct EpuckTask;

/// An e-puck level: its scenario and decoder.
#[derive(Debug)]
pub struct EpuckRunner {
    scenario: EpuckScenario,
    decoder: Arc<ContinuousDecoder>,
}

impl Task for EpuckTask {
    const INFO: TaskInfo = TaskInfo {
        kind: TaskKind::Epuck,
        columns: &[
            EpisodeColumn::new("goal", ColumnKind::City),
            EpisodeColumn::new("committed", ColumnKind::OptCity),
            EpisodeColumn::new("time_secs", ColumnKind::NonNegative),
            EpisodeColumn::new("path_m", ColumnKind::NonNegative),
            EpisodeColumn::new("errps", ColumnKind::Count),
            EpisodeColumn::new("detected", ColumnKind::Count),
            EpisodeColumn::new("false_alarms", ColumnKind::Count),
            EpisodeColumn::new("missed", ColumnKind::Count),
            EpisodeColumn::new("detected_turning", ColumnKind::Count),
            EpisodeColumn::new("detected_driving", ColumnKind::Count),
            EpisodeColumn::new("detected_on_goal", ColumnKind::Count),
            EpisodeColumn::new("hit_rate", ColumnKind::OptRate),
            EpisodeColumn::new("false_alarms_per_min", ColumnKind::OptNonNegative),
        ],
        cost_column: "time_secs",
        cost_label: "time (s)",
        committed_column: "committed",
        detector_columns: Some(("hit_rate", "false_alarms_per_min")),
        rows_per_sync: 16,
        sweepable: &[
            ("t_e", "control.t_e"),
            ("k_turn", "control.k_turn"),
            ("k_p", "control.k_p"),
            ("k_n", "control.k_n"),
            ("sigma_deg", "control.sigma_deg"),
            ("p_c", "control.p_c"),
            ("stop_secs", "control.stop_secs"),
            ("drive_speed_fraction", "control.drive_speed_fraction"),
            ("turn_speed_fraction", "control.turn_speed_fraction"),
            ("strategy", "control.strategy"),
            ("fov_deg", "user.fov_deg"),
            ("reaction_latency_ms", "user.reaction_latency_ms"),
            ("reelicit_secs", "user.reelicit_secs"),
            ("max_secs", "max_secs"),
            ("rate_hz", "tracker.rate_hz"),
            ("position_noise_cm", "tracker.position_noise_cm"),
            ("heading_noise_deg", "tracker.heading_noise_deg"),
        ],
    };
    type Scenario = EpuckScenario;
    type Shared = ();
    type Decoder = ContinuousDecoder;
    type Runner = EpuckRunner;

    /// The held-out operating point, and with an online target the
    /// calibration itself, depend on the detector and T_e too.
    fn decoder_key(s: &EpuckScenario) -> String {
        let key = StableKey::new("epuck-decoder", 1);
        let key = match &s.own_eeg {
            None => key,
            Some(r) => key
                .text("recording", &r.file.display().to_string())
                .text("calibration", &format!("{:?}", r.part))
                .text("error", &r.names.error)
                .text("correct", &r.names.correct)
                .text(
                    "false_alarms_per_min",
                    &format!("{:?}", r.false_alarms_per_min),
                ),
        };
        key.float("accuracy", s.accuracy.get())
            .int("user_seed", s.user_seed)
            .value("online_target", &s.online_target)
            .value("detector", &s.params.detector)
            .float("t_e", s.params.control.t_e)
            .realism(&s.realism)
            .finish()
    }

    fn shared(_: &[&EpuckScenario]) -> Result<()> {
        Ok(())
    }

    fn prepare(
        s: &EpuckScenario,
        _: &(),
        cache: &dyn TargetingCache,
    ) -> Result<(ContinuousDecoder, DecoderInfo)> {
        let prepared = prepare_epuck_decoder(s, cache, |_| {}, |_| {})?;
        let a = prepared.report.calibrated.accuracy;
        let point = prepared.decoder.online.as_ref().map(|o| o.point);
        let own_eeg = prepared.decoder.own_eeg.as_deref();
        let info = DecoderInfo {
            // On a recording, the accuracy it gives (the control assumes it).
            accuracy: own_eeg.map_or(s.accuracy.get(), |r| r.accuracy),
            kind: if s.own_eeg.is_some() {
                "svm-hybrid".into()
            } else {
                "svm".into()
            },
            calibration_seed: s.user_seed,
            errp_to_noise: own_eeg.is_none().then_some(prepared.report.targeting.ratio),
            cv_correct: Some(a.correct),
            cv_error: Some(a.error),
            cv_mean: Some(a.mean()),
            online_hit_rate: point.map(|p| p.hit_rate),
            online_false_alarms_per_min: point.map(|p| p.false_alarms_per_min),
            own_eeg: own_eeg.map(|r| r.file.clone()),
            cached: prepared.cached,
        };
        Ok((prepared.decoder, info))
    }

    fn runner(s: &EpuckScenario, decoder: Arc<ContinuousDecoder>) -> Result<EpuckRunner> {
        Ok(EpuckRunner {
            scenario: s.clone(),
            decoder,
        })
    }

    fn run_episode(runner: &EpuckRunner, _k: usize, seed: u64) -> Result<EpisodeRow> {
        let s = &runner.scenario;
        let r = run_epuck_episode(s, &runner.decoder, seed, &mut ())?;
        Ok(epuck_row(&s.layout, &r))
    }

    /// The goal is the scenario's; success is a commitment to it; the
    /// detections by phase add up to all detections.
    fn check_fields(
        s: &EpuckScenario,
        _k: usize,
        success: bool,
        f: &[&str],
    ) -> std::result::Result<(), FieldError> {
        let goal = &s.layout.goals()[s.episode.goal].name;
        if f[0] != goal {
            return Err(FieldError {
                column: "goal",
                expected: format!("{goal}, the scenario's goal"),
            });
        }
        if success != (f[1] == goal) {
            return Err(FieldError {
                column: "committed",
                expected: format!("{goal} exactly when success is 1"),
            });
        }
        let count = |i: usize| f[i].parse::<u64>().unwrap_or(0);
        let detected = count(5);
        if count(8) + count(9) + count(10) != detected {
            return Err(FieldError {
                column: "detected_on_goal",
                expected: format!(
                    "a count that makes the detections by phase add up to detected = {detected}"
                ),
            });
        }
        if count(6) > detected {
            return Err(FieldError {
                column: "false_alarms",
                expected: format!("at most detected = {detected}"),
            });
        }
        Ok(())
    }

    fn figure(s: &EpuckScenario) -> FigureText {
        FigureText {
            task: format!("E-puck task, {}", s.name),
            decoder: "sliding-window SVM decoder".into(),
            cost_label: "time to convergence, s (successful episodes)".into(),
            paper: PAPER_EPUCK
                .iter()
                .filter(|(name, _, _)| *name == s.name)
                .map(|(name, secs, _)| PaperPoint {
                    label: name.to_string(),
                    // The paper gives no accuracy for its continuous
                    // decoder: drawn at the scenario's.
                    accuracy: s.accuracy.get(),
                    value: *secs,
                    sd: None,
                })
                .collect(),
            paper_label: format!(
                "paper, {} (one run; drawn at the scenario's {})",
                s.name,
                format_number(s.accuracy.get())
            ),
        }
    }
}
