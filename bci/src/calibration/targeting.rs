//! Accuracy targeting: find the ErrP-to-noise ratio at which the real
//! decoder's cross-validated mean accuracy equals a requested value.

use errp_valid::Valid;
use serde::{Deserialize, Serialize};

use crate::calibration::continuous::{ContinuousSetup, simulate_continuous_session};
use crate::calibration::{
    Accuracy, CalibrationSession, CalibrationSetup, SessionOptions, TargetingParams,
    cross_validate, cv_seed, simulate_session,
};
use crate::classify::{Classifier, Features};
use crate::error::{BciError, Result, check};
use crate::generator::Components;
use crate::svm::SvmDecoder;

/// One evaluation of the search.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TargetingStep {
    /// ErrP-to-noise ratio tried.
    pub ratio: f64,
    /// Cross-validated accuracy there.
    pub accuracy: Accuracy,
}

/// Outcome of a search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TargetingResult {
    /// Requested mean accuracy.
    pub requested: f64,
    /// The ratio found.
    pub ratio: f64,
    /// Cross-validated accuracy at that ratio.
    pub accuracy: Accuracy,
    /// Every evaluation, in order.
    pub steps: Vec<TargetingStep>,
}

/// An ErrP-to-noise ratio as a message shows it: in full, or in
/// scientific notation when it is far from 1 (a damaged 1e308 is not 309
/// digits).
pub fn ratio_text(ratio: f64) -> String {
    if ratio != 0.0 && !(1e-4..1e4).contains(&ratio.abs()) {
        format!("{ratio:e}")
    } else {
        ratio.to_string()
    }
}

impl TargetingResult {
    /// Why this result (read back from a cache, say) cannot be the one
    /// its search found, given `recomputed`, the accuracy its ratio gives
    /// when evaluated again: `None` if it can.
    ///
    /// The ratio must be a positive finite number; the accuracy it gives
    /// must be the one the result records, within `search.tolerance`; and
    /// it must be within that tolerance of the request, unless the search
    /// used every evaluation it had (it then returns its closest).
    pub fn inconsistency(&self, recomputed: Accuracy, search: &TargetingParams) -> Option<String> {
        let (got, kept) = (recomputed.mean(), self.accuracy.mean());
        if !(self.ratio.is_finite() && self.ratio > 0.0) {
            return Some(format!(
                "its ErrP-to-noise ratio {} is not a positive number",
                ratio_text(self.ratio)
            ));
        }
        if !(got - kept).abs().le(&search.tolerance) {
            return Some(format!(
                "its ratio {} gives {:.2} % again, not the {:.2} % it records",
                ratio_text(self.ratio),
                100.0 * got,
                100.0 * kept
            ));
        }
        let exhausted = self.steps.len() >= search.max_evaluations;
        if !(got - self.requested).abs().le(&search.tolerance) && !exhausted {
            return Some(format!(
                "its ratio {} gives {:.2} %, not the {:.2} % requested",
                ratio_text(self.ratio),
                100.0 * got,
                100.0 * self.requested
            ));
        }
        None
    }
}

/// A requested mean accuracy (the mean of the correct- and error-class
/// rates), checked once where it enters: strictly between chance (0.5) and
/// perfect (1), the range a real decoder can be targeted at. Every function
/// that targets an accuracy takes one, so none checks it again.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Serialize, Deserialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct MeanAccuracy(f64);

impl MeanAccuracy {
    /// `value` if it is in (0.5, 1); otherwise an
    /// [`InvalidParameter`](BciError::InvalidParameter) naming `accuracy`
    /// and the range.
    pub fn new(value: f64) -> Result<Self> {
        check(
            value.is_finite() && value > 0.5 && value < 1.0,
            "accuracy",
            value,
            "a mean accuracy strictly between 0.5 (chance) and 1, e.g. 0.7438",
        )?;
        Ok(Self(value))
    }

    /// The accuracy.
    pub const fn get(self) -> f64 {
        self.0
    }
}

impl TryFrom<f64> for MeanAccuracy {
    type Error = BciError;

    fn try_from(value: f64) -> Result<Self> {
        Self::new(value)
    }
}

