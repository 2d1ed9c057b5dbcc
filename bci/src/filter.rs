//! Causal IIR filters: biquad sections, Butterworth designs and a notch.

use std::f64::consts::PI;

/// One second-order section, transposed direct form II, normalised `a0 = 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Biquad {
    b: [f64; 3],
    a: [f64; 2],
}

impl Biquad {
    /// Low-pass section (bilinear transform with pre-warping; RBJ cookbook).
    pub fn lowpass(cutoff_hz: f64, q: f64, sfreq_hz: f64) -> Self {
        let (cos_w, alpha) = Self::warp(cutoff_hz, q, sfreq_hz);
        let b1 = 1.0 - cos_w;
        Self::normalise(
            [b1 / 2.0, b1, b1 / 2.0],
            [1.0 + alpha, -2.0 * cos_w, 1.0 - alpha],
        )
    }

    /// High-pass section.
    pub fn highpass(cutoff_hz: f64, q: f64, sfreq_hz: f64) -> Self {
        let (cos_w, alpha) = Self::warp(cutoff_hz, q, sfreq_hz);
        let b1 = 1.0 + cos_w;
        Self::normalise(
            [b1 / 2.0, -b1, b1 / 2.0],
            [1.0 + alpha, -2.0 * cos_w, 1.0 - alpha],
        )
    }

    /// Notch (band-stop) section at `centre_hz` with quality factor `q`.
    pub fn notch(centre_hz: f64, q: f64, sfreq_hz: f64) -> Self {
        let (cos_w, alpha) = Self::warp(centre_hz, q, sfreq_hz);
        Self::normalise(
            [1.0, -2.0 * cos_w, 1.0],
            [1.0 + alpha, -2.0 * cos_w, 1.0 - alpha],
        )
    }

    fn warp(f_hz: f64, q: f64, sfreq_hz: f64) -> (f64, f64) {
        let w = 2.0 * PI * f_hz / sfreq_hz;
        (w.cos(), w.sin() / (2.0 * q))
    }

    fn normalise(b: [f64; 3], a: [f64; 3]) -> Self {
        Self {
            b: [b[0] / a[0], b[1] / a[0], b[2] / a[0]],
            a: [a[1] / a[0], a[2] / a[0]],
        }
    }

    /// Magnitude of the frequency response at `f_hz`.
    pub fn gain(&self, f_hz: f64, sfreq_hz: f64) -> f64 {
        let w = 2.0 * PI * f_hz / sfreq_hz;
        let (c1, s1, c2, s2) = (w.cos(), w.sin(), (2.0 * w).cos(), (2.0 * w).sin());
        let num_re = self.b[0] + self.b[1] * c1 + self.b[2] * c2;
        let num_im = -(self.b[1] * s1 + self.b[2] * s2);
        let den_re = 1.0 + self.a[0] * c1 + self.a[1] * c2;
        let den_im = -(self.a[0] * s1 + self.a[1] * s2);
        ((num_re * num_re + num_im * num_im) / (den_re * den_re + den_im * den_im)).sqrt()
    }
}

/// Q factors of the two sections of a 4th-order Butterworth filter.
const BUTTERWORTH4_Q: [f64; 2] = [0.541_196_100_146_197, 1.306_562_964_876_376_6];

/// A cascade of biquads with its own state: one per channel.
#[derive(Debug, Clone, PartialEq)]
pub struct FilterChain {
    sections: Vec<Biquad>,
    state: Vec<[f64; 2]>,
}

impl FilterChain {
    /// The paper's preprocessing (sec. 2.1): a notch at `line_hz` (Q = 30)
    /// and a [low, high] Hz band-pass made of 4th-order Butterworth high-pass
    /// and low-pass filters. All causal, as online.
    pub fn paper(line_hz: f64, low_hz: f64, high_hz: f64, sfreq_hz: f64) -> Self {
        let mut sections = vec![Biquad::notch(line_hz, 30.0, sfreq_hz)];
        for q in BUTTERWORTH4_Q {
            sections.push(Biquad::highpass(low_hz, q, sfreq_hz));
        }
        for q in BUTTERWORTH4_Q {
            sections.push(Biquad::lowpass(high_hz, q, sfreq_hz));
        }
        Self::new(sections)
    }

    /// A chain of the given sections, at rest.
    pub fn new(sections: Vec<Biquad>) -> Self {
        let state = vec![[0.0; 2]; sections.len()];
        Self { sections, state }
    }

    /// Clears the state (as at the start of a signal).
    pub fn reset(&mut self) {
        for s in &mut self.state {
            *s = [0.0; 2];
        }
    }

    /// Filters `x` in place, carrying state across calls.
    pub fn process(&mut self, x: &mut [f64]) {
        for (sec, st) in self.sections.iter().zip(self.state.iter_mut()) {
            let [b0, b1, b2] = sec.b;
            let [a1, a2] = sec.a;
            let [mut z1, mut z2] = *st;
            for v in x.iter_mut() {
                let input = *v;
                let y = b0 * input + z1;
                z1 = b1 * input - a1 * y + z2;
                z2 = b2 * input - a2 * y;
                *v = y;
            }
            *st = [z1, z2];
        }
    }

