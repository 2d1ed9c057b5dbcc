//! What one decoded action tells of the user's verdict: the mutual
//! information between the true label (error or correct) and the decoder's
//! p(error), in bits, at equal priors.
//!
//! At equal priors the mutual information is the Jensen-Shannon divergence
//! of the two classes' output distributions. Two channels bound it at a
//! given accuracy a (the mean of the two classes' rates of the decoder's class
//! decisions):
//!
//! * the binary symmetric channel, which gives only a class, right with
//!   probability a: 1 - H(a) bits, the least a decoder whose classes are
//!   right at this rate carries (Fano's inequality);
//! * the erasure channel, whose outputs are either certain or a coin flip:
//!   2a - 1 bits, the most a decoder at this accuracy can carry when its
//!   p(error) is calibrated.
//!
//! So two decoders at one accuracy can move a belief by very different
//! amounts: the shape of the output distribution matters, not its accuracy
//! alone.

/// Bins of p(error) over [0, 1] in [`ActionInformation::measure`]: the
/// plug-in estimate's bias is about (bins - 1) / (2 n ln 2) bits for n
/// outputs, 0.007 bits at 1000 per class.
pub const INFORMATION_BINS: usize = 20;

/// The information per action of a decoder, measured on outputs of known
/// class.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActionInformation {
    /// Mutual information between label and p(error) at equal priors
    /// (bits, 0 to 1).
    pub bits: f64,
    /// The decoder's accuracy on the same actions: the mean of the two
    /// classes' rates of its class decisions.
    pub accuracy: f64,
    /// Outputs of each class (error, correct).
    pub outputs: (usize, usize),
}

impl ActionInformation {
    /// Measures on the decoder's outputs, p(error) and its class decision
    /// (true: error), for actions the user judged erroneous (`error`) and
    /// correct (`correct`); p(error) is binned in [`INFORMATION_BINS`]
    /// equal bins of [0, 1]. `None` if a class has no output or an output is
    /// not a probability.
    pub fn measure(error: &[(f64, bool)], correct: &[(f64, bool)]) -> Option<Self> {
        let histogram = |p: &[(f64, bool)]| -> Option<[f64; INFORMATION_BINS]> {
            if p.is_empty() {
                return None;
            }
            let mut h = [0.0; INFORMATION_BINS];
            for &(v, _) in p {
                if !(0.0..=1.0).contains(&v) {
                    return None;
                }
                let k = ((v * INFORMATION_BINS as f64) as usize).min(INFORMATION_BINS - 1);
                h[k] += 1.0 / p.len() as f64;
            }
            Some(h)
        };
        let e = histogram(error)?;
        let c = histogram(correct)?;
        let mut bits = 0.0;
        for (pe, pc) in e.iter().zip(&c) {
            let m = 0.5 * (pe + pc);
            for p in [pe, pc] {
                if *p > 0.0 {
                    bits += 0.5 * p * (p / m).log2();
                }
            }
        }
        let share = |p: &[(f64, bool)], error: bool| {
            p.iter().filter(|(_, says)| *says == error).count() as f64 / p.len() as f64
        };
        Some(Self {
            bits: bits.clamp(0.0, 1.0),
            accuracy: 0.5 * (share(error, true) + share(correct, false)),
            outputs: (error.len(), correct.len()),
        })
    }

    /// What a binary symmetric channel at this accuracy carries: the least
    /// at this accuracy.
    pub fn binary_symmetric_bits(&self) -> f64 {
        binary_symmetric_bits(self.accuracy)
    }

    /// What an erasure channel at this accuracy carries: the most at this
    /// accuracy.
    pub fn erasure_bits(&self) -> f64 {
        erasure_bits(self.accuracy)
    }
}

/// Binary entropy (bits).
pub fn binary_entropy(p: f64) -> f64 {
    let h = |x: f64| if x > 0.0 { -x * x.log2() } else { 0.0 };
    h(p) + h(1.0 - p)
}

/// 1 - H(a): the information of a binary symmetric channel right with
/// probability `accuracy`, at equal priors (bits).
pub fn binary_symmetric_bits(accuracy: f64) -> f64 {
    1.0 - binary_entropy(accuracy)
}

