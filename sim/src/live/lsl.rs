//! The link of `errp stream`: liblsl's outlets and inlet (`errp_lsl`) as a
//! [`LiveLink`], the streams as the contract describes them
//! ([`crate::live::contract`]).

use std::time::Duration;

use errp_bci::{EegBlock, Montage};
use errp_lsl::{Inlet, Lsl, LslError, Outlet};

use crate::error::{Result, SimError};
use crate::live::contract::{
    EEG_STREAM, EegHeader, MARKER_STREAM, STATE_STREAM, SessionId, check_decoder_stream, eeg_spec,
    session_of, text_spec,
};
use crate::live::{LiveLink, Received};

/// The streams of a live session over Lab Streaming Layer, and the
/// decoder's inlet.
pub struct LslLink {
    lsl: Lsl,
    eeg: Outlet,
    markers: Outlet,
    state: Outlet,
    query: (String, String),
    session: SessionId,
    /// Decoder streams of other sessions seen (their source ids).
    others: Vec<String>,
    decisions: Option<Inlet>,
    sample: Vec<f32>,
    /// Seconds spent publishing the EEG (LSL's clock).
    pub busy: f64,
}

fn live_error(e: LslError) -> SimError {
    SimError::Live(e.to_string())
}

impl LslLink {
    /// Opens the three streams of `montage`'s EEG as `header` describes
    /// it; the decoder's stream is the first whose LSL property `query.0`
    /// is `query.1` (`name=errp-decoder`) and whose source id ends with
    /// the session's id.
    pub fn open(
        lsl: &Lsl,
        montage: &Montage,
        header: &EegHeader,
        query: (&str, &str),
    ) -> Result<Self> {
        let session = header.session;
        let open = |spec| lsl.outlet(&spec).map_err(live_error);
        Ok(Self {
            lsl: lsl.clone(),
            eeg: open(eeg_spec(montage, header))?,
            markers: open(text_spec(MARKER_STREAM, "Markers", session))?,
            state: open(text_spec(STATE_STREAM, "State", session))?,
            query: (query.0.into(), query.1.into()),
            session,
            others: Vec::new(),
            decisions: None,
            sample: vec![0.0; montage.len()],
            busy: 0.0,
        })
    }
}

impl LiveLink for LslLink {
    fn clock(&self) -> f64 {
        self.lsl.clock()
    }

    fn eeg(&mut self, block: &EegBlock, first: f64, period: f64) -> Result<()> {
        let t = self.lsl.clock();
        for i in 0..block.n_samples {
            for (ch, v) in self.sample.iter_mut().enumerate() {
                *v = block.channel(ch)[i] as f32;
            }
            self.eeg
                .push(&self.sample, first + i as f64 * period)
                .map_err(live_error)?;
        }
        self.busy += self.lsl.clock() - t;
        Ok(())
    }

    fn marker(&mut self, text: &str, stamp: f64) -> Result<()> {
        self.markers.push_text(text, stamp).map_err(live_error)
    }

    fn state(&mut self, text: &str, stamp: f64) -> Result<()> {
        self.state.push_text(text, stamp).map_err(live_error)
    }

    fn wait_for_readers(&mut self, timeout: f64) -> Result<()> {
        if !self.eeg.wait_for_consumers(timeout) {
            return Err(SimError::Live(format!(
                "no program opened the EEG stream {EEG_STREAM} within {timeout} s (--timeout): \
                 start the decoder (it reads the calibration from the stream) before or with \
                 errp stream"
            )));
        }
        Ok(())
    }

    fn connect(&mut self, timeout_secs: f64) -> Result<bool> {
        let (prop, value) = (&self.query.0, &self.query.1);
        let found = self
            .lsl
            .resolve(prop, value, timeout_secs)
            .map_err(live_error)?;
        // Another session's decoder (or one that names no session) is
        // passed over, and named if none of this session's comes.
        let mut ours = None;
        for stream in &found {
            let id = stream.source_id();
            if session_of(&id) == self.session.as_str() {
                ours = Some(stream);
                break;
            }
            if !self.others.contains(&id) && self.others.len() < 8 {
                self.others.push(id);
            }
        }
        let Some(stream) = ours else {
            return Ok(false);
        };
        let shape = (stream.channels(), stream.format(), stream.rate_hz());
        check_decoder_stream(&stream.name(), (prop, value), shape).map_err(SimError::Live)?;
        self.decisions = Some(stream.open(5.0).map_err(live_error)?);
        Ok(true)
    }

    fn disconnect(&mut self) {
        self.decisions = None;
    }

    fn passed_over(&self) -> Option<String> {
        (!self.others.is_empty()).then(|| {
            format!(
                "found only decoder streams of other sessions (source ids {}), none whose \
                 source id ends with this session's id {:?}",
                self.others
                    .iter()
                    .map(|id| format!("{id:?}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                self.session.as_str()
            )
        })
    }

    fn wait(&mut self, until: f64) -> Result<Vec<Received>> {
        let mut got = Vec::new();
        let Some(inlet) = &self.decisions else {
            let left = until - self.lsl.clock();
            if left > 0.0 {
                std::thread::sleep(Duration::from_secs_f64(left));
            }
            return Ok(got);
        };
        let mut buf = [0.0; 2];
        loop {
            let left = (until - self.lsl.clock()).max(0.0);
            match inlet.pull(&mut buf, left).map_err(live_error)? {
                Some(_) => got.push(Received {
                    id: buf[0],
                    p_error: buf[1],
                    arrived: self.lsl.clock(),
                }),
                None if left <= 0.0 => break,
                None => {}
            }
            if got.len() > 10_000 {
                return Err(SimError::Live(format!(
                    "the decoder stream {:?} sent over 10 000 decisions within one 62.5 ms hop",
                    inlet.name()
                )));
            }
        }
        Ok(got)
    }
}
