//! Features of the continuous decoder (sec. 2.2.2): the temporal features of
//! the discrete one plus the theta-band PSD, over one 800 ms window.

use crate::features::{EpochWindow, FeatureExtractor};
use crate::generator::EegBlock;
use crate::psd::ThetaPsd;

/// The 512 features of one 800 ms window of the continuous decoder
/// (sec. 2.2.2 of the paper).
///
/// Without a cue the ErrP may sit anywhere in a sliding window, so the paper
/// adds frequency features that are "rather insensitive to time shifts" to
/// the temporal ones. The window starts at sample `onset`:
/// * temporal: exactly [`EpochWindow::paper`] relative to the window start
///   ([200, 800] ms at 64 Hz, 8 x 39 = 312);
/// * PSD: [`ThetaPsd::paper`] over samples `onset .. onset + round(0.8 fs)`
///   (3..=9 Hz every 0.25 Hz, 8 x 25 = 200).
///
/// Layout: all temporal features (channel by channel), then all PSD features
/// (channel by channel).
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuousFeatures {
    /// The temporal part.
    pub temporal: EpochWindow,
    /// The frequency part.
    pub psd: ThetaPsd,
}

impl ContinuousFeatures {
    /// The paper's features at `sfreq_hz` (a multiple of 64 Hz).
    pub fn paper(sfreq_hz: f64) -> Self {
        Self {
            temporal: EpochWindow::paper(sfreq_hz),
            psd: ThetaPsd::paper(sfreq_hz),
        }
    }

    /// Samples needed from the window start on (205 at 256 Hz).
    pub fn span(&self) -> usize {
        self.temporal.span().max(self.psd.span())
    }

    /// Number of features for `n_channels` channels (512 for 8).
    pub fn n_features(&self, n_channels: usize) -> usize {
        self.temporal.n_features(n_channels) + self.psd.n_features(n_channels)
    }

    /// Appends the features of the window starting at sample `onset` of
    /// `block` (preprocessed, `(n_channels, n)`) to `out`. Panics if the
    /// window does not fit in the block.
    pub fn extract_into(&self, block: &EegBlock, onset: usize, out: &mut Vec<f64>) {
        assert!(
            onset + self.span() <= block.n_samples,
            "window at sample {onset} runs past the block ({} samples)",
            block.n_samples
        );
        self.temporal.extract_into(block, onset, out);
        self.psd.extract_into(block, onset, out);
    }

    /// The features of one window.
    pub fn extract(&self, block: &EegBlock, onset: usize) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.n_features(block.n_channels));
        self.extract_into(block, onset, &mut out);
        out
    }
}

impl FeatureExtractor for ContinuousFeatures {
    fn span(&self) -> usize {
        ContinuousFeatures::span(self)
    }

    fn n_features(&self, n_channels: usize) -> usize {
        ContinuousFeatures::n_features(self, n_channels)
    }

    fn extract_into(&self, block: &EegBlock, onset: usize, out: &mut Vec<f64>) {
        ContinuousFeatures::extract_into(self, block, onset, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_features_are_312_temporal_then_200_psd() {
        let f = ContinuousFeatures::paper(256.0);
        assert_eq!(f.n_features(8), 512);
        assert_eq!(f.span(), 205);
        let mut b = EegBlock::zeros(8, 400);
        for ch in 0..8 {
            for (t, v) in b.channel_mut(ch).iter_mut().enumerate() {
                *v = ((t as f64) * 0.13 * (ch + 1) as f64).sin();
            }
        }
        let x = f.extract(&b, 17);
        assert_eq!(x.len(), 512);
        assert_eq!(&x[..312], &EpochWindow::paper(256.0).extract(&b, 17)[..]);
        let mut psd = Vec::new();
        f.psd.extract_into(&b, 17, &mut psd);
        assert_eq!(&x[312..], &psd[..]);
        // Through the trait, the same.
        let dynamic: &dyn FeatureExtractor = &f;
        let mut y = Vec::new();
        dynamic.extract_into(&b, 17, &mut y);
        assert_eq!(x, y);
        assert_eq!(dynamic.span(), 205);
    }
}
