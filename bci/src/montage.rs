//! Channel names, kinds and electrode positions.

use crate::error::{BciError, Result};

const ELECTRODES_CSV: &str = include_str!("../../assets/electrodes.csv");

/// What a channel records.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChannelKind {
    /// Scalp EEG, referenced to the left earlobe before CAR.
    Eeg,
    /// Monopolar EOG, referenced to the left mastoid.
    Eog,
}

/// One electrode.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// Name in 10-10 notation (`FCz`) or `EOG LA` style for EOG.
    pub name: String,
    /// EEG or EOG.
    pub kind: ChannelKind,
    /// Position on the unit head sphere: x right, y front (nasion), z up.
    pub position: [f64; 3],
}

/// The montage: all EEG channels first, then the EOG channels.
#[derive(Debug, Clone, PartialEq)]
pub struct Montage {
    channels: Vec<Channel>,
    n_eeg: usize,
}

/// The eight fronto-central channels the paper decodes from (sec. 2.2.1).
pub const DECODING_CHANNELS: [&str; 8] = ["Fz", "FC1", "FCz", "FC2", "C1", "Cz", "C2", "CPz"];

impl Montage {
    /// The default montage: the paper's 32 EEG channels plus C1 and C2, and
    /// six EOG channels (above and below each eye, outer canthi), read from
    /// `assets/electrodes.csv`.
    pub fn standard() -> Self {
        Self::from_csv(ELECTRODES_CSV).expect("assets/electrodes.csv is valid")
    }

    fn from_csv(text: &str) -> Result<Self> {
        let bad = |message: String| BciError::Asset {
            file: "electrodes.csv",
            message,
        };
        let mut channels = Vec::new();
        for (lineno, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') || line.starts_with("name,") {
                continue;
            }
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() != 5 {
                return Err(bad(format!("line {}: expected 5 fields", lineno + 1)));
            }
            let kind = match fields[1] {
                "eeg" => ChannelKind::Eeg,
                "eog" => ChannelKind::Eog,
                other => return Err(bad(format!("line {}: kind {other:?}", lineno + 1))),
            };
            let mut position = [0.0; 3];
            for (p, f) in position.iter_mut().zip(&fields[2..]) {
                *p = f
                    .parse()
                    .map_err(|_| bad(format!("line {}: bad number {f:?}", lineno + 1)))?;
            }
            channels.push(Channel {
                name: fields[0].to_string(),
                kind,
                position,
            });
        }
        let n_eeg = channels
            .iter()
            .filter(|c| c.kind == ChannelKind::Eeg)
            .count();
        if channels[..n_eeg].iter().any(|c| c.kind != ChannelKind::Eeg) {
            return Err(bad("EEG channels must come before EOG channels".into()));
        }
        Ok(Self { channels, n_eeg })
    }

    /// The channels at `keep` (increasing indices), EEG still first: the
    /// part of the montage own EEG has.
    pub fn subset(&self, keep: &[usize]) -> Result<Self> {
        if !keep.windows(2).all(|w| w[0] < w[1]) || keep.iter().any(|&i| i >= self.len()) {
            return Err(BciError::InvalidParameter {
                name: "keep",
                value: format!("{keep:?}"),
                expected: format!("increasing channel indices below {}", self.len()),
            });
        }
        let channels: Vec<Channel> = keep.iter().map(|&i| self.channels[i].clone()).collect();
        let n_eeg = channels
            .iter()
            .filter(|c| c.kind == ChannelKind::Eeg)
            .count();
        Ok(Self { channels, n_eeg })
    }

    /// All channels, EEG first.
    pub fn channels(&self) -> &[Channel] {
        &self.channels
    }

    /// Number of channels (EEG + EOG).
    pub fn len(&self) -> usize {
        self.channels.len()
    }

    /// True if there are no channels.
    pub fn is_empty(&self) -> bool {
        self.channels.is_empty()
    }

    /// Number of EEG channels; they occupy indices `0..n_eeg()`.
    pub fn n_eeg(&self) -> usize {
        self.n_eeg
    }

    /// Number of EOG channels; they occupy indices `n_eeg()..len()`.
    pub fn n_eog(&self) -> usize {
        self.channels.len() - self.n_eeg
    }

    /// Index of the channel called `name`.
    pub fn index(&self, name: &str) -> Result<usize> {
        self.channels
            .iter()
            .position(|c| c.name == name)
            .ok_or_else(|| BciError::UnknownChannel(name.to_string()))
    }

    /// Indices of the eight decoding channels of the paper.
    pub fn decoding_indices(&self) -> Vec<usize> {
        DECODING_CHANNELS
            .iter()
            .map(|n| self.index(n).expect("decoding channels are in the montage"))
            .collect()
    }

    /// Great-circle distance (radians) between two channels.
    pub fn angular_distance(&self, a: usize, b: usize) -> f64 {
        angle_between(self.channels[a].position, self.channels[b].position)
    }
}

