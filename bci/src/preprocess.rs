//! Preprocessing as in sec. 2.1: notch, band-pass, CAR and EOG regression.

use errp_valid::{Check, Valid};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::error::{BciError, Result, check};
use crate::filter::{FilterBank, FilterChain};
use crate::generator::EegBlock;
use crate::montage::Montage;

/// Preprocessing parameters (sec. 2.1 of the paper).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PreprocessParams {
    /// Power-line notch (Hz).
    pub line_hz: f64,
    /// Band-pass lower edge (Hz).
    pub low_hz: f64,
    /// Band-pass upper edge (Hz).
    pub high_hz: f64,
}

impl Default for PreprocessParams {
    fn default() -> Self {
        Self {
            line_hz: 50.0,
            low_hz: 1.0,
            high_hz: 10.0,
        }
    }
}

/// The preprocessing at a sampling rate: what [`Preprocessor::fit`] takes,
/// checked (the band edges against the rate).
#[derive(Debug, Clone, PartialEq)]
pub struct Preprocessing {
    /// The filters.
    pub params: PreprocessParams,
    /// The sampling rate of the EEG it runs on (Hz).
    pub sfreq_hz: f64,
}

impl Check for Preprocessing {
    type Error = BciError;

    fn check(&self) -> Result<()> {
        self.params.validate(self.sfreq_hz)
    }
}

impl PreprocessParams {
    /// Checks the band edges against the sampling rate.
    fn validate(&self, sfreq_hz: f64) -> Result<()> {
        let nyq = sfreq_hz / 2.0;
        check(
            self.low_hz.is_finite() && self.low_hz > 0.0 && self.low_hz < self.high_hz,
            "low_hz",
            self.low_hz,
            "a frequency > 0 and below high_hz",
        )?;
        check(
            self.high_hz.is_finite() && self.high_hz < nyq,
            "high_hz",
            self.high_hz,
            &format!("a frequency below Nyquist ({nyq} Hz)"),
        )?;
        check(
            self.line_hz.is_finite() && self.line_hz > 0.0 && self.line_hz < nyq,
            "line_hz",
            self.line_hz,
            &format!("a frequency in (0, {nyq}) Hz"),
        )
    }
}

/// Seconds of filter start-up discarded before fitting the EOG regression.
const FIT_SKIP_SECS: f64 = 2.0;

/// A fitted, streaming preprocessor: raw EEG + EOG in, clean EEG out.
///
/// The paper filters, then re-references (CAR), then regresses out the
/// horizontal, vertical and radial EOG. All three are linear and the same
/// filter is applied to every channel, so they commute: the preprocessor first
/// applies one spatial matrix `(n_outputs, n_channels)` (CAR and EOG regression
/// together) and then filters only the output channels. The result is the
/// paper's pipeline, computed for the channels that are needed. Filters are
/// causal (online).
#[derive(Debug, Clone)]
pub struct Preprocessor {
    outputs: Vec<usize>,
    n_in: usize,
    spatial: Vec<f64>,
    chain: FilterChain,
    filters: FilterBank,
    eog_weights: DMatrix<f64>,
}

