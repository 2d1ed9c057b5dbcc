//! A hybrid EEG feed on a person's own EEG: the file's EEG as the
//! background (read in order, looped), and the subject's error-minus-correct
//! response, taken from the same file, added at each scheduled erroneous
//! assessment with the synthetic generator's single-trial latency jitter and
//! amplitude variability.

use std::sync::Arc;

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

use crate::erp::AssessmentKind;
use crate::error::{BciError, Result};
use crate::generator::{Assessment, EegBlock, GeneratorParams};
use crate::montage::Montage;
use crate::rng::labelled;

/// Seconds of the subject's response kept from each event: the ErrP's
/// components end within 600 ms; 1 s holds them and their return to zero.
pub const TEMPLATE_SECS: f64 = 1.0;
/// Seconds before each event averaged as its baseline.
pub const BASELINE_SECS: f64 = 0.2;

/// The subject's error-minus-correct response on every channel of own
/// EEG, `(n_channels, TEMPLATE_SECS)` in uV from the event: the
/// average of the error epochs minus that of the correct epochs, each
/// epoch less its baseline.
#[derive(Debug, Clone)]
pub struct ErrpTemplate {
    /// The response, one row per channel of the own EEG's montage.
    pub response: EegBlock,
    /// Error and correct epochs averaged.
    pub counts: (usize, usize),
}

impl ErrpTemplate {
    /// The template of `events` (own EEG's calibration part) in `raw`
    /// at `fs` Hz; an event whose epoch or baseline leaves the EEG is
    /// skipped. Refused without an epoch of each class.
    pub fn from_raw(raw: &EegBlock, fs: f64, events: &[Assessment]) -> Result<Self> {
        let span = (TEMPLATE_SECS * fs).round() as usize;
        let base = (BASELINE_SECS * fs).round() as usize;
        let n_ch = raw.n_channels;
        let mut sums = [vec![0.0; n_ch * span], vec![0.0; n_ch * span]];
        let mut counts = [0usize; 2];
        for e in events {
            let at = (e.onset_secs * fs).round() as usize;
            if at < base || at + span > raw.n_samples {
                continue;
            }
            let k = usize::from(e.kind == AssessmentKind::Error);
            counts[k] += 1;
            for ch in 0..n_ch {
                let x = raw.channel(ch);
                let baseline = x[at - base..at].iter().sum::<f64>() / base as f64;
                for (s, v) in sums[k][ch * span..(ch + 1) * span]
                    .iter_mut()
                    .zip(&x[at..at + span])
                {
                    *s += v - baseline;
                }
            }
        }
        if counts[0] == 0 || counts[1] == 0 {
            return Err(BciError::Format(format!(
                "the subject's response needs epochs of both classes; the calibration part \
                 holds {} error and {} correct ones inside the recording",
                counts[1], counts[0]
            )));
        }
        let mut response = EegBlock::zeros(n_ch, span);
        for (i, r) in response.data.iter_mut().enumerate() {
            *r = sums[1][i] / counts[1] as f64 - sums[0][i] / counts[0] as f64;
        }
        Ok(Self {
            response,
            counts: (counts[1], counts[0]),
        })
    }
}

/// One scheduled response: its onset (samples), latency shift (samples)
/// and gain.
#[derive(Debug, Clone, Copy)]
struct Active {
    onset: f64,
    shift: f64,
    gain: f64,
}

/// The hybrid feed: the own EEG's background looped, the subject's
/// response added at each erroneous assessment.
#[derive(Debug, Clone)]
pub struct HybridEeg {
    background: Arc<EegBlock>,
    template: Arc<ErrpTemplate>,
    params: GeneratorParams,
    /// Where the background is read next.
    cursor: usize,
    /// Samples generated so far.
    sample: u64,
    active: Vec<Active>,
    rng: ChaCha8Rng,
}

impl HybridEeg {
    /// A feed over `background` (the own EEG's raw channels, in the
    /// montage's order) starting at sample `start` of it, with `template`
    /// added at errors; `params` gives the rate and the single-trial
    /// variability; every draw from `seed`.
    pub fn new(
        background: Arc<EegBlock>,
        template: Arc<ErrpTemplate>,
        params: &GeneratorParams,
        start: usize,
        seed: u64,
    ) -> Result<Self> {
        if background.n_samples == 0 || background.n_channels != template.response.n_channels {
            return Err(BciError::Format(format!(
                "a hybrid stream needs a background of the template's {} channels",
                template.response.n_channels
            )));
        }
        Ok(Self {
            cursor: start % background.n_samples,
            background,
            template,
            params: params.clone(),
            sample: 0,
            active: Vec::new(),
            rng: labelled(seed, "hybrid/erp"),
        })
    }

    /// The feed's parameters (its rate).
    pub fn params(&self) -> &GeneratorParams {
        &self.params
    }

    /// Seconds generated so far.
    pub fn now_secs(&self) -> f64 {
        self.sample as f64 / self.params.sfreq_hz
    }

