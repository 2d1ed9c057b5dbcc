//! Online, asynchronous ErrP detection (sec. 2.2.2 of the paper, and how
//! asynchronous-ErrP studies score it): the 800 ms window sliding every
//! 62.5 ms over an EEG feed, the detector that turns its p(error) series
//! into error events, and the detector's operating point measured on a
//! held-out session.
//!
//! Without a cue, a decoder that looks every 62.5 ms has about 16 chances a
//! second to fire on background EEG, and one ErrP is visible in several
//! consecutive windows. Asynchronous-ErrP studies therefore do not count
//! windows: they aggregate consecutive windows into events and score events
//! per ErrP (a hit when an event follows the ErrP within the decoder's
//! response span) and per unit of error-free time (false alarms per minute).
//! [`Detector`] does this; [`DetectorMode::Literal`] keeps the paper's
//! literal reading (each window against T_e on its own).

use crate::classify::ErrorModel;
use crate::continuous::ContinuousFeatures;
use crate::erp::AssessmentKind;
use crate::error::Result;
use crate::generator::{Assessment, EegBlock, EegFeed};
use crate::montage::Montage;
use crate::preprocess::Preprocessor;
use crate::svm::SvmModel;

mod detector;
mod held_out;
mod targeting;

pub use detector::*;
pub use held_out::*;
pub use targeting::*;

/// The decoder's window step: 62.5 ms (sec. 2.2.2).
pub const WINDOW_STEP_SECS: f64 = 0.0625;
/// Seconds of EEG fed before the window's time 0 so the causal filters
/// settle; the window's time 0 is generator time `WARM_UP_SECS`.
pub const WARM_UP_SECS: f64 = 2.0;

/// An EEG feed and the 800 ms window sliding over its preprocessed
/// channels, one hop of 62.5 ms at a time.
#[derive(Debug)]
pub struct SlidingWindow {
    generator: EegFeed,
    preprocessor: Preprocessor,
    features: ContinuousFeatures,
    window: EegBlock,
    scratch: Vec<f64>,
    raw: EegBlock,
    /// The raw samples of the warm-up, all channels.
    warm_up: EegBlock,
    /// Rows of FCz and Cz among the preprocessed channels.
    fcz_cz: [usize; 2],
}

impl SlidingWindow {
    /// Starts feeding `generator` (fresh, at its time 0) through a
    /// reset copy of `preprocessor`, and lets the filters settle for
    /// [`WARM_UP_SECS`]: the window's time 0 is generator time `WARM_UP_SECS`.
    pub fn start(
        generator: impl Into<EegFeed>,
        preprocessor: &Preprocessor,
        features: &ContinuousFeatures,
        montage: &Montage,
    ) -> Result<Self> {
        let mut generator = generator.into();
        let fs = generator.sfreq_hz();
        let mut preprocessor = preprocessor.clone();
        preprocessor.reset();
        let warm_up = generator.generate((WARM_UP_SECS * fs) as usize);
        let warm = preprocessor.process(&warm_up);
        let span = features.span();
        let mut window = EegBlock::zeros(warm.n_channels, span);
        for ch in 0..warm.n_channels {
            let src = warm.channel(ch);
            window
                .channel_mut(ch)
                .copy_from_slice(&src[src.len() - span..]);
        }
        let row = |name: &str| -> Result<usize> {
            let i = montage.index(name)?;
            Ok(preprocessor
                .outputs()
                .iter()
                .position(|&o| o == i)
                .unwrap_or(0))
        };
        let fcz_cz = [row("FCz")?, row("Cz")?];
        let hop = (WINDOW_STEP_SECS * fs).round() as usize;
        Ok(Self {
            generator,
            preprocessor,
            features: features.clone(),
            window,
            scratch: Vec::with_capacity(features.n_features(warm.n_channels)),
            raw: EegBlock::zeros(montage.len(), hop),
            warm_up,
            fcz_cz,
        })
    }

    /// Schedules the potential of an assessment at the window's time
    /// `onset_secs` (its time zero).
    pub fn schedule(&mut self, onset_secs: f64, kind: AssessmentKind) {
        self.generator.schedule(Assessment {
            onset_secs: WARM_UP_SECS + onset_secs,
            kind,
        });
    }

    /// Feeds one more hop through the preprocessing, slides the window,
    /// and returns the new preprocessed samples `(n_channels, hop)`.
    pub fn advance(&mut self) -> EegBlock {
        self.generator.generate_into(&mut self.raw);
        let fresh = self.preprocessor.process(&self.raw);
        let hop = fresh.n_samples;
        for ch in 0..fresh.n_channels {
            let w = self.window.channel_mut(ch);
            w.copy_within(hop.., 0);
            let n = w.len();
            w[n - hop..].copy_from_slice(fresh.channel(ch));
        }
        fresh
    }

    /// The raw samples of the warm-up ([`WARM_UP_SECS`] before the window's
    /// time 0), all channels.
    pub fn warm_up_raw(&self) -> &EegBlock {
        &self.warm_up
    }