impl Preprocessor {
    /// Fits the EOG regression on `eog_session` (raw samples of every
    /// channel, ideally an EOG session with deliberate blinks and saccades) and
    /// returns a preprocessor producing the EEG channels `outputs`. A
    /// montage without EOG channels (own EEG that has none) gets no
    /// EOG regression: CAR and the filters only.
    pub fn fit(
        montage: &Montage,
        preprocessing: &Valid<Preprocessing>,
        eog_session: &EegBlock,
        outputs: &[usize],
    ) -> Result<Self> {
        let Preprocessing { params, sfreq_hz } = preprocessing.get();
        let sfreq_hz = *sfreq_hz;
        let n_eeg = montage.n_eeg();
        let n_ch = montage.len();
        if let Some(&bad) = outputs.iter().find(|&&o| o >= n_eeg) {
            return Err(BciError::InvalidParameter {
                name: "outputs",
                value: bad.to_string(),
                expected: format!("EEG channel indices below {n_eeg}"),
            });
        }
        let skip = (FIT_SKIP_SECS * sfreq_hz) as usize;
        if eog_session.n_samples < skip + (10.0 * sfreq_hz) as usize {
            return Err(BciError::Training(format!(
                "the EOG session has {} samples; at least {} s are needed",
                eog_session.n_samples,
                FIT_SKIP_SECS + 10.0
            )));
        }
        // A recording without EOG channels gets no EOG regression.
        let n_eog = montage.n_eog();
        let derivation = if n_eog == 0 {
            DMatrix::zeros(3, 0)
        } else {
            eog_derivation(montage)?
        };

        // Filter every channel, drop the start-up, then CAR and derive the EOG.
        let n = eog_session.n_samples - skip;
        let mut filtered = DMatrix::zeros(n_ch, n);
        for ch in 0..n_ch {
            let mut x = eog_session.channel(ch).to_vec();
            FilterChain::paper(params.line_hz, params.low_hz, params.high_hz, sfreq_hz)
                .process(&mut x);
            for (t, v) in x[skip..].iter().enumerate() {
                filtered[(ch, t)] = *v;
            }
        }
        let car = car_matrix(n_eeg);
        let eeg = &car * filtered.rows(0, n_eeg);
        let eog_weights = if n_eog == 0 {
            DMatrix::zeros(n_eeg, 3)
        } else {
            let eog = &derivation * filtered.rows(n_eeg, n_eog);
            // Least squares: eeg ~ B eog, B = eeg eog' (eog eog')^-1.
            let gram = &eog * eog.transpose();
            let gram_inv = gram
                .try_inverse()
                .ok_or_else(|| BciError::Training("the EOG derivations are collinear".into()))?;
            &eeg * eog.transpose() * gram_inv
        };

        // Spatial matrix on raw channels: [CAR | -B D].
        let mut full = DMatrix::zeros(n_eeg, n_ch);
        full.view_mut((0, 0), (n_eeg, n_eeg)).copy_from(&car);
        full.view_mut((0, n_eeg), (n_eeg, n_ch - n_eeg))
            .copy_from(&(-&eog_weights * &derivation));
        let mut spatial = Vec::with_capacity(outputs.len() * n_ch);
        for &o in outputs {
            spatial.extend(full.row(o).iter());
        }
        let chain = FilterChain::paper(params.line_hz, params.low_hz, params.high_hz, sfreq_hz);
        let filters = FilterBank::new(&chain, outputs.len());
        Ok(Self {
            outputs: outputs.to_vec(),
            n_in: n_ch,
            spatial,
            chain,
            filters,
            eog_weights,
        })
    }

    /// The spatial part alone (CAR and EOG regression), unfiltered:
    /// `(n_channels, n)` in, `(n_outputs, n)` out.
    pub fn apply_spatial(&self, raw: &EegBlock) -> EegBlock {
        assert_eq!(raw.n_channels, self.n_in, "channel count");
        let n = raw.n_samples;
        let mut out = EegBlock::zeros(self.outputs.len(), n);
        for o in 0..self.outputs.len() {
            let weights = &self.spatial[o * self.n_in..(o + 1) * self.n_in];
            let dst = &mut out.data[o * n..(o + 1) * n];
            for (ch, &w) in weights.iter().enumerate() {
                if w != 0.0 {
                    for (d, s) in dst.iter_mut().zip(raw.channel(ch)) {
                        *d += w * s;
                    }
                }
            }
        }
        out
    }

    /// A fresh copy of the temporal filter (notch + band-pass).
    pub fn filter(&self) -> FilterChain {
        self.chain.clone()
    }

    /// Output channel indices (into the montage).
    pub fn outputs(&self) -> &[usize] {
        &self.outputs
    }

    /// The fitted regression weights, `(n_eeg, 3)`: columns horizontal,
    /// vertical, radial EOG.
    pub fn eog_weights(&self) -> &DMatrix<f64> {
        &self.eog_weights
    }

    /// Clears filter state (a new signal starts).
    pub fn reset(&mut self) {
        self.filters.reset();
    }

    /// Preprocesses the next block of raw samples; shape in
    /// `(n_channels, n)`, out `(n_outputs, n)`. State carries across calls.
    pub fn process(&mut self, raw: &EegBlock) -> EegBlock {
        let mut out = self.apply_spatial(raw);
        self.filters.process(&mut out.data, out.n_samples);
        out
    }
}

/// Common average reference, `(n, n)`.
fn car_matrix(n: usize) -> DMatrix<f64> {
    DMatrix::from_fn(n, n, |i, j| f64::from(u8::from(i == j)) - 1.0 / n as f64)
}

