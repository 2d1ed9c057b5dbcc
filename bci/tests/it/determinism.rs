//! The determinism contracts of `errp_bci`: a seed gives the same samples,
//! sessions and decoders every time, and the golden digests below pin the
//! numbers themselves, so that a change that alters them (a new RNG stream,
//! another filter order) shows here first. Update a digest only for a change
//! meant to alter the numbers, and say so in the commit.

use errp_bci::{
    Assessment, AssessmentKind, ContinuousCalibrationParams, ContinuousSetup, EegGenerator,
    ErrorModel, GeneratorParams, Montage, SvmDecoder, Valid, calibrate_continuous,
};

use errp_bci::rng::fnv1a;

use crate::{continuous, decoder};

/// The digest of `value`'s exact `Debug` text.
fn digest(value: &impl std::fmt::Debug) -> u64 {
    fnv1a(format!("{value:?}"))
}

/// One second of the 40-channel EEG of seed 7 with an ErrP at 0.2 s.
#[test]
fn the_generator_gives_the_golden_samples() {
    let mut g = EegGenerator::new(
        &Valid::<GeneratorParams>::default(),
        &Montage::standard(),
        7,
    )
    .unwrap();
    g.schedule(Assessment {
        onset_secs: 0.2,
        kind: AssessmentKind::Error,
    });
    let got = digest(&g.generate(256).data);
    assert_eq!(got, 0x25b5_3aa5_4f0e_e762, "EEG of seed 7: digest {got:#x}");
}

/// The discrete calibration session's features of seed 9.
#[test]
fn the_discrete_session_has_the_golden_features() {
    let (features, labels) = decoder::small_session(9);
    let got = digest(&(features, labels));
    assert_eq!(
        got, 0x475d_ba2f_cc12_b8d7,
        "session of seed 9: digest {got:#x}"
    );
}

/// The continuous decoder calibrated twice on seed 5 is the same decoder,
/// and the golden one: its cross-validated rates, Platt scaling and
/// decision on a fixed input.
#[test]
fn calibration_is_deterministic() {
    let setup = Valid::new(ContinuousSetup {
        calibration: ContinuousCalibrationParams {
            per_class: 40,
            ..ContinuousCalibrationParams::default()
        },
        ..continuous::setup_at(1.0).into_inner()
    })
    .unwrap();
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
    let got = digest(&(a.accuracy, a.platt, a.model.decision(&fixed)));
    assert_eq!(
        got, 0x6ff9_a399_1796_09fa,
        "continuous decoder of seed 5: digest {got:#x}"
    );
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
