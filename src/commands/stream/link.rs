//! The link of `errp stream`: liblsl's outlets and inlet (`errp_lsl`)
//! behind `errp_sim::live::LiveLink`, and the EEG stream's description.

use std::time::Duration;

use anyhow::Result;
use errp_bci::{ChannelKind, EegBlock, Montage};
use errp_lsl::{Element, Format, Inlet, Lsl, LslError, Outlet, StreamSpec};
use errp_sim::SimError;
use errp_sim::live::{LiveLink, Received};

use super::{CONTRACT, EEG_STREAM, MARKER_STREAM, STATE_STREAM};

/// The streams of `errp stream` and the decoder's inlet.
pub(super) struct LslLink {
    lsl: Lsl,
    eeg: Outlet,
    markers: Outlet,
    state: Outlet,
    query: (String, String),
    decisions: Option<Inlet>,
    sample: Vec<f32>,
    /// Seconds spent publishing the EEG (LSL's clock).
    pub(super) busy: f64,
}

/// What the EEG stream says of itself beyond its channels.
pub(super) struct EegStream {
    /// The true sampling rate (Hz).
    pub(super) fs: f64,
    pub(super) speed: f64,
    pub(super) seed: u64,
    /// `grid` or `epuck`.
    pub(super) task: &'static str,
}

impl LslLink {
    pub(super) fn open(
        lsl: &Lsl,
        montage: &Montage,
        stream: &EegStream,
        query: (&str, &str),
    ) -> Result<Self> {
        let seed = stream.seed;
        let eeg = lsl.outlet(&eeg_spec(montage, stream))?;
        let text = |name: &str, kind: &str| StreamSpec {
            name: name.into(),
            kind: kind.into(),
            channels: 1,
            rate_hz: 0.0,
            format: Format::String,
            source_id: format!("{name}-{seed}"),
            desc: vec![Element::leaf("contract", CONTRACT)],
        };
        Ok(Self {
            lsl: lsl.clone(),
            eeg,
            markers: lsl.outlet(&text(MARKER_STREAM, "Markers"))?,
            state: lsl.outlet(&text(STATE_STREAM, "State"))?,
            query: (query.0.into(), query.1.into()),
            decisions: None,
            sample: vec![0.0; montage.len()],
            busy: 0.0,
        })
    }
}

/// The EEG stream's description, after LSL's meta-data conventions for EEG
/// (channels with label, type and unit; the cap; the acquisition), and
/// what the testbed adds: the contract, the speed and the true rate.
fn eeg_spec(montage: &Montage, stream: &EegStream) -> StreamSpec {
    let EegStream {
        fs,
        speed,
        seed,
        task,
    } = *stream;
    let channels = montage
        .channels()
        .iter()
        .map(|c| {
            // The montage's unit sphere at MNE's default head radius
            // (`HEAD_SIZE_DEFAULT`, 95 mm, as `make_standard_montage`
            // scales the 10-20 positions), in LSL's millimetres.
            let [x, y, z] = c.position;
            Element::node(
                "channel",
                vec![
                    Element::leaf("label", &c.name),
                    Element::leaf(
                        "type",
                        match c.kind {
                            ChannelKind::Eeg => "EEG",
                            ChannelKind::Eog => "EOG",
                        },
                    ),
                    Element::leaf("unit", "microvolts"),
                    Element::node(
                        "location",
                        vec![
                            Element::leaf("X", format!("{:.1}", x * 95.0)),
                            Element::leaf("Y", format!("{:.1}", y * 95.0)),
                            Element::leaf("Z", format!("{:.1}", z * 95.0)),
                        ],
                    ),
                ],
            )
        })
        .collect();
    StreamSpec {
        name: EEG_STREAM.into(),
        kind: "EEG".into(),
        channels: montage.len() as u32,
        rate_hz: fs * speed,
        format: Format::Float32,
        source_id: format!("{EEG_STREAM}-{seed}"),
        desc: vec![
            Element::node("channels", channels),
            Element::node(
                "reference",
                vec![
                    Element::leaf("label", "A1"),
                    Element::leaf("subtracted", "yes"),
                ],
            ),
            Element::node("cap", vec![Element::leaf("labelscheme", "10-20")]),
            Element::node(
                "acquisition",
                vec![
                    Element::leaf("manufacturer", "errp-testbed"),
                    Element::leaf("model", "simulated user"),
                ],
            ),
            Element::node(
                "errp",
                vec![
                    Element::leaf("contract", CONTRACT),
                    Element::leaf("task", task),
                    Element::leaf("speed", speed),
                    Element::leaf("sampling_rate_hz", fs),
                    Element::leaf("seed", seed),
                ],
            ),
        ],
    }
}

fn live_error(e: LslError) -> SimError {
    SimError::Live(e.to_string())
}

impl LiveLink for LslLink {
    fn clock(&self) -> f64 {
        self.lsl.clock()
    }

    fn eeg(&mut self, block: &EegBlock, first: f64, period: f64) -> errp_sim::Result<()> {
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

    fn marker(&mut self, text: &str, stamp: f64) -> errp_sim::Result<()> {
        self.markers.push_text(text, stamp).map_err(live_error)
    }

    fn state(&mut self, text: &str, stamp: f64) -> errp_sim::Result<()> {
        self.state.push_text(text, stamp).map_err(live_error)
    }

    fn wait_for_readers(&mut self, timeout: f64) -> errp_sim::Result<()> {
        if !self.eeg.wait_for_consumers(timeout) {
            return Err(SimError::Live(format!(
                "no program opened the EEG stream {EEG_STREAM} within {timeout} s (--timeout): \
                 start the decoder (it reads the calibration from the stream) before or with \
                 errp stream"
            )));
        }
        Ok(())
    }

    fn connect(&mut self, timeout_secs: f64) -> errp_sim::Result<bool> {
        let (prop, value) = (&self.query.0, &self.query.1);
        let found = self
            .lsl
            .resolve(prop, value, timeout_secs)
            .map_err(live_error)?;
        let Some(stream) = found.first() else {
            return Ok(false);
        };
        let name = stream.name();
        let numeric = !matches!(stream.format(), Some(Format::String) | None);
        if stream.channels() != 2 || stream.rate_hz() != 0.0 || !numeric {
            return Err(SimError::Live(format!(
                "the decoder stream {name:?} ({prop}={value}) has {} channels of {} at {} Hz; \
                 expected 2 numeric channels (action, p(error)) at an irregular rate (0 Hz)",
                stream.channels(),
                stream.format().map_or("an unknown format", Format::name),
                stream.rate_hz()
            )));
        }
        self.decisions = Some(stream.open(5.0).map_err(live_error)?);
        Ok(true)
    }

    fn disconnect(&mut self) {
        self.decisions = None;
    }

    fn wait(&mut self, until: f64) -> errp_sim::Result<Vec<Received>> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_eeg_description_lists_every_channel() {
        let m = Montage::standard();
        let stream = EegStream {
            fs: 256.0,
            speed: 4.0,
            seed: 1,
            task: "grid",
        };
        let spec = eeg_spec(&m, &stream);
        assert_eq!(spec.rate_hz, 1024.0);
        let channels = &spec.desc[0].children;
        assert_eq!(channels.len(), m.len());
        assert_eq!(
            channels[0].children[0],
            Element::leaf("label", &m.channels()[0].name)
        );
        let eog = channels
            .iter()
            .filter(|c| c.children[1] == Element::leaf("type", "EOG"))
            .count();
        assert_eq!(eog, m.n_eog());
    }
}
