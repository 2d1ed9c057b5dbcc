//! What a scenario asks of its decoder: the accuracy or online operating
//! point it is calibrated for, the detector that reads it, and what a
//! scenario on own EEG cannot ask ([`rules`]).

use std::path::Path;

use errp_bci::{DetectorMode, DetectorParams, MeanAccuracy, OnlineTarget, RequestedAccuracy};
use errp_robot::Valid;

use crate::epuck::schema::{DetectorFile, UserFile};
use crate::error::{Result, SimError};
use crate::own_eeg::OwnEegSpec;
use crate::rules::{self, Claim, Origin};
use crate::scenario_file::{field_error, whole};
use crate::task_kind::TaskKind;

/// A parameter error of `errp_bci` as a field error of the scenario's
/// `[table]`.
pub(super) fn table_error(path: &Path, table: &str, e: errp_bci::BciError) -> SimError {
    match e {
        errp_bci::BciError::InvalidParameter {
            name,
            value,
            expected,
        } => field_error(path, &format!("{table}.{name}"), value, &expected),
        other => SimError::Scenario(format!("{}: [{table}] {other}", path.display())),
    }
}

/// The accuracy an e-puck scenario on own EEG holds until its decoder
/// is calibrated (nothing reads it: the control assumes the one the EEG
/// gives).
pub(super) const OWN_EEG_PLACEHOLDER_ACCURACY: f64 = 0.75;

/// What a scenario on own EEG is also given, as its file writes it, in
/// the order [`rules::own_eeg_is_the_user`] reports them: a decoder target
/// (own EEG has the accuracy it gives) and T_e (set for a
/// false-alarm rate on the own EEG).
pub(super) fn refuse_with_own_eeg(
    u: &UserFile,
    t_e_given: bool,
    own: &OwnEegSpec,
    path: &Path,
) -> Result<()> {
    let at = Origin::Scenario(path);
    let mut claims = Vec::new();
    if let Some(a) = u.accuracy {
        claims.push((Claim::Accuracy(a), at));
    }
    if let Some(h) = u.hit_rate {
        claims.push((Claim::HitRate(h), at));
    }
    if let Some(f) = u.false_alarms_per_min {
        claims.push((Claim::FalseAlarmsPerMin(f), at));
    }
    if t_e_given {
        claims.push((Claim::DetectorThreshold, at));
    }
    rules::own_eeg_is_the_user(Some(own.origin(path, TaskKind::Epuck)), &claims)
}

/// The decoder a `[user]` table asks for: a cross-validated accuracy, or an
/// online operating point (a hit rate and, optionally, false alarms per
/// minute, when the file sets no `control.t_e`: `t_e_given`), with the
/// accuracy the device assumes (info gain).
pub(super) fn decoder_target(
    u: &UserFile,
    t_e_given: bool,
    path: &Path,
) -> Result<(Option<Valid<OnlineTarget>>, MeanAccuracy)> {
    let bad =
        |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
    // The accuracy the device assumes (info gain): the cross-validated
    // accuracy, or the targeted hit rate.
    match (u.accuracy, u.hit_rate, u.false_alarms_per_min) {
        (Some(a), None, None) => {
            match rules::accuracy_for(TaskKind::Epuck, false, a, Origin::Scenario(path))? {
                RequestedAccuracy::Targeted(a) => Ok((None, a)),
                RequestedAccuracy::Perfect => unreachable!("the rule refuses a perfect e-puck"),
            }
        }
        (None, Some(h), fa) => {
            let target = OnlineTarget {
                hit_rate: h,
                false_alarms_per_min: fa,
            };
            // Checked here, once: the search takes it checked.
            let target = Valid::new(target).map_err(|e| table_error(path, "user", e))?;
            if fa.is_some() && t_e_given {
                return Err(bad(
                    "control.t_e",
                    "given".into(),
                    "no t_e when user.false_alarms_per_min is given: T_e is then \
                     calibrated to meet that false-alarm rate",
                ));
            }
            // A hit rate is below 1, so this is a mean accuracy.
            let assumed = MeanAccuracy::new(h.max(0.51))
                .map_err(|_| bad("user.hit_rate", h.to_string(), "a hit rate in (0, 1)"))?;
            Ok((Some(target), assumed))
        }
        (None, None, Some(f)) => Err(bad(
            "user.false_alarms_per_min",
            f.to_string(),
            "user.hit_rate beside it (an online operating point is a hit rate and, \
                 optionally, a false-alarm rate)",
        )),
        (None, None, None) => Err(bad(
            "user.accuracy",
            "missing".into(),
            "the decoder: accuracy = A (cross-validated mean accuracy in (0.5, 1)) or \
                 hit_rate = H [and false_alarms_per_min = F] (the online operating point)",
        )),
        (Some(a), _, _) => Err(bad(
            "user.accuracy",
            a.to_string(),
            "either accuracy or hit_rate [and false_alarms_per_min], not both",
        )),
    }
}

/// The detector of a `[detector]` table (literal or smoothed, on the
/// defaults), checked once.
pub(super) fn detector_params(d: &DetectorFile, path: &Path) -> Result<Valid<DetectorParams>> {
    let bad =
        |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
    let mut p = DetectorParams::default();
    if let Some(m) = d.mode {
        p = match m {
            DetectorMode::Literal => DetectorParams::literal().into_inner(),
            DetectorMode::Smoothed => DetectorParams::default(),
        };
    }
    if let Some(n) = d.smooth_windows {
        p.smooth_windows = whole(
            path,
            "detector.smooth_windows",
            n,
            1,
            16,
            " windows (up to 1 s of 62.5 ms steps)",
        )?;
    }
    if let Some(r) = d.refractory_secs {
        p.refractory_secs = r;
    }
    if p.mode == DetectorMode::Literal
        && (d.smooth_windows.is_some() || d.refractory_secs.is_some())
    {
        return Err(bad(
            "detector.mode",
            "\"literal\"".into(),
            "\"smoothed\" when smooth_windows or refractory_secs is given (the \
             literal reading compares each window with T_e on its own)",
        ));
    }
    // Checked here, once: episodes and detectors take it checked.
    Valid::new(p).map_err(|e| table_error(path, "detector", e))
}
