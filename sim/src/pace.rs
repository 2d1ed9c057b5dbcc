//! The pace of a live session: simulated time against the link's clock.
//!
//! A session runs `speed` times faster than the link's (the wall) clock:
//! simulated second `t` is stamped `origin + t / speed`, a sampling rate
//! `fs` is published at the nominal `fs * speed`, and a span of the link's
//! clock is `speed` times as long in simulated time. Every conversion
//! between the two clocks is written here once.

use std::fmt;

use serde::{Deserialize, Serialize};

/// The fastest a live session runs: 100 times the wall clock.
pub const MAX_SPEED: f64 = 100.0;
/// The slowest: a tenth of the wall clock (a grid action's 3 s then last
/// 30 s; slower, a session's timers and timeouts would mean nothing).
pub const MIN_SPEED: f64 = 0.1;

/// Simulated seconds per second of the link's clock: a number in
/// [[`MIN_SPEED`], [`MAX_SPEED`]], checked where it enters.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Serialize, Deserialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct Speed(f64);

impl Speed {
    /// Real time.
    pub const REAL_TIME: Speed = Speed(1.0);

    /// `k` if it is a speed: from [`MIN_SPEED`] to [`MAX_SPEED`].
    pub fn new(k: f64) -> Option<Speed> {
        (MIN_SPEED..=MAX_SPEED).contains(&k).then_some(Speed(k))
    }

    /// The factor.
    pub fn get(self) -> f64 {
        self.0
    }

    /// A span of simulated time as a span of the link's clock (s).
    pub fn to_link(self, sim_secs: f64) -> f64 {
        sim_secs / self.0
    }

    /// A span of the link's clock as a span of simulated time (s).
    pub fn to_sim(self, link_secs: f64) -> f64 {
        link_secs * self.0
    }

    /// The nominal rate, on the link's clock, of a stream sampled at `fs`
    /// in simulated time (Hz).
    pub fn rate(self, fs_hz: f64) -> f64 {
        fs_hz * self.0
    }
}

impl TryFrom<f64> for Speed {
    type Error = String;

    fn try_from(k: f64) -> Result<Self, String> {
        Speed::new(k).ok_or_else(|| {
            format!(
                "{} is not a speed, expected a factor from {MIN_SPEED} to {MAX_SPEED}",
                errp_bci::shown(k)
            )
        })
    }
}

impl From<Speed> for f64 {
    fn from(s: Speed) -> f64 {
        s.0
    }
}

/// As a number (`40`, `2.5`).
impl fmt::Display for Speed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

/// A session's clock: sample `n` of a stream at `fs` is simulated second
/// `n / fs`, stamped `origin + (n / fs) / speed` on the link's clock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pace {
    origin: f64,
    fs_hz: f64,
    speed: Speed,
}

impl Pace {
    /// Simulated time 0 at `origin` on the link's clock, for samples at
    /// `fs_hz`.
    pub fn new(origin: f64, fs_hz: f64, speed: Speed) -> Self {
        Self {
            origin,
            fs_hz,
            speed,
        }
    }

    /// The sampling rate (Hz, simulated time).
    pub fn fs_hz(&self) -> f64 {
        self.fs_hz
    }

    /// The speed.
    pub fn speed(&self) -> Speed {
        self.speed
    }

    /// The simulated time of sample `n` (s).
    pub fn sample_secs(&self, n: u64) -> f64 {
        n as f64 / self.fs_hz
    }

    /// The link's timestamp of simulated second `secs`.
    pub fn stamp(&self, secs: f64) -> f64 {
        self.origin + self.speed.to_link(secs)
    }

    /// The link's time between two samples (s).
    pub fn period(&self) -> f64 {
        1.0 / self.speed.rate(self.fs_hz)
    }

    /// The samples of simulated time that `link_secs` of the link's clock
    /// hold (at least one).
    pub fn samples_in_link(&self, link_secs: f64) -> usize {
        (link_secs * self.fs_hz * self.speed.get()).round().max(1.0) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_speed_is_checked_where_it_enters() {
        for bad in [
            0.0,
            1e-300,
            1e-6,
            0.09,
            -1.0,
            100.5,
            f64::NAN,
            f64::INFINITY,
        ] {
            assert!(Speed::new(bad).is_none(), "{bad}");
            assert!(serde_json::from_str::<Speed>(&bad.to_string()).is_err());
        }
        let k = Speed::new(40.0).unwrap();
        assert_eq!(k.to_string(), "40");
        assert_eq!(serde_json::to_string(&k).unwrap(), "40.0");
        assert_eq!(serde_json::from_str::<Speed>("40.0").unwrap(), k);
        assert_eq!(Speed::new(2.5).unwrap().to_string(), "2.5");
    }

    #[test]
    fn the_two_clocks_convert_both_ways() {
        let k = Speed::new(4.0).unwrap();
        assert_eq!(k.to_link(8.0), 2.0);
        assert_eq!(k.to_sim(2.0), 8.0);
        assert_eq!(k.rate(256.0), 1024.0);
        let pace = Pace::new(100.0, 256.0, k);
        assert_eq!(pace.stamp(8.0), 102.0);
        assert_eq!(pace.sample_secs(512), 2.0);
        assert_eq!(pace.period(), 1.0 / 1024.0);
        assert_eq!(pace.samples_in_link(0.25), 256);
        assert_eq!(pace.samples_in_link(0.0), 1);
    }
}
