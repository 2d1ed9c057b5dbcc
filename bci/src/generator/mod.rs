//! The synthetic EEG generator: assessment events in, multichannel samples out.

use errp_valid::Check;
use serde::{Deserialize, Serialize};

use crate::erp::AssessmentKind;
use crate::error::{BciError, Result, check};

mod effects;
mod hybrid;
mod realism;
mod synthesis;

pub use hybrid::{
    BASELINE_SECS, EegFeed, ErrpTemplate, HybridEeg, HybridSource, MIN_HYBRID_PART_SECS,
    TEMPLATE_SECS,
};

pub use realism::Realism;
pub use synthesis::*;

/// The sampling rate of the synthetic EEG (Hz): the paper records at 256
/// Hz (sec. 2.1). Every rate the testbed writes (the generator's default,
/// the EDF export, the stream) is this one.
pub const SFREQ_HZ: f64 = 256.0;

/// Parameters of the synthetic EEG. Amplitudes are in uV; every default is
/// documented next to its field.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GeneratorParams {
    /// Sampling rate (Hz); the paper records at 256 Hz.
    pub sfreq_hz: f64,
    /// SD of the 1/f background on every EEG channel (uV). 10 uV is typical
    /// of resting scalp EEG below 40 Hz.
    pub background_uv: f64,
    /// Spatial correlation length of the background on the unit head sphere:
    /// correlation exp(-d / length) for chord distance d (1.0: ~0.75 between
    /// neighbours 3 cm apart, ~0.2 across the head).
    pub spatial_length: f64,
    /// SD of the alpha rhythm at Oz (uV); it falls off towards the front.
    pub alpha_uv: f64,
    /// Alpha centre frequency (Hz).
    pub alpha_hz: f64,
    /// Alpha bandwidth (Hz).
    pub alpha_bandwidth_hz: f64,
    /// White sensor noise SD on every channel (uV).
    pub sensor_noise_uv: f64,
    /// Mains interference amplitude (uV), mostly common-mode.
    pub line_noise_uv: f64,
    /// Mains frequency (Hz); the paper's lab is on 50 Hz.
    pub line_hz: f64,
    /// Mean blink rate (per second).
    pub blink_rate_hz: f64,
    /// Mean blink amplitude on the electrodes above the eyes (uV).
    pub blink_uv: f64,
    /// Mean saccade rate (per second).
    pub saccade_rate_hz: f64,
    /// SD of the horizontal gaze potential at the outer canthi (uV).
    pub saccade_uv: f64,
    /// Peak of the error-minus-correct difference at FCz divided by the SD
    /// of the background EEG there: the knob accuracy targeting searches.
    pub errp_to_noise: f64,
    /// SD of the single-trial latency jitter of the ERPs (ms).
    pub latency_jitter_ms: f64,
    /// SD of the single-trial amplitude factor (mean 1, clipped at 0).
    pub amplitude_variability: f64,
    /// How far the user is from the ideal one: drifts, an ErrP that
    /// changes, lapses, artifacts ([`Realism`]; all off by default). Left
    /// out of the serde form when ideal, so that the keys of an ideal user
    /// are what they were before these effects existed.
    #[serde(skip_serializing_if = "Realism::is_ideal")]
    pub realism: Realism,
}

impl Default for GeneratorParams {
    fn default() -> Self {
        Self {
            sfreq_hz: SFREQ_HZ,
            background_uv: 10.0,
            spatial_length: 1.0,
            alpha_uv: 6.0,
            alpha_hz: 10.0,
            alpha_bandwidth_hz: 2.0,
            sensor_noise_uv: 1.0,
            line_noise_uv: 10.0,
            line_hz: 50.0,
            blink_rate_hz: 0.2,
            blink_uv: 150.0,
            saccade_rate_hz: 0.5,
            saccade_uv: 30.0,
            errp_to_noise: 0.5,
            latency_jitter_ms: 25.0,
            amplitude_variability: 0.3,
            realism: Realism::default(),
        }
    }
}

