//! Real time: the simulated user and device on the wall clock, with a
//! decoder outside the process in the loop (`errp stream`).
//!
//! The loop publishes the user's raw EEG, markers and the device's state
//! through a [`LiveLink`] (Lab Streaming Layer in `errp stream`; anything
//! with a clock in the tests) and takes the decoder's decisions back from
//! it. Simulated time runs `speed` times faster than the link's clock: the
//! sample `n` carries the timestamp `origin + n / (fs * speed)` and is
//! published once that time has passed, 16 samples (62.5 ms) at a time.
//!
//! Timing has rules ([`DecisionTracker`]): an action's decision must come
//! before the next action; one that comes later is counted late and not
//! applied; a decoder silent for `timeout_secs` stops the loop.

use errp_bci::EegBlock;

use crate::epuck::EpuckObserver;
use crate::error::{Result, SimError};

mod decisions;
pub mod epuck;
pub mod grid;
#[cfg(feature = "rerun")]
pub mod save;

pub use decisions::{
    DecisionTracker, Decisions, Fate, LiveRunStats, LoggedDecision, Received, WindowTracker,
};

/// The fastest a live loop runs: 100 times the wall clock.
pub const MAX_SPEED: f64 = 100.0;
/// The longest wait for a silent decoder (s).
pub const MAX_TIMEOUT_SECS: f64 = 3600.0;
/// Samples published at once: 62.5 ms at 256 Hz.
pub const HOP_SAMPLES: usize = 16;

/// How a live loop runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LiveOptions {
    /// Simulated seconds per second of the link's clock, in (0,
    /// [`MAX_SPEED`]].
    pub speed: f64,
    /// Seconds of the link's clock the loop waits for a decoder that has
    /// not appeared or has gone silent before it stops, in (0,
    /// [`MAX_TIMEOUT_SECS`]].
    pub timeout_secs: f64,
    /// Simulated seconds of rest before each run.
    pub rest_secs: f64,
    /// Actions of the calibration session, in [`MIN_CALIBRATION_ACTIONS`,
    /// `MAX_CALIBRATION_ACTIONS`]; none for the paper's 400.
    pub calibration_actions: Option<usize>,
}

/// The shortest calibration a live session streams: 40 actions (about 8
/// errors).
pub const MIN_CALIBRATION_ACTIONS: usize = 40;
/// The longest: 4000 actions (3.6 hours at the paper's pace).
pub const MAX_CALIBRATION_ACTIONS: usize = 4000;

impl Default for LiveOptions {
    fn default() -> Self {
        Self {
            speed: 1.0,
            timeout_secs: 30.0,
            rest_secs: 3.0,
            calibration_actions: None,
        }
    }
}

impl LiveOptions {
    /// Checks the speed, the timeout and the calibration's length; errors
    /// name `names` (the flags).
    pub fn check(&self, names: [&str; 3]) -> Result<()> {
        if let Some(n) = self.calibration_actions
            && !(MIN_CALIBRATION_ACTIONS..=MAX_CALIBRATION_ACTIONS).contains(&n)
        {
            return Err(SimError::Scenario(format!(
                "{}: {n} actions, expected {MIN_CALIBRATION_ACTIONS} to \
                 {MAX_CALIBRATION_ACTIONS} (the paper: 400)",
                names[2]
            )));
        }
        if !(self.speed.is_finite() && self.speed > 0.0 && self.speed <= MAX_SPEED) {
            return Err(SimError::Scenario(format!(
                "{}: {} is not a speed, expected a factor > 0 and at most {MAX_SPEED} (1: real \
                 time)",
                names[0], self.speed
            )));
        }
        if !(self.timeout_secs.is_finite()
            && self.timeout_secs > 0.0
            && self.timeout_secs <= MAX_TIMEOUT_SECS)
        {
            return Err(SimError::Scenario(format!(
                "{}: {} is not a timeout, expected seconds > 0 and at most {MAX_TIMEOUT_SECS}",
                names[1], self.timeout_secs
            )));
        }
        Ok(())
    }
}