    /// Schedules an assessment: an error adds the subject's response with a
    /// latency jitter and a gain drawn now; a correct one adds nothing (the
    /// background already holds the subject's correct responses' level).
    pub fn schedule(&mut self, assessment: Assessment) {
        let jitter_ms =
            self.params.trial_latency_sd_ms() * self.rng.sample::<f64, _>(StandardNormal);
        let gain = (1.0
            + self.params.amplitude_variability * self.rng.sample::<f64, _>(StandardNormal))
        .max(0.0);
        if assessment.kind != AssessmentKind::Error {
            return;
        }
        let fs = self.params.sfreq_hz;
        self.active.push(Active {
            onset: assessment.onset_secs * fs,
            shift: jitter_ms * 1e-3 * fs,
            gain,
        });
    }

    /// The next `n_samples` of every channel.
    pub fn generate(&mut self, n_samples: usize) -> EegBlock {
        let mut block = EegBlock::zeros(self.background.n_channels, n_samples);
        self.generate_into(&mut block);
        block
    }

    /// Fills `block` with the next `block.n_samples` samples.
    pub fn generate_into(&mut self, block: &mut EegBlock) {
        let n = block.n_samples;
        let bg = &self.background;
        for ch in 0..block.n_channels {
            let src = bg.channel(ch);
            let dst = block.channel_mut(ch);
            let mut at = self.cursor;
            for d in dst.iter_mut() {
                *d = src[at];
                at += 1;
                if at == src.len() {
                    at = 0;
                }
            }
        }
        let span = self.template.response.n_samples;
        let start = self.sample as f64;
        for a in &self.active {
            let first = a.onset + a.shift;
            for t in 0..n {
                // Linear interpolation of the response at a fractional lag.
                let lag = start + t as f64 - first;
                if lag < 0.0 || lag >= (span - 1) as f64 {
                    continue;
                }
                let i = lag.floor() as usize;
                let w = lag - i as f64;
                for ch in 0..block.n_channels {
                    let r = self.template.response.channel(ch);
                    block.channel_mut(ch)[t] += a.gain * ((1.0 - w) * r[i] + w * r[i + 1]);
                }
            }
        }
        let end = start + n as f64;
        self.active
            .retain(|a| a.onset + a.shift + span as f64 > end);
        self.cursor = (self.cursor + n) % bg.n_samples;
        self.sample += n as u64;
    }
}

/// What a hybrid session or feed is made of: a person's own EEG (its
/// channels and raw EEG, split where its calibration part ends) and the
/// subject's response from that part. The calibration session loops over
/// the calibration part and the online feeds over the rest, so no
/// background the decoder was trained on is ever decoded online.
#[derive(Debug, Clone)]
pub struct HybridSource {
    /// The own EEG's channels.
    pub montage: Montage,
    /// The calibration part's raw EEG, less the subject's response at its
    /// errors: the calibration session's background (and the preprocessing
    /// is fitted on it).
    pub calibration: Arc<EegBlock>,
    /// The rest of the own EEG, likewise cleaned: the online background.
    pub held_out: Arc<EegBlock>,
    /// The subject's error-minus-correct response.
    pub template: Arc<ErrpTemplate>,
}

/// The shortest part of own EEG a hybrid loops over, s: an online
/// window (800 ms) many times over.
pub const MIN_HYBRID_PART_SECS: f64 = 30.0;

impl HybridSource {
    /// The hybrid of own EEG (`raw` on `montage`, at `fs` Hz, its
    /// `events`), the subject's response taken from the first `calibration`
    /// events, whose end (1 s after the last of them) splits the
    /// background. The background is the own EEG less that response at
    /// each of its own error events, so that the feed's errors are the
    /// scheduled ones only. Refused when either part is shorter than
    /// [`MIN_HYBRID_PART_SECS`].
    pub fn from_own_eeg(
        montage: &Montage,
        raw: &EegBlock,
        fs: f64,
        events: &[Assessment],
        calibration: usize,
    ) -> Result<Self> {
        let k = calibration.min(events.len());
        let template = ErrpTemplate::from_raw(raw, fs, &events[..k])?;
        let mut background = raw.clone();
        let span = template.response.n_samples;
        for e in events.iter().filter(|e| e.kind == AssessmentKind::Error) {
            let at = (e.onset_secs * fs).round() as usize;
            for ch in 0..background.n_channels {
                let r = template.response.channel(ch);
                let row = background.channel_mut(ch);
                for (x, v) in row.iter_mut().skip(at).zip(r.iter().take(span)) {
                    *x -= v;
                }
            }
        }
        let end = k.checked_sub(1).map_or(0, |i| {
            ((events[i].onset_secs + TEMPLATE_SECS) * fs).round() as usize
        });
        let end = end.min(raw.n_samples);
        let min = (MIN_HYBRID_PART_SECS * fs).round() as usize;
        if end < min || raw.n_samples - end < min {
            return Err(BciError::Format(format!(
                "the calibration part ends at {:.1} s of a {:.1} s recording; a hybrid needs \
                 at least {MIN_HYBRID_PART_SECS} s of background on each side",
                end as f64 / fs,
                raw.n_samples as f64 / fs
            )));
        }
        Ok(Self {
            montage: montage.clone(),
            calibration: Arc::new(background.samples(0..end)),
            held_out: Arc::new(background.samples(end..raw.n_samples)),
            template: Arc::new(template),
        })
    }

