//! Temporal features of the discrete decoder (sec. 2.2.1), and the shape
//! every feature extractor shares.

use crate::generator::EegBlock;

/// Something that turns the preprocessed EEG after an onset into a feature
/// vector: the temporal features ([`EpochWindow`]) or the continuous
/// decoder's temporal + PSD features
/// ([`ContinuousFeatures`](crate::ContinuousFeatures)).
pub trait FeatureExtractor {
    /// Samples needed from the onset on.
    fn span(&self) -> usize;

    /// Number of features for `n_channels` channels.
    fn n_features(&self, n_channels: usize) -> usize;

    /// Appends the features of the window whose onset is sample `onset` of
    /// `block` (preprocessed, `(n_channels, n)`) to `out`. Panics if the
    /// window does not fit in the block.
    fn extract_into(&self, block: &EegBlock, onset: usize, out: &mut Vec<f64>);
}

/// Where the temporal features come from, relative to the action onset.
///
/// The paper takes [200, 800] ms downsampled to 64 Hz and gets 39 samples per
/// channel (8 x 39 = 312): both ends included, i.e. 200 ms + k x 15.625 ms for
/// k = 0..38. At 256 Hz that is every 4th sample from sample round(0.2 fs).
/// The signal is already low-passed at 10 Hz, so plain decimation does not
/// alias.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpochWindow {
    /// First sample after the onset.
    pub start: usize,
    /// Decimation step in samples.
    pub step: usize,
    /// Samples per channel.
    pub count: usize,
}

impl EpochWindow {
    /// The paper's window at `sfreq_hz` (a multiple of 64 Hz).
    pub fn paper(sfreq_hz: f64) -> Self {
        let step = (sfreq_hz / 64.0).round().max(1.0) as usize;
        Self {
            start: (0.2 * sfreq_hz).round() as usize,
            step,
            count: 39,
        }
    }

    /// Samples needed after the onset to extract the features.
    pub fn span(&self) -> usize {
        self.start + self.step * (self.count - 1) + 1
    }

    /// Number of features for `n_channels` channels.
    pub fn n_features(&self, n_channels: usize) -> usize {
        self.count * n_channels
    }

    /// Appends the features of the epoch whose onset is sample `onset` of
    /// `block` (preprocessed, `(n_channels, n)`) to `out`, channel by channel.
    /// Panics if the epoch does not fit in the block.
    pub fn extract_into(&self, block: &EegBlock, onset: usize, out: &mut Vec<f64>) {
        assert!(
            onset + self.span() <= block.n_samples,
            "epoch at sample {onset} runs past the block ({} samples)",
            block.n_samples
        );
        for ch in 0..block.n_channels {
            let x = block.channel(ch);
            out.extend((0..self.count).map(|k| x[onset + self.start + k * self.step]));
        }
    }

    /// The features of one epoch.
    pub fn extract(&self, block: &EegBlock, onset: usize) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.n_features(block.n_channels));
        self.extract_into(block, onset, &mut out);
        out
    }
}

impl FeatureExtractor for EpochWindow {
    fn span(&self) -> usize {
        EpochWindow::span(self)
    }

    fn n_features(&self, n_channels: usize) -> usize {
        EpochWindow::n_features(self, n_channels)
    }

    fn extract_into(&self, block: &EegBlock, onset: usize, out: &mut Vec<f64>) {
        EpochWindow::extract_into(self, block, onset, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_window_gives_312_features_from_200_to_794_ms() {
        let w = EpochWindow::paper(256.0);
        assert_eq!(w.n_features(8), 312);
        assert_eq!(w.start, 51);
        let last_ms = (w.start + w.step * (w.count - 1)) as f64 / 256.0 * 1000.0;
        assert!((last_ms - 793.0).abs() < 1.0, "{last_ms}");
    }

    #[test]
    fn extract_reads_the_right_samples() {
        let mut b = EegBlock::zeros(2, 400);
        for ch in 0..2 {
            for (t, v) in b.channel_mut(ch).iter_mut().enumerate() {
                *v = (ch * 1000 + t) as f64;
            }
        }
        let w = EpochWindow::paper(256.0);
        let f = w.extract(&b, 10);
        assert_eq!(f.len(), 78);
        assert_eq!(f[0], 61.0);
        assert_eq!(f[1], 65.0);
        assert_eq!(f[39], 1061.0);
    }
}
