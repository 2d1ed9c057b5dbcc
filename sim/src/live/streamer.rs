//! The stream of a live session: the EEG published on the link's clock at
//! the session's pace, the markers and the state beside it, and the steps
//! both tasks' sessions share (the calibration streamed with its labels,
//! the rest until the decoder appears, the control's start and the
//! session's end).

use errp_bci::{Assessment, AssessmentKind, EegBlock, EegGenerator};

use crate::error::{Result, SimError};
use crate::live::contract::{Label, Marker, State, encode};
use crate::live::sink::Sink;
use crate::live::{Decisions, HOP_SAMPLES, LiveLink, LiveOptions};
use crate::pace::{Pace, Speed};

/// After the calibration: rest EEG from `eeg` until the decoder's stream
/// appears (or `options.timeout_secs` pass: an error naming `decoder`).
pub(crate) fn wait_for_decoder<D: Decisions>(
    s: &mut Streamer<'_, D>,
    eeg: &mut EegGenerator,
    options: LiveOptions,
    decoder: &str,
    sink: &mut Sink<'_>,
) -> Result<()> {
    sink.note(&format!(
        "calibration sent; waiting up to {} s for the decoder stream {decoder:?}",
        options.timeout_secs
    ));
    let waited_from = s.link().clock();
    loop {
        s.stream(&eeg.generate(s.pace.samples_in_link(0.25)))?;
        if s.link().connect(0.2)? {
            sink.note("decoder found; control starts");
            return Ok(());
        }
        if s.link().clock() - waited_from > options.timeout_secs {
            return Err(SimError::Live(match s.link().passed_over() {
                Some(others) => format!(
                    "no decoder stream {decoder:?} of this session appeared within {} s after \
                     the calibration (--timeout): {others} (a decoder for another session is \
                     refused: publish yours with source id errp-decoder-{})",
                    options.timeout_secs, options.session
                ),
                None => format!(
                    "no decoder stream {decoder:?} appeared within {} s after the calibration \
                     (--timeout): is the decoder running, and does its stream have that name?",
                    options.timeout_secs
                ),
            }));
        }
    }
}

/// How a calibration example is marked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum CalibrationMark {
    /// At the grid action's onset.
    Action,
    /// At the user's button press (the e-puck).
    Example,
}

/// Streams a calibration session: `eeg` up to each assessment of
/// `schedule`, the assessment scheduled at its onset and its marker (with
/// its index and label) stamped `lag_secs(i)` after the onset (a button
/// press); then 2 s more, between the markers `calibration_start` and
/// `calibration_end`.
pub(crate) fn stream_calibration<D: Decisions>(
    s: &mut Streamer<'_, D>,
    eeg: &mut EegGenerator,
    schedule: &[Assessment],
    mark: CalibrationMark,
    lag_secs: impl Fn(usize) -> f64,
) -> Result<()> {
    let fs = s.pace.fs_hz();
    s.marker(&Marker::CalibrationStart {
        count: schedule.len(),
    })?;
    for (i, a) in schedule.iter().enumerate() {
        let due = (a.onset_secs * fs).round() as i64 - (s.now_secs() * fs).round() as i64;
        s.stream(&eeg.generate(due.max(0) as usize))?;
        let label = if a.kind == AssessmentKind::Error {
            Label::Error
        } else {
            Label::Correct
        };
        let at = s.now_secs() + lag_secs(i);
        let marker = match mark {
            CalibrationMark::Action => Marker::CalibrationAction { index: i, label },
            CalibrationMark::Example => Marker::CalibrationExample { index: i, label },
        };
        s.marker_at(at, &marker)?;
        eeg.schedule(Assessment {
            onset_secs: eeg.now_secs(),
            kind: a.kind,
        });
    }
    s.stream(&eeg.generate((2.0 * fs) as usize))?;
    s.marker(&Marker::CalibrationEnd)
}

/// The control starts: silence counts from now, and the marker says how
/// many runs follow.
pub(crate) fn begin_control<D: Decisions>(s: &mut Streamer<'_, D>, runs: usize) -> Result<()> {
    let now = s.link().clock();
    s.tracker.start(now);
    s.marker(&Marker::ControlStart { runs })
}

/// The session ends: the decoder's stream let go, the `end` marker, and 1
/// s more of `eeg` so that a reader sees the marker inside the EEG.
pub(crate) fn end_session<D: Decisions>(
    s: &mut Streamer<'_, D>,
    eeg: &mut EegGenerator,
) -> Result<()> {
    s.link().disconnect();
    s.marker(&Marker::End)?;
    let fs = s.pace.fs_hz();
    s.stream(&eeg.generate(fs as usize))
}

/// Publishes the EEG on the link's clock at the session's pace, and keeps
/// the decisions coming in the meantime.
pub struct Streamer<'l, D> {
    link: &'l mut dyn LiveLink,
    pace: Pace,
    sent: u64,
    /// The decisions.
    pub tracker: D,
}

impl<'l, D: Decisions> Streamer<'l, D> {
    /// Starts the clock now: sample 0 (at `fs_hz`) is stamped with the
    /// link's time.
    pub fn new(link: &'l mut dyn LiveLink, fs_hz: f64, speed: Speed, tracker: D) -> Self {
        let pace = Pace::new(link.clock(), fs_hz, speed);
        Self {
            link,
            pace,
            sent: 0,
            tracker,
        }
    }

    /// The link.
    pub fn link(&mut self) -> &mut dyn LiveLink {
        self.link
    }

    /// The session's pace.
    pub fn pace(&self) -> Pace {
        self.pace
    }

    /// The simulated time of the next sample (s).
    pub fn now_secs(&self) -> f64 {
        self.pace.sample_secs(self.sent)
    }

    /// The timestamp of the next sample.
    pub fn now_stamp(&self) -> f64 {
        self.pace.stamp(self.now_secs())
    }

    /// Publishes a marker at the next sample.
    pub fn marker(&mut self, marker: &Marker<'_>) -> Result<()> {
        let stamp = self.now_stamp();
        self.link.marker(&encode(marker), stamp)
    }

    /// Publishes a marker at simulated second `secs`.
    pub fn marker_at(&mut self, secs: f64, marker: &Marker<'_>) -> Result<()> {
        let stamp = self.pace.stamp(secs);
        self.link.marker(&encode(marker), stamp)
    }

    /// Publishes the state at the next sample.
    pub fn state(&mut self, state: &State<'_>) -> Result<()> {
        let stamp = self.now_stamp();
        self.link.state(&encode(state), stamp)
    }

    /// Publishes `block`, [`HOP_SAMPLES`] at a time, each once its last
    /// sample's time has come, taking the decisions that came meanwhile.
    pub fn stream(&mut self, block: &EegBlock) -> Result<()> {
        let period = self.pace.period();
        let n = block.n_samples;
        let mut start = 0;
        while start < n {
            let end = (start + HOP_SAMPLES).min(n);
            let due = self
                .pace
                .stamp(self.pace.sample_secs(self.sent + end as u64));
            let got = self.link.wait(due)?;
            let now = self.link.clock();
            self.tracker.receive(&got, now)?;
            let first = self
                .pace
                .stamp(self.pace.sample_secs(self.sent + start as u64));
            self.link.eeg(&block.samples(start..end), first, period)?;
            let last = self
                .pace
                .stamp(self.pace.sample_secs(self.sent + end as u64 - 1));
            self.tracker.published(last, self.sent + end as u64);
            errp_bci::stop::check()?;
            start = end;
        }
        self.sent += n as u64;
        Ok(())
    }
}
