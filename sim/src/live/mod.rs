//! Real time: the simulated user and device on the wall clock, with a
//! decoder outside the process in the loop (`errp stream`).
//!
//! A [`LiveSession`] publishes the user's raw EEG, markers and the
//! device's state through a [`LiveLink`] (Lab Streaming Layer in `errp
//! stream`, [`LslLink`]; anything with a clock in the tests) and takes the
//! decoder's decisions back from it, all as the stream contract says
//! ([`contract`]). Simulated time runs `speed` times faster than the
//! link's clock ([`crate::pace`]): the sample `n` carries the timestamp `origin +
//! n / (fs * speed)` and is published once that time has passed, 16
//! samples (62.5 ms) at a time.
//!
//! Timing has rules ([`DecisionTracker`]): an action's decision must come
//! before the next action; one that comes later is counted late and not
//! applied; a decoder silent for `timeout_secs` stops the loop.

use errp_bci::EegBlock;

use crate::error::{Result, SimError};
use crate::live::contract::SessionId;
use crate::names::Names;
use crate::pace::{self, Speed};
use crate::runner::RunObserver;

pub mod contract;
mod decisions;
pub mod epuck;
pub mod grid;
mod lsl;
mod runs;
#[cfg(feature = "rerun")]
pub mod save;
mod session;
mod sink;
mod streamer;

pub use decisions::{
    DecisionTracker, Decisions, Fate, LiveRunStats, LoggedDecision, Received, WindowTracker,
};
pub use lsl::LslLink;
pub use runs::{EpuckLiveRun, GridLiveRun};
pub use session::{LiveOutcome, LiveRequest, LiveSession};
pub use streamer::Streamer;

/// The longest wait for a silent decoder (s).
pub const MAX_TIMEOUT_SECS: f64 = 3600.0;
/// Samples published at once: 62.5 ms at 256 Hz.
pub const HOP_SAMPLES: usize = 16;

/// How a live loop runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LiveOptions {
    /// Simulated seconds per second of the link's clock.
    pub speed: Speed,
    /// Seconds of the link's clock the loop waits for a decoder that has
    /// not appeared or has gone silent before it stops, in (0,
    /// [`MAX_TIMEOUT_SECS`]].
    pub timeout_secs: f64,
    /// Simulated seconds of rest before each run.
    pub rest_secs: f64,
    /// Actions of the calibration session, in [`MIN_CALIBRATION_ACTIONS`,
    /// `MAX_CALIBRATION_ACTIONS`]; none for the paper's 400.
    pub calibration_actions: Option<usize>,
    /// The session's id, in its streams' source ids (a fresh one by
    /// default).
    pub session: SessionId,
}

/// The shortest calibration a live session streams: 40 actions (about 8
/// errors).
pub const MIN_CALIBRATION_ACTIONS: usize = 40;
/// The longest: 4000 actions (3.6 hours at the paper's pace).
pub const MAX_CALIBRATION_ACTIONS: usize = 4000;

impl Default for LiveOptions {
    fn default() -> Self {
        Self {
            speed: Speed::REAL_TIME,
            timeout_secs: 30.0,
            rest_secs: 3.0,
            calibration_actions: None,
            session: SessionId::fresh(),
        }
    }
}

impl LiveOptions {
    /// The options a front end gives: the calibration's length, the speed
    /// and the timeout, checked in that order; errors name them as `names`
    /// does.
    pub fn new(
        speed: f64,
        timeout_secs: f64,
        calibration_actions: Option<usize>,
        names: &Names,
    ) -> Result<Self> {
        if let Some(n) = calibration_actions
            && !(MIN_CALIBRATION_ACTIONS..=MAX_CALIBRATION_ACTIONS).contains(&n)
        {
            return Err(SimError::OutOfRange {
                name: names.calibration_actions.into(),
                given: format!("{n} actions"),
                expected: format!(
                    "{MIN_CALIBRATION_ACTIONS} to {MAX_CALIBRATION_ACTIONS} (the paper: 400)"
                ),
            });
        }
        let speed = Speed::new(speed).ok_or_else(|| SimError::OutOfRange {
            name: names.speed.into(),
            given: format!("{} is not a speed", errp_bci::shown(speed)),
            expected: format!(
                "a factor from {} to {} (1: real time)",
                pace::MIN_SPEED,
                pace::MAX_SPEED
            ),
        })?;
        if !(timeout_secs.is_finite() && timeout_secs > 0.0 && timeout_secs <= MAX_TIMEOUT_SECS) {
            return Err(SimError::OutOfRange {
                name: names.timeout.into(),
                given: format!("{} is not a timeout", errp_bci::shown(timeout_secs)),
                expected: format!("seconds > 0 and at most {MAX_TIMEOUT_SECS}"),
            });
        }
        Ok(Self {
            speed,
            timeout_secs,
            calibration_actions,
            ..Self::default()
        })
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
    /// What the link found but did not take while it looked for the
    /// decoder (a stream of another session), for the message when none
    /// came.
    fn passed_over(&self) -> Option<String> {
        None
    }
    /// Lets the decoder's stream go (the session ends).
    fn disconnect(&mut self);
    /// Waits until the clock reads `until` and returns what the decoder
    /// sent meanwhile (nothing before [`LiveLink::connect`]).
    fn wait(&mut self, until: f64) -> Result<Vec<Received>>;
}

/// What a live session tells its front end as it goes: what a run tells
/// offline ([`RunObserver`]: the calibration's steps), and the session's
/// own notes and runs.
pub trait LiveObserver: RunObserver {
    /// A line about the session (its phase, what it waits for).
    fn note(&mut self, _text: &str) {}
    /// Grid run `k` ended.
    fn grid_run(&mut self, _k: usize, _run: &GridLiveRun) {}
    /// E-puck run `k` ended.
    fn epuck_run(&mut self, _k: usize, _run: &EpuckLiveRun) {}
}

impl LiveObserver for () {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_name_their_flags() {
        let names = &Names::CLI;
        let e = LiveOptions::new(0.0, 30.0, None, names)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("--speed: 0 is not a speed"), "{e}");
        // A speed too slow for the session's timers; its number as given.
        let e = LiveOptions::new(1e-300, 30.0, None, names)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("--speed: 1e-300 is not a speed") && e.contains("0.1 to 100"),
            "{e}"
        );
        assert!(LiveOptions::new(1.0, f64::NAN, None, names).is_err());
        let e = LiveOptions::new(0.0, 30.0, Some(39), names)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("--calibration-actions: 39 actions, expected 40"),
            "{e}"
        );
        let ok = LiveOptions::new(1.0, 30.0, None, names).unwrap();
        let default = LiveOptions::default();
        // (Each session draws its own id.)
        assert_ne!(ok.session, default.session);
        assert_eq!(
            LiveOptions {
                session: default.session,
                ..ok
            },
            default
        );
    }
}
