//! Small statistics: mean and sd, median, quantiles and percentiles,
//! Pearson correlation with its two-sided p-value, Wilson intervals.

use errp_bci::ln_gamma;

/// Mean and sample standard deviation.
pub fn mean_sd(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    if xs.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let m = xs.iter().sum::<f64>() / n;
    let sd = if xs.len() > 1 {
        (xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    (m, sd)
}

/// Median of `xs` (NaN if empty).
pub fn median(xs: &[f64]) -> f64 {
    if xs.is_empty() {
        return f64::NAN;
    }
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The share of `values` below `x`, ties counted half (the mid-rank
/// percentile, 0 to 1); NaN for no values.
pub fn percentile_of(values: &[f64], x: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let below = values.iter().filter(|&&v| v < x).count() as f64;
    let equal = values.iter().filter(|&&v| v == x).count() as f64;
    (below + 0.5 * equal) / values.len() as f64
}

/// The `q` quantile (0 to 1) of `values` by linear interpolation between
/// order statistics; NaN for no values.
pub fn quantile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let pos = q.clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let (i, frac) = (pos.floor() as usize, pos - pos.floor());
    if i + 1 < v.len() {
        v[i] + frac * (v[i + 1] - v[i])
    } else {
        v[i]
    }
}

/// Pearson's r between `x` and `y` and the two-sided p-value of r = 0
/// (Student's t with n - 2 degrees of freedom). NaN when undefined.
pub fn pearson(x: &[f64], y: &[f64]) -> (f64, f64) {
    let n = x.len().min(y.len());
    if n < 3 {
        return (f64::NAN, f64::NAN);
    }
    let nf = n as f64;
    let mx = x[..n].iter().sum::<f64>() / nf;
    let my = y[..n].iter().sum::<f64>() / nf;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for i in 0..n {
        sxy += (x[i] - mx) * (y[i] - my);
        sxx += (x[i] - mx).powi(2);
        syy += (y[i] - my).powi(2);
    }
    if sxx == 0.0 || syy == 0.0 {
        return (f64::NAN, f64::NAN);
    }
    let r = (sxy / (sxx * syy).sqrt()).clamp(-1.0, 1.0);
    (r, correlation_p_value(r, n))
}

/// The two-sided p-value of Pearson's `r` over `n` pairs under r = 0
/// (Student's t with n - 2 degrees of freedom).
pub fn correlation_p_value(r: f64, n: usize) -> f64 {
    if n < 3 || !r.is_finite() {
        return f64::NAN;
    }
    let df = n as f64 - 2.0;
    if (1.0 - r * r) <= 0.0 {
        return 0.0;
    }
    let t = r * (df / (1.0 - r * r)).sqrt();
    // Two-sided p = I_{df/(df+t^2)}(df/2, 1/2).
    incomplete_beta(df / 2.0, 0.5, df / (df + t * t))
}

/// Pearson's r accumulated one pair at a time (Welford's co-moments), for
/// data streamed from disk: constant memory, whatever the number of pairs.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RunningPearson {
    n: usize,
    mean_x: f64,
    mean_y: f64,
    sxx: f64,
    syy: f64,
    sxy: f64,
}

impl RunningPearson {
    /// Adds the pair (x, y).
    pub fn push(&mut self, x: f64, y: f64) {
        self.n += 1;
        let n = self.n as f64;
        let dx = x - self.mean_x;
        self.mean_x += dx / n;
        let dy = y - self.mean_y;
        self.mean_y += dy / n;
        self.sxx += dx * (x - self.mean_x);
        self.syy += dy * (y - self.mean_y);
        self.sxy += dx * (y - self.mean_y);
    }

    /// Pairs so far.
    pub fn len(&self) -> usize {
        self.n
    }

    /// True before the first pair.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// r and its two-sided p-value, as [`pearson`] gives them (NaN when
    /// undefined).
    pub fn r_p(&self) -> (f64, f64) {
        if self.n < 3 || self.sxx <= 0.0 || self.syy <= 0.0 {
            return (f64::NAN, f64::NAN);
        }
        let r = (self.sxy / (self.sxx * self.syy).sqrt()).clamp(-1.0, 1.0);
        (r, correlation_p_value(r, self.n))
    }
}

/// The 95 % Wilson score interval of a proportion of `successes` out of `n`
/// ((NaN, NaN) for n = 0).
pub fn wilson_interval(successes: usize, n: usize) -> (f64, f64) {
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let z = 1.959_963_984_540_054_f64;
    let nf = n as f64;
    let p = successes as f64 / nf;
    let denom = 1.0 + z * z / nf;
    let centre = (p + z * z / (2.0 * nf)) / denom;
    let half = z * (p * (1.0 - p) / nf + z * z / (4.0 * nf * nf)).sqrt() / denom;
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

/// Regularised incomplete beta function I_x(a, b) (continued fraction,
/// Numerical Recipes `betai`).
pub fn incomplete_beta(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front = ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln();
    let front = ln_front.exp();
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_cf(a, b, x) / a
    } else {
        1.0 - front * beta_cf(b, a, 1.0 - x) / b
    }
}

fn beta_cf(a: f64, b: f64, x: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    if d.abs() < TINY {
        d = TINY;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..300 {
        let m = f64::from(m);
        let m2 = 2.0 * m;
        let aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        d = if d.abs() < TINY { TINY } else { d };
        c = 1.0 + aa / c;
        c = if c.abs() < TINY { TINY } else { c };
        d = 1.0 / d;
        h *= d * c;
        let aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        d = if d.abs() < TINY { TINY } else { d };
        c = 1.0 + aa / c;
        c = if c.abs() < TINY { TINY } else { c };
        d = 1.0 / d;
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

/// `x` with `decimals` decimals, or `-` when it is undefined (NaN or
/// infinite: a rate of no trials, the median of no runs), so that no
/// printed figure is invented.
pub fn fixed_or_dash(x: f64, decimals: usize) -> String {
    if x.is_finite() {
        format!("{x:.decimals$}")
    } else {
        "-".to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pearson_matches_known_values() {
        // scipy.stats.pearsonr([1, 2, 3, 4, 5], [2, 1, 4, 3, 5])
        // = (0.8, 0.10408803866182788).
        let (r, p) = pearson(&[1.0, 2.0, 3.0, 4.0, 5.0], &[2.0, 1.0, 4.0, 3.0, 5.0]);
        assert!((r - 0.8).abs() < 1e-12);
        assert!((p - 0.104_088_038_661_827_88).abs() < 1e-9, "{p}");
        // The paper's fixed-goal figure: r = -0.47 over 20 runs gives p ~ 0.037.
        let t = -0.47 * (18.0f64 / (1.0 - 0.47 * 0.47)).sqrt();
        let p = incomplete_beta(9.0, 0.5, 18.0 / (18.0 + t * t));
        assert!((p - 0.0365).abs() < 0.002, "{p}");
        assert!(pearson(&[1.0, 1.0, 1.0], &[1.0, 2.0, 3.0]).0.is_nan());
    }

    #[test]
    fn running_pearson_equals_the_two_pass_one() {
        let x: Vec<f64> = (0..50).map(|i| (i as f64 * 0.37).sin() + 3.0).collect();
        let y: Vec<f64> = (0..50)
            .map(|i| (i as f64 * 0.11).cos() * 40.0 + x[i])
            .collect();
        let mut s = RunningPearson::default();
        for i in 0..50 {
            s.push(x[i], y[i]);
        }
        let (r, p) = s.r_p();
        let (r2, p2) = pearson(&x, &y);
        assert!(
            (r - r2).abs() < 1e-12 && (p - p2).abs() < 1e-10,
            "{r} {r2} {p} {p2}"
        );
        assert!(RunningPearson::default().r_p().0.is_nan());
    }

    #[test]
    fn wilson_interval_matches_known_values() {
        // statsmodels proportion_confint(8, 10, method="wilson")
        // = (0.4901624, 0.9433178).
        let (lo, hi) = wilson_interval(8, 10);
        assert!((lo - 0.490_162_4).abs() < 1e-6 && (hi - 0.943_317_8).abs() < 1e-6);
        let (lo, hi) = wilson_interval(0, 20);
        assert!(lo == 0.0 && hi > 0.1 && hi < 0.2);
        assert!(wilson_interval(0, 0).0.is_nan());
    }

    #[test]
    fn percentiles_and_quantiles() {
        let v = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(percentile_of(&v, 2.5), 0.5);
        assert_eq!(percentile_of(&v, 2.0), 0.375);
        assert_eq!(percentile_of(&v, 0.0), 0.0);
        assert_eq!(percentile_of(&v, 9.0), 1.0);
        assert!(percentile_of(&[], 1.0).is_nan());
        assert_eq!(quantile(&v, 0.5), 2.5);
        assert_eq!(quantile(&v, 0.0), 1.0);
        assert_eq!(quantile(&v, 1.0), 4.0);
        assert!((quantile(&v, 0.1) - 1.3).abs() < 1e-12);
    }
}
