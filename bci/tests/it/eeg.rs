//! Statistical properties of the synthetic EEG that a decoder would notice.

use errp_bci::{Components, EegGenerator, FilterChain, GeneratorParams, Montage, Valid};
use realfft::RealFftPlanner;

fn background(seed: u64, secs: usize) -> (Montage, errp_bci::EegBlock) {
    let m = Montage::standard();
    let mut g = EegGenerator::new(&Valid::<GeneratorParams>::default(), &m, seed)
        .unwrap()
        .with_components(Components {
            background: true,
            artifacts: false,
            erp: false,
        });
    let b = g.generate(256 * secs);
    (m, b)
}

/// Welch PSD with 4 s Hann windows, half overlap; returns (freqs, power).
fn welch(x: &[f64], fs: f64) -> (Vec<f64>, Vec<f64>) {
    let n = 1024;
    let mut planner = RealFftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(n);
    let hann: Vec<f64> = (0..n)
        .map(|i| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos())
        .collect();
    let mut psd = vec![0.0; n / 2 + 1];
    let mut count = 0;
    let mut start = 0;
    while start + n <= x.len() {
        let mut buf: Vec<f64> = x[start..start + n]
            .iter()
            .zip(&hann)
            .map(|(a, w)| a * w)
            .collect();
        let mut spec = fft.make_output_vec();
        fft.process(&mut buf, &mut spec).unwrap();
        for (p, c) in psd.iter_mut().zip(&spec) {
            *p += c.norm_sqr();
        }
        count += 1;
        start += n / 2;
    }
    let freqs = (0..psd.len()).map(|k| k as f64 * fs / n as f64).collect();
    (freqs, psd.into_iter().map(|p| p / count as f64).collect())
}

#[test]
fn background_spectrum_falls_as_one_over_f_with_an_alpha_peak() {
    let (m, b) = background(1, 600);
    // Frontal site (little alpha): log-log slope between 2 and 30 Hz near -1.
    let (f, p) = welch(b.channel(m.index("FCz").unwrap()), 256.0);
    let pts: Vec<(f64, f64)> = f
        .iter()
        .zip(&p)
        .filter(|(f, _)| (2.0..=30.0).contains(*f) && !(7.0..=13.0).contains(*f))
        .map(|(f, p)| (f.ln(), p.ln()))
        .collect();
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let slope = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / pts.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    assert!((slope + 1.0).abs() < 0.25, "1/f slope {slope}");

    // Occipital site: a peak at 10 Hz above the 1/f trend.
    let (f, p) = welch(b.channel(m.index("Oz").unwrap()), 256.0);
    let at = |hz: f64| p[f.iter().position(|&x| (x - hz).abs() < 0.13).unwrap()];
    assert!(
        at(10.0) > 2.0 * at(7.0) && at(10.0) > 2.0 * at(13.0),
        "alpha peak"
    );
}

#[test]
fn band_passed_background_is_gaussian() {
    // The white drives are uniform; after 1/f shaping and the 1-10 Hz
    // band-pass the EEG the decoder sees has Gaussian moments.
    let (m, b) = background(2, 300);
    let mut x = b.channel(m.index("Cz").unwrap()).to_vec();
    FilterChain::paper(50.0, 1.0, 10.0, 256.0).process(&mut x);
    let x = &x[512..];
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    let skew = x.iter().map(|v| (v - mean).powi(3)).sum::<f64>() / n / var.powf(1.5);
    let kurt = x.iter().map(|v| (v - mean).powi(4)).sum::<f64>() / n / (var * var);
    assert!(skew.abs() < 0.1, "skewness {skew}");
    assert!((kurt - 3.0).abs() < 0.2, "kurtosis {kurt}");
}
