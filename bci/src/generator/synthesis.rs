//! The generator: synthetic EEG and EOG streamed block by block, with the
//! background, the artifacts and the ERPs of scheduled assessments.

use std::f64::consts::PI;

use nalgebra::DMatrix;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Exp, StandardNormal};

use errp_valid::Valid;

use super::effects::RealismState;
use super::{Assessment, Components, EegBlock, GeneratorParams};
use crate::erp::{AssessmentKind, ErpTemplates, waveform};
use crate::error::Result;
use crate::montage::{Montage, angle_between};
use crate::noise::{PinkNoise, Resonator};
use crate::rng::labelled;

#[derive(Debug, Clone)]
struct ActiveErp {
    onset_sample: f64,
    kind: AssessmentKind,
    jitter_ms: f64,
    gain: f64,
}

/// sqrt(12) / 65536: a centred 16-bit uniform scaled to unit variance.
const UNIFORM_TO_UNIT_SD: f64 = 3.464_101_615_137_754_6 / 65536.0;
/// How long an ERP lasts after its onset (s).
const ERP_LENGTH_SECS: f64 = 1.2;
/// Duration of a blink (s).
const BLINK_SECS: f64 = 0.35;
/// Duration of a saccade (s).
const SACCADE_SECS: f64 = 0.04;

/// Streams synthetic EEG + EOG for a [`Montage`]. Schedule assessments with
/// [`EegGenerator::schedule`], pull samples with [`EegGenerator::generate`];
/// blocks carry all state, so ten 1 s blocks equal one 10 s block.
///
/// Model per EEG channel: spatially correlated 1/f background + alpha
/// (posterior) + white sensor noise + mains + blink and saccade potentials
/// leaking from the eyes (falling off with distance) + ERPs with the FCz-centred
/// topography of the templates. EOG channels carry the eye potentials, their
/// own 1/f noise and sensor noise.
#[derive(Debug, Clone)]
pub struct EegGenerator {
    params: GeneratorParams,
    components: Components,
    montage: Montage,
    templates: ErpTemplates,
    topography: Vec<f64>,
    erp_scale: f64,
    /// Lower-triangular mixing of the background sources, `(n_eeg, n_eeg)`,
    /// stored column-major (`mixing[k * n_eeg + ch]`), in uV.
    mixing: Vec<f64>,
    pink: Vec<PinkNoise>,
    alpha: Resonator,
    alpha_weight: Vec<f64>,
    line_cos: Vec<f64>,
    line_sin: Vec<f64>,
    blink_coeff: Vec<f64>,
    gaze_coeff: Vec<f64>,
    blinks: Vec<(u64, f64)>,
    next_blink: u64,
    gaze_from: f64,
    gaze_to: f64,
    saccade_start: u64,
    next_saccade: u64,
    erps: Vec<ActiveErp>,
    sample: u64,
    uniforms: Vec<u16>,
    scratch: Vec<f64>,
    alpha_buf: Vec<f64>,
    blink_buf: Vec<f64>,
    gaze_buf: Vec<f64>,
    line_c_buf: Vec<f64>,
    line_s_buf: Vec<f64>,
    erp_buf: Vec<f64>,
    rng_background: ChaCha8Rng,
    rng_alpha: ChaCha8Rng,
    rng_artifacts: ChaCha8Rng,
    rng_erp: ChaCha8Rng,
    realism: RealismState,
    bg_gain_buf: Vec<f64>,
    alpha_gain_buf: Vec<f64>,
}

/// The background's mixing matrix (column-major, lower triangle): the
/// Cholesky factor of the correlation exp(-chord / length) between EEG
/// sites, scaled to the background's amplitude.
fn background_mixing(params: &GeneratorParams, montage: &Montage) -> Vec<f64> {
    let n_eeg = montage.n_eeg();
    let pos = |i: usize| montage.channels()[i].position;
    let corr = DMatrix::from_fn(n_eeg, n_eeg, |i, j| {
        let (a, b) = (pos(i), pos(j));
        let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        (-d / params.spatial_length).exp()
    });
    let l = corr
        .cholesky()
        .expect("an exponential kernel on distinct points is positive definite")
        .l();
    let mut mixing = vec![0.0; n_eeg * n_eeg];
    for i in 0..n_eeg {
        for j in 0..=i {
            mixing[j * n_eeg + i] = l[(i, j)] * params.background_uv;
        }
    }
    mixing
}

