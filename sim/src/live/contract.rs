//! The stream contract: what `errp stream` publishes over Lab Streaming
//! Layer and what it takes back, written once (the guide's "Your online
//! BCI in the loop" describes it to a lab writing its own client).
//!
//! - `errp-eeg`: the simulated user's raw EEG, its description after LSL's
//!   EEG meta-data ([`eeg_spec`]);
//! - `errp-markers`: one JSON [`Marker`] per event, never the user's
//!   verdict in the control phase;
//! - `errp-state`: the device's [`State`] as JSON;
//! - the decoder's stream: 2 numeric channels at an irregular rate
//!   ([`check_decoder_stream`]), `[action id, p(error)]` per grid action or
//!   `[timestamp of the window's last sample, p(error)]` per e-puck window.
//!
//! Every stream's source id ends with the session's id ([`SessionId`],
//! also `desc/errp/session` of the EEG stream), and the decoder's stream
//! is accepted only if its source id ends with it too: two sessions on one
//! host never take each other's streams.
//!
//! [`CONTRACT`] is the version a client can check (`desc/errp/contract`);
//! any change of a byte below changes it.

use errp_bci::{ChannelKind, Montage};
use errp_lsl::{Element, Format, StreamSpec};
use serde::Serialize;

use crate::pace::Speed;
use crate::task_kind::TaskKind;

/// The version of the contract the streams follow, in every stream's
/// description (2: every source id ends with the session's id, and so must
/// the decoder's).
pub const CONTRACT: u32 = 2;
/// The EEG stream's name.
pub const EEG_STREAM: &str = "errp-eeg";
/// The markers' stream.
pub const MARKER_STREAM: &str = "errp-markers";
/// The device's state.
pub const STATE_STREAM: &str = "errp-state";
/// The decoder's stream, as `--decisions` looks for it by default.
pub const DECODER_STREAM: &str = "errp-decoder";
/// The radius the montage's unit sphere is scaled to in the channels'
/// locations: MNE's default head (`HEAD_SIZE_DEFAULT`, 95 mm, as
/// `make_standard_montage` scales the 10-20 positions).
pub const HEAD_RADIUS_MM: f64 = 95.0;

/// The names of MNE's 12 `loc` values of a channel, as MNE-LSL reads
/// them from a channel's `loc` element (the XDF `location` above is not
/// read by it).
const MNE_LOC: [&str; 12] = [
    "R0x", "R0y", "R0z", "Exx", "Exy", "Exz", "Eyx", "Eyy", "Eyz", "Ezx", "Ezy", "Ezz",
];

/// A channel's `loc` as MNE-LSL reads it into `info["chs"][k]["loc"]`:
/// the position on the unit sphere `position`, in metres on MNE's default
/// head, then the reference's position and the orientation, unknown: 0.
fn mne_loc(position: [f64; 3]) -> Element {
    let metres = position.map(|v| v * HEAD_RADIUS_MM / 1000.0);
    Element::node(
        "loc",
        MNE_LOC
            .iter()
            .enumerate()
            .map(|(i, name)| Element::leaf(name, format!("{:.6}", metres.get(i).unwrap_or(&0.0))))
            .collect(),
    )
}

/// A live session's id: 1 to 16 letters, digits or `_` (no `-`, which
/// ends the rest of a source id). Given (`errp stream --session`) or
/// drawn afresh for each session.
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct SessionId {
    bytes: [u8; SessionId::MAX_LEN],
    len: u8,
}

impl SessionId {
    /// The longest id.
    pub const MAX_LEN: usize = 16;

    /// `text` if it is an id.
    pub fn new(text: &str) -> Option<Self> {
        let ok = (1..=Self::MAX_LEN).contains(&text.len())
            && text.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_');
        ok.then(|| {
            let mut bytes = [0; Self::MAX_LEN];
            bytes[..text.len()].copy_from_slice(text.as_bytes());
            Self {
                bytes,
                len: text.len() as u8,
            }
        })
    }

