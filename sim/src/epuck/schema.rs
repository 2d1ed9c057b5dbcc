//! The TOML schema of an e-puck scenario file: what each table may hold,
//! before any value is checked (sim/src/epuck/scenario.rs checks them and
//! converts centimetres and degrees to SI).

use std::fmt;

use errp_bci::DetectorMode;
use errp_robot::EpuckControlParams;
use serde::Deserialize;
use serde::de::{self, SeqAccess, Visitor};

use crate::scenario_file::Pair;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct EpuckFile {
    pub(crate) task: String,
    #[serde(default)]
    pub(crate) name: Option<String>,
    #[serde(default)]
    pub(crate) description: Option<String>,
    #[serde(default = "default_seed")]
    pub(crate) seed: u64,
    pub(crate) start: StartFile,
    #[serde(default = "default_heading")]
    pub(crate) start_heading_deg: f64,
    pub(crate) goal: String,
    #[serde(default)]
    pub(crate) runs: Option<f64>,
    #[serde(default = "default_max_secs")]
    pub(crate) max_secs: f64,
    /// Required but with own EEG (`[eeg]`), whose user is the person.
    #[serde(default)]
    pub(crate) user: UserFile,
    /// A person's own EEG in place of the synthetic user's EEG.
    #[serde(default)]
    pub(crate) eeg: Option<crate::own_eeg::OwnEegTable>,
    /// Straight into the robot's type: its field names are the file's.
    #[serde(default)]
    pub(crate) control: EpuckControlParams,
    #[serde(default)]
    pub(crate) tracker: Option<TrackerFile>,
    #[serde(default)]
    pub(crate) avoidance: Option<AvoidanceFile>,
    #[serde(default)]
    pub(crate) detector: Option<DetectorFile>,
    #[serde(default)]
    pub(crate) arena: Option<ArenaFile>,
    /// Straight into the EEG model's type: how far the user is from the
    /// ideal one (all off by default).
    #[serde(default)]
    pub(crate) realism: errp_bci::Realism,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct DetectorFile {
    pub(crate) mode: Option<DetectorMode>,
    pub(crate) smooth_windows: Option<f64>,
    pub(crate) refractory_secs: Option<f64>,
}

pub(crate) fn default_seed() -> u64 {
    1
}

pub(crate) fn default_heading() -> f64 {
    90.0
}

pub(crate) fn default_max_secs() -> f64 {
    600.0
}

/// Where the e-puck starts: a city's name or a position in centimetres.
#[derive(Debug)]
pub(crate) enum StartFile {
    City(String),
    Cm([f64; 2]),
}

impl<'de> Deserialize<'de> for StartFile {
    fn deserialize<D: de::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Start;
        impl<'de> Visitor<'de> for Start {
            type Value = StartFile;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a city (\"Mexico\") or a position [x_cm, y_cm]")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<StartFile, E> {
                Ok(StartFile::City(v.to_string()))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<StartFile, A::Error> {
                // A scenario file is at most 1 MiB, so the array is bounded.
                let mut v: Vec<f64> = Vec::new();
                while let Some(x) = seq.next_element()? {
                    v.push(x);
                }
                let n = v.len();
                <[f64; 2]>::try_from(v)
                    .map(StartFile::Cm)
                    .map_err(|_| de::Error::invalid_length(n, &"a position [x_cm, y_cm]"))
            }
        }
        d.deserialize_any(Start)
    }
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct UserFile {
    pub(crate) seed: Option<u64>,
    pub(crate) accuracy: Option<f64>,
    pub(crate) hit_rate: Option<f64>,
    pub(crate) false_alarms_per_min: Option<f64>,
    pub(crate) fov_deg: Option<f64>,
    pub(crate) reaction_latency_ms: Option<f64>,
    pub(crate) reelicit_secs: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TrackerFile {
    pub(crate) rate_hz: Option<f64>,
    pub(crate) position_noise_cm: Option<f64>,
    pub(crate) heading_noise_deg: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct AvoidanceFile {
    pub(crate) enabled: Option<bool>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ArenaFile {
    #[serde(default)]
    pub(crate) obstacle: Vec<ObstacleFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ObstacleFile {
    pub(crate) shape: String,
    pub(crate) center_cm: Pair<f64>,
    #[serde(default)]
    pub(crate) size_cm: Option<Pair<f64>>,
    #[serde(default)]
    pub(crate) radius_cm: Option<f64>,
    #[serde(default)]
    pub(crate) angle_deg: f64,
}
