//! The determinism contracts of `errp_bci`: a seed gives the same samples,
//! sessions and decoders every time, and the golden digests below pin the
//! numbers themselves, so that a change that alters them (a new RNG stream,
//! another filter order) shows here first. Update a digest only for a change
//! meant to alter the numbers, and say so in the commit.

use errp_bci::{
    Assessment, AssessmentKind, ContinuousCalibrationParams, ContinuousSetup, EegGenerator,
    ErrorModel, GeneratorParams, Montage, SvmDecoder, calibrate_continuous,
};

use crate::{continuous, decoder};

/// FNV-1a over the bit patterns of `values`: equal digests, equal bits.
fn digest(values: impl IntoIterator<Item = f64>) -> u64 {
    values.into_iter().fold(0xcbf2_9ce4_8422_2325, |h, v| {
        (h ^ v.to_bits()).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

#[track_caller]
fn assert_digest(what: &str, got: u64, golden: u64) {
    assert_eq!(
        got, golden,
        "{what}: digest {got:#018x}, golden {golden:#018x}"
    );
}

/// One second of the 40-channel EEG of seed 7 with an ErrP at 0.2 s.
#[test]
fn the_generator_gives_the_golden_samples() {
    let mut g = EegGenerator::new(GeneratorParams::default(), &Montage::standard(), 7).unwrap();
    g.schedule(Assessment {
        onset_secs: 0.2,
        kind: AssessmentKind::Error,
    });
    let block = g.generate(256);
    assert_digest(
        "EEG of seed 7",
        digest(block.data.iter().copied()),
        0x2bce_dcc1_4d2c_a7ab,
    );
}

/// The discrete calibration session's features of seed 9.
#[test]
fn the_discrete_session_has_the_golden_features() {
    let (features, labels) = decoder::small_session(9);
    let bits = features
        .iter()
        .copied()
        .chain(labels.iter().map(|&l| f64::from(u8::from(l))));
    assert_digest("session of seed 9", digest(bits), 0x9da1_bc4d_e834_31de);
}

/// The continuous decoder calibrated on seed 5: its cross-validated rates,
/// Platt scaling and decision on a fixed input.
#[test]
fn the_continuous_decoder_is_the_golden_one() {
    let setup = ContinuousSetup {
        calibration: ContinuousCalibrationParams {
            per_class: 40,
            ..ContinuousCalibrationParams::default()
        },
        ..continuous::setup_at(1.0)
    };
    let c = calibrate_continuous(&SvmDecoder::default(), &setup, 5).unwrap();
    let fixed: Vec<f64> = (0..512).map(|k| (k as f64 * 0.37).sin()).collect();
    let values = [
        c.accuracy.correct,
        c.accuracy.error,
        c.platt.a,
        c.platt.b,
        c.model.decision(&fixed),
    ];
    assert_digest(
        "continuous decoder of seed 5",
        digest(values),
        0xe877_07dd_3757_9a60,
    );
}

#[test]
fn calibration_is_deterministic() {
    let setup = ContinuousSetup {
        calibration: ContinuousCalibrationParams {
            per_class: 40,
            ..ContinuousCalibrationParams::default()
        },
        ..continuous::setup_at(1.0)
    };
    let a = calibrate_continuous(&SvmDecoder::default(), &setup, 5).unwrap();
    let b = calibrate_continuous(&SvmDecoder::default(), &setup, 5).unwrap();
    assert_eq!(a.accuracy, b.accuracy);
    assert_eq!(a.platt, b.platt);
    assert_eq!(a.platt, a.model.platt());
    let fixed: Vec<f64> = (0..512).map(|k| (k as f64 * 0.37).sin()).collect();
    assert_eq!(a.model.decision(&fixed), b.model.decision(&fixed));
    for x in continuous::rows(&a.session.features).take(10) {
        assert_eq!(a.model.decision(&x), b.model.decision(&x));
    }
    assert_eq!(a.model.n_features(), 512);
}

#[test]
fn sessions_are_deterministic() {
    let (a, la) = decoder::small_session(9);
    let (b, lb) = decoder::small_session(9);
    assert_eq!(a, b);
    assert_eq!(la, lb);
    let (c, _) = decoder::small_session(10);
    assert_ne!(a, c);
    assert!(la.iter().any(|&l| l) && la.iter().any(|&l| !l));
}
