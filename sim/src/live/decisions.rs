//! The decisions a live loop takes from the decoder: what came, when, and
//! what became of each ([`DecisionTracker`] for the grid's actions,
//! [`WindowTracker`] for the e-puck's windows), with the rules every
//! decoder keeps: p(error) a probability, no long silence, no flood.

use crate::error::{Result, SimError};
use crate::pace::Speed;

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

/// What became of a decision received.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fate {
    /// Applied to the run's action (grid) or the device's window (e-puck)
    /// of this index, from 0.
    Applied(usize),
    /// Late: for an action already past (or decided already), or a window
    /// no newer than the last applied or from before the movement phase.
    Late,
    /// For nothing announced (an unknown action, a window not yet
    /// published).
    Stray,
}

impl Fate {
    /// `applied`, `late` or `stray`.
    pub fn name(self) -> &'static str {
        match self {
            Fate::Applied(_) => "applied",
            Fate::Late => "late",
            Fate::Stray => "stray",
        }
    }
}

/// A decision received, and what the loop made of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoggedDecision {
    /// As the decoder sent it.
    pub received: Received,
    /// Seconds of the link's clock from its event (the action's onset, the
    /// window's last sample) to its arrival; NaN for a stray decision.
    pub latency_secs: f64,
    /// What became of it.
    pub fate: Fate,
}

/// Per run: every decision received, and the actions or windows left
/// without one.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LiveRunStats {
    /// The decisions received during the run, in order of arrival.
    pub decisions: Vec<LoggedDecision>,
    /// Actions whose decision did not come before the next action (grid),
    /// or device windows without a decision (e-puck).
    pub missed: usize,
    /// The link's timestamp of the run's time 0 (its first action, or the
    /// end of the e-puck's warm-up): decisions' arrivals on the run's
    /// clock are `(arrived - origin) * speed`.
    pub origin: f64,
}

impl LiveRunStats {
    /// The latencies of the decisions applied (s, link clock), in order.
    pub fn latencies_secs(&self) -> Vec<f64> {
        self.decisions
            .iter()
            .filter(|d| matches!(d.fate, Fate::Applied(_)))
            .map(|d| d.latency_secs)
            .collect()
    }

    /// Decisions that came late.
    pub fn late(&self) -> usize {
        self.count(Fate::Late)
    }

    /// Decisions for nothing announced.
    pub fn stray(&self) -> usize {
        self.count(Fate::Stray)
    }

    fn count(&self, fate: Fate) -> usize {
        self.decisions.iter().filter(|d| d.fate == fate).count()
    }

    /// The `q` quantile of the latencies applied (s; linear between order
    /// statistics), none without decisions.
    pub fn latency_quantile(&self, q: f64) -> Option<f64> {
        let v = self.latencies_secs();
        (!v.is_empty()).then(|| crate::stats::quantile(&v, q))
    }

    /// The decisions applied, their latencies (median and 95th percentile,
    /// ms of the link's clock, and of simulated time at `speed` if given),
    /// and those missed, late and stray; `windows` for the e-puck's (a
    /// latency from the window's last sample; a device window without a
    /// decision).
    pub fn timing(&self, windows: bool, speed: Option<Speed>) -> String {
        // Milliseconds of the link's clock, or of simulated time.
        let ms = |q: f64, speed: Option<Speed>| {
            self.latency_quantile(q).map_or("-".into(), |v| {
                let link = v * 1000.0;
                format!("{:.0}", speed.map_or(link, |k| k.to_sim(link)))
            })
        };
        let (from, missed) = if windows {
            ("the window's end", "device windows without one")
        } else {
            ("the action's onset", "missed")
        };
        let simulated = speed.map_or(String::new(), |k| {
            format!(
                " (simulated: {} / {} ms)",
                ms(0.5, Some(k)),
                ms(0.95, Some(k))
            )
        });
        format!(
            "{} applied, latency from {from} median {} ms, 95th percentile {} ms{simulated}; {} \
             {missed}, {} late, {} stray",
            self.latencies_secs().len(),
            ms(0.5, None),
            ms(0.95, None),
            self.missed,
            self.late(),
            self.stray()
        )
    }