    /// A fresh id: 8 hexadecimal digits from the standard library's
    /// random hasher keys (drawn from the operating system) and the
    /// process id; nothing the results depend on.
    pub fn fresh() -> Self {
        use std::hash::{BuildHasher, Hasher};
        let mut h = std::collections::hash_map::RandomState::new().build_hasher();
        h.write_u32(std::process::id());
        let text = format!("{:08x}", h.finish() as u32);
        Self::new(&text).unwrap_or(Self {
            bytes: [b'0'; Self::MAX_LEN],
            len: 8,
        })
    }

    /// The id.
    pub fn as_str(&self) -> &str {
        std::str::from_utf8(&self.bytes[..usize::from(self.len)]).unwrap_or_default()
    }
}

impl std::fmt::Display for SessionId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::fmt::Debug for SessionId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SessionId({:?})", self.as_str())
    }
}

/// The EEG channels' positions as MNE-LSL reads digitisation points
/// (`desc/dig/point`: `kind` 3, FIFF's EEG point; `ident` from 1; `loc` X,
/// Y, Z in metres, head coordinates): with them, MNE's `get_montage()`
/// gives the montage (it takes the positions from the channels' `loc`,
/// and needs some digitisation to exist).
fn mne_dig(montage: &Montage) -> Element {
    let points = montage
        .channels()
        .iter()
        .filter(|c| c.kind == ChannelKind::Eeg)
        .enumerate()
        .map(|(i, c)| {
            let metres = c.position.map(|v| v * HEAD_RADIUS_MM / 1000.0);
            Element::node(
                "point",
                vec![
                    Element::leaf("kind", 3),
                    Element::leaf("ident", i + 1),
                    Element::node(
                        "loc",
                        ["X", "Y", "Z"]
                            .iter()
                            .zip(metres)
                            .map(|(name, v)| Element::leaf(name, format!("{v:.6}")))
                            .collect(),
                    ),
                ],
            )
        })
        .collect();
    Element::node("dig", points)
}

/// A stream's source id: its name and the session's id.
pub fn source_id(stream: &str, session: SessionId) -> String {
    format!("{stream}-{session}")
}

/// The session a stream's source id names: what follows its last `-`.
pub fn session_of(source_id: &str) -> &str {
    source_id.rsplit('-').next().unwrap_or(source_id)
}

/// What the EEG stream says of itself beyond its channels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EegHeader {
    /// The true sampling rate (Hz).
    pub fs_hz: f64,
    /// Simulated seconds per second of the link's clock.
    pub speed: Speed,
    /// The scenario's seed.
    pub seed: u64,
    /// The task.
    pub task: TaskKind,
    /// The session.
    pub session: SessionId,
}

/// The EEG stream, after LSL's meta-data conventions for EEG (channels
/// with label, type, unit and location; the reference; the cap; the
/// acquisition), and what the testbed adds (`errp`: the contract, the
/// task, the speed, the true rate, the seed, the session). Its nominal
/// rate is the true rate times the speed.
pub fn eeg_spec(montage: &Montage, header: &EegHeader) -> StreamSpec {
    let EegHeader {
        fs_hz,
        speed,
        seed,
        task,
        session,
    } = *header;
    let channels = montage
        .channels()
        .iter()
        .map(|c| {
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
                            Element::leaf("X", format!("{:.1}", x * HEAD_RADIUS_MM)),
                            Element::leaf("Y", format!("{:.1}", y * HEAD_RADIUS_MM)),
                            Element::leaf("Z", format!("{:.1}", z * HEAD_RADIUS_MM)),
                        ],
                    ),
                    mne_loc([x, y, z]),
                ],
            )
        })
        .collect();
    StreamSpec {
        name: EEG_STREAM.into(),
        kind: "EEG".into(),
        channels: montage.len() as u32,
        rate_hz: speed.rate(fs_hz),
        format: Format::Float32,
        source_id: source_id(EEG_STREAM, session),
        desc: vec![
            Element::node("channels", channels),
            mne_dig(montage),
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
                    Element::leaf("sampling_rate_hz", fs_hz),
                    Element::leaf("seed", seed),
                    Element::leaf("session", session),
                ],
            ),
        ],
    }
}