/// Angle (radians) between two vectors.
pub(crate) fn angle_between(a: [f64; 3], b: [f64; 3]) -> f64 {
    let dot: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
    let na = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    let nb = b.iter().map(|x| x * x).sum::<f64>().sqrt();
    (dot / (na * nb)).clamp(-1.0, 1.0).acos()
}

/// A name as compared: trimmed, lower case, without an `EEG ` or `EOG `
/// prefix (MNE drops `EOG ` when it infers channel types).
fn bare(name: &str) -> String {
    let n = name.trim().to_ascii_lowercase();
    for prefix in ["eeg ", "eog ", "eeg-", "eog-"] {
        if let Some(rest) = n.strip_prefix(prefix) {
            return rest.trim().to_string();
        }
    }
    n
}

/// The index in `labels` of montage channel `name`, compared bare; two
/// labels that both match are an error naming both (a relabelled channel
/// would otherwise be decoded as another).
pub(crate) fn find_label(labels: &[&str], name: &str) -> Result<Option<usize>, String> {
    let want = bare(name);
    let mut hits = labels
        .iter()
        .enumerate()
        .filter(|(_, l)| bare(l) == want)
        .map(|(i, _)| i);
    match (hits.next(), hits.next()) {
        (Some(i), Some(j)) => Err(format!(
            "two channels match {name:?}: {:?} (channel {}) and {:?} (channel {}); rename or \
             drop one (e.g. MNE's raw.rename_channels or raw.drop_channels)",
            labels[i],
            i + 1,
            labels[j],
            j + 1
        )),
        (first, _) => Ok(first),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_montage_has_34_eeg_and_6_eog() {
        let m = Montage::standard();
        assert_eq!(m.n_eeg(), 34);
        assert_eq!(m.n_eog(), 6);
        for name in DECODING_CHANNELS {
            assert!(m.index(name).is_ok(), "{name}");
        }
        for c in m.channels() {
            let r: f64 = c.position.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!((r - 1.0).abs() < 1e-3, "{} not on the unit sphere", c.name);
        }
    }

    #[test]
    fn neighbours_are_close_and_antipodes_far() {
        let m = Montage::standard();
        let d = |a, b| m.angular_distance(m.index(a).unwrap(), m.index(b).unwrap());
        // FCz is 10 % of the nasion-inion arc (18 deg) from Cz and from Fz.
        assert!((d("FCz", "Cz").to_degrees() - 18.0).abs() < 0.1);
        assert!((d("FCz", "Fz").to_degrees() - 18.0).abs() < 0.1);
        assert!((d("T7", "T8").to_degrees() - 180.0).abs() < 0.1);
        assert!(d("C1", "Cz") < d("C3", "Cz"));
    }

    #[test]
    fn unknown_channel_is_an_error() {
        assert!(matches!(
            Montage::standard().index("XYZ"),
            Err(BciError::UnknownChannel(_))
        ));
    }
}