/// The mains' cosine and sine amplitudes per channel: mostly common-mode,
/// with a small per-channel spread, drawn from `rng`.
fn mains(params: &GeneratorParams, n_ch: usize, rng: &mut ChaCha8Rng) -> (Vec<f64>, Vec<f64>) {
    let common_phase = rng.random::<f64>() * 2.0 * PI;
    let mut line_cos = Vec::with_capacity(n_ch);
    let mut line_sin = Vec::with_capacity(n_ch);
    for _ in 0..n_ch {
        let amp = params.line_noise_uv * rng.random_range(0.5..1.5);
        let phase = common_phase + 0.3 * rng.sample::<f64, _>(StandardNormal);
        line_cos.push(amp * phase.cos());
        line_sin.push(amp * phase.sin());
    }
    (line_cos, line_sin)
}

impl EegGenerator {
    /// A generator for `montage` with the shipped ERP templates.
    pub fn new(params: &Valid<GeneratorParams>, montage: &Montage, seed: u64) -> Result<Self> {
        Self::with_templates(params, montage, ErpTemplates::default(), seed)
    }

    /// A generator with custom ERP templates.
    pub fn with_templates(
        params: &Valid<GeneratorParams>,
        montage: &Montage,
        templates: ErpTemplates,
        seed: u64,
    ) -> Result<Self> {
        let params = params.get().clone();
        let mut rng_background = labelled(seed, "eeg/background");
        let mut rng_artifacts = labelled(seed, "eeg/artifacts");
        let rng_erp = labelled(seed, "eeg/erp");
        let mut rng_alpha = labelled(seed, "eeg/alpha");
        let n_eeg = montage.n_eeg();
        let n_ch = montage.len();
        let fs = params.sfreq_hz;

        let pos = |i: usize| montage.channels()[i].position;
        let mixing = background_mixing(&params, montage);
        let pink = (0..n_ch)
            .map(|_| PinkNoise::new(fs, &mut rng_background))
            .collect();
        let alpha = Resonator::new(
            params.alpha_hz,
            params.alpha_bandwidth_hz,
            fs,
            &mut rng_alpha,
        );
        let oz = pos(montage.index("Oz")?);
        let alpha_weight = (0..n_ch)
            .map(|ch| {
                if ch < n_eeg {
                    let d = angle_between(pos(ch), oz);
                    params.alpha_uv * (-0.5 * (d / 0.9).powi(2)).exp()
                } else {
                    0.0
                }
            })
            .collect::<Vec<_>>();

        let (line_cos, line_sin) = mains(&params, n_ch, &mut rng_artifacts);

        // Eye potentials: blinks (vertical) and gaze (horizontal).
        let (blink_coeff, gaze_coeff) = eye_coefficients(montage)?;

        let centre = montage.index(&templates.centre)?;
        let bg_sd_at_centre = (params.background_uv.powi(2)
            + alpha_weight[centre].powi(2)
            + params.sensor_noise_uv.powi(2))
        .sqrt();
        let erp_scale = params.errp_to_noise * bg_sd_at_centre / templates.difference_peak_uv();
        let topography = templates.topography(montage)?;
        let realism = RealismState::new(&params.realism, montage, fs, seed)?;

        let mut generator = Self {
            components: Components::default(),
            montage: montage.clone(),
            templates,
            topography,
            erp_scale,
            mixing,
            pink,
            alpha,
            alpha_weight,
            line_cos,
            line_sin,
            blink_coeff,
            gaze_coeff,
            blinks: Vec::new(),
            next_blink: 0,
            gaze_from: 0.0,
            gaze_to: 0.0,
            saccade_start: 0,
            next_saccade: 0,
            erps: Vec::new(),
            sample: 0,
            uniforms: Vec::new(),
            scratch: Vec::new(),
            alpha_buf: Vec::new(),
            blink_buf: Vec::new(),
            gaze_buf: Vec::new(),
            line_c_buf: Vec::new(),
            line_s_buf: Vec::new(),
            erp_buf: Vec::new(),
            rng_background,
            rng_alpha,
            rng_artifacts,
            rng_erp,
            realism,
            bg_gain_buf: Vec::new(),
            alpha_gain_buf: Vec::new(),
            params,
        };
        generator.next_blink = generator.draw_interval(generator.params.blink_rate_hz);
        generator.next_saccade = generator.draw_interval(generator.params.saccade_rate_hz);
        Ok(generator)
    }

    /// Switches parts of the signal on or off (see [`Components`]).
    pub fn with_components(mut self, components: Components) -> Self {
        self.components = components;
        self
    }

    /// The parameters in force.
    pub fn params(&self) -> &GeneratorParams {
        &self.params
    }

    /// The montage generated for.
    pub fn montage(&self) -> &Montage {
        &self.montage
    }

