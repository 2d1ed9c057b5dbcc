//! Contract and statistical tests of the EEG generator and the discrete
//! decoder: every classifier obeys the same contract, accuracy targeting lands
//! where asked, the ErrP has the shape of Fig. 1, and shuffled labels give
//! chance.

use errp_bci::{
    CalibrationParams, CalibrationSetup, Classifier, Components, ErrorModel, Features,
    GeneratorParams, LdaDecoder, MeanAccuracy, SessionOptions, SessionParts, Shrinkage, SvmDecoder,
    TargetingParams, Valid, calibrate, calibrate_session, cross_validate, rng::labelled,
    simulate_session, target_accuracy,
};
use rand::seq::SliceRandom;

fn setup_at(ratio: f64) -> Valid<CalibrationSetup> {
    Valid::new(CalibrationSetup::with_ratio(ratio).unwrap()).unwrap()
}

/// The default setup with `n_actions` actions at ErrP-to-noise `ratio`.
pub(crate) fn sized(n_actions: usize, ratio: f64) -> Valid<CalibrationSetup> {
    Valid::new(CalibrationSetup {
        calibration: CalibrationParams {
            n_actions,
            ..CalibrationParams::default()
        },
        ..CalibrationSetup::with_ratio(ratio).unwrap()
    })
    .unwrap()
}

pub(crate) fn small_session(seed: u64) -> (Features, Vec<bool>) {
    let setup = sized(150, 1.0);
    let s = simulate_session(&setup, seed, SessionOptions::default()).unwrap();
    (s.features, s.labels)
}

fn assert_send_sync<T: Send + Sync>() {}

/// The contract every classifier must meet (pyRiemann-style common tests).
fn classifier_contract<C: Classifier>(classifier: C) {
    assert_send_sync::<C>();
    assert_send_sync::<C::Model>();
    let (x, y) = small_session(21);
    let a = classifier.fit(&x, &y, 7).unwrap();
    let b = classifier.fit(&x, &y, 7).unwrap();
    assert_eq!(a.n_features(), 312);
    let mut pairs = Vec::new();
    for i in 0..x.nrows() {
        let row: Vec<f64> = x.row(i).iter().copied().collect();
        let p = a.p_error(&row);
        assert!((0.0..=1.0).contains(&p), "p = {p}");
        assert_eq!(p, b.p_error(&row), "same seed, same model");
        assert_eq!(a.decision(&row), b.decision(&row), "same seed, same model");
        pairs.push((a.decision(&row), p));
    }
    // Decision and p agree: p(error) never decreases with the decision value
    // (the LDA's p is its sigmoid; the SVM's is its Platt scaling, whose 0.5
    // point need not sit exactly at decision 0, as in libsvm).
    pairs.sort_by(|u, v| u.0.total_cmp(&v.0));
    assert!(
        pairs.windows(2).all(|w| w[1].1 >= w[0].1),
        "p(error) increases with the decision"
    );
    // One class only, or mismatched shapes: a clear error, not a panic.
    assert!(classifier.fit(&x, &vec![false; y.len()], 7).is_err());
    assert!(classifier.fit(&x, &y[1..], 7).is_err());
}

#[test]
fn every_classifier_meets_the_contract() {
    classifier_contract(LdaDecoder::default());
    classifier_contract(LdaDecoder {
        pca_variance: 0.99,
        shrinkage: Shrinkage::Fixed(0.2),
    });
    classifier_contract(SvmDecoder::default());
    classifier_contract(SvmDecoder {
        c: 10.0,
        gamma: Some(0.01),
        tolerance: 1e-4,
    });
}

#[test]
fn features_are_linear_in_the_errp_to_noise_ratio() {
    // Targeting relies on: features(r) = features(noise) + r * features(ERP at 1).
    let setup = sized(30, 1.0);
    let part = |c: Components, ratio: f64| {
        let s = Valid::new(setup.at_ratio(ratio).unwrap()).unwrap();
        simulate_session(
            &s,
            4,
            SessionOptions {
                components: c,
                ..SessionOptions::default()
            },
        )
        .unwrap()
        .features
    };
    let noise = part(
        Components {
            erp: false,
            ..Components::default()
        },
        1.0,
    );
    let erp = part(
        Components {
            background: false,
            artifacts: false,
            erp: true,
        },
        1.0,
    );
    let whole = part(Components::default(), 0.7);
    let combined = &noise + &erp * 0.7;
    let worst = (&whole - &combined).abs().max();
    assert!(worst < 1e-6, "largest difference {worst}");
}

#[test]
fn session_parts_give_the_session_and_the_calibration_at_any_ratio() {
    // Sweeps simulate a session once and calibrate every level from it.
    let setup = sized(120, 0.6);
    let parts = SessionParts::simulate(&setup, 8).unwrap();
    let direct = simulate_session(&setup, 8, SessionOptions::default()).unwrap();
    let from_parts = parts.session_at(0.6);
    assert_eq!(from_parts.labels, direct.labels);
    assert_eq!(from_parts.assessments, direct.assessments);
    let worst = (&from_parts.features - &direct.features).abs().max();
    assert!(worst < 1e-6, "largest difference {worst}");
    let lda = LdaDecoder::default();
    let a = calibrate(&lda, &setup, 8, SessionOptions::default()).unwrap();
    let b = calibrate_session(&lda, from_parts, setup.calibration.folds, 8).unwrap();
    assert_eq!(a.accuracy, b.accuracy);
    let x = direct.features.row(0).iter().copied().collect::<Vec<_>>();
    let (da, db) = (a.model.decision(&x), b.model.decision(&x));
    assert!((da - db).abs() < 1e-6 * (1.0 + da.abs()), "{da} {db}");
}