/// Horizontal, vertical and radial EOG from the six monopolar electrodes
/// (Croft & Barry style): H = LO - RO, V = mean(above) - mean(below),
/// R = mean of all six. Shape `(3, n_eog)`.
fn eog_derivation(montage: &Montage) -> Result<DMatrix<f64>> {
    let n_eeg = montage.n_eeg();
    let mut d = DMatrix::zeros(3, montage.n_eog());
    let col = |name: &str| -> Result<usize> { Ok(montage.index(name)? - n_eeg) };
    d[(0, col("EOG LO")?)] = 1.0;
    d[(0, col("EOG RO")?)] = -1.0;
    for n in ["EOG LA", "EOG RA"] {
        d[(1, col(n)?)] = 0.5;
    }
    for n in ["EOG LB", "EOG RB"] {
        d[(1, col(n)?)] = -0.5;
    }
    for c in 0..montage.n_eog() {
        d[(2, c)] = 1.0 / montage.n_eog() as f64;
    }
    Ok(d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generator::{Components, EegGenerator, GeneratorParams};

    fn paper() -> Valid<Preprocessing> {
        Valid::new(Preprocessing {
            params: PreprocessParams::default(),
            sfreq_hz: 256.0,
        })
        .unwrap()
    }

    fn eye_heavy() -> Valid<GeneratorParams> {
        Valid::new(GeneratorParams {
            blink_rate_hz: 0.5,
            saccade_rate_hz: 1.0,
            ..GeneratorParams::default()
        })
        .unwrap()
    }

    #[test]
    fn eog_regression_removes_most_of_the_eye_artifacts() {
        let m = Montage::standard();
        let fs = 256.0;
        let params = paper();
        let session = EegGenerator::new(&eye_heavy(), &m, 1)
            .unwrap()
            .generate(256 * 60);
        let fz = m.index("Fz").unwrap();
        let fp1 = m.index("Fp1").unwrap();
        let mut pre = Preprocessor::fit(&m, &params, &session, &[fp1, fz]).unwrap();

        // Fresh data: the eye part alone, with and without regression.
        let only_eyes = Components {
            background: false,
            artifacts: true,
            erp: false,
        };
        let eyes = EegGenerator::new(&eye_heavy(), &m, 2)
            .unwrap()
            .with_components(only_eyes)
            .generate(256 * 60);
        let cleaned = pre.process(&eyes);
        // The same without the regression: CAR + filter only.
        let car_only = {
            let mut x: Vec<f64> = (0..eyes.n_samples)
                .map(|t| {
                    let mean =
                        (0..m.n_eeg()).map(|c| eyes.channel(c)[t]).sum::<f64>() / m.n_eeg() as f64;
                    eyes.channel(fp1)[t] - mean
                })
                .collect();
            FilterChain::paper(50.0, 1.0, 10.0, fs).process(&mut x);
            x
        };
        let rms = |x: &[f64]| (x[512..].iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
        let before = rms(&car_only);
        let after = rms(cleaned.channel(0));
        assert!(after < 0.1 * before, "Fp1 eye residue {after} vs {before}");
    }

    #[test]
    fn blockwise_equals_one_block() {
        let m = Montage::standard();
        let mut g = EegGenerator::new(&eye_heavy(), &m, 3).unwrap();
        let session = g.generate(256 * 20);
        let outputs = m.decoding_indices();
        let fit = || Preprocessor::fit(&m, &paper(), &session, &outputs).unwrap();
        let data = g.generate(256 * 4);
        let whole = fit().process(&data);
        let mut pre = fit();
        let mut parts: Option<EegBlock> = None;
        for k in 0..4 {
            let mut b = EegBlock::zeros(data.n_channels, 256);
            for ch in 0..data.n_channels {
                b.channel_mut(ch)
                    .copy_from_slice(&data.channel(ch)[k * 256..(k + 1) * 256]);
            }
            let out = pre.process(&b);
            match parts.as_mut() {
                Some(p) => p.append(&out),
                None => parts = Some(out),
            }
        }
        assert_eq!(whole, parts.unwrap());
    }

    #[test]
    fn bad_band_is_rejected() {
        let p = PreprocessParams {
            low_hz: 12.0,
            ..PreprocessParams::default()
        };
        assert!(
            Preprocessing {
                params: p,
                sfreq_hz: 256.0
            }
            .check()
            .unwrap_err()
            .to_string()
            .contains("low_hz")
        );
    }
}