    /// ERP amplitude at the centre electrode per template uV (the rescaling
    /// that `errp_to_noise` implies).
    pub fn erp_scale(&self) -> f64 {
        self.erp_scale
    }

    /// Time of the next sample to be generated (s).
    pub fn now_secs(&self) -> f64 {
        self.sample as f64 / self.params.sfreq_hz
    }

    /// Schedules the ERP of an assessment. Its single-trial latency jitter and
    /// amplitude are drawn now, from the ERP stream, in scheduling order;
    /// then what the user makes of the action ([`Realism`](super::Realism):
    /// a lapse, a misjudgement, the expectancy, the session's slopes, a
    /// blink after it), from a stream of its own.
    pub fn schedule(&mut self, assessment: Assessment) {
        let jitter_ms =
            self.params.trial_latency_sd_ms() * self.rng_erp.sample::<f64, _>(StandardNormal);
        let gain = (1.0
            + self.params.amplitude_variability * self.rng_erp.sample::<f64, _>(StandardNormal))
        .max(0.0);
        let perceived = self
            .realism
            .perceive(assessment.kind, assessment.onset_secs);
        let Some(kind) = perceived.kind else {
            return;
        };
        let erp = ActiveErp {
            onset_sample: assessment.onset_secs * self.params.sfreq_hz,
            kind,
            jitter_ms: jitter_ms + perceived.shift_ms,
            gain: gain * perceived.gain,
        };
        // Kept sorted by onset so that rendering stops at the first future ERP.
        let at = self
            .erps
            .partition_point(|e| e.onset_sample <= erp.onset_sample);
        self.erps.insert(at, erp);
    }

    fn draw_interval(&mut self, rate_hz: f64) -> u64 {
        if rate_hz <= 0.0 {
            return u64::MAX;
        }
        let secs: f64 = self
            .rng_artifacts
            .sample(Exp::new(rate_hz).expect("rate > 0"));
        self.sample + (secs * self.params.sfreq_hz).ceil().max(1.0) as u64
    }

    /// Generates the next `n_samples` samples of every channel, shape
    /// `(n_channels, n_samples)`, in uV.
    pub fn generate(&mut self, n_samples: usize) -> EegBlock {
        let mut block = EegBlock::zeros(self.montage.len(), n_samples);
        self.generate_into(&mut block);
        block
    }

    /// The background into `data` (`n` samples per channel, the 1/f
    /// sources in the scratch's first rows, scaled by `bg`): the EEG
    /// sources mixed spatially (lower-triangular), four sources per pass
    /// over the output row; EOG channels keep their own source.
    fn mix_background(&self, n: usize, bg: f64, data: &mut [f64]) {
        let n_ch = self.montage.len();
        let n_eeg = self.montage.n_eeg();
        let sources = &self.scratch[..n_ch * n];
        data.fill(0.0);
        for ch in 0..n_eeg {
            let out = &mut data[ch * n..(ch + 1) * n];
            let l = |k: usize| bg * self.mixing[k * n_eeg + ch];
            let src = |k: usize| &sources[k * n..(k + 1) * n];
            let mut k = 0;
            while k + 4 <= ch + 1 {
                let (l0, l1, l2, l3) = (l(k), l(k + 1), l(k + 2), l(k + 3));
                let (s0, s1, s2, s3) = (src(k), src(k + 1), src(k + 2), src(k + 3));
                for t in 0..n {
                    out[t] += l0 * s0[t] + l1 * s1[t] + l2 * s2[t] + l3 * s3[t];
                }
                k += 4;
            }
            for k in k..=ch {
                let (lk, sk) = (l(k), src(k));
                for (o, s) in out.iter_mut().zip(sk) {
                    *o += lk * s;
                }
            }
        }
        let eog_bg = bg * 0.5 * self.params.background_uv;
        for ch in n_eeg..n_ch {
            let src = &self.scratch[ch * n..(ch + 1) * n];
            for (o, s) in data[ch * n..(ch + 1) * n].iter_mut().zip(src) {
                *o = eog_bg * s;
            }
        }
    }

