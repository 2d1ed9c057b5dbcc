//! The statistics `errp realism` measures on resting EEG: a Welch spectrum,
//! its aperiodic exponent and alpha peak, band-limited amplitude and
//! kurtosis.

use std::f64::consts::PI;

use errp_bci::FilterChain;

/// Welch segment length (samples at 256 Hz: 4 s, 0.25 Hz resolution).
const SEGMENT: usize = 1024;
/// Frequencies evaluated (Hz): 1 to 40 in 0.25 Hz steps.
const F_MIN: f64 = 1.0;
const F_MAX: f64 = 40.0;
const F_STEP: f64 = 0.25;

/// Welch's power spectrum of `x` (4 s Hann segments, half overlap), at
/// 1-40 Hz in 0.25 Hz steps: (frequencies, power in arbitrary units).
pub(super) fn welch(x: &[f64], fs: f64) -> (Vec<f64>, Vec<f64>) {
    let n_f = ((F_MAX - F_MIN) / F_STEP) as usize + 1;
    let freqs: Vec<f64> = (0..n_f).map(|k| F_MIN + k as f64 * F_STEP).collect();
    let hann: Vec<f64> = (0..SEGMENT)
        .map(|i| 0.5 - 0.5 * (2.0 * PI * i as f64 / SEGMENT as f64).cos())
        .collect();
    let mut power = vec![0.0; n_f];
    let mut count = 0usize;
    let mut start = 0;
    let mut seg = vec![0.0; SEGMENT];
    while start + SEGMENT <= x.len() {
        let mean = x[start..start + SEGMENT].iter().sum::<f64>() / SEGMENT as f64;
        for (s, (v, w)) in seg
            .iter_mut()
            .zip(x[start..start + SEGMENT].iter().zip(&hann))
        {
            *s = (v - mean) * w;
        }
        for (p, &f) in power.iter_mut().zip(&freqs) {
            // One DFT bin by rotation (Goertzel-like, in floating point).
            let step = 2.0 * PI * f / fs;
            let (sin_d, cos_d) = step.sin_cos();
            let (mut c, mut s) = (1.0f64, 0.0f64);
            let (mut re, mut im) = (0.0, 0.0);
            for v in &seg {
                re += v * c;
                im -= v * s;
                (c, s) = (c * cos_d - s * sin_d, s * cos_d + c * sin_d);
            }
            *p += re * re + im * im;
        }
        count += 1;
        start += SEGMENT / 2;
    }
    for p in &mut power {
        *p /= count.max(1) as f64;
    }
    (freqs, power)
}

/// The aperiodic exponent chi of P ~ 1 / f^chi: minus the slope of
/// log10 P on log10 f over 2-40 Hz with the alpha band (7-14 Hz) and the
/// edges left out, by least squares.
pub(super) fn aperiodic_exponent(f: &[f64], p: &[f64]) -> f64 {
    let pts: Vec<(f64, f64)> = f
        .iter()
        .zip(p)
        .filter(|(f, _)| (2.0..=40.0).contains(*f) && !(7.0..=14.0).contains(*f))
        .map(|(f, p)| (f.log10(), p.max(1e-300).log10()))
        .collect();
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    -sxy / sxx
}

/// The frequency of the largest power in 7-14 Hz.
pub(super) fn alpha_peak_hz(f: &[f64], p: &[f64]) -> f64 {
    f.iter()
        .zip(p)
        .filter(|(f, _)| (7.0..=14.0).contains(*f))
        .fold(
            (f64::NAN, f64::MIN),
            |a, (&f, &p)| if p > a.1 { (f, p) } else { a },
        )
        .0
}

/// `x` through a 50 Hz notch and a 1-40 Hz band-pass (causal), the first
/// 2 s (the filters settling) left out.
pub(super) fn band(x: &[f64], fs: f64) -> Vec<f64> {
    let mut y = x.to_vec();
    FilterChain::paper(50.0, 1.0, 40.0, fs).process(&mut y);
    y.split_off((2.0 * fs) as usize)
}

/// Standard deviation.
pub(super) fn sd(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / n).sqrt()
}

/// Excess kurtosis (0 for a Gaussian).
pub(super) fn excess_kurtosis(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = x.iter().map(|a| (a - m).powi(2)).sum::<f64>() / n;
    x.iter().map(|a| (a - m).powi(4)).sum::<f64>() / n / (v * v) - 3.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welch_finds_a_sine_and_the_slope_of_a_power_law() {
        let fs = 256.0;
        let x: Vec<f64> = (0..256 * 60)
            .map(|t| (2.0 * PI * 10.5 * t as f64 / fs).sin())
            .collect();
        let (f, p) = welch(&x, fs);
        assert_eq!(alpha_peak_hz(&f, &p), 10.5);
        // A spectrum that is exactly 1 / f^1.7 gives 1.7.
        let p: Vec<f64> = f.iter().map(|f| f.powf(-1.7)).collect();
        assert!((aperiodic_exponent(&f, &p) - 1.7).abs() < 1e-9);
    }

    #[test]
    fn a_gaussian_has_no_excess_kurtosis_and_a_spike_train_has_much() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let x: Vec<f64> = (0..100_000)
            .map(|_| StandardNormal.sample(&mut rng))
            .collect();
        assert!(excess_kurtosis(&x).abs() < 0.1);
        let spikes: Vec<f64> = (0..10_000)
            .map(|i| if i % 100 == 0 { 10.0 } else { 0.0 })
            .collect();
        assert!(excess_kurtosis(&spikes) > 50.0);
    }
}
