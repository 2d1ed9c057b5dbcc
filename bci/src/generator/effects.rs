//! The running state of the [`Realism`] effects inside the generator:
//! drifts, electrode offsets, the user's recent error rate, lapses, action
//! blinks, EMG bursts, pops and a bad channel.

use std::f64::consts::PI;

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Exp, StandardNormal};

use super::realism::Realism;
use crate::erp::AssessmentKind;
use crate::error::Result;
use crate::montage::{Montage, angle_between};
use crate::rng::labelled;

/// The SD of one step of an Ornstein-Uhlenbeck process of stationary SD
/// `sd` and time constant `tau` sampled every `dt`, and its pole.
fn ou_step(sd: f64, tau: f64, dt: f64) -> (f64, f64) {
    let a = (-dt / tau).exp();
    (a, sd * (1.0 - a * a).sqrt())
}

/// Samples between two knots of the electrode offsets (interpolated
/// linearly between them).
const OFFSET_KNOT: u64 = 16;
/// Decay time constant of an electrode pop (s).
const POP_SECS: f64 = 0.3;
/// Sites of the muscles whose EMG the scalp picks up most: temporalis
/// (T7, T8, FT sites) and frontalis (Fp1, Fp2), with the angular width
/// (rad on the unit head sphere) over which it falls off.
const EMG_SITES: [(&str, f64); 6] = [
    ("T7", 1.0),
    ("T8", 1.0),
    ("F7", 0.8),
    ("F8", 0.8),
    ("Fp1", 0.5),
    ("Fp2", 0.5),
];
const EMG_WIDTH_RAD: f64 = 0.35;

#[derive(Debug, Clone, Copy)]
struct Burst {
    start: u64,
    len: u64,
    amp: f64,
}

#[derive(Debug, Clone, Copy)]
struct Pop {
    start: u64,
    ch: usize,
    amp: f64,
}

/// The running state of the effects: drifts, offsets, the user's recent
/// error rate, pending action blinks, EMG bursts and pops.
#[derive(Debug, Clone)]
pub(crate) struct RealismState {
    p: Realism,
    fs: f64,
    n_ch: usize,
    log_bg: f64,
    log_alpha: f64,
    drift_pole: f64,
    gain_from: (f64, f64),
    gain_to: (f64, f64),
    offsets_from: Vec<f64>,
    offsets_to: Vec<f64>,
    offset_pole: f64,
    offset_step: f64,
    /// The user's recent error rate (perceived actions).
    q: f64,
    pending_blinks: Vec<(u64, f64)>,
    emg_weight: Vec<(usize, f64)>,
    bursts: Vec<Burst>,
    next_burst: u64,
    pops: Vec<Pop>,
    next_pop: u64,
    bad: Option<usize>,
    rng_drift: ChaCha8Rng,
    rng_offsets: ChaCha8Rng,
    rng_user: ChaCha8Rng,
    rng_artifacts: ChaCha8Rng,
    rng_emg: ChaCha8Rng,
    rng_bad: ChaCha8Rng,
    n_eeg: usize,
}

/// What the user made of one action: whether an ERP follows, of which kind,
/// with what extra gain and latency, and whether a blink follows.
pub(crate) struct Perceived {
    /// The ERP's kind, or none (not attended).
    pub kind: Option<AssessmentKind>,
    /// Factor on the ERP's amplitude.
    pub gain: f64,
    /// Added latency (ms).
    pub shift_ms: f64,
}