/// Checked where it enters (a scenario, a setup, a Python keyword) and
/// carried as a [`Valid`](errp_valid::Valid); [`EegGenerator`] takes it
/// checked.
impl Check for GeneratorParams {
    type Error = BciError;

    fn check(&self) -> Result<()> {
        self.validate()
    }
}

impl GeneratorParams {
    /// SD of the ERPs' single-trial latency (ms): the user's
    /// ([`Realism::trial_latency_sd_ms`]) if set, else the EEG model's
    /// `latency_jitter_ms`.
    pub fn trial_latency_sd_ms(&self) -> f64 {
        self.realism
            .trial_latency_sd_ms
            .unwrap_or(self.latency_jitter_ms)
    }

    /// Checks every field; the error names the field and the accepted range.
    fn validate(&self) -> Result<()> {
        let finite_nonneg = |v: f64| v.is_finite() && v >= 0.0;
        check(
            self.sfreq_hz.is_finite() && self.sfreq_hz >= 64.0,
            "sfreq_hz",
            self.sfreq_hz,
            "a sampling rate of at least 64 Hz",
        )?;
        for (name, v) in [
            ("background_uv", self.background_uv),
            ("alpha_uv", self.alpha_uv),
            ("sensor_noise_uv", self.sensor_noise_uv),
            ("line_noise_uv", self.line_noise_uv),
            ("blink_rate_hz", self.blink_rate_hz),
            ("blink_uv", self.blink_uv),
            ("saccade_rate_hz", self.saccade_rate_hz),
            ("saccade_uv", self.saccade_uv),
            ("errp_to_noise", self.errp_to_noise),
            ("latency_jitter_ms", self.latency_jitter_ms),
            ("amplitude_variability", self.amplitude_variability),
        ] {
            check(finite_nonneg(v), name, v, "a finite number >= 0")?;
        }
        check(
            self.background_uv > 0.0,
            "background_uv",
            self.background_uv,
            "a number > 0 (the ErrP-to-noise ratio is relative to it)",
        )?;
        check(
            self.spatial_length.is_finite() && self.spatial_length > 0.0,
            "spatial_length",
            self.spatial_length,
            "a finite number > 0",
        )?;
        let nyquist = self.sfreq_hz / 2.0;
        for (name, v) in [("alpha_hz", self.alpha_hz), ("line_hz", self.line_hz)] {
            check(
                v.is_finite() && v > 0.0 && v < nyquist,
                name,
                v,
                &format!("a frequency in (0, {nyquist}) Hz"),
            )?;
        }
        check(
            self.alpha_bandwidth_hz.is_finite() && self.alpha_bandwidth_hz > 0.0,
            "alpha_bandwidth_hz",
            self.alpha_bandwidth_hz,
            "a finite number > 0",
        )?;
        // The montage's names only where a bad channel is named.
        let montage =
            (!self.realism.bad_channel.is_empty()).then(crate::montage::Montage::standard);
        let eeg: Vec<&str> = montage
            .iter()
            .flat_map(|m| m.channels()[..m.n_eeg()].iter().map(|c| c.name.as_str()))
            .collect();
        self.realism.validate(&eeg)
    }
}

/// A user's judgement of one action, at a time on the generator's clock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Assessment {
    /// Action onset (s since the generator started).
    pub onset_secs: f64,
    /// Correct or erroneous.
    pub kind: AssessmentKind,
}

/// Multichannel samples, channel-major: shape `(n_channels, n_samples)`.
#[derive(Debug, Clone, PartialEq)]
pub struct EegBlock {
    /// Number of channels (rows).
    pub n_channels: usize,
    /// Number of samples per channel (columns).
    pub n_samples: usize,
    /// `data[ch * n_samples + t]`.
    pub data: Vec<f64>,
}