    /// Fills `block` (its channel count must be the montage's) with the next
    /// `block.n_samples` samples.
    ///
    /// Works in stages over the whole block (draws, 1/f filters, spatial
    /// mixing, per-sample sources, then one pass per channel), so that the
    /// inner loops vectorise. Every random stream is consumed sample by sample
    /// in a fixed order, so block boundaries never change the samples.
    pub fn generate_into(&mut self, block: &mut EegBlock) {
        assert_eq!(block.n_channels, self.montage.len(), "channel count");
        let n = block.n_samples;
        let n_ch = self.montage.len();
        let fs = self.params.sfreq_hz;
        let c = self.components;
        let bg = if c.background { 1.0 } else { 0.0 };
        let start = self.sample;

        // 1. White noise: per sample, n_ch drivers of the 1/f sources and
        //    n_ch sensor-noise values, as 16-bit uniforms scaled to unit
        //    variance. Only their second-order statistics reach the decoder:
        //    after the 1/f shaping and the 10 Hz low-pass every sample is a
        //    sum of many of them, Gaussian by the central limit theorem.
        self.uniforms.resize(n * 2 * n_ch, 0);
        self.rng_background.fill(&mut self.uniforms[..]);
        let unit = |u: u16| (f64::from(u) + 0.5 - 32768.0) * UNIFORM_TO_UNIT_SD;

        // 2. The 1/f sources and the sensor noise, channel-major scratch:
        //    rows 0..n_ch sources, rows n_ch..2 n_ch sensor noise.
        self.scratch.resize(2 * n_ch * n, 0.0);
        let (sources, sensor_noise) = self.scratch.split_at_mut(n_ch * n);
        let stride = 2 * n_ch;
        for ch in 0..n_ch {
            let uniforms = &self.uniforms;
            self.pink[ch].run(
                |t| unit(uniforms[t * stride + ch]),
                &mut sources[ch * n..(ch + 1) * n],
            );
            for (t, v) in sensor_noise[ch * n..(ch + 1) * n].iter_mut().enumerate() {
                *v = unit(uniforms[t * stride + n_ch + ch]);
            }
        }

        // 2b. Drifts of the background's and alpha's amplitude (Realism).
        let drifts = self.realism.drifts();
        if drifts {
            self.realism
                .drift_gains(start, n, &mut self.bg_gain_buf, &mut self.alpha_gain_buf);
            let (sources, _) = self.scratch.split_at_mut(n_ch * n);
            for row in sources.chunks_exact_mut(n) {
                for (v, g) in row.iter_mut().zip(&self.bg_gain_buf) {
                    *v *= g;
                }
            }
        }
        // 3. Spatial mixing of the EEG sources.
        self.mix_background(n, bg, &mut block.data);

        // 4. Sources shared by all channels, one value per sample.
        self.shared_sources(n);
        if drifts {
            for (v, g) in self.alpha_buf.iter_mut().zip(&self.alpha_gain_buf) {
                *v *= g;
            }
        }

        // 5. Per channel: add everything with that channel's weights.
        let sensor = bg * self.params.sensor_noise_uv;
        let alpha = &self.alpha_buf[..n];
        let blink = &self.blink_buf[..n];
        let gaze = &self.gaze_buf[..n];
        let line_c = &self.line_c_buf[..n];
        let line_s = &self.line_s_buf[..n];
        let erp = &self.erp_buf[..n];
        for ch in 0..n_ch {
            let row = &mut block.data[ch * n..(ch + 1) * n];
            let noise = &self.scratch[(n_ch + ch) * n..(n_ch + ch + 1) * n];
            let (aw, lc, ls) = (self.alpha_weight[ch], self.line_cos[ch], -self.line_sin[ch]);
            let (bw, gw, tw) = (
                self.blink_coeff[ch],
                self.gaze_coeff[ch],
                self.topography[ch],
            );
            for t in 0..n {
                row[t] += aw * alpha[t]
                    + sensor * noise[t]
                    + lc * line_c[t]
                    + ls * line_s[t]
                    + bw * blink[t]
                    + gw * gaze[t]
                    + tw * erp[t];
            }
        }
        let art = if c.artifacts { 1.0 } else { 0.0 };
        self.realism.add_artifacts(&mut block.data, start, n, art);
        let now = self.sample as f64;
        let erp_len = ERP_LENGTH_SECS * fs;
        self.erps.retain(|e| now < e.onset_sample + erp_len);
    }