impl RealismState {
    pub(crate) fn new(p: &Realism, montage: &Montage, fs: f64, seed: u64) -> Result<Self> {
        let n_ch = montage.len();
        let mut rng_drift = labelled(seed, "eeg/realism/drift");
        let mut rng_offsets = labelled(seed, "eeg/realism/offsets");
        let dt = 1.0 / fs;
        let (drift_pole, _) = ou_step(1.0, p.drift_secs, OFFSET_KNOT as f64 * dt);
        let (offset_pole, offset_step) = ou_step(
            p.electrode_drift_uv,
            p.electrode_drift_secs,
            OFFSET_KNOT as f64 * dt,
        );
        let log_bg = p.background_drift * rng_drift.sample::<f64, _>(StandardNormal);
        let log_alpha = p.alpha_drift * rng_drift.sample::<f64, _>(StandardNormal);
        let offsets_from: Vec<f64> = (0..n_ch)
            .map(|_| p.electrode_drift_uv * rng_offsets.sample::<f64, _>(StandardNormal))
            .collect();
        let offsets_to = offsets_from.clone();
        let mut emg_weight = Vec::new();
        for ch in 0..montage.n_eeg() {
            let pos = montage.channels()[ch].position;
            let mut w = 0.0f64;
            for (site, scale) in EMG_SITES {
                let at = montage.channels()[montage.index(site)?].position;
                let d = angle_between(pos, at);
                w = w.max(scale * (-0.5 * (d / EMG_WIDTH_RAD).powi(2)).exp());
            }
            if w > 0.01 {
                emg_weight.push((ch, w));
            }
        }
        let bad = if p.bad_channel.is_empty() {
            None
        } else {
            Some(montage.index(&p.bad_channel)?)
        };
        let mut state = Self {
            p: p.clone(),
            fs,
            n_ch,
            log_bg,
            log_alpha,
            drift_pole,
            gain_from: (1.0, 1.0),
            gain_to: (
                (log_bg - p.background_drift.powi(2)).exp(),
                (log_alpha - p.alpha_drift.powi(2)).exp(),
            ),
            offsets_from,
            offsets_to,
            offset_pole,
            offset_step,
            q: p.expectancy_reference,
            pending_blinks: Vec::new(),
            emg_weight,
            bursts: Vec::new(),
            next_burst: 0,
            pops: Vec::new(),
            next_pop: 0,
            bad,
            rng_drift,
            rng_offsets,
            rng_user: labelled(seed, "eeg/realism/user"),
            rng_artifacts: labelled(seed, "eeg/realism/artifacts"),
            rng_emg: labelled(seed, "eeg/realism/emg"),
            rng_bad: labelled(seed, "eeg/realism/bad-channel"),
            n_eeg: montage.n_eeg(),
        };
        state.next_burst = state.draw_interval(0, state.p.emg_rate_hz);
        state.next_pop = state.draw_interval(0, state.p.pop_rate_hz);
        Ok(state)
    }

    fn draw_interval(&mut self, from: u64, rate_hz: f64) -> u64 {
        if rate_hz <= 0.0 {
            return u64::MAX;
        }
        let secs: f64 = self
            .rng_artifacts
            .sample(Exp::new(rate_hz).expect("rate > 0"));
        from + (secs * self.fs).ceil().max(1.0) as u64
    }

    /// Session hours at `onset_secs` of the generator's clock.
    fn hours(&self, onset_secs: f64) -> f64 {
        (self.p.clock_offset_secs + onset_secs) / 3600.0
    }