/// 2a - 1 (0 below a = 0.5): the information of an erasure channel whose
/// outputs are certain with probability 2a - 1 and a coin flip otherwise,
/// at equal priors (bits).
pub fn erasure_bits(accuracy: f64) -> f64 {
    (2.0 * accuracy - 1.0).max(0.0)
}

/// The information of a decoder that reports each class, right with
/// probability `error_rate` on errors and `correct_rate` on correct
/// actions, and nothing else (a binary channel of those rates), at equal
/// priors (bits): what published per-class rates alone guarantee.
pub fn binary_channel_bits(error_rate: f64, correct_rate: f64) -> f64 {
    binary_entropy(0.5 * (error_rate + 1.0 - correct_rate))
        - 0.5 * (binary_entropy(error_rate) + binary_entropy(correct_rate))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A symmetric channel's outputs in exact proportion: the measure is
    /// 1 - H(a) to rounding.
    #[test]
    fn exact_binary_symmetric_outputs_give_one_minus_the_entropy() {
        for (right, n) in [(7438, 10_000), (600, 1000), (95, 100)] {
            let a = right as f64 / n as f64;
            let outputs = |error: bool| -> Vec<(f64, bool)> {
                (0..n)
                    .map(|i| {
                        let says = (i < right) == error;
                        (if says { a } else { 1.0 - a }, says)
                    })
                    .collect()
            };
            let m = ActionInformation::measure(&outputs(true), &outputs(false)).expect("measured");
            assert!((m.accuracy - a).abs() < 1e-12);
            assert!((m.bits - binary_symmetric_bits(a)).abs() < 1e-9, "{m:?}");
        }
        assert!((binary_symmetric_bits(0.7438) - 0.1790).abs() < 1e-4);
    }

    /// Certain outputs on a share q of each class, 0.5 on the rest: q bits,
    /// at accuracy (1 + q) / 2, which is 2a - 1.
    #[test]
    fn an_erasure_channel_carries_twice_its_accuracy_less_one() {
        let q = 0.5;
        // The coin flips decide at random: half of them right.
        let error: Vec<(f64, bool)> = (0..1000)
            .map(|i| {
                if i < 500 {
                    (1.0, true)
                } else {
                    (0.5, i % 2 == 0)
                }
            })
            .collect();
        let correct: Vec<(f64, bool)> = (0..1000)
            .map(|i| {
                if i < 500 {
                    (0.0, false)
                } else {
                    (0.5, i % 2 == 0)
                }
            })
            .collect();
        let m = ActionInformation::measure(&error, &correct).expect("measured");
        assert!((m.bits - q).abs() < 1e-12, "{m:?}");
        assert!((m.accuracy - 0.75).abs() < 1e-12);
        assert!((m.erasure_bits() - m.bits).abs() < 1e-12);
    }

    #[test]
    fn identical_classes_carry_nothing_and_separate_ones_one_bit() {
        let same: Vec<(f64, bool)> = (0..100).map(|i| (i as f64 / 99.0, i >= 50)).collect();
        let m = ActionInformation::measure(&same, &same).expect("measured");
        assert!(m.bits.abs() < 1e-12);
        assert!((m.accuracy - 0.5).abs() < 1e-12);
        let m =
            ActionInformation::measure(&[(0.9, true); 10], &[(0.1, false); 10]).expect("measured");
        assert!((m.bits - 1.0).abs() < 1e-12);
        assert!((m.accuracy - 1.0).abs() < 1e-12);
        let c = [(0.1, false)];
        assert!(ActionInformation::measure(&[], &c).is_none());
        assert!(ActionInformation::measure(&[(f64::NAN, true)], &c).is_none());
        assert!(ActionInformation::measure(&[(1.5, true)], &c).is_none());
    }

    /// A binary channel with equal rates is the symmetric one; the
    /// published rates of Ferrez & Millan 2008 (79.2 %, 83.5 %) give 0.31
    /// bits.
    #[test]
    fn a_binary_channel_of_equal_rates_is_symmetric() {
        assert!((binary_channel_bits(0.8, 0.8) - binary_symmetric_bits(0.8)).abs() < 1e-12);
        assert!((binary_channel_bits(0.792, 0.835) - 0.3068).abs() < 1e-3);
        assert!(binary_channel_bits(0.5, 0.5).abs() < 1e-12);
    }
}
