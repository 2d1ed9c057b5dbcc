//! `errp realism`: the simulated user's statistics beside published
//! EEG of people. Each row measures one statistic on the user of a
//! scenario (its `[realism]` table) and sets it beside the published range,
//! with the source and whether the simulated user falls inside it.

mod published;
mod spectrum;

use errp_bci::{
    CalibrationSetup, Components, EegGenerator, LdaDecoder, Montage, SessionOptions, Valid,
    calibrate,
};

use crate::calibration::NoCache;
use crate::epuck::{EpuckScenario, prepare_epuck_decoder};
use crate::error::Result;
use crate::grid::{
    GridScenario, INFORMATION_PER_CLASS, pooled_accuracy, prepare_decoder, run_grid_scenario,
};

pub use published::{PUBLISHED, Published, Source};
use spectrum::{alpha_peak_hz, aperiodic_exponent, band, excess_kurtosis, sd, welch};

/// Seconds of resting EEG the background's statistics are measured on.
pub const RESTING_SECS: usize = 300;

/// One statistic of the simulated user beside its published value.
#[derive(Debug, Clone, PartialEq)]
pub struct RealismRow {
    /// The published statistic this row measures (its key in
    /// [`PUBLISHED`]).
    pub published: &'static Published,
    /// The simulated user's value, in the published unit.
    pub ours: f64,
}

impl RealismRow {
    /// Inside the published range (none if the sources give one value, or
    /// no figure was found).
    pub fn inside(&self) -> Option<bool> {
        self.published.source?;
        self.published
            .range
            .map(|(lo, hi)| (lo..=hi).contains(&self.ours))
    }
}

/// Every row of `errp realism`, in the order of [`PUBLISHED`].
#[derive(Debug, Clone, PartialEq)]
pub struct RealismReport {
    /// The grid scenario whose user and decoder were measured.
    pub grid: String,
    /// The e-puck scenario whose detector was measured.
    pub epuck: String,
    /// The rows.
    pub rows: Vec<RealismRow>,
}

/// What the stages of [`measure_realism`] report as they start.
pub type Stage<'a> = &'a mut dyn FnMut(&str);

/// Measures the user of `grid` (background, ErrP, discrete decoder,
/// calibration against the closed loop) and the detector of `epuck`.
pub fn measure_realism(
    grid: &GridScenario,
    epuck: &EpuckScenario,
    stage: Stage<'_>,
) -> Result<RealismReport> {
    stage("resting EEG");
    let mut values = background(grid)?;
    stage("grid: calibration and closed loop");
    values.extend(grid_values(grid)?);
    stage("e-puck: calibration and held-out recording");
    values.extend(epuck_values(epuck)?);
    let rows = PUBLISHED
        .iter()
        .map(|p| {
            let ours = values
                .iter()
                .find(|(k, _)| *k == p.key)
                .map_or(f64::NAN, |(_, v)| *v);
            RealismRow { published: p, ours }
        })
        .collect();
    Ok(RealismReport {
        grid: grid.name.clone(),
        epuck: epuck.name.clone(),
        rows,
    })
}

/// The resting EEG of the grid scenario's user (no actions): spectrum,
/// amplitude, kurtosis and the spread of 10 s blocks.
fn background(s: &GridScenario) -> Result<Vec<(&'static str, f64)>> {
    let montage = Montage::standard();
    let setup = CalibrationSetup::default().with_realism(&s.realism)?;
    let mut g =
        EegGenerator::new(&setup.generator, &montage, s.seed)?.with_components(Components {
            erp: false,
            ..Components::default()
        });
    let fs = setup.generator.sfreq_hz;
    let raw = g.generate(RESTING_SECS * fs as usize);
    let cz = raw.channel(montage.index("Cz")?);
    let oz = raw.channel(montage.index("Oz")?);
    let (f, p) = welch(cz, fs);
    let exponent = aperiodic_exponent(&f, &p);
    let (f, p) = welch(oz, fs);
    let alpha = alpha_peak_hz(&f, &p);
    let mut amplitudes = Vec::new();
    let mut kurtosis = 0.0;
    for ch in 0..montage.n_eeg() {
        let x = band(raw.channel(ch), fs);
        amplitudes.push(sd(&x));
        kurtosis += excess_kurtosis(&x) / montage.n_eeg() as f64;
    }
    amplitudes.sort_by(f64::total_cmp);
    let median = amplitudes[amplitudes.len() / 2];
    let cz_band = band(cz, fs);
    let blocks: Vec<f64> = cz_band.chunks_exact(10 * fs as usize).map(sd).collect();
    let spread = sd(&blocks) / (blocks.iter().sum::<f64>() / blocks.len() as f64);
    Ok(vec![
        ("aperiodic_exponent", exponent),
        ("alpha_peak_hz", alpha),
        ("amplitude_uv", median),
        ("kurtosis", kurtosis),
        ("block_sd_spread", 100.0 * spread),
    ])
}