    /// Every run's decisions in one (the origin: the first run's).
    pub fn merged(runs: &[LiveRunStats]) -> LiveRunStats {
        LiveRunStats {
            decisions: runs.iter().flat_map(|r| r.decisions.clone()).collect(),
            missed: runs.iter().map(|r| r.missed).sum(),
            origin: runs.first().map_or(0.0, |r| r.origin),
        }
    }
}

/// What a live loop does with the decisions that come.
pub trait Decisions {
    /// Takes what came by `now` (the link's clock).
    fn receive(&mut self, got: &[Received], now: f64) -> Result<()>;
    /// Samples up to `stamp` are published, `samples` since the session
    /// began.
    fn published(&mut self, stamp: f64, samples: u64);
    /// The control starts at `now`: silence counts from here.
    fn start(&mut self, now: f64);
}

/// Decisions a decoder may send beyond one per EEG sample published (a
/// grid decision sent twice, an e-puck window decoded again).
pub const FLOOD_MARGIN: u64 = 1000;

/// The rules every decoder keeps: p(error) is a probability, silence
/// lasts at most `timeout_secs` once the control has started, and at most
/// one decision comes per EEG sample published (and [`FLOOD_MARGIN`]
/// more), so that what the loop keeps of them is bounded by the session's
/// length.
#[derive(Debug)]
struct Rules {
    name: String,
    timeout_secs: f64,
    /// When the decoder was last heard from (or the control started).
    heard: Option<f64>,
    /// Decisions received in the session.
    received: u64,
    /// EEG samples published in the session.
    samples: u64,
}

impl Rules {
    fn new(name: &str, timeout_secs: f64) -> Self {
        Self {
            name: name.into(),
            timeout_secs,
            heard: None,
            received: 0,
            samples: 0,
        }
    }

    fn check(&mut self, r: &Received) -> Result<()> {
        self.received += 1;
        if self.received > self.samples + FLOOD_MARGIN {
            return Err(SimError::Live(format!(
                "the decoder stream {:?} sent {} decisions while {} EEG samples were \
                 published: at most one decision per sample (and {FLOOD_MARGIN} more) is \
                 read, one per grid action or e-puck window",
                self.name, self.received, self.samples
            )));
        }
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
    rules: Rules,
    /// The action waiting (its id and onset on the link's clock).
    pending: Option<(u64, f64)>,
    /// Its decision, once come.
    decided: Option<f64>,
    /// Each action announced so far: its onset (link clock).
    onsets: Vec<f64>,
    /// The id of the current run's first action.
    run_first: u64,
    /// The current run's statistics.
    stats: LiveRunStats,
}

impl DecisionTracker {
    /// A tracker for the decoder `name`, stopping after `timeout_secs` of
    /// silence once [`DecisionTracker::start`]ed.
    pub fn new(name: &str, timeout_secs: f64) -> Self {
        Self {
            rules: Rules::new(name, timeout_secs),
            pending: None,
            decided: None,
            onsets: Vec::new(),
            run_first: 0,
            stats: LiveRunStats::default(),
        }
    }

    /// Announces the next action, with its onset at `onset` (link clock);
    /// returns its id.
    pub fn announce(&mut self, onset: f64) -> u64 {
        let id = self.onsets.len() as u64;
        if id == self.run_first {
            self.stats.origin = onset;
        }
        self.onsets.push(onset);
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
        self.run_first = self.onsets.len() as u64;
        std::mem::take(&mut self.stats)
    }
}

impl Decisions for DecisionTracker {
    fn start(&mut self, now: f64) {
        self.rules.heard = Some(now);
    }

    fn published(&mut self, _stamp: f64, samples: u64) {
        self.rules.samples = samples;
    }

