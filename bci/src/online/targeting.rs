//! Calibrating for an online operating point (a hit rate, and optionally false
//! alarms per minute) instead of a cross-validated accuracy.

use serde::{Deserialize, Serialize};

use errp_valid::{Check, Valid};

use super::detector::{Detector, DetectorParams};
use super::held_out::{HeldOutSession, OperatingPoint, detector_span, operating_point};
use crate::calibration::TargetingParams;
use crate::error::{BciError, Result, check};

/// An online operating point to calibrate for, instead of a cross-validated
/// accuracy: the detector's hit rate per ErrP on the held-out session, and
/// optionally its false alarms per minute (then T_e is calibrated too, as a
/// personal decision threshold).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OnlineTarget {
    /// Requested hit rate per ErrP, in (0, 1).
    pub hit_rate: f64,
    /// Requested false alarms per minute of error-free time, in (0, 60];
    /// `None`: keep the given T_e.
    pub false_alarms_per_min: Option<f64>,
}

/// Checked where a scenario enters; the search takes it checked.
impl Check for OnlineTarget {
    type Error = BciError;

    fn check(&self) -> Result<()> {
        self.validate()
    }
}

impl OnlineTarget {
    /// Checks both fields; names them as the scenario's `[user]` does.
    fn validate(&self) -> Result<()> {
        check(
            self.hit_rate.is_finite() && self.hit_rate > 0.0 && self.hit_rate < 1.0,
            "hit_rate",
            self.hit_rate,
            "a hit rate per ErrP in (0, 1), e.g. 0.9",
        )?;
        if let Some(f) = self.false_alarms_per_min {
            check(
                f.is_finite() && f > 0.0 && f <= 60.0,
                "false_alarms_per_min",
                f,
                "a rate in (0, 60] per minute, e.g. 0.5",
            )?;
        }
        Ok(())
    }
}

/// One evaluation of [`target_online`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OnlineStep {
    /// ErrP-to-noise ratio tried.
    pub ratio: f64,
    /// T_e used (calibrated when false alarms are targeted).
    pub t_e: f64,
    /// The operating point reached.
    pub point: OperatingPoint,
}

/// The outcome of [`target_online`]: the ratio and T_e whose operating point
/// is closest to the request, and every evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct OnlineTargeting {
    /// What was asked for.
    pub target: OnlineTarget,
    /// The ratio found.
    pub ratio: f64,
    /// The T_e found (or the one given).
    pub t_e: f64,
    /// The operating point there.
    pub point: OperatingPoint,
    /// Every evaluation, in order.
    pub steps: Vec<OnlineStep>,
}