    /// The raw samples of the last hop, all channels `(n_channels, hop)`:
    /// what an amplifier would have delivered.
    pub fn raw(&self) -> &EegBlock {
        &self.raw
    }

    /// p(error) of the current window.
    pub fn p_error(&mut self, model: &SvmModel) -> f64 {
        self.scratch.clear();
        self.features
            .extract_into(&self.window, 0, &mut self.scratch);
        model.p_error(&self.scratch)
    }

    /// The current window: the last 800 ms of preprocessed EEG, `(n_channels,
    /// n_samples)`, the oldest sample first.
    pub fn window(&self) -> &EegBlock {
        &self.window
    }

    /// Rows of FCz and Cz in the blocks [`advance`](Self::advance) returns.
    pub fn fcz_cz(&self) -> [usize; 2] {
        self.fcz_cz
    }
}

#[cfg(test)]
mod tests {
    use rand::Rng;

    use super::*;
    use crate::rng::labelled;
    use errp_valid::{Check, Valid};

    #[test]
    fn the_literal_detector_fires_on_every_window_at_t_e() {
        let mut d = Detector::new(DetectorParams::literal(), 0.8).unwrap();
        let out: Vec<bool> = [0.5, 0.8, 0.9, 0.79, 0.85]
            .iter()
            .enumerate()
            .map(|(k, &p)| d.push(p, k as f64 * WINDOW_STEP_SECS).detected)
            .collect();
        assert_eq!(out, [false, true, true, false, true]);
    }

    #[test]
    fn the_smoothed_detector_averages_and_then_waits() {
        let params = DetectorParams {
            mode: DetectorMode::Smoothed,
            smooth_windows: 3,
            refractory_secs: 0.5,
        };
        let mut d = Detector::new(Valid::new(params).unwrap(), 0.8).unwrap();
        // One window at 1.0 among lows never reaches a mean of 0.8.
        let mut fired = Vec::new();
        let ps = [
            0.6, 1.0, 0.6, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9,
        ];
        for (k, &p) in ps.iter().enumerate() {
            if d.push(p, k as f64 * WINDOW_STEP_SECS).detected {
                fired.push(k);
            }
        }
        // Mean of (1.0, 0.6, 0.9) = 0.83 at k = 3 (at k = 2 the mean is
        // 0.73); the next no earlier than 0.5 s = 8 steps later.
        assert_eq!(fired, [3, 11]);
        assert!((params.delay_secs() - 0.125).abs() < 1e-12);
    }

    #[test]
    fn bad_detector_settings_are_named() {
        let e = DetectorParams {
            smooth_windows: 0,
            ..DetectorParams::default()
        }
        .check()
        .unwrap_err()
        .to_string();
        assert!(e.contains("smooth_windows") && e.contains("1 to 16"), "{e}");
        let e = Detector::new(Valid::default(), 1.5)
            .unwrap_err()
            .to_string();
        assert!(e.contains("t_e"), "{e}");
        let e = HeldOutParams {
            duration_secs: 1e9,
            ..HeldOutParams::default()
        }
        .check()
        .unwrap_err()
        .to_string();
        assert!(e.contains("duration_secs"), "{e}");
    }

    #[test]
    fn scoring_attributes_by_span_and_counts_false_alarms_per_minute() {
        // 60 s, ErrPs at 10 and 30 s; p = 1 at 10.75 s (a hit, 0.75 s late),
        // at 20 s (false) and at 31.5 s (outside [0.5, 1.0]: false).
        let n = (60.0 / WINDOW_STEP_SECS) as usize;
        let mut p = vec![0.0; n];
        let at = |t: f64| (t / WINDOW_STEP_SECS).round() as usize - 1;
        p[at(10.75)] = 1.0;
        p[at(20.0)] = 1.0;
        p[at(31.5)] = 1.0;
        let rec = HeldOutSession {
            p_error: p,
            errps: vec![10.0, 30.0],
        };
        let span = ResponseSpan {
            from_secs: 0.5,
            to_secs: 1.0,
        };
        let op = operating_point(
            &rec,
            Detector::new(DetectorParams::literal(), 0.8).unwrap(),
            span,
        );
        assert_eq!(op.n_errps, 2);
        assert!((op.hit_rate - 0.5).abs() < 1e-12);
        assert!((op.median_latency_secs - 0.75).abs() < 1e-9);
        // Clean time: 60 s minus two spans of 9 windows each.
        let clean_min = (n - 18) as f64 * WINDOW_STEP_SECS / 60.0;
        assert!((op.clean_minutes - clean_min).abs() < 1e-9);
        assert!((op.false_alarms_per_min - 2.0 / clean_min).abs() < 1e-9);
    }