/// A text stream of JSON strings (the markers, `"Markers"`; the state,
/// `"State"`) at an irregular rate.
pub fn text_spec(name: &str, kind: &str, session: SessionId) -> StreamSpec {
    StreamSpec {
        name: name.into(),
        kind: kind.into(),
        channels: 1,
        rate_hz: 0.0,
        format: Format::String,
        source_id: source_id(name, session),
        desc: vec![Element::leaf("contract", CONTRACT)],
    }
}

/// Refuses a decoder's stream (`name`, found by `prop=value`) of another
/// shape than the contract's: 2 numeric channels at an irregular rate.
pub fn check_decoder_stream(
    name: &str,
    (prop, value): (&str, &str),
    (channels, format, rate_hz): (i32, Option<Format>, f64),
) -> Result<(), String> {
    let numeric = !matches!(format, Some(Format::String) | None);
    if channels != 2 || rate_hz != 0.0 || !numeric {
        return Err(format!(
            "the decoder stream {name:?} ({prop}={value}) has {channels} channels of {} at \
             {rate_hz} Hz; expected 2 numeric channels (action, p(error)) at an irregular \
             rate (0 Hz)",
            format.map_or("an unknown format", Format::name),
        ));
    }
    Ok(())
}

/// A calibration example's class, as its marker labels it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Label {
    /// An erroneous action.
    Error,
    /// A correct action.
    Correct,
}

/// A grid cell as the markers write it: `[x, y]`.
pub type CellXy = [usize; 2];

/// One marker of `errp-markers`, as a JSON object whose `event` says what
/// it marks. Written by [`encode`].
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Marker<'a> {
    /// The calibration starts: `count` labelled actions or examples follow.
    CalibrationStart {
        /// How many.
        count: usize,
    },
    /// A grid calibration action at its onset, with its class.
    CalibrationAction {
        /// From 0.
        index: usize,
        /// Its class.
        label: Label,
    },
    /// An e-puck calibration example at the user's button press, with its
    /// class.
    CalibrationExample {
        /// From 0.
        index: usize,
        /// Its class.
        label: Label,
    },
    /// The calibration ended.
    CalibrationEnd,
    /// The control starts: `runs` runs follow.
    ControlStart {
        /// How many.
        runs: usize,
    },
    /// A grid run starts.
    #[serde(rename = "run_start")]
    GridRunStart {
        /// From 0.
        run: usize,
        /// The cursor's start.
        start: CellXy,
        /// The user's goal.
        goal: CellXy,
    },
    /// A grid action at its onset (never the user's verdict).
    Action {
        /// From 0.
        run: usize,
        /// The action's id, which the decoder's decision names (counted
        /// over the whole session).
        action: u64,
        /// What it is (`up`, `goal-reached`, ...).
        name: &'a str,
        /// The cursor before it.
        from: CellXy,
        /// The cursor after it.
        to: CellXy,
    },
    /// A grid run ended.
    #[serde(rename = "run_end")]
    GridRunEnd {
        /// From 0.
        run: usize,
        /// True if it converged on the user's goal.
        reached: bool,
        /// The cell it converged on, if any.
        committed: Option<CellXy>,
        /// Its actions.
        actions: usize,
    },
    /// An e-puck run starts.
    #[serde(rename = "run_start")]
    EpuckRunStart {
        /// From 0.
        run: usize,
        /// The user's goal, by name.
        goal: &'a str,
    },
    /// The e-puck's movement phase changed.
    Phase {
        /// From 0.
        run: usize,
        /// `turning`, `driving` or `stopped`.
        phase: &'a str,
        /// The goal it heads for, by name.
        target: &'a str,
    },
    /// An e-puck run ended.
    #[serde(rename = "run_end")]
    EpuckRunEnd {
        /// From 0.
        run: usize,
        /// True if it converged on the user's goal.
        reached: bool,
        /// The goal it converged on, by name, if any.
        committed: Option<&'a str>,
        /// When (s of simulated time).
        time: f64,
    },
    /// The session ended.
    End,
}