impl From<MeanAccuracy> for f64 {
    fn from(a: MeanAccuracy) -> f64 {
        a.0
    }
}

impl std::fmt::Display for MeanAccuracy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// An accuracy a decoder may be asked for: a [`MeanAccuracy`] in (0.5, 1),
/// which an EEG decoder is targeted at, or exactly 1, which only the grid's
/// oracle decoder can be. The one statement of that rule: scenario files,
/// `errp run --accuracy` and sweep levels all check it here (which decoder
/// may be perfect is the task's to say).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RequestedAccuracy {
    /// A real decoder's target.
    Targeted(MeanAccuracy),
    /// A perfect decoder: the grid's oracle.
    Perfect,
}

impl RequestedAccuracy {
    /// The accepted values, in words.
    pub const RANGE: &'static str = "a mean accuracy strictly between 0.5 (chance) and 1, e.g. 0.7438, or 1 for the \
         grid's oracle decoder";

    /// `value` if it is in (0.5, 1] ; otherwise an
    /// [`InvalidParameter`](BciError::InvalidParameter) naming `accuracy`
    /// and [`RANGE`](Self::RANGE).
    pub fn new(value: f64) -> Result<Self> {
        if value == 1.0 {
            return Ok(Self::Perfect);
        }
        MeanAccuracy::new(value).map(Self::Targeted).or_else(|_| {
            check(false, "accuracy", value, Self::RANGE)?;
            unreachable!("check(false, ..) is an error")
        })
    }

    /// The accuracy.
    pub fn get(self) -> f64 {
        match self {
            Self::Targeted(a) => a.get(),
            Self::Perfect => 1.0,
        }
    }

    /// The target of a real decoder, if this is one.
    pub fn targeted(self) -> Option<MeanAccuracy> {
        match self {
            Self::Targeted(a) => Some(a),
            Self::Perfect => None,
        }
    }
}

/// Searches the ErrP-to-noise ratio of `params` so that `classifier`,
/// trained on a calibration session simulated from `seed`, scores `requested`
/// (mean of the per-class rates) in cross-validation.
///
/// The preprocessing and the features are linear in the signal and the
/// generator's parts add up exactly, so the session is simulated once as
/// background + artifacts and once as ERPs at ratio 1; the features at ratio r
/// are then `background + r * erp` and each step costs one cross-validation.
/// The search brackets the target, then interpolates on the probit scale
/// (accuracy ~ Phi(c r) for an ideal observer), bisecting when that stalls.
pub fn target_accuracy<C: Classifier>(
    requested: MeanAccuracy,
    classifier: &C,
    setup: &Valid<CalibrationSetup>,
    search: &TargetingParams,
    seed: u64,
    progress: impl FnMut(&TargetingStep),
) -> Result<TargetingResult> {
    let parts = SessionParts::simulate(setup, seed)?;
    target_accuracy_on(&parts, requested, classifier, setup, search, seed, progress)
}

/// [`target_accuracy`] on a session already simulated as its parts (e.g.
/// shared by every level of a sweep).
pub fn target_accuracy_on<C: Classifier>(
    parts: &SessionParts,
    requested: MeanAccuracy,
    classifier: &C,
    setup: &Valid<CalibrationSetup>,
    search: &TargetingParams,
    seed: u64,
    progress: impl FnMut(&TargetingStep),
) -> Result<TargetingResult> {
    let labels = &parts.noise.labels;
    let cv_seed = cv_seed(seed);
    search_ratio(
        requested,
        search,
        |ratio| {
            cross_validate(
                classifier,
                &parts.features_at(ratio),
                labels,
                setup.calibration.folds,
                cv_seed,
            )
        },
        progress,
    )
}

/// A discrete calibration session simulated once, in two parts that add up
/// to the session at any ErrP-to-noise ratio r: background + artifacts, and
/// the ERPs at ratio 1. The preprocessing and the features are linear in the
/// signal and the generator's parts add up exactly, so the session's
/// features at r are `noise + r * erp` (to rounding), and the preprocessor
/// (fitted on an EOG session without ERPs) does not depend on r.
#[derive(Debug, Clone)]
pub struct SessionParts {
    noise: CalibrationSession,
    erp: Features,
}