    /// What the user makes of an action of `kind` at `onset_secs`: the
    /// lapses, the expectancy, the session's slopes and the phase. Draws
    /// from the user's stream in scheduling order, whatever is switched on.
    pub(crate) fn perceive(&mut self, kind: AssessmentKind, onset_secs: f64) -> Perceived {
        let p = &self.p;
        let hours = self.hours(onset_secs);
        let u_lapse: f64 = self.rng_user.random();
        let u_judge: f64 = self.rng_user.random();
        let u_blink: f64 = self.rng_user.random();
        let blink_z: f64 = self.rng_user.sample(StandardNormal);
        let blink_amp: f64 = self.rng_user.sample(StandardNormal);
        let lapse = (p.lapse_rate + p.lapse_per_hour * hours).clamp(0.0, 1.0);
        if u_lapse < lapse {
            return Perceived {
                kind: None,
                gain: 0.0,
                shift_ms: 0.0,
            };
        }
        let judged = if u_judge < p.misjudge_rate {
            match kind {
                AssessmentKind::Error => AssessmentKind::Correct,
                AssessmentKind::Correct => AssessmentKind::Error,
            }
        } else {
            kind
        };
        let mut gain = p.erp_gain * (1.0 + p.errp_amplitude_per_hour * hours).max(0.0);
        let is_error = judged == AssessmentKind::Error;
        if is_error {
            gain *= (1.0 - p.expectancy * (self.q - p.expectancy_reference)).max(0.0);
        }
        let w = 1.0 / p.expectancy_actions;
        self.q += w * (f64::from(u8::from(is_error)) - self.q);
        if u_blink < p.action_blink_probability {
            let latency_ms = p.action_blink_latency_ms * (1.0 + 0.25 * blink_z);
            let at = (onset_secs + latency_ms.max(0.0) / 1000.0) * self.fs;
            let amp = (1.0 + 0.2 * blink_amp).max(0.2);
            let at = at.round() as u64;
            let i = self.pending_blinks.partition_point(|&(s, _)| s <= at);
            self.pending_blinks.insert(i, (at, amp));
        }
        Perceived {
            kind: Some(judged),
            gain,
            shift_ms: p.erp_latency_shift_ms + p.errp_latency_ms_per_hour * hours,
        }
    }

    /// Action blinks due by sample `s` (their relative amplitudes), removed.
    pub(crate) fn blinks_due(&mut self, s: u64, mut push: impl FnMut(u64, f64)) {
        let due = self.pending_blinks.partition_point(|&(at, _)| at <= s);
        for (at, amp) in self.pending_blinks.drain(..due) {
            push(at, amp);
        }
    }

    /// The two drifts' amplitude factors (mean square 1) for samples
    /// `start..start + n`, into `bg` and `alpha`: the processes advance at
    /// knots every [`OFFSET_KNOT`] samples (their time constants are tens of
    /// seconds), the factors are linear between knots.
    pub(crate) fn drift_gains(
        &mut self,
        start: u64,
        n: usize,
        bg: &mut Vec<f64>,
        alpha: &mut Vec<f64>,
    ) {
        bg.clear();
        alpha.clear();
        let a = self.drift_pole;
        let b = (1.0 - a * a).sqrt();
        let (sb, sa) = (self.p.background_drift, self.p.alpha_drift);
        for t in 0..n {
            let s = start + t as u64;
            if s.is_multiple_of(OFFSET_KNOT) {
                let z1: f64 = self.rng_drift.sample(StandardNormal);
                let z2: f64 = self.rng_drift.sample(StandardNormal);
                self.log_bg = a * self.log_bg + b * sb * z1;
                self.log_alpha = a * self.log_alpha + b * sa * z2;
                self.gain_from = self.gain_to;
                self.gain_to = (
                    (self.log_bg - sb * sb).exp(),
                    (self.log_alpha - sa * sa).exp(),
                );
            }
            let x = (s % OFFSET_KNOT) as f64 / OFFSET_KNOT as f64;
            let (f, to) = (self.gain_from, self.gain_to);
            bg.push(f.0 + (to.0 - f.0) * x);
            alpha.push(f.1 + (to.1 - f.1) * x);
        }
    }

    /// True if the drifts are on (otherwise [`drift_gains`] is 1, 1 and
    /// need not be called).
    ///
    /// [`drift_gains`]: Self::drift_gains
    pub(crate) fn drifts(&self) -> bool {
        self.p.background_drift > 0.0 || self.p.alpha_drift > 0.0
    }

    /// Adds this module's artifacts for samples `start..start + n` to
    /// `data` (channel-major, `n` per channel), scaled by `scale` (0 when
    /// artifacts are switched off: the draws are made all the same, so the
    /// parts of a seed still add up to the whole). Each process draws from
    /// a stream of its own, sample by sample, so block boundaries never
    /// change the values.
    pub(crate) fn add_artifacts(&mut self, data: &mut [f64], start: u64, n: usize, scale: f64) {
        if self.p.electrode_drift_uv > 0.0 {
            self.add_offsets(data, start, n, scale);
        }
        if self.p.emg_rate_hz > 0.0 || self.p.pop_rate_hz > 0.0 {
            self.add_bursts_and_pops(data, start, n, scale);
        }
        if let Some(bad) = self.bad {
            let sd = scale * self.p.bad_channel_uv;
            for v in &mut data[bad * n..(bad + 1) * n] {
                let z: f64 = self.rng_bad.sample(StandardNormal);
                *v += sd * z;
            }
        }
    }