impl EegBlock {
    /// A block of zeros.
    pub fn zeros(n_channels: usize, n_samples: usize) -> Self {
        Self {
            n_channels,
            n_samples,
            data: vec![0.0; n_channels * n_samples],
        }
    }

    /// Samples of one channel.
    pub fn channel(&self, ch: usize) -> &[f64] {
        &self.data[ch * self.n_samples..(ch + 1) * self.n_samples]
    }

    /// Mutable samples of one channel.
    pub fn channel_mut(&mut self, ch: usize) -> &mut [f64] {
        &mut self.data[ch * self.n_samples..(ch + 1) * self.n_samples]
    }

    /// Samples `range` of every channel, as a block of their own.
    pub fn samples(&self, range: std::ops::Range<usize>) -> EegBlock {
        let n_samples = range.len();
        let mut data = Vec::with_capacity(self.n_channels * n_samples);
        for ch in 0..self.n_channels {
            data.extend_from_slice(&self.channel(ch)[range.clone()]);
        }
        EegBlock {
            n_channels: self.n_channels,
            n_samples,
            data,
        }
    }

    /// The blocks one after another (all with the same channel count), in
    /// one allocation: for many blocks, where repeated [`append`]s would
    /// copy the growing block each time.
    ///
    /// [`append`]: Self::append
    pub fn concat(blocks: &[EegBlock]) -> EegBlock {
        let n_channels = blocks.first().map_or(0, |b| b.n_channels);
        assert!(
            blocks.iter().all(|b| b.n_channels == n_channels),
            "channel counts differ"
        );
        let n_samples = blocks.iter().map(|b| b.n_samples).sum();
        let mut data = Vec::with_capacity(n_channels * n_samples);
        for ch in 0..n_channels {
            for b in blocks {
                data.extend_from_slice(b.channel(ch));
            }
        }
        EegBlock {
            n_channels,
            n_samples,
            data,
        }
    }

    /// Appends `other` (same channel count) after this block's samples.
    pub fn append(&mut self, other: &EegBlock) {
        assert_eq!(self.n_channels, other.n_channels, "channel counts differ");
        let n = self.n_samples + other.n_samples;
        let mut data = Vec::with_capacity(self.n_channels * n);
        for ch in 0..self.n_channels {
            data.extend_from_slice(self.channel(ch));
            data.extend_from_slice(other.channel(ch));
        }
        self.data = data;
        self.n_samples = n;
    }
}

/// Which parts of the signal are switched on. The random streams advance
/// identically whatever is switched off, so the parts of one seed add up to the
/// whole signal exactly (accuracy targeting relies on this).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Components {
    /// Background EEG (1/f, alpha) and sensor noise.
    pub background: bool,
    /// Line noise, blinks and saccades.
    pub artifacts: bool,
    /// Event-related potentials.
    pub erp: bool,
}