    /// A decision for the action waiting is kept (the first one), others
    /// are counted. A decoder silent too long, or a p(error) that is not
    /// one, is an error.
    fn receive(&mut self, got: &[Received], now: f64) -> Result<()> {
        for r in got {
            self.rules.check(r)?;
            let id =
                (r.id.is_finite() && r.id >= 0.0 && r.id.fract() == 0.0).then_some(r.id as u64);
            let onset = id.and_then(|id| self.onsets.get(id as usize).copied());
            let fate = match (id, self.pending) {
                (Some(id), Some((waiting, _))) if id == waiting && self.decided.is_none() => {
                    self.decided = Some(r.p_error);
                    Fate::Applied(id.saturating_sub(self.run_first) as usize)
                }
                _ if onset.is_some() => Fate::Late,
                _ => Fate::Stray,
            };
            self.stats.decisions.push(LoggedDecision {
                received: *r,
                latency_secs: onset.map_or(f64::NAN, |o| r.arrived - o),
                fate,
            });
        }
        let waiting = self
            .pending
            .map(|(id, _)| format!(" (waiting for action {id})"))
            .unwrap_or_default();
        self.rules.quiet(now, &waiting)
    }
}

/// The decisions of the e-puck: p(error) of windows, each named by the
/// timestamp of its window's last sample. A window's decision is applied at
/// the device's next window if it is newer than the last one applied and
/// the window ended within the current movement phase; one about an
/// earlier phase is late (it judged a motion already past).
#[derive(Debug)]
pub struct WindowTracker {
    rules: Rules,
    /// The timestamp at which the current movement phase began.
    phase_start: f64,
    /// The window of the last decision applied.
    last_applied: f64,
    /// The last sample published.
    published: f64,
    /// Decisions come since the device's last window.
    accepted: Vec<f64>,
    /// The device's windows so far in the run.
    windows: usize,
    stats: LiveRunStats,
}

impl WindowTracker {
    /// A tracker for the decoder `name`, stopping after `timeout_secs` of
    /// silence once [`WindowTracker::start`]ed.
    pub fn new(name: &str, timeout_secs: f64) -> Self {
        Self {
            rules: Rules::new(name, timeout_secs),
            phase_start: f64::NEG_INFINITY,
            last_applied: f64::NEG_INFINITY,
            published: f64::NEG_INFINITY,
            accepted: Vec::new(),
            windows: 0,
            stats: LiveRunStats::default(),
        }
    }

    /// The run's time 0 is the sample stamped `stamp`.
    pub fn run_began(&mut self, stamp: f64) {
        self.stats.origin = stamp;
    }

    /// A movement phase began with the sample stamped `stamp`.
    pub fn phase_began(&mut self, stamp: f64) {
        self.phase_start = stamp;
    }

    /// A run's warm-up began: until its first movement phase, a decision
    /// judges no motion, so it is late (the previous run's phase no longer
    /// counts).
    pub fn warm_up_began(&mut self) {
        self.phase_start = f64::INFINITY;
    }

    /// The decisions to apply at the device's window (counted missed if
    /// none).
    pub fn take(&mut self) -> Vec<f64> {
        if self.accepted.is_empty() {
            self.stats.missed += 1;
        }
        self.windows += 1;
        std::mem::take(&mut self.accepted)
    }

    /// The statistics of the run that ended, and a fresh count. Decisions
    /// accepted after the run's last window were never applied: late.
    pub fn take_run(&mut self) -> LiveRunStats {
        if !self.accepted.is_empty() {
            for d in &mut self.stats.decisions {
                if d.fate == Fate::Applied(self.windows) {
                    d.fate = Fate::Late;
                }
            }
        }
        self.accepted.clear();
        self.windows = 0;
        self.last_applied = f64::NEG_INFINITY;
        std::mem::take(&mut self.stats)
    }
}

impl Decisions for WindowTracker {
    fn start(&mut self, now: f64) {
        self.rules.heard = Some(now);
    }

    fn published(&mut self, stamp: f64, samples: u64) {
        self.published = stamp;
        self.rules.samples = samples;
    }