/// The device's state on `errp-state`, as a JSON object.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum State<'a> {
    /// The grid: the cursor before the next action.
    Grid {
        /// From 0.
        run: usize,
        /// The cursor.
        cursor: CellXy,
        /// The user's goal.
        goal: CellXy,
        /// The belief over the cells.
        belief: &'a [f64],
    },
    /// The e-puck at a window.
    Epuck {
        /// From 0.
        run: usize,
        /// Simulated time (s).
        time: f64,
        /// The tracked pose: x, y (m), heading (rad).
        pose: [f64; 3],
        /// The goal it heads for (index in the layout).
        target: usize,
        /// The user's goal (index in the layout).
        goal: usize,
        /// The belief over the goals.
        belief: &'a [f64],
    },
}

/// A marker or a state as its stream carries it: compact JSON with the
/// keys in byte order (the contract's bytes; serde_json's map is ordered
/// by key).
pub fn encode<T: Serialize>(message: &T) -> String {
    match serde_json::to_value(message) {
        Ok(v) => v.to_string(),
        // Markers and states hold only strings, numbers and arrays.
        Err(e) => unreachable!("a marker or state is JSON: {e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_marker_and_state_is_written_as_the_contract_says() {
        let cases: Vec<(String, &str)> = vec![
            (
                encode(&Marker::CalibrationStart { count: 400 }),
                r#"{"count":400,"event":"calibration_start"}"#,
            ),
            (
                encode(&Marker::CalibrationAction {
                    index: 0,
                    label: Label::Correct,
                }),
                r#"{"event":"calibration_action","index":0,"label":"correct"}"#,
            ),
            (
                encode(&Marker::CalibrationExample {
                    index: 3,
                    label: Label::Error,
                }),
                r#"{"event":"calibration_example","index":3,"label":"error"}"#,
            ),
            (
                encode(&Marker::CalibrationEnd),
                r#"{"event":"calibration_end"}"#,
            ),
            (
                encode(&Marker::ControlStart { runs: 5 }),
                r#"{"event":"control_start","runs":5}"#,
            ),
            (
                encode(&Marker::GridRunStart {
                    run: 0,
                    start: [3, 0],
                    goal: [3, 2],
                }),
                r#"{"event":"run_start","goal":[3,2],"run":0,"start":[3,0]}"#,
            ),
            (
                encode(&Marker::Action {
                    run: 0,
                    action: 17,
                    name: "up",
                    from: [3, 0],
                    to: [3, 1],
                }),
                r#"{"action":17,"event":"action","from":[3,0],"name":"up","run":0,"to":[3,1]}"#,
            ),
            (
                encode(&Marker::GridRunEnd {
                    run: 0,
                    reached: false,
                    committed: None,
                    actions: 14,
                }),
                r#"{"actions":14,"committed":null,"event":"run_end","reached":false,"run":0}"#,
            ),
            (
                encode(&Marker::EpuckRunStart {
                    run: 1,
                    goal: "Pisa",
                }),
                r#"{"event":"run_start","goal":"Pisa","run":1}"#,
            ),
            (
                encode(&Marker::Phase {
                    run: 0,
                    phase: "driving",
                    target: "Pisa",
                }),
                r#"{"event":"phase","phase":"driving","run":0,"target":"Pisa"}"#,
            ),
            (
                encode(&Marker::EpuckRunEnd {
                    run: 0,
                    reached: true,
                    committed: Some("Pisa"),
                    time: 41.0,
                }),
                r#"{"committed":"Pisa","event":"run_end","reached":true,"run":0,"time":41.0}"#,
            ),
            (encode(&Marker::End), r#"{"event":"end"}"#),
            (
                encode(&State::Grid {
                    run: 2,
                    cursor: [1, 4],
                    goal: [0, 0],
                    belief: &[0.5, f64::NAN],
                }),
                r#"{"belief":[0.5,null],"cursor":[1,4],"goal":[0,0],"run":2}"#,
            ),
            (
                encode(&State::Epuck {
                    run: 0,
                    time: 2.0625,
                    pose: [0.1, -0.0, std::f64::consts::FRAC_PI_2],
                    target: 1,
                    goal: 1,
                    belief: &[1e-7],
                }),
                r#"{"belief":[1e-7],"goal":1,"pose":[0.1,-0.0,1.5707963267948966],"run":0,"target":1,"time":2.0625}"#,
            ),
        ];
        for (got, want) in cases {
            assert_eq!(
                got, want,
                "a marker or state changed: if on purpose, bump CONTRACT and the guide"
            );
        }
    }

    #[test]
    fn the_keys_are_in_byte_order_as_json_maps_write_them() {
        // The order of every marker's keys above; a dependency that turns
        // on serde_json's `preserve_order` would change it.
        let v = serde_json::json!({"b": 0, "a": 0});
        assert_eq!(v.to_string(), r#"{"a":0,"b":0}"#);
    }

    #[test]
    fn the_eeg_stream_describes_every_channel_and_the_contract() {
        let m = Montage::standard();
        let header = EegHeader {
            fs_hz: 256.0,
            speed: Speed::new(4.0).unwrap(),
            seed: 1,
            task: TaskKind::Grid,
            session: SessionId::new("lab_a1").unwrap(),
        };
        let spec = eeg_spec(&m, &header);
        assert_eq!(spec.rate_hz, 1024.0);
        assert_eq!(spec.source_id, "errp-eeg-lab_a1");
        assert_eq!(session_of(&spec.source_id), "lab_a1");
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
        let errp = spec.desc.last().unwrap();
        assert_eq!(
            errp.children,
            vec![
                Element::leaf("contract", "2"),
                Element::leaf("task", "grid"),
                Element::leaf("speed", "4"),
                Element::leaf("sampling_rate_hz", "256"),
                Element::leaf("seed", "1"),
                Element::leaf("session", "lab_a1"),
            ]
        );
    }

    #[test]
    fn a_session_id_is_short_plain_and_fresh_each_time() {
        for bad in ["", "a-b", "x y", "ü", "12345678901234567"] {
            assert!(SessionId::new(bad).is_none(), "{bad:?}");
        }
        assert_eq!(SessionId::new("Lab_2").unwrap().to_string(), "Lab_2");
        let (a, b) = (SessionId::fresh(), SessionId::fresh());
        assert_eq!(a.as_str().len(), 8);
        assert_ne!(a, b);
        assert_eq!(session_of("errp-decoder-Lab_2"), "Lab_2");
        assert_eq!(session_of("Lab_2"), "Lab_2");
    }

    #[test]
    fn a_decoder_stream_of_another_shape_is_refused_naming_it() {
        let q = ("name", "d");
        assert!(check_decoder_stream("d", q, (2, Some(Format::Double64), 0.0)).is_ok());
        let e = check_decoder_stream("d", q, (3, Some(Format::Float32), 0.0)).unwrap_err();
        assert!(
            e.starts_with("the decoder stream \"d\" (name=d) has 3 channels"),
            "{e}"
        );
        assert!(check_decoder_stream("d", q, (2, Some(Format::String), 0.0)).is_err());
        assert!(check_decoder_stream("d", q, (2, None, 0.0)).is_err());
        assert!(check_decoder_stream("d", q, (2, Some(Format::Double64), 10.0)).is_err());
    }
}
