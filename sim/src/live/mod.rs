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

use crate::error::{Result, SimError};

pub mod epuck;
pub mod grid;

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

/// A decision as the decoder sent it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Received {
    /// The action it is for (the marker's `action`), as sent.
    pub id: f64,
    /// Its p(error).
    pub p_error: f64,
    /// When it arrived (the link's clock, s).
    pub arrived: f64,
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

/// Per run: what the decoder's timing was.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LiveRunStats {
    /// Each decision applied: seconds (link clock) from its action's onset
    /// to its arrival.
    pub latencies_secs: Vec<f64>,
    /// Actions whose decision did not come before the next action.
    pub missed: usize,
    /// Decisions that came for an action already past (or twice).
    pub late: usize,
    /// Decisions for no action announced.
    pub stray: usize,
}

impl LiveRunStats {
    /// The `q` quantile of the latencies (s; linear between order
    /// statistics), none without decisions.
    pub fn latency_quantile(&self, q: f64) -> Option<f64> {
        let mut v = self.latencies_secs.clone();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        let pos = q.clamp(0.0, 1.0) * (v.len() - 1) as f64;
        let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
        Some(v[lo] + (v[hi] - v[lo]) * (pos - lo as f64))
    }
}

/// What a live loop does with the decisions that come.
pub trait Decisions {
    /// Takes what came by `now` (the link's clock).
    fn receive(&mut self, got: &[Received], now: f64) -> Result<()>;
    /// Samples up to `stamp` are published.
    fn published(&mut self, _stamp: f64) {}
    /// The control starts at `now`: silence counts from here.
    fn start(&mut self, now: f64);
}

/// The rules every decoder keeps: p(error) is a probability, and silence
/// lasts at most `timeout_secs` once the control has started.
#[derive(Debug)]
struct Silence {
    name: String,
    timeout_secs: f64,
    /// When the decoder was last heard from (or the control started).
    heard: Option<f64>,
}

impl Silence {
    fn new(name: &str, timeout_secs: f64) -> Self {
        Self {
            name: name.into(),
            timeout_secs,
            heard: None,
        }
    }

    fn check(&mut self, r: &Received) -> Result<()> {
        if !(r.p_error.is_finite() && (0.0..=1.0).contains(&r.p_error)) {
            return Err(SimError::Live(format!(
                "the decoder stream {:?} sent p(error) = {} for {}, expected a number from 0 \
                 to 1",
                self.name, r.p_error, r.id
            )));
        }
        self.heard = Some(r.arrived);
        Ok(())
    }

    fn quiet(&self, now: f64, waiting: &str) -> Result<()> {
        if let Some(heard) = self.heard
            && now - heard > self.timeout_secs
        {
            return Err(SimError::Live(format!(
                "the decoder stream {:?} sent nothing for {:.1} s{waiting}: it stopped or \
                 hangs; the loop waits at most --timeout {} s",
                self.name,
                now - heard,
                self.timeout_secs
            )));
        }
        Ok(())
    }
}

/// The decisions of the grid: which action waits for one, what came in
/// time, and what came late. A decision names its action by the id of the
/// action's marker.
#[derive(Debug)]
pub struct DecisionTracker {
    silence: Silence,
    /// The action waiting (its id and onset on the link's clock).
    pending: Option<(u64, f64)>,
    /// Its decision, once come.
    decided: Option<f64>,
    /// Actions announced so far.
    announced: u64,
    /// The current run's statistics.
    stats: LiveRunStats,
}

impl DecisionTracker {
    /// A tracker for the decoder `name`, stopping after `timeout_secs` of
    /// silence once [`DecisionTracker::start`]ed.
    pub fn new(name: &str, timeout_secs: f64) -> Self {
        Self {
            silence: Silence::new(name, timeout_secs),
            pending: None,
            decided: None,
            announced: 0,
            stats: LiveRunStats::default(),
        }
    }

    /// Announces the next action, with its onset at `onset` (link clock);
    /// returns its id.
    pub fn announce(&mut self, onset: f64) -> u64 {
        let id = self.announced;
        self.announced += 1;
        self.pending = Some((id, onset));
        self.decided = None;
        id
    }

    /// Ends the action waiting: its decision, or none (counted missed).
    pub fn settle(&mut self) -> Option<f64> {
        self.pending = None;
        let d = self.decided.take();
        if d.is_none() {
            self.stats.missed += 1;
        }
        d
    }

    /// The statistics of the run that ended, and a fresh count.
    pub fn take_run(&mut self) -> LiveRunStats {
        std::mem::take(&mut self.stats)
    }
}

impl Decisions for DecisionTracker {
    fn start(&mut self, now: f64) {
        self.silence.heard = Some(now);
    }

    /// A decision for the action waiting is kept (the first one), others
    /// are counted. A decoder silent too long, or a p(error) that is not
    /// one, is an error.
    fn receive(&mut self, got: &[Received], now: f64) -> Result<()> {
        for r in got {
            self.silence.check(r)?;
            let id =
                (r.id.is_finite() && r.id >= 0.0 && r.id.fract() == 0.0).then_some(r.id as u64);
            match (id, self.pending) {
                (Some(id), Some((waiting, onset))) if id == waiting && self.decided.is_none() => {
                    self.decided = Some(r.p_error);
                    self.stats.latencies_secs.push(r.arrived - onset);
                }
                (Some(id), _) if id < self.announced => self.stats.late += 1,
                _ => self.stats.stray += 1,
            }
        }
        let waiting = self
            .pending
            .map(|(id, _)| format!(" (waiting for action {id})"))
            .unwrap_or_default();
        self.silence.quiet(now, &waiting)
    }
}