/// What carries a live loop: EEG, markers and state out, decisions in.
pub trait LiveLink: Send {
    /// The link's clock (s); every timestamp is on it.
    fn clock(&self) -> f64;
    /// Publishes raw EEG `(n_channels, n)`: sample `i` at `first + i *
    /// period`.
    fn eeg(&mut self, block: &EegBlock, first: f64, period: f64) -> Result<()>;
    /// Publishes a marker (JSON text) at `stamp`.
    fn marker(&mut self, text: &str, stamp: f64) -> Result<()>;
    /// Publishes the device's state (JSON text) at `stamp`.
    fn state(&mut self, text: &str, stamp: f64) -> Result<()>;
    /// Waits up to `timeout_secs` for a reader of the EEG (the decoder
    /// reads the calibration from it).
    fn wait_for_readers(&mut self, timeout_secs: f64) -> Result<()>;
    /// Looks for the decoder's stream for up to `timeout_secs`: true once
    /// it is connected.
    fn connect(&mut self, timeout_secs: f64) -> Result<bool>;
    /// Lets the decoder's stream go (the session ends).
    fn disconnect(&mut self);
    /// Waits until the clock reads `until` and returns what the decoder
    /// sent meanwhile (nothing before [`LiveLink::connect`]).
    fn wait(&mut self, until: f64) -> Result<Vec<Received>>;
}

/// What a live session tells its caller as it goes.
pub trait LiveObserver<R> {
    /// A line about the session (its phase, what it waits for).
    fn note(&mut self, text: &str);
    /// Run `k` ended.
    fn run(&mut self, k: usize, run: &R);
    /// What watches the e-puck's run `k` (seed `seed`) step by step as it
    /// runs (a recording), if anything; the grid's runs carry their steps.
    fn watch(&mut self, _k: usize, _seed: u64) -> Option<&mut dyn EpuckObserver> {
        None
    }
}

/// After the calibration: rest EEG from `eeg` until the decoder's stream
/// appears (or `options.timeout_secs` pass: an error naming `decoder`).
pub(crate) fn wait_for_decoder<D: Decisions, R>(
    s: &mut Streamer<'_, D>,
    eeg: &mut errp_bci::EegGenerator,
    options: LiveOptions,
    decoder: &str,
    observer: &mut dyn LiveObserver<R>,
) -> Result<()> {
    let fs = eeg.params().sfreq_hz;
    observer.note(&format!(
        "calibration sent; waiting up to {} s for the decoder stream {decoder:?}",
        options.timeout_secs
    ));
    let waited_from = s.link().clock();
    loop {
        s.stream(&eeg.generate((0.25 * fs * options.speed).round().max(1.0) as usize))?;
        if s.link().connect(0.2)? {
            observer.note("decoder found; control starts");
            return Ok(());
        }
        if s.link().clock() - waited_from > options.timeout_secs {
            return Err(SimError::Live(format!(
                "no decoder stream {decoder:?} appeared within {} s after the calibration \
                 (--timeout): is the decoder running, and does its stream have that name?",
                options.timeout_secs
            )));
        }
    }
}

/// Streams a calibration session: `eeg` up to each assessment of
/// `schedule`, the assessment scheduled at its onset and its marker
/// (`event`, with its index and label) stamped `lag_secs(i)` after the
/// onset (a button press); then 2 s more, between the markers
/// `calibration_start` and `calibration_end`.
pub(crate) fn stream_calibration<D: Decisions>(
    s: &mut Streamer<'_, D>,
    eeg: &mut errp_bci::EegGenerator,
    schedule: &[errp_bci::Assessment],
    event: &str,
    lag_secs: impl Fn(usize) -> f64,
) -> Result<()> {
    let fs = eeg.params().sfreq_hz;
    s.marker(&serde_json::json!({"event": "calibration_start", "count": schedule.len()}))?;
    for (i, a) in schedule.iter().enumerate() {
        let due = (a.onset_secs * fs).round() as i64 - (s.now_secs() * fs).round() as i64;
        s.stream(&eeg.generate(due.max(0) as usize))?;
        let error = a.kind == errp_bci::AssessmentKind::Error;
        let at = s.now_secs() + lag_secs(i);
        s.marker_at(
            at,
            &serde_json::json!({
                "event": event,
                "index": i,
                "label": if error { "error" } else { "correct" },
            }),
        )?;
        eeg.schedule(errp_bci::Assessment {
            onset_secs: eeg.now_secs(),
            kind: a.kind,
        });
    }
    s.stream(&eeg.generate((2.0 * fs) as usize))?;
    s.marker(&serde_json::json!({"event": "calibration_end"}))
}

/// The control starts: silence counts from now, and the marker says how
/// many runs follow.
pub(crate) fn begin_control<D: Decisions>(s: &mut Streamer<'_, D>, runs: usize) -> Result<()> {
    let now = s.link().clock();
    s.tracker.start(now);
    s.marker(&serde_json::json!({"event": "control_start", "runs": runs}))
}