fn lands_within_1_5_points(requested: f64, seed: u64) {
    let decoder = LdaDecoder::default();
    let setup: Valid<CalibrationSetup> = Valid::default();
    let found = target_accuracy(
        MeanAccuracy::new(requested).unwrap(),
        &decoder,
        &setup,
        &TargetingParams::default(),
        seed,
        |_| {},
    )
    .unwrap();
    // The session at the ratio found, simulated from scratch.
    let c = calibrate(
        &decoder,
        &setup_at(found.ratio),
        seed,
        SessionOptions::default(),
    )
    .unwrap();
    let got = c.accuracy.mean();
    assert!(
        (got - requested).abs() <= 0.015,
        "requested {requested}, got {got} at ratio {}",
        found.ratio
    );
    assert!(
        (got - found.accuracy.mean()).abs() < 0.005,
        "search and rerun agree"
    );
    assert!(c.accuracy.n_correct + c.accuracy.n_error == 400);
}

#[test]
fn targeting_lands_at_65_percent() {
    lands_within_1_5_points(0.65, 11);
}

#[test]
fn targeting_lands_at_the_papers_74_38_percent() {
    lands_within_1_5_points(0.7438, 1);
}

#[test]
fn targeting_lands_at_80_percent() {
    lands_within_1_5_points(0.80, 12);
}

#[test]
fn targeting_lands_at_90_percent() {
    lands_within_1_5_points(0.90, 13);
}

#[test]
fn unreachable_accuracy_is_a_clear_error() {
    let setup = sized(60, GeneratorParams::default().errp_to_noise);
    let search = TargetingParams {
        max_ratio: 0.3,
        ..TargetingParams::default()
    };
    let err = target_accuracy(
        MeanAccuracy::new(0.99).unwrap(),
        &LdaDecoder::default(),
        &setup,
        &search,
        1,
        |_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("accuracy") && err.contains("largest"), "{err}");
}

#[test]
fn grand_average_difference_at_fcz_has_the_three_components_of_fig1() {
    let s = simulate_session(
        &setup_at(1.0),
        3,
        SessionOptions {
            grand_average: true,
            ..SessionOptions::default()
        },
    )
    .unwrap();
    let ga = s.grand_average.unwrap();
    let diff = ga.difference();
    let row = |n: &str| ga.channels.iter().position(|c| c == n).unwrap();
    let fcz = row("FCz");
    let extreme = |lo: f64, hi: f64, sign: f64| {
        (0..ga.times_ms.len())
            .filter(|&t| ga.times_ms[t] >= lo && ga.times_ms[t] <= hi)
            .max_by(|&a, &b| (sign * diff[(fcz, a)]).total_cmp(&(sign * diff[(fcz, b)])))
            .map(|t| (ga.times_ms[t], diff[(fcz, t)]))
            .unwrap()
    };
    let (t_n1, v_n1) = extreme(150.0, 300.0, -1.0);
    let (t_p, v_p) = extreme(280.0, 420.0, 1.0);
    let (t_n2, v_n2) = extreme(400.0, 560.0, -1.0);
    // Documented latencies (assets/errp_waveforms.toml): 250, 350, 455 ms.
    assert!(
        (t_n1 - 250.0).abs() <= 30.0 && v_n1 < -1.0,
        "N ~250: {t_n1} ms {v_n1} uV"
    );
    assert!(
        (t_p - 350.0).abs() <= 30.0 && v_p > 2.0,
        "P ~350: {t_p} ms {v_p} uV"
    );
    assert!(
        (t_n2 - 455.0).abs() <= 35.0 && v_n2 < -1.0,
        "N ~455: {t_n2} ms {v_n2} uV"
    );
    // Fronto-central: the positivity is larger at FCz than at Pz and Oz.
    let peak_t = ga.times_ms.iter().position(|&t| t == t_p).unwrap();
    assert!(diff[(fcz, peak_t)] > 2.0 * diff[(row("Oz"), peak_t)].abs());
    assert!(diff[(fcz, peak_t)] > diff[(row("Pz"), peak_t)]);
    // Before the action there is nothing to see.
    let pre = (0..ga.times_ms.len())
        .filter(|&t| ga.times_ms[t] < 0.0)
        .map(|t| diff[(fcz, t)].abs())
        .fold(0.0, f64::max);
    assert!(pre < 0.5 * v_p, "pre-onset {pre} uV");
}

#[test]
fn decoder_trained_on_shuffled_labels_scores_chance() {
    let s = simulate_session(&setup_at(1.0), 5, SessionOptions::default()).unwrap();
    let decoder = LdaDecoder::default();
    let real = cross_validate(&decoder, &s.features, &s.labels, 10, 1).unwrap();
    let mut shuffled = s.labels.clone();
    shuffled.shuffle(&mut labelled(5, "test/shuffle"));
    let chance = cross_validate(&decoder, &s.features, &shuffled, 10, 1).unwrap();
    assert!(real.mean() > 0.7, "real labels: {}", real.mean());
    assert!(
        (chance.mean() - 0.5).abs() < 0.06,
        "shuffled labels: {}",
        chance.mean()
    );
}