    #[test]
    fn the_threshold_search_meets_a_false_alarm_rate() {
        // Background p(error) uniform in [0, 1) per window (seeded): the
        // literal detector's false alarms fall as T_e rises.
        let mut rng = labelled(3, "test");
        let n = (600.0 / WINDOW_STEP_SECS) as usize;
        let p: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
        let rec = HeldOutSession {
            p_error: p,
            errps: vec![100.0],
        };
        let (t_e, op) = threshold_for_false_alarms(&rec, DetectorParams::literal(), 30.0).unwrap();
        assert!((op.false_alarms_per_min - 30.0).abs() < 3.0, "{t_e} {op:?}");
        // 16 windows a second: 30 a minute is a per-window rate of 1/32.
        assert!((t_e - (1.0 - 1.0 / 32.0)).abs() < 0.01, "{t_e}");
        let bad = OnlineTarget {
            hit_rate: 1.5,
            false_alarms_per_min: None,
        }
        .check()
        .unwrap_err()
        .to_string();
        assert!(bad.contains("hit_rate") && bad.contains("(0, 1)"), "{bad}");
    }

    /// 50 ErrPs 5 s apart over 300 s; windows respond with probability
    /// `early` from 0.25 to 0.5 s after each (windows that hold only the
    /// start of the ErrP) and always from 0.5625 to 1.0 s; background
    /// windows fire now and then.
    fn synthetic_recording(early: f64) -> HeldOutSession {
        let mut rng = labelled(7, "test");
        let n = (300.0 / WINDOW_STEP_SECS) as usize;
        let errps: Vec<f64> = (0..50).map(|k| 3.0 + 5.0 * k as f64).collect();
        let mut p: Vec<f64> = (0..n)
            .map(|_| if rng.random_bool(0.01) { 0.95 } else { 0.1 })
            .collect();
        for &o in &errps {
            for (k, v) in p.iter_mut().enumerate() {
                let lag = HeldOutSession::window_end_secs(k) - o;
                if (0.5625 - 1e-9..=1.0 + 1e-9).contains(&lag)
                    || ((0.25 - 1e-9..=0.5 + 1e-9).contains(&lag) && rng.random_bool(early))
                {
                    *v = 0.9;
                }
            }
        }
        HeldOutSession { p_error: p, errps }
    }

    #[test]
    fn binomial_tails() {
        assert_eq!(binomial_upper_tail(0, 10, 0.3), 1.0);
        assert_eq!(binomial_upper_tail(11, 10, 0.3), 0.0);
        // P(X >= 1) = 1 - 0.7^10; P(X >= 10) = 0.3^10.
        assert!((binomial_upper_tail(1, 10, 0.3) - (1.0 - 0.7f64.powi(10))).abs() < 1e-12);
        assert!((binomial_upper_tail(10, 10, 0.3) - 0.3f64.powi(10)).abs() < 1e-15);
        // Two of 100 at a rate of 1e-4: about (0.01)^2 / 2.
        let t = binomial_upper_tail(2, 100, 1e-4);
        assert!((t / 4.95e-5 - 1.0).abs() < 0.01, "{t}");
    }

    #[test]
    fn the_response_span_is_where_windows_respond() {
        let rec = synthetic_recording(0.0);
        let s = detector_span(&rec, DetectorParams::literal(), 0.8).unwrap();
        assert!((s.from_secs - 0.5625).abs() < 0.07, "{s:?}");
        assert!((s.to_secs - 1.0).abs() < 0.07, "{s:?}");
    }

    #[test]
    fn early_responses_are_part_of_the_span_not_false_alarms() {
        // A third of the windows that hold only the start of an ErrP fire:
        // far above the 1 % background, though a third of the peak.
        let rec = synthetic_recording(0.3);
        for (detector, late) in [
            (DetectorParams::literal(), 1.0),
            (
                Valid::default(),
                1.0 + DetectorParams::default().delay_secs(),
            ),
        ] {
            let span = detector_span(&rec, detector, 0.8).unwrap();
            assert!(span.from_secs <= 0.3 + 1e-9, "{detector:?}: {span:?}");
            assert!(
                span.to_secs >= 0.9 && span.to_secs <= late + 0.07,
                "{detector:?}: {span:?}"
            );
            let op = operating_point(&rec, Detector::new(detector, 0.8).unwrap(), span);
            assert!(op.hit_rate > 0.97, "{detector:?}: {op:?}");
            // The background fires on 1 % of the windows (9.6 a minute);
            // early responses counted as false alarms would add 50 ErrPs'
            // worth (about 10 a minute for the literal reading).
            let bound = match detector.mode {
                DetectorMode::Literal => 12.0,
                DetectorMode::Smoothed => 2.0,
            };
            assert!(op.false_alarms_per_min < bound, "{detector:?}: {op:?}");
        }
        // A span that starts at the peak's fifth, as a fraction-of-peak
        // rule gives, would call the early responses false alarms.
        let late_span = ResponseSpan {
            from_secs: 0.5625,
            to_secs: 1.0,
        };
        let op = operating_point(
            &rec,
            Detector::new(DetectorParams::literal(), 0.8).unwrap(),
            late_span,
        );
        assert!(op.false_alarms_per_min > 14.0, "{op:?}");
    }
}