impl Default for Components {
    fn default() -> Self {
        Self {
            background: true,
            artifacts: true,
            erp: true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::montage::Montage;
    use errp_valid::Valid;

    fn generator(seed: u64) -> EegGenerator {
        EegGenerator::new(&Valid::default(), &Montage::standard(), seed).unwrap()
    }

    #[test]
    fn concat_equals_appending_block_by_block() {
        let mut g = generator(2);
        let blocks: Vec<EegBlock> = (1..5).map(|k| g.generate(37 * k)).collect();
        let mut appended = blocks[0].clone();
        for b in &blocks[1..] {
            appended.append(b);
        }
        assert_eq!(EegBlock::concat(&blocks), appended);
        assert_eq!(EegBlock::concat(&[]).n_samples, 0);
    }

    #[test]
    fn ten_one_second_blocks_equal_one_ten_second_block() {
        let mut a = generator(5);
        let mut b = generator(5);
        for g in [&mut a, &mut b] {
            for k in 0..6 {
                let kind = if k % 2 == 0 {
                    AssessmentKind::Error
                } else {
                    AssessmentKind::Correct
                };
                g.schedule(Assessment {
                    onset_secs: 0.7 + 1.5 * k as f64,
                    kind,
                });
            }
        }
        let whole = a.generate(2560);
        let mut parts = b.generate(256);
        for _ in 1..10 {
            parts.append(&b.generate(256));
        }
        assert_eq!(whole, parts);
    }

    #[test]
    fn components_add_up_to_the_whole_signal() {
        let sched = |g: &mut EegGenerator| {
            g.schedule(Assessment {
                onset_secs: 0.5,
                kind: AssessmentKind::Error,
            })
        };
        let mut whole = generator(9);
        sched(&mut whole);
        let whole = whole.generate(600);
        let mut parts = Vec::new();
        for comp in [
            Components {
                background: true,
                artifacts: false,
                erp: false,
            },
            Components {
                background: false,
                artifacts: true,
                erp: false,
            },
            Components {
                background: false,
                artifacts: false,
                erp: true,
            },
        ] {
            let mut g = generator(9).with_components(comp);
            sched(&mut g);
            parts.push(g.generate(600));
        }
        for i in 0..whole.data.len() {
            let sum: f64 = parts.iter().map(|p| p.data[i]).sum();
            assert!((sum - whole.data[i]).abs() < 1e-9);
        }
    }

    #[test]
    fn same_seed_same_samples_other_seed_other_samples() {
        assert_eq!(generator(1).generate(300), generator(1).generate(300));
        assert_ne!(generator(1).generate(300), generator(2).generate(300));
    }

    #[test]
    fn background_has_the_requested_sd_and_is_spatially_correlated() {
        let m = Montage::standard();
        let mut g = generator(11).with_components(Components {
            background: true,
            artifacts: false,
            erp: false,
        });
        let block = g.generate(256 * 120);
        let fcz = block.channel(m.index("FCz").unwrap());
        let sd = (fcz.iter().map(|x| x * x).sum::<f64>() / fcz.len() as f64).sqrt();
        assert!((sd - 10.0).abs() < 2.5, "FCz background sd {sd}");
        let corr = |a: &[f64], b: &[f64]| {
            let ab: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
            let aa: f64 = a.iter().map(|x| x * x).sum();
            let bb: f64 = b.iter().map(|x| x * x).sum();
            ab / (aa * bb).sqrt()
        };
        let cz = block.channel(m.index("Cz").unwrap());
        let t8 = block.channel(m.index("T8").unwrap());
        assert!(corr(fcz, cz) > 0.6, "neighbours correlate");
        assert!(
            corr(fcz, cz) > corr(fcz, t8) + 0.2,
            "far sites correlate less"
        );
    }

    #[test]
    fn blinks_dominate_eog_and_leak_into_frontal_eeg() {
        let m = Montage::standard();
        let params = GeneratorParams {
            blink_rate_hz: 1.0,
            ..GeneratorParams::default()
        };
        let mut g = EegGenerator::new(&Valid::new(params).unwrap(), &m, 4)
            .unwrap()
            .with_components(Components {
                background: false,
                artifacts: true,
                erp: false,
            });
        let block = g.generate(256 * 30);
        let peak = |n: &str| {
            block
                .channel(m.index(n).unwrap())
                .iter()
                .fold(0.0f64, |a, &x| a.max(x.abs()))
        };
        assert!(peak("EOG LA") > 100.0);
        assert!(peak("Fp1") > peak("Fz") && peak("Fz") > peak("Pz"));
    }

    #[test]
    fn invalid_parameters_are_rejected_by_name() {
        let params = GeneratorParams {
            errp_to_noise: f64::NAN,
            ..GeneratorParams::default()
        };
        let err = Valid::new(params).unwrap_err();
        assert!(err.to_string().contains("errp_to_noise"), "{err}");
    }
}