impl SessionParts {
    /// Simulates both parts of the session of `setup` (whose ratio is
    /// ignored) from `seed`.
    pub fn simulate(setup: &Valid<CalibrationSetup>, seed: u64) -> Result<Self> {
        Self::from_parts(
            Self::simulate_part(setup, seed, false)?,
            Self::simulate_part(setup, seed, true)?,
        )
    }

    /// One part of [`SessionParts::simulate`]: the ERPs at ratio 1 if
    /// `erp`, else background + artifacts (the two can run in parallel).
    pub fn simulate_part(
        setup: &Valid<CalibrationSetup>,
        seed: u64,
        erp: bool,
    ) -> Result<CalibrationSession> {
        simulate_session(
            &Valid::new(setup.at_ratio(1.0)?)?,
            seed,
            SessionOptions {
                components: Components {
                    background: !erp,
                    artifacts: !erp,
                    erp,
                },
                ..SessionOptions::default()
            },
        )
    }

    /// Joins the two parts of one session (same setup and seed).
    pub fn from_parts(noise: CalibrationSession, erp: CalibrationSession) -> Result<Self> {
        if noise.labels != erp.labels || noise.features.shape() != erp.features.shape() {
            return Err(BciError::Training(
                "the noise and ERP parts are not of the same session".into(),
            ));
        }
        Ok(Self {
            noise,
            erp: erp.features,
        })
    }

    /// The preprocessor fitted on the calibration's EOG session (the same at
    /// every ratio).
    pub fn preprocessor(&self) -> &crate::Preprocessor {
        &self.noise.preprocessor
    }

    /// The session's features at `ratio`, `(n_actions, n_features)`.
    pub fn features_at(&self, ratio: f64) -> Features {
        &self.noise.features + &self.erp * ratio
    }

    /// The whole session at `ratio`, as [`simulate_session`] gives it (to
    /// rounding; no grand averages).
    pub fn session_at(&self, ratio: f64) -> CalibrationSession {
        CalibrationSession {
            features: self.features_at(ratio),
            ..self.noise.clone()
        }
    }
}

/// The continuous decoder's [`target_accuracy`]: the ErrP-to-noise ratio at
/// which `classifier`, trained on a continuous calibration session simulated
/// from `seed` (sec. 5.1), scores `requested` in cross-validation.
///
/// The PSD features are not linear in the signal, so each step re-simulates
/// the session at the ratio tried (same seed: the same background, artifacts,
/// schedule and button presses) and cross-validates on it, with the folds of
/// [`calibrate_continuous`](crate::calibrate_continuous).
pub fn target_continuous_accuracy(
    requested: MeanAccuracy,
    classifier: &SvmDecoder,
    setup: &Valid<ContinuousSetup>,
    search: &TargetingParams,
    seed: u64,
    progress: impl FnMut(&TargetingStep),
) -> Result<TargetingResult> {
    let cv_seed = cv_seed(seed);
    search_ratio(
        requested,
        search,
        |ratio| {
            let at = Valid::new(setup.at_ratio(ratio)?)?;
            let s = simulate_continuous_session(&at, seed, SessionOptions::default())?;
            cross_validate(
                classifier,
                &s.features,
                &s.labels,
                setup.calibration.folds,
                cv_seed,
            )
        },
        progress,
    )
}