/// The session ends: the decoder's stream let go, the `end` marker, and 1
/// s more of `eeg` so that a reader sees the marker inside the EEG.
pub(crate) fn end_session<D: Decisions>(
    s: &mut Streamer<'_, D>,
    eeg: &mut errp_bci::EegGenerator,
) -> Result<()> {
    s.link().disconnect();
    s.marker(&serde_json::json!({"event": "end"}))?;
    let fs = eeg.params().sfreq_hz;
    s.stream(&eeg.generate(fs as usize))
}

/// Publishes the EEG on the link's clock, `speed` times faster than it,
/// and keeps the decisions coming in the meantime.
pub struct Streamer<'l, D> {
    link: &'l mut dyn LiveLink,
    origin: f64,
    speed: f64,
    fs: f64,
    sent: u64,
    /// The decisions.
    pub tracker: D,
}

impl<'l, D: Decisions> Streamer<'l, D> {
    /// Starts the clock now: sample 0 is stamped with the link's time.
    pub fn new(link: &'l mut dyn LiveLink, fs: f64, speed: f64, tracker: D) -> Self {
        let origin = link.clock();
        Self {
            link,
            origin,
            speed,
            fs,
            sent: 0,
            tracker,
        }
    }

    /// The link.
    pub fn link(&mut self) -> &mut dyn LiveLink {
        self.link
    }

    /// The timestamp of simulated second `secs`.
    pub fn stamp(&self, secs: f64) -> f64 {
        self.origin + secs / self.speed
    }

    /// The simulated time of the next sample (s).
    pub fn now_secs(&self) -> f64 {
        self.sent as f64 / self.fs
    }

    /// The timestamp of the next sample.
    pub fn now_stamp(&self) -> f64 {
        self.stamp(self.now_secs())
    }

    /// Publishes a marker at the next sample.
    pub fn marker(&mut self, value: &serde_json::Value) -> Result<()> {
        let stamp = self.now_stamp();
        self.link.marker(&value.to_string(), stamp)
    }

    /// Publishes a marker at simulated second `secs`.
    pub fn marker_at(&mut self, secs: f64, value: &serde_json::Value) -> Result<()> {
        let stamp = self.stamp(secs);
        self.link.marker(&value.to_string(), stamp)
    }

    /// Publishes the state at the next sample.
    pub fn state(&mut self, value: &serde_json::Value) -> Result<()> {
        let stamp = self.now_stamp();
        self.link.state(&value.to_string(), stamp)
    }

    /// Publishes `block`, [`HOP_SAMPLES`] at a time, each once its last
    /// sample's time has come, taking the decisions that came meanwhile.
    pub fn stream(&mut self, block: &EegBlock) -> Result<()> {
        let period = 1.0 / (self.fs * self.speed);
        let n = block.n_samples;
        let mut start = 0;
        while start < n {
            let end = (start + HOP_SAMPLES).min(n);
            let due = self.stamp((self.sent + end as u64) as f64 / self.fs);
            let got = self.link.wait(due)?;
            let now = self.link.clock();
            self.tracker.receive(&got, now)?;
            let first = self.stamp((self.sent + start as u64) as f64 / self.fs);
            self.link.eeg(&block.samples(start..end), first, period)?;
            let last = self.stamp((self.sent + end as u64 - 1) as f64 / self.fs);
            self.tracker.published(last);
            errp_bci::stop::check()?;
            start = end;
        }
        self.sent += n as u64;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_name_their_flags() {
        let bad = LiveOptions {
            speed: 0.0,
            ..LiveOptions::default()
        };
        let names = ["--speed", "--timeout", "--calibration-actions"];
        let e = bad.check(names).unwrap_err().to_string();
        assert!(e.starts_with("--speed: 0 is not a speed"), "{e}");
        let bad = LiveOptions {
            timeout_secs: f64::NAN,
            ..LiveOptions::default()
        };
        assert!(bad.check(names).is_err());
        let bad = LiveOptions {
            calibration_actions: Some(39),
            ..LiveOptions::default()
        };
        let e = bad.check(names).unwrap_err().to_string();
        assert!(
            e.starts_with("--calibration-actions: 39 actions, expected 40"),
            "{e}"
        );
        LiveOptions::default().check(names).unwrap();
    }
}