    /// Electrode offsets: knots every [`OFFSET_KNOT`] samples of an
    /// Ornstein-Uhlenbeck process per channel, linear between knots.
    fn add_offsets(&mut self, data: &mut [f64], start: u64, n: usize, scale: f64) {
        let (a, b) = (self.offset_pole, self.offset_step);
        let mut t = 0;
        while t < n {
            let s = start + t as u64;
            if s.is_multiple_of(OFFSET_KNOT) {
                std::mem::swap(&mut self.offsets_from, &mut self.offsets_to);
                for ch in 0..self.n_ch {
                    let z: f64 = self.rng_offsets.sample(StandardNormal);
                    self.offsets_to[ch] = a * self.offsets_from[ch] + b * z;
                }
            }
            let phase = s % OFFSET_KNOT;
            let seg = ((OFFSET_KNOT - phase) as usize).min(n - t);
            for ch in 0..self.n_ch {
                let (from, to) = (self.offsets_from[ch], self.offsets_to[ch]);
                let row = &mut data[ch * n + t..ch * n + t + seg];
                for (k, v) in row.iter_mut().enumerate() {
                    let x = (phase + k as u64) as f64 / OFFSET_KNOT as f64;
                    *v += scale * (from + (to - from) * x);
                }
            }
            t += seg;
        }
    }

    /// EMG bursts on the channels near the temporal and frontal muscles,
    /// and electrode pops on a random EEG channel.
    fn add_bursts_and_pops(&mut self, data: &mut [f64], start: u64, n: usize, scale: f64) {
        let pop_len = POP_SECS * self.fs;
        for t in 0..n {
            let s = start + t as u64;
            while s >= self.next_burst {
                let len_secs = self.p.emg_secs * self.rng_artifacts.random_range(0.5..1.5);
                let burst = Burst {
                    start: self.next_burst,
                    len: ((len_secs * self.fs) as u64).max(2),
                    amp: self.rng_artifacts.random_range(0.5..1.5),
                };
                self.bursts.push(burst);
                self.next_burst = self.draw_interval(self.next_burst, self.p.emg_rate_hz);
            }
            while s >= self.next_pop {
                let ch = self.rng_artifacts.random_range(0..self.n_eeg);
                let sign = if self.rng_artifacts.random_bool(0.5) {
                    1.0
                } else {
                    -1.0
                };
                let amp = sign * self.p.pop_uv * self.rng_artifacts.random_range(0.5..1.5);
                self.pops.push(Pop {
                    start: self.next_pop,
                    ch,
                    amp,
                });
                self.next_pop = self.draw_interval(self.next_pop, self.p.pop_rate_hz);
            }
            self.bursts.retain(|b| s < b.start + b.len);
            let e: f64 = self
                .bursts
                .iter()
                .map(|b| b.amp * envelope((s - b.start) as f64 / b.len as f64))
                .sum();
            if e > 0.0 {
                let sd = scale * self.p.emg_uv * e;
                for &(ch, w) in &self.emg_weight {
                    let z: f64 = self.rng_emg.sample(StandardNormal);
                    data[ch * n + t] += sd * w * z;
                }
            }
            self.pops
                .retain(|p| ((s - p.start) as f64) < POP_DECAYS * pop_len);
            for p in &self.pops {
                let decay = (-((s - p.start) as f64) / pop_len).exp();
                data[p.ch * n + t] += scale * p.amp * decay;
            }
        }
    }
}

/// How many time constants a pop is followed for.
const POP_DECAYS: f64 = 8.0;

/// Raised cosine envelope of a burst, 0 at its ends and 1 in its middle.
fn envelope(x: f64) -> f64 {
    (PI * x).sin().powi(2)
}