    /// Stage 4 of [`generate_into`](Self::generate_into): the sources all
    /// channels share (alpha, blinks, gaze, line noise, the ERPs), one value
    /// per sample of the next `n`, into their buffers.
    fn shared_sources(&mut self, n: usize) {
        let fs = self.params.sfreq_hz;
        let c = self.components;
        let bg = if c.background { 1.0 } else { 0.0 };
        let art = if c.artifacts { 1.0 } else { 0.0 };
        let erp_on = if c.erp { 1.0 } else { 0.0 };
        for buf in [
            &mut self.alpha_buf,
            &mut self.blink_buf,
            &mut self.gaze_buf,
            &mut self.line_c_buf,
            &mut self.line_s_buf,
            &mut self.erp_buf,
        ] {
            buf.clear();
        }
        let blink_len = (BLINK_SECS * fs) as u64;
        let saccade_len = ((SACCADE_SECS * fs) as u64).max(1);
        let erp_len = ERP_LENGTH_SECS * fs;
        let line_step = self.params.line_hz / fs;
        for _ in 0..n {
            let s = self.sample;
            let alpha = self
                .alpha
                .step(self.rng_alpha.sample::<f64, _>(StandardNormal));
            while s >= self.next_blink {
                let amp = self.params.blink_uv
                    * (1.0 + 0.2 * self.rng_artifacts.sample::<f64, _>(StandardNormal)).max(0.2);
                self.blinks.push((self.next_blink, amp));
                self.next_blink = self.draw_interval(self.params.blink_rate_hz);
            }
            let (blinks, blink_uv) = (&mut self.blinks, self.params.blink_uv);
            self.realism
                .blinks_due(s, |at, amp| blinks.push((at, blink_uv * amp)));
            while s >= self.next_saccade {
                self.gaze_from = self.gaze_at(s, saccade_len);
                self.gaze_to =
                    self.params.saccade_uv * self.rng_artifacts.sample::<f64, _>(StandardNormal);
                self.saccade_start = self.next_saccade;
                self.next_saccade = self.draw_interval(self.params.saccade_rate_hz);
            }
            self.blinks.retain(|&(start, _)| s < start + blink_len);
            let blink: f64 = self
                .blinks
                .iter()
                .map(|&(start, amp)| {
                    let x = (s - start) as f64 / blink_len as f64;
                    amp * (PI * x).sin().powi(2)
                })
                .sum();
            let phase = 2.0 * PI * (line_step * s as f64).fract();
            let (line_s, line_c) = phase.sin_cos();
            let mut erp = 0.0;
            for e in &self.erps {
                let dt = s as f64 - e.onset_sample;
                if dt < 0.0 {
                    break;
                }
                if dt < erp_len {
                    let t_ms = dt / fs * 1000.0 - e.jitter_ms;
                    erp += e.gain * waveform(self.templates.components(e.kind), t_ms);
                }
            }
            self.alpha_buf.push(bg * alpha);
            self.blink_buf.push(art * blink);
            self.gaze_buf.push(art * self.gaze_at(s, saccade_len));
            self.line_c_buf.push(art * line_c);
            self.line_s_buf.push(art * line_s);
            self.erp_buf.push(erp_on * self.erp_scale * erp);
            self.sample += 1;
        }
    }

    fn gaze_at(&self, s: u64, saccade_len: u64) -> f64 {
        if s < self.saccade_start {
            return self.gaze_from;
        }
        let x = ((s - self.saccade_start) as f64 / saccade_len as f64).min(1.0);
        let smooth = x * x * (3.0 - 2.0 * x);
        self.gaze_from + (self.gaze_to - self.gaze_from) * smooth
    }
}

/// Blink and gaze coefficients per channel. EOG: blinks are positive above
/// the eyes and smaller, negative below; gaze is opposite at the two canthi.
/// EEG: both leak with distance from the eyes (a blink reaches Fp1/Fp2 at
/// ~40 % of its supra-orbital size and Fz at ~10 %, as propagation factors
/// reported for EOG correction).
fn eye_coefficients(montage: &Montage) -> Result<(Vec<f64>, Vec<f64>)> {
    let pos =
        |name: &str| -> Result<[f64; 3]> { Ok(montage.channels()[montage.index(name)?].position) };
    let (la, ra, lo, ro) = (
        pos("EOG LA")?,
        pos("EOG RA")?,
        pos("EOG LO")?,
        pos("EOG RO")?,
    );
    let mut blink = Vec::with_capacity(montage.len());
    let mut gaze = Vec::with_capacity(montage.len());
    for c in montage.channels() {
        let (b, g) = match c.name.as_str() {
            "EOG LA" => (1.0, 0.1),
            "EOG RA" => (1.0, -0.1),
            "EOG LB" => (-0.35, 0.1),
            "EOG RB" => (-0.35, -0.1),
            "EOG LO" => (0.15, 0.5),
            "EOG RO" => (0.15, -0.5),
            _ => {
                let d_eye = angle_between(c.position, la).min(angle_between(c.position, ra));
                let b = 0.6 * (-d_eye / 0.6).exp();
                let g = 0.4
                    * ((-angle_between(c.position, lo) / 0.5).exp()
                        - (-angle_between(c.position, ro) / 0.5).exp());
                (b, g)
            }
        };
        blink.push(b);
        gaze.push(g);
    }
    Ok((blink, gaze))
}