    /// A calibration feed: over the calibration part, from a point drawn
    /// from `seed`, with the single-trial variability of `params`.
    pub fn calibration_feed(&self, params: &GeneratorParams, seed: u64) -> Result<HybridEeg> {
        self.feed_over(&self.calibration, params, seed)
    }

    /// An online feed: over the held-out part, likewise.
    pub fn online_feed(&self, params: &GeneratorParams, seed: u64) -> Result<HybridEeg> {
        self.feed_over(&self.held_out, params, seed)
    }

    fn feed_over(
        &self,
        background: &Arc<EegBlock>,
        params: &GeneratorParams,
        seed: u64,
    ) -> Result<HybridEeg> {
        let start = labelled(seed, "hybrid/start").random_range(0..background.n_samples.max(1));
        HybridEeg::new(
            Arc::clone(background),
            Arc::clone(&self.template),
            params,
            start,
            seed,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::montage::Montage;

    #[test]
    fn the_background_loops_and_an_error_adds_the_response() {
        let montage = Montage::standard();
        let n_ch = montage.len();
        let fs = 256.0;
        let mut bg = EegBlock::zeros(n_ch, 1000);
        for (i, v) in bg.data.iter_mut().enumerate() {
            *v = (i % 1000) as f64;
        }
        let mut response = EegBlock::zeros(n_ch, 256);
        response.data.fill(10.0);
        let template = Arc::new(ErrpTemplate {
            response,
            counts: (1, 1),
        });
        let params = GeneratorParams {
            amplitude_variability: 0.0,
            latency_jitter_ms: 0.0,
            ..GeneratorParams::default()
        };
        let mut eeg = HybridEeg::new(Arc::new(bg), template, &params, 990, 1).unwrap();
        eeg.schedule(Assessment {
            onset_secs: 1000.0 / fs,
            kind: AssessmentKind::Error,
        });
        let block = eeg.generate(1200);
        let x = block.channel(0);
        // Read from sample 990, looped at 1000.
        assert_eq!((x[0], x[9], x[10]), (990.0, 999.0, 0.0));
        // The response from sample 1000 of the stream (plus any latency
        // SD the model keeps), 10 uV on every channel.
        let lag = params.trial_latency_sd_ms();
        if lag == 0.0 {
            assert_eq!(x[1000] - x[999], 10.0 + 1.0);
        }
        assert!(block.channel(n_ch - 1)[1100] - bg_at(1100, 990) > 9.0);
        assert!((eeg.now_secs() - 1200.0 / fs).abs() < 1e-12);
    }

    fn bg_at(t: usize, start: usize) -> f64 {
        ((t + start) % 1000) as f64
    }
}

/// The EEG the online decoder reads: the synthetic user's, or a hybrid on
/// a person's own EEG.
#[derive(Debug, Clone)]
pub enum EegFeed {
    /// The synthetic generator.
    Synthetic(Box<crate::generator::EegGenerator>),
    /// Own EEG's background with the subject's response.
    Hybrid(Box<HybridEeg>),
}

impl From<crate::generator::EegGenerator> for EegFeed {
    fn from(g: crate::generator::EegGenerator) -> Self {
        Self::Synthetic(Box::new(g))
    }
}

impl From<HybridEeg> for EegFeed {
    fn from(h: HybridEeg) -> Self {
        Self::Hybrid(Box::new(h))
    }
}

impl EegFeed {
    /// The sampling rate, Hz.
    pub fn sfreq_hz(&self) -> f64 {
        match self {
            Self::Synthetic(g) => g.params().sfreq_hz,
            Self::Hybrid(h) => h.params().sfreq_hz,
        }
    }

    /// Schedules an assessment.
    pub fn schedule(&mut self, assessment: Assessment) {
        match self {
            Self::Synthetic(g) => g.schedule(assessment),
            Self::Hybrid(h) => h.schedule(assessment),
        }
    }

    /// The next `n_samples` of every channel.
    pub fn generate(&mut self, n_samples: usize) -> EegBlock {
        match self {
            Self::Synthetic(g) => g.generate(n_samples),
            Self::Hybrid(h) => h.generate(n_samples),
        }
    }

    /// Fills `block` with the next samples.
    pub fn generate_into(&mut self, block: &mut EegBlock) {
        match self {
            Self::Synthetic(g) => g.generate_into(block),
            Self::Hybrid(h) => h.generate_into(block),
        }
    }
}