/// The grid user's ErrP at FCz (the calibration session's grand average),
/// the discrete decoder's per-class rates, and calibration against the
/// closed loop.
fn grid_values(s: &GridScenario) -> Result<Vec<(&'static str, f64)>> {
    let (decoder, report) = prepare_decoder(s, |_| {})?;
    let Some(report) = report else {
        return Err(crate::SimError::Scenario(format!(
            "{}: errp realism measures the EEG decoder, not the oracle (decoder = \"eeg\")",
            s.path.display()
        )));
    };
    let setup = Valid::new(
        CalibrationSetup::default()
            .with_realism(&s.realism)?
            .at_ratio(report.targeting.ratio)?,
    )?;
    let options = SessionOptions {
        grand_average: true,
        ..SessionOptions::default()
    };
    let session = calibrate(&LdaDecoder::default(), &setup, s.seed, options)?.session;
    let average = session
        .grand_average
        .expect("the session was asked for its grand average");
    let fcz = average
        .channels
        .iter()
        .position(|c| c == "FCz")
        .expect("FCz is a decoding channel");
    let diff = average.difference();
    let at = |from: f64, to: f64, sign: f64| {
        let mut best = (f64::NAN, f64::MIN);
        for (k, &t) in average.times_ms.iter().enumerate() {
            let v = sign * diff[(fcz, k)];
            if (from..=to).contains(&t) && v > best.1 {
                best = (t, v);
            }
        }
        (best.0, sign * best.1)
    };
    let (neg_ms, neg_uv) = at(150.0, 320.0, -1.0);
    let (pos_ms, pos_uv) = at(250.0, 450.0, 1.0);
    let cv = report.calibrated.accuracy;
    let information = decoder.information(
        &s.params,
        INFORMATION_PER_CLASS,
        errp_bci::rng::derive_seed(s.seed, "realism/information", 0),
    )?;
    let episodes = run_grid_scenario(s, &decoder, false, |_, _| {})?;
    let online = pooled_accuracy(&episodes);
    Ok(vec![
        ("errp_negative_ms", neg_ms),
        ("errp_negative_uv", neg_uv),
        ("errp_positive_ms", pos_ms),
        ("errp_positive_uv", pos_uv),
        ("latency_jitter_ms", setup.generator.trial_latency_sd_ms()),
        ("blinks_per_min", 60.0 * setup.generator.blink_rate_hz),
        ("discrete_error_class", 100.0 * cv.error),
        ("discrete_correct_class", 100.0 * cv.correct),
        (
            "binary_channel_bits",
            errp_bci::binary_channel_bits(cv.error, cv.correct),
        ),
        ("information_bits", information.bits),
        (
            "calibration_minus_online",
            100.0 * (cv.mean() - online.mean()),
        ),
    ])
}

/// The e-puck detector's per-trial rates on the held-out session: a hit
/// per ErrP, and the chance that the span of a trial's response holds no
/// false alarm.
fn epuck_values(s: &EpuckScenario) -> Result<Vec<(&'static str, f64)>> {
    let prepared = prepare_epuck_decoder(s, &NoCache, |_| {}, |_| {})?;
    let online = prepared
        .decoder
        .online
        .as_ref()
        .expect("the e-puck decoder is measured online when prepared");
    let point = online.point;
    let span_secs = point.span.to_secs - point.span.from_secs;
    let tnr = (-point.false_alarms_per_min * span_secs / 60.0).exp();
    Ok(vec![
        ("continuous_tpr", 100.0 * point.hit_rate),
        ("continuous_tnr", 100.0 * tnr),
    ])
}

impl std::fmt::Display for RealismReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "The simulated user beside published recordings (grid: {}; e-puck: {})",
            self.grid, self.epuck
        )?;
        writeln!(
            f,
            "{:<58} {:>8}  {:<12} {:<6}  source",
            "statistic", "ours", "published", "inside"
        )?;
        for row in &self.rows {
            let p = row.published;
            let published = match (p.range, p.source) {
                (_, None) => "-".to_string(),
                (Some((lo, hi)), _) => format!("{} to {}", trim(lo), trim(hi)),
                (None, _) => format!("{} (one)", trim(p.value)),
            };
            let inside = match row.inside() {
                Some(true) => "yes",
                Some(false) => "no",
                None => "-",
            };
            writeln!(
                f,
                "{:<58} {:>8}  {:<12} {:<6}  {}",
                if p.unit.is_empty() {
                    p.what.to_string()
                } else {
                    format!("{} ({})", p.what, p.unit)
                },
                format!("{:.2}", row.ours),
                published,
                inside,
                p.source.map_or("no published figure found", |s| s.cite)
            )?;
        }
        Ok(())
    }
}

/// A number without trailing zeros.
fn trim(x: f64) -> String {
    let s = format!("{x:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