    /// Zero-phase filtering of a whole signal (forward, then backward,
    /// from rest), as offline ERP analysis does; squares the magnitude
    /// response. Not causal: for display and grand averages only.
    pub fn filtfilt(&self, x: &mut [f64]) {
        let mut f = Self::new(self.sections.clone());
        f.process(x);
        x.reverse();
        f.reset();
        f.process(x);
        x.reverse();
    }

    /// Magnitude response of the whole chain at `f_hz`.
    pub fn gain(&self, f_hz: f64, sfreq_hz: f64) -> f64 {
        self.sections
            .iter()
            .map(|s| s.gain(f_hz, sfreq_hz))
            .product()
    }
}

/// The same cascade applied to every row of a block, each row with its own
/// state. Rows are processed side by side, sample by sample, so the CPU
/// overlaps the channels' independent recursions.
#[derive(Debug, Clone, PartialEq)]
pub struct FilterBank {
    sections: Vec<Biquad>,
    /// `state[section * n_rows + row]`.
    state: Vec<[f64; 2]>,
    n_rows: usize,
}

impl FilterBank {
    /// `chain`'s sections for `n_rows` rows, at rest.
    pub fn new(chain: &FilterChain, n_rows: usize) -> Self {
        Self {
            sections: chain.sections.clone(),
            state: vec![[0.0; 2]; chain.sections.len() * n_rows],
            n_rows,
        }
    }

    /// Clears the state.
    pub fn reset(&mut self) {
        self.state.fill([0.0; 2]);
    }

    /// Filters `data` (`(n_rows, n)`, row-major) in place, carrying state.
    pub fn process(&mut self, data: &mut [f64], n: usize) {
        assert_eq!(data.len(), self.n_rows * n, "block shape");
        const LANES: usize = 4;
        for (si, sec) in self.sections.iter().enumerate() {
            let [b0, b1, b2] = sec.b;
            let [a1, a2] = sec.a;
            let state = &mut self.state[si * self.n_rows..(si + 1) * self.n_rows];
            // Groups of four rows, their states held in locals (registers).
            for (g, st) in state.chunks_mut(LANES).enumerate() {
                let lanes = st.len();
                let rows = &mut data[g * LANES * n..(g * LANES + lanes) * n];
                let mut z1 = [0.0; LANES];
                let mut z2 = [0.0; LANES];
                for j in 0..lanes {
                    [z1[j], z2[j]] = st[j];
                }
                for t in 0..n {
                    for j in 0..lanes {
                        let v = &mut rows[j * n + t];
                        let input = *v;
                        let y = b0 * input + z1[j];
                        z1[j] = b1 * input - a1 * y + z2[j];
                        z2[j] = b2 * input - a2 * y;
                        *v = y;
                    }
                }
                for j in 0..lanes {
                    st[j] = [z1[j], z2[j]];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_chain_passes_the_errp_band_and_rejects_the_rest() {
        let f = FilterChain::paper(50.0, 1.0, 10.0, 256.0);
        assert!((f.gain(4.0, 256.0) - 1.0).abs() < 0.02);
        assert!(
            (f.gain(1.0, 256.0) - 0.5f64.sqrt()).abs() < 0.02,
            "-3 dB at 1 Hz"
        );
        assert!(
            (f.gain(10.0, 256.0) - 0.5f64.sqrt()).abs() < 0.02,
            "-3 dB at 10 Hz"
        );
        assert!(f.gain(0.1, 256.0) < 1e-3);
        assert!(f.gain(50.0, 256.0) < 1e-4);
        assert!(f.gain(30.0, 256.0) < 0.02);
    }

    #[test]
    fn filtering_in_blocks_equals_filtering_at_once() {
        let x: Vec<f64> = (0..1000)
            .map(|i| ((i * 7919) % 101) as f64 - 50.0)
            .collect();
        let mut whole = x.clone();
        FilterChain::paper(50.0, 1.0, 10.0, 256.0).process(&mut whole);
        let mut f = FilterChain::paper(50.0, 1.0, 10.0, 256.0);
        let mut parts = x.clone();
        for chunk in parts.chunks_mut(77) {
            f.process(chunk);
        }
        assert_eq!(whole, parts);
    }

    #[test]
    fn a_bank_filters_each_row_like_its_own_chain() {
        let chain = FilterChain::paper(50.0, 1.0, 10.0, 256.0);
        let n = 300;
        let mut data: Vec<f64> = (0..3 * n).map(|i| ((i * 31) % 17) as f64 - 8.0).collect();
        let mut expected = data.clone();
        for r in 0..3 {
            chain.clone().process(&mut expected[r * n..(r + 1) * n]);
        }
        FilterBank::new(&chain, 3).process(&mut data, n);
        assert_eq!(data, expected);
    }

    #[test]
    fn measured_response_matches_the_analytic_gain() {
        let fs = 256.0;
        let mut f = FilterChain::paper(50.0, 1.0, 10.0, fs);
        let mut x: Vec<f64> = (0..4096)
            .map(|i| (2.0 * PI * 6.0 * i as f64 / fs).sin())
            .collect();
        f.process(&mut x);
        let tail = &x[2048..];
        let amp = tail.iter().fold(0.0f64, |a, &v| a.max(v.abs()));
        assert!((amp - f.gain(6.0, fs)).abs() < 0.01, "{amp}");
    }
}