/// T_e in [0.5, 0.999] at which `detector` gives `false_alarms_per_min` on
/// `recording` (bisection: false alarms fall as T_e rises), with the
/// operating point there, scored over the span measured at that T_e.
pub fn threshold_for_false_alarms(
    recording: &HeldOutSession,
    detector: Valid<DetectorParams>,
    false_alarms_per_min: f64,
) -> Result<(f64, OperatingPoint)> {
    let at = |t_e: f64| -> Result<OperatingPoint> {
        let span = detector_span(recording, detector, t_e)?;
        Ok(operating_point(
            recording,
            Detector::new(detector, t_e)?,
            span,
        ))
    };
    let (mut lo, mut hi) = (0.5, 0.999);
    let mut best = (hi, at(hi)?);
    for _ in 0..18 {
        let mid = 0.5 * (lo + hi);
        let p = at(mid)?;
        if (p.false_alarms_per_min - false_alarms_per_min).abs()
            < (best.1.false_alarms_per_min - false_alarms_per_min).abs()
        {
            best = (mid, p);
        }
        if p.false_alarms_per_min > false_alarms_per_min {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(best)
}

/// Searches the ErrP-to-noise ratio (and T_e, if false alarms are targeted)
/// at which the detector's operating point on the held-out session meets
/// `target`. `evaluate(ratio)` calibrates the decoder at that ratio and
/// returns its held-out session; the hit rate rises with the ratio, so the
/// search brackets it by doubling from 0.25 (up to `search.max_ratio`) and
/// then bisects until the hit rate is within `search.tolerance` (of a hit
/// rate) or `search.max_evaluations` are spent. Returns the closest
/// evaluation.
/// Errors of `evaluate` pass through (any error type a [`BciError`]
/// converts into).
///
/// [`BciError`]: crate::BciError
pub fn target_online<E: From<crate::error::BciError>>(
    target: Valid<OnlineTarget>,
    detector: Valid<DetectorParams>,
    t_e: f64,
    search: &TargetingParams,
    mut evaluate: impl FnMut(f64) -> std::result::Result<HeldOutSession, E>,
    mut progress: impl FnMut(&OnlineStep),
) -> std::result::Result<OnlineTargeting, E> {
    let mut steps: Vec<OnlineStep> = Vec::new();
    let mut eval = |ratio: f64, steps: &mut Vec<OnlineStep>| -> std::result::Result<f64, E> {
        let recording = evaluate(ratio)?;
        let (t, point) = match target.false_alarms_per_min {
            Some(f) => threshold_for_false_alarms(&recording, detector, f)?,
            None => {
                let span = detector_span(&recording, detector, t_e)?;
                (
                    t_e,
                    operating_point(&recording, Detector::new(detector, t_e)?, span),
                )
            }
        };
        let step = OnlineStep {
            ratio,
            t_e: t,
            point,
        };
        progress(&step);
        steps.push(step);
        Ok(point.hit_rate)
    };
    let (max_ratio, tolerance, max_evaluations) =
        (search.max_ratio, search.tolerance, search.max_evaluations);
    let close = |h: f64| (h - target.hit_rate).abs() <= tolerance;
    let (mut lo, mut hi) = (0.0, 0.25);
    let mut hit = eval(hi, &mut steps)?;
    while hit < target.hit_rate && !close(hit) {
        if hi >= max_ratio || steps.len() >= max_evaluations {
            return Err(crate::error::BciError::InvalidParameter {
                name: "hit_rate",
                value: target.hit_rate.to_string(),
                expected: format!(
                    "a hit rate the detector can reach: it catches {:.1} % of ErrPs at the \
                     largest ErrP-to-noise ratio tried ({hi})",
                    100.0 * hit
                ),
            }
            .into());
        }
        lo = hi;
        hi = (hi * 2.0).min(max_ratio);
        hit = eval(hi, &mut steps)?;
    }
    while !close(hit) && steps.len() < max_evaluations {
        let mid = 0.5 * (lo + hi);
        hit = eval(mid, &mut steps)?;
        if hit < target.hit_rate {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let best = *steps
        .iter()
        .min_by(|a, b| {
            (a.point.hit_rate - target.hit_rate)
                .abs()
                .total_cmp(&(b.point.hit_rate - target.hit_rate).abs())
        })
        .expect("at least one evaluation");
    if !close(best.point.hit_rate) && best.point.hit_rate > target.hit_rate {
        // Every ratio down to almost none catches more: the detector's
        // chance hits at this threshold (a high false-alarm rate) are
        // above the target.
        let fa = target
            .false_alarms_per_min
            .map_or(String::new(), |f| format!(" at {f} false alarms a minute"));
        return Err(crate::error::BciError::InvalidParameter {
            name: "hit_rate",
            value: target.hit_rate.to_string(),
            expected: format!(
                "a hit rate the detector can reach{fa}: it catches at least {:.1} % of ErrPs \
                 there, by chance, with almost no ErrP in the EEG; ask for more{}",
                100.0 * best.point.hit_rate,
                if target.false_alarms_per_min.is_some() {
                    ", or for fewer false alarms a minute"
                } else {
                    ""
                }
            ),
        }
        .into());
    }
    Ok(OnlineTargeting {
        target: *target,
        ratio: best.ratio,
        t_e: best.t_e,
        point: best.point,
        steps,
    })
}
