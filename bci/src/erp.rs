//! Event-related potential templates: the ErrP and the correct-action ERP.

use serde::Deserialize;

use crate::error::{BciError, Result};
use crate::montage::Montage;

const WAVEFORMS_TOML: &str = include_str!("../../assets/errp_waveforms.toml");

/// How the user assessed an action.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AssessmentKind {
    /// The action was judged correct.
    Correct,
    /// The action was judged erroneous: an ErrP follows.
    Error,
}

/// One Gaussian component of a waveform.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Component {
    /// Peak amplitude at the centre electrode (uV).
    pub amplitude_uv: f64,
    /// Peak latency after the action onset (ms).
    pub latency_ms: f64,
    /// Gaussian standard deviation (ms).
    pub width_ms: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TemplatesFile {
    topography: TopographyFile,
    error: Vec<Component>,
    correct: Vec<Component>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TopographyFile {
    centre: String,
    width_rad: f64,
}

/// The error and correct waveforms and their scalp distribution, as shipped in
/// `assets/errp_waveforms.toml` (the file documents every amplitude).
#[derive(Debug, Clone, PartialEq)]
pub struct ErpTemplates {
    /// Components of the ERP after an erroneous assessment.
    pub error: Vec<Component>,
    /// Components of the ERP after a correct assessment.
    pub correct: Vec<Component>,
    /// Electrode where both waveforms are largest.
    pub centre: String,
    /// Gaussian fall-off (radians on the unit head sphere) around the centre.
    pub width_rad: f64,
}

impl Default for ErpTemplates {
    fn default() -> Self {
        Self::builtin().expect("assets/errp_waveforms.toml is valid")
    }
}

impl ErpTemplates {
    /// The shipped templates.
    pub fn builtin() -> Result<Self> {
        let file: TemplatesFile = toml::from_str(WAVEFORMS_TOML).map_err(|e| BciError::Asset {
            file: "errp_waveforms.toml",
            message: e.to_string(),
        })?;
        Ok(Self {
            error: file.error,
            correct: file.correct,
            centre: file.topography.centre,
            width_rad: file.topography.width_rad,
        })
    }

    /// Components for one assessment kind.
    pub fn components(&self, kind: AssessmentKind) -> &[Component] {
        match kind {
            AssessmentKind::Error => &self.error,
            AssessmentKind::Correct => &self.correct,
        }
    }

    /// Waveform at the centre electrode (uV) at `t_ms` after the onset, with
    /// no jitter.
    pub fn value(&self, kind: AssessmentKind, t_ms: f64) -> f64 {
        waveform(self.components(kind), t_ms)
    }

    /// Largest |error - correct| at the centre electrode over [0, 1000] ms.
    pub fn difference_peak_uv(&self) -> f64 {
        (0..=1000)
            .map(|t| {
                let t = t as f64;
                (self.value(AssessmentKind::Error, t) - self.value(AssessmentKind::Correct, t))
                    .abs()
            })
            .fold(0.0, f64::max)
    }

    /// Relative amplitude at every channel of `montage` (1 at the centre);
    /// zero on EOG channels. Shape `(n_channels,)`.
    pub fn topography(&self, montage: &Montage) -> Result<Vec<f64>> {
        let centre = montage.index(&self.centre)?;
        let n_eeg = montage.n_eeg();
        Ok((0..montage.len())
            .map(|ch| {
                if ch >= n_eeg {
                    0.0
                } else {
                    let d = montage.angular_distance(ch, centre);
                    (-0.5 * (d / self.width_rad).powi(2)).exp()
                }
            })
            .collect())
    }
}

/// Sum of Gaussian components at `t_ms`.
pub(crate) fn waveform(components: &[Component], t_ms: f64) -> f64 {
    components
        .iter()
        .map(|c| {
            let z = (t_ms - c.latency_ms) / c.width_ms;
            c.amplitude_uv * (-0.5 * z * z).exp()
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn difference_wave_has_the_three_components_of_fig1() {
        let t = ErpTemplates::default();
        let diff =
            |ms: f64| t.value(AssessmentKind::Error, ms) - t.value(AssessmentKind::Correct, ms);
        assert!(diff(250.0) < -2.0);
        assert!(diff(350.0) > 3.0);
        assert!(diff(455.0) < -2.0);
        assert!(diff(0.0).abs() < 0.01 && diff(900.0).abs() < 0.01);
    }

    #[test]
    fn topography_peaks_at_fcz_and_falls_off() {
        let m = Montage::standard();
        let topo = ErpTemplates::default().topography(&m).unwrap();
        let at = |n: &str| topo[m.index(n).unwrap()];
        assert!((at("FCz") - 1.0).abs() < 1e-12);
        assert!(at("Cz") > at("Pz") && at("Pz") > at("Oz"));
        assert_eq!(at("EOG LA"), 0.0);
    }
}