/// The decisions of the e-puck: p(error) of windows, each named by the
/// timestamp of its window's last sample. A window's decision is applied at
/// the device's next window if it is newer than the last one applied and
/// the window ended within the current movement phase; one about an
/// earlier phase is late (it judged a motion already past).
#[derive(Debug)]
pub struct WindowTracker {
    silence: Silence,
    /// The timestamp at which the current movement phase began.
    phase_start: f64,
    /// The window of the last decision applied.
    last_applied: f64,
    /// The last sample published.
    published: f64,
    /// Decisions come since the device's last window.
    accepted: Vec<f64>,
    stats: LiveRunStats,
}

impl WindowTracker {
    /// A tracker for the decoder `name`, stopping after `timeout_secs` of
    /// silence once [`WindowTracker::start`]ed.
    pub fn new(name: &str, timeout_secs: f64) -> Self {
        Self {
            silence: Silence::new(name, timeout_secs),
            phase_start: f64::NEG_INFINITY,
            last_applied: f64::NEG_INFINITY,
            published: f64::NEG_INFINITY,
            accepted: Vec::new(),
            stats: LiveRunStats::default(),
        }
    }

    /// A movement phase began with the sample stamped `stamp`.
    pub fn phase_began(&mut self, stamp: f64) {
        self.phase_start = stamp;
    }

    /// The decisions to apply at the device's window (counted missed if
    /// none).
    pub fn take(&mut self) -> Vec<f64> {
        if self.accepted.is_empty() {
            self.stats.missed += 1;
        }
        std::mem::take(&mut self.accepted)
    }

    /// The statistics of the run that ended, and a fresh count (decisions
    /// not yet applied are dropped).
    pub fn take_run(&mut self) -> LiveRunStats {
        self.accepted.clear();
        self.last_applied = f64::NEG_INFINITY;
        std::mem::take(&mut self.stats)
    }
}

impl Decisions for WindowTracker {
    fn start(&mut self, now: f64) {
        self.silence.heard = Some(now);
    }

    fn published(&mut self, stamp: f64) {
        self.published = stamp;
    }

    fn receive(&mut self, got: &[Received], now: f64) -> Result<()> {
        for r in got {
            self.silence.check(r)?;
            let w = r.id;
            if !w.is_finite() || w > self.published + 1e-9 {
                self.stats.stray += 1;
            } else if w <= self.last_applied || w < self.phase_start {
                self.stats.late += 1;
            } else {
                self.last_applied = w;
                self.accepted.push(r.p_error);
                self.stats.latencies_secs.push(r.arrived - w);
            }
        }
        self.silence.quiet(now, "")
    }
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

    fn got(id: f64, p: f64, arrived: f64) -> Received {
        Received {
            id,
            p_error: p,
            arrived,
        }
    }

    #[test]
    fn a_decision_in_time_is_applied_and_a_late_one_counted() {
        let mut t = DecisionTracker::new("dec", 10.0);
        t.start(0.0);
        let a = t.announce(1.0);
        t.receive(&[got(a as f64, 0.9, 1.3)], 1.3).unwrap();
        // A second decision for the same action is not applied again.
        t.receive(&[got(a as f64, 0.1, 1.4)], 1.4).unwrap();
        assert_eq!(t.settle(), Some(0.9));
        let b = t.announce(4.0);
        assert_eq!(t.settle(), None);
        t.receive(&[got(b as f64, 0.2, 7.5), got(9.0, 0.5, 7.5)], 7.5)
            .unwrap();
        let s = t.take_run();
        assert_eq!(s.missed, 1);
        assert_eq!(s.late, 2);
        assert_eq!(s.stray, 1);
        assert!((s.latencies_secs[0] - 0.3).abs() < 1e-12);
        assert_eq!(s.latency_quantile(0.5), Some(s.latencies_secs[0]));
    }

    #[test]
    fn a_silent_decoder_or_a_bad_probability_stops_the_loop() {
        let mut t = DecisionTracker::new("dec", 2.0);
        t.receive(&[], 100.0).unwrap();
        t.start(100.0);
        t.receive(&[], 101.9).unwrap();
        let e = t.receive(&[], 102.5).unwrap_err().to_string();
        assert!(e.contains("--timeout 2 s"), "{e}");
        assert!(e.contains("\"dec\" sent nothing for 2.5 s"), "{e}");
        let mut t = DecisionTracker::new("dec", 2.0);
        t.start(0.0);
        let e = t
            .receive(&[got(0.0, 1.5, 0.1)], 0.1)
            .unwrap_err()
            .to_string();
        assert!(e.contains("p(error) = 1.5"), "{e}");
    }

    #[test]
    fn a_window_decision_applies_once_and_within_its_phase() {
        let mut t = WindowTracker::new("dec", 10.0);
        assert_eq!(t.take(), Vec::<f64>::new());
        t.take_run();
        t.start(0.0);
        t.published(5.0);
        t.phase_began(3.0);
        t.receive(
            &[
                got(4.0, 0.9, 5.01),
                got(4.0, 0.8, 5.02),
                got(2.5, 0.7, 5.03),
                got(6.0, 0.1, 5.04),
                got(4.5, 0.2, 5.05),
            ],
            5.05,
        )
        .unwrap();
        assert_eq!(t.take(), vec![0.9, 0.2]);
        assert_eq!(t.take(), Vec::<f64>::new());
        let s = t.take_run();
        assert_eq!((s.late, s.stray, s.missed), (2, 1, 1));
        assert!((s.latencies_secs[0] - 1.01).abs() < 1e-9);
    }

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