    fn receive(&mut self, got: &[Received], now: f64) -> Result<()> {
        for r in got {
            self.rules.check(r)?;
            let w = r.id;
            let fate = if !w.is_finite() || w > self.published + 1e-9 {
                Fate::Stray
            } else if w <= self.last_applied || w < self.phase_start {
                Fate::Late
            } else {
                self.last_applied = w;
                self.accepted.push(r.p_error);
                Fate::Applied(self.windows)
            };
            self.stats.decisions.push(LoggedDecision {
                received: *r,
                latency_secs: if fate == Fate::Stray {
                    f64::NAN
                } else {
                    r.arrived - w
                },
                fate,
            });
        }
        self.rules.quiet(now, "")
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
    fn a_window_before_the_runs_first_phase_is_late() {
        let mut t = WindowTracker::new("dec", 10.0);
        t.start(0.0);
        // The previous run's phase began at 1 s; this run's warm-up
        // streams from 10 s to 12 s, its first phase from 12 s.
        t.phase_began(1.0);
        t.take_run();
        t.warm_up_began();
        t.published(11.9, 10_000);
        t.receive(&[got(10.5, 1.0, 10.6), got(11.9, 1.0, 12.0)], 12.0)
            .unwrap();
        t.phase_began(12.0);
        t.published(12.0625, 10_000);
        t.receive(&[got(12.0625, 0.2, 12.1)], 12.1).unwrap();
        assert_eq!(t.take(), [0.2]);
        let s = t.take_run();
        let fates: Vec<Fate> = s.decisions.iter().map(|d| d.fate).collect();
        assert_eq!(fates, [Fate::Late, Fate::Late, Fate::Applied(0)]);
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
        assert_eq!((s.late(), s.stray()), (2, 1));
        assert_eq!(s.origin, 1.0);
        let fates: Vec<Fate> = s.decisions.iter().map(|d| d.fate).collect();
        assert_eq!(
            fates,
            [Fate::Applied(0), Fate::Late, Fate::Late, Fate::Stray]
        );
        // A late decision's latency is from its own action's onset.
        assert!((s.decisions[2].latency_secs - 3.5).abs() < 1e-12);
        assert!(s.decisions[3].latency_secs.is_nan());
        assert!((s.latencies_secs()[0] - 0.3).abs() < 1e-12);
        assert_eq!(s.latency_quantile(0.5), Some(s.latencies_secs()[0]));
        // The next run counts its actions from 0.
        let c = t.announce(9.0);
        t.receive(&[got(c as f64, 0.4, 9.2)], 9.2).unwrap();
        assert_eq!(t.settle(), Some(0.4));
        let s = t.take_run();
        assert_eq!(s.decisions[0].fate, Fate::Applied(0));
        assert_eq!(s.origin, 9.0);
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
    fn more_decisions_than_samples_published_stop_the_loop() {
        // One per sample and the margin are read; one more is a flood.
        for window in [false, true] {
            let mut grid = DecisionTracker::new("dec", 10.0);
            let mut epuck = WindowTracker::new("dec", 10.0);
            let t: &mut dyn Decisions = if window { &mut epuck } else { &mut grid };
            t.start(0.0);
            t.published(1.0, 256);
            let many = vec![got(7.0, 0.5, 1.0); 256 + FLOOD_MARGIN as usize];
            t.receive(&many, 1.0).unwrap();
            let e = t
                .receive(&[got(7.0, 0.5, 1.0)], 1.0)
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("\"dec\" sent 1257 decisions while 256 EEG samples were published"),
                "{e}"
            );
            // As more samples are published, more decisions are read.
            t.published(2.0, 512);
            t.receive(&[got(7.0, 0.5, 2.0)], 2.0).unwrap();
        }
    }

    #[test]
    fn a_window_decision_applies_once_and_within_its_phase() {
        let mut t = WindowTracker::new("dec", 10.0);
        assert_eq!(t.take(), Vec::<f64>::new());
        t.take_run();
        t.start(0.0);
        t.published(5.0, 10_000);
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
        // A decision accepted after the run's last window was never
        // applied.
        t.published(5.5, 10_000);
        t.receive(&[got(5.4, 0.3, 5.6)], 5.6).unwrap();
        let s = t.take_run();
        assert_eq!((s.late(), s.stray(), s.missed), (3, 1, 1));
        let fates: Vec<Fate> = s.decisions.iter().map(|d| d.fate).collect();
        assert_eq!(
            fates,
            [
                Fate::Applied(0),
                Fate::Late,
                Fate::Late,
                Fate::Stray,
                Fate::Applied(0),
                Fate::Late
            ]
        );
        assert!((s.latencies_secs()[0] - 1.01).abs() < 1e-9);
        assert!(s.decisions[3].latency_secs.is_nan());
    }
}
