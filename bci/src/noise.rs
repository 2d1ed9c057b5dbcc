//! Coloured noise sources: 1/f ("pink") noise and a narrow-band resonator.

use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_distr::StandardNormal;

/// Corner frequencies (Hz) of the first-order sections whose sum is pink.
const PINK_CORNERS_HZ: [f64; 6] = [0.05, 0.2, 0.8, 3.2, 12.8, 51.2];

/// Unit-variance 1/f noise: a sum of first-order low-pass sections with
/// corners two octaves apart, each weighted so that every octave carries the
/// same power (the classic "sum of Lorentzians" approximation). The spectrum
/// falls as 1/f between about 0.05 Hz and 50 Hz at 256 Hz sampling.
#[derive(Debug, Clone)]
pub struct PinkNoise {
    poles: [f64; 6],
    gains: [f64; 6],
    state: [f64; 6],
}

impl PinkNoise {
    /// A source at `sfreq_hz` whose state is drawn from its stationary
    /// distribution (no start-up transient).
    pub fn new(sfreq_hz: f64, rng: &mut impl Rng) -> Self {
        let mut poles = [0.0; 6];
        let mut gains = [0.0; 6];
        for (k, &fc) in PINK_CORNERS_HZ.iter().enumerate() {
            poles[k] = (-2.0 * std::f64::consts::PI * fc / sfreq_hz).exp();
            gains[k] = (1.0 - poles[k]) / fc.sqrt();
        }
        let cov = DMatrix::from_fn(6, 6, |j, k| {
            gains[j] * gains[k] / (1.0 - poles[j] * poles[k])
        });
        let var: f64 = cov.iter().sum();
        let scale = 1.0 / var.sqrt();
        for g in &mut gains {
            *g *= scale;
        }
        let chol = (cov * (scale * scale))
            .cholesky()
            .expect("the stationary covariance is positive definite");
        let z = DVector::from_fn(6, |_, _| rng.sample::<f64, _>(StandardNormal));
        let s = chol.l() * z;
        let mut state = [0.0; 6];
        state.copy_from_slice(s.as_slice());
        Self {
            poles,
            gains,
            state,
        }
    }

    /// Advances one sample, driven by the white-noise sample `w`.
    #[inline]
    pub fn step(&mut self, w: f64) -> f64 {
        let mut sum = 0.0;
        for k in 0..6 {
            self.state[k] = self.poles[k] * self.state[k] + self.gains[k] * w;
            sum += self.state[k];
        }
        sum
    }
}

impl PinkNoise {
    /// Advances `out.len()` samples, driven by `drive(t)`, writing the output
    /// to `out` (state kept in registers for the whole run).
    #[inline]
    pub fn run(&mut self, mut drive: impl FnMut(usize) -> f64, out: &mut [f64]) {
        let (p, g) = (self.poles, self.gains);
        let mut st = self.state;
        for (t, o) in out.iter_mut().enumerate() {
            let w = drive(t);
            let mut sum = 0.0;
            for k in 0..6 {
                st[k] = p[k] * st[k] + g[k] * w;
                sum += st[k];
            }
            *o = sum;
        }
        self.state = st;
    }
}

/// Unit-variance narrow-band noise: a second-order autoregressive resonator
/// (used for the alpha rhythm).
#[derive(Debug, Clone)]
pub struct Resonator {
    a1: f64,
    a2: f64,
    gain: f64,
    x1: f64,
    x2: f64,
}

impl Resonator {
    /// A resonator at `centre_hz` with -3 dB bandwidth of about
    /// `bandwidth_hz`, started in its stationary distribution.
    pub fn new(centre_hz: f64, bandwidth_hz: f64, sfreq_hz: f64, rng: &mut impl Rng) -> Self {
        let r = (-std::f64::consts::PI * bandwidth_hz / sfreq_hz).exp();
        let a1 = 2.0 * r * (2.0 * std::f64::consts::PI * centre_hz / sfreq_hz).cos();
        let a2 = -r * r;
        // Variance of x_t = a1 x_{t-1} + a2 x_{t-2} + e_t with unit-variance e.
        let var = (1.0 - a2) / ((1.0 + a2) * ((1.0 - a2).powi(2) - a1 * a1));
        let gain = 1.0 / var.sqrt();
        // Stationary start: lag-one autocorrelation a1 / (1 - a2).
        let rho = a1 / (1.0 - a2);
        let z1: f64 = rng.sample(StandardNormal);
        let z2: f64 = rng.sample(StandardNormal);
        let x1 = z1;
        let x2 = rho * z1 + (1.0 - rho * rho).max(0.0).sqrt() * z2;
        Self {
            a1,
            a2,
            gain,
            x1,
            x2,
        }
    }

    /// Advances one sample, driven by the white-noise sample `w`.
    #[inline]
    pub fn step(&mut self, w: f64) -> f64 {
        let x = self.a1 * self.x1 + self.a2 * self.x2 + self.gain * w;
        self.x2 = self.x1;
        self.x1 = x;
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::labelled;

    fn variance(xs: &[f64]) -> f64 {
        let m = xs.iter().sum::<f64>() / xs.len() as f64;
        xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / xs.len() as f64
    }

    #[test]
    fn sources_have_unit_variance() {
        let mut rng = labelled(3, "test");
        // Average over many short independent runs: pink noise has long memory.
        let mut pink_var = 0.0;
        for _ in 0..200 {
            let mut p = PinkNoise::new(256.0, &mut rng);
            let xs: Vec<f64> = (0..512)
                .map(|_| p.step(rng.sample(StandardNormal)))
                .collect();
            pink_var += xs.iter().map(|x| x * x).sum::<f64>() / 512.0 / 200.0;
        }
        assert!((pink_var - 1.0).abs() < 0.1, "pink variance {pink_var}");
        let mut a = Resonator::new(10.0, 2.0, 256.0, &mut rng);
        let xs: Vec<f64> = (0..200_000)
            .map(|_| a.step(rng.sample(StandardNormal)))
            .collect();
        let v = variance(&xs);
        assert!((v - 1.0).abs() < 0.05, "alpha variance {v}");
    }
}