/// The search of the targeting functions, over any evaluation of the mean
/// accuracy at an ErrP-to-noise ratio: it brackets `requested` (from 0.25,
/// doubling up to `search.max_ratio`; ratio 0 is taken as chance), then
/// interpolates on the probit scale (accuracy ~ Phi(c r) for an ideal
/// observer), bisecting when that stalls, until within `search.tolerance` or
/// `search.max_evaluations`. Returns the closest evaluation.
pub fn search_ratio(
    requested: MeanAccuracy,
    search: &TargetingParams,
    mut evaluate: impl FnMut(f64) -> Result<Accuracy>,
    mut progress: impl FnMut(&TargetingStep),
) -> Result<TargetingResult> {
    let requested = requested.get();
    let mut steps: Vec<TargetingStep> = Vec::new();
    let mut evaluate = |ratio: f64, steps: &mut Vec<TargetingStep>| -> Result<f64> {
        crate::stop::check()?;
        let accuracy = evaluate(ratio)?;
        let step = TargetingStep { ratio, accuracy };
        progress(&step);
        steps.push(step);
        Ok(accuracy.mean())
    };
    let close = |acc: f64| (acc - requested).abs() <= search.tolerance;

    // Bracket: lo scores below the target (ratio 0 is chance), hi above.
    let (mut lo, mut lo_acc) = (0.0, 0.5);
    let mut hi = 0.25;
    let mut hi_acc = evaluate(hi, &mut steps)?;
    while hi_acc < requested && !close(hi_acc) {
        if hi >= search.max_ratio || steps.len() >= search.max_evaluations {
            return Err(BciError::InvalidParameter {
                name: "accuracy",
                value: requested.to_string(),
                expected: format!(
                    "an accuracy the decoder can reach: it scores {:.2} % at the largest \
                     ErrP-to-noise ratio tried ({hi})",
                    100.0 * hi_acc
                ),
            });
        }
        (lo, lo_acc) = (hi, hi_acc);
        hi = (hi * 2.0).min(search.max_ratio);
        hi_acc = evaluate(hi, &mut steps)?;
    }
    let mut bisect_next = false;
    let mut last = hi_acc;
    while !close(last) && steps.len() < search.max_evaluations {
        let probit = |a: f64| inverse_normal_cdf(a.clamp(0.5 + 1e-6, 1.0 - 1e-6));
        let (zl, zh, zt) = (probit(lo_acc), probit(hi_acc), probit(requested));
        let mut r = if bisect_next || zh <= zl {
            0.5 * (lo + hi)
        } else {
            lo + (hi - lo) * (zt - zl) / (zh - zl)
        };
        // Stay well inside the bracket so that it always shrinks.
        let margin = 0.05 * (hi - lo);
        r = r.clamp(lo + margin, hi - margin);
        last = evaluate(r, &mut steps)?;
        let width = hi - lo;
        if last < requested {
            (lo, lo_acc) = (r, last);
        } else {
            (hi, hi_acc) = (r, last);
        }
        bisect_next = (hi - lo) > 0.6 * width;
    }
    let best = *steps
        .iter()
        .min_by(|a, b| {
            (a.accuracy.mean() - requested)
                .abs()
                .total_cmp(&(b.accuracy.mean() - requested).abs())
        })
        .expect("at least one evaluation");
    Ok(TargetingResult {
        requested,
        ratio: best.ratio,
        accuracy: best.accuracy,
        steps,
    })
}

/// Inverse of the standard normal CDF (Acklam's rational approximation,
/// relative error below 1.2e-9).
pub fn inverse_normal_cdf(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let p_low = 0.024_25;
    if p < p_low {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else if p <= 1.0 - p_low {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        -inverse_normal_cdf(1.0 - p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_normal_cdf_known_values() {
        assert!(inverse_normal_cdf(0.5).abs() < 1e-9);
        assert!((inverse_normal_cdf(0.975) - 1.959_963_985).abs() < 1e-6);
        assert!((inverse_normal_cdf(0.01) + 2.326_347_874).abs() < 1e-6);
    }

    #[test]
    fn requested_accuracy_must_be_above_chance_and_below_one() {
        for bad in [0.5, 1.0, 1.7, -0.2, f64::NAN] {
            let err = MeanAccuracy::new(bad).unwrap_err().to_string();
            assert!(err.contains("accuracy"), "{err}");
        }
        assert_eq!(MeanAccuracy::new(0.7438).unwrap().get(), 0.7438);
        // Deserialized values are checked too.
        let parse =
            |text: &str| toml::from_str::<std::collections::BTreeMap<String, MeanAccuracy>>(text);
        assert_eq!(parse("a = 0.7438").unwrap()["a"].get(), 0.7438);
        assert!(parse("a = 0.4").is_err());
    }
}
