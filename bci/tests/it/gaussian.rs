//! The self-calibration papers' Gaussian classifier: its densities and
//! confusion matrix equal to what the authors' MATLAB code computes (run
//! in GNU Octave on the same data, values pinned here), two classes told
//! apart, a useless classifier flattened by its confusion correction, the
//! reference's folds, and the same classifier from sums kept up to date.

use errp_bci::{
    ClassMoments, Features, GaussianClassifier, PAPER_FOLDS, PAPER_SHRINK, SoftLabel,
    confusion_matrix, corrected, reference_folds,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// 80 trials of 57 features given by a formula both languages compute
/// alike (rows and columns from 1, as in MATLAB), every fifth and seventh
/// trial an error with a cosine added, soft labels 0.9 / 0.1.
fn formula_data() -> (Features, Vec<SoftLabel>) {
    let (n, d) = (80, 57);
    let error = |i: usize| i.is_multiple_of(5) || i.is_multiple_of(7);
    let x = Features::from_fn(n, d, |r, c| {
        let (i, j) = ((r + 1) as f64, (c + 1) as f64);
        let e = if error(r + 1) { 1.0 } else { 0.0 };
        3.0 * (0.37 * i * j + 1.1 * i + 0.3 * j).sin() + e * 2.0 * (0.5 * j).cos()
    });
    let labels = (1..=n)
        .map(|i| if error(i) { [0.1, 0.9] } else { [0.9, 0.1] })
        .collect();
    (x, labels)
}

fn row(x: &Features, i: usize) -> Vec<f64> {
    x.row(i).iter().copied().collect()
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

#[test]
fn densities_and_confusion_are_the_reference_codes() {
    let (x, labels) = formula_data();
    let model = GaussianClassifier::fit(&x, &labels, PAPER_SHRINK).unwrap();
    // `GaussianUninformativePrior_classifier('shrink', 0.5)` of `lfui`
    // (210e052) with `matlab_tools` (9efc858), GNU Octave 7.3:
    // `c.fit(X, pY); c.logpredict(X(1:3, :), false)` and `c.logpredict(X(1:3, :))`.
    let log_densities = GOLDEN_LOG_DENSITIES;
    let posteriors = GOLDEN_POSTERIORS;
    for i in 0..3 {
        let got = model.log_densities(&row(&x, i)).unwrap();
        let p = model.posterior(&row(&x, i));
        for k in 0..2 {
            assert!(close(got[k], log_densities[i][k], 1e-9), "{i} {k}: {got:?}");
            assert!((p[k] - posteriors[i][k]).abs() < 1e-9, "{i} {k}: {p:?}");
        }
    }
    // The 10-fold split of `cross_validation.m` with `randperm` replaced
    // by the trials in the order 37 i mod 80, `proba_confusion_matrix`,
    // each column normalised.
    let shuffled: Vec<usize> = (0..80).map(|i| i * 37 % 80).collect();
    let folds = reference_folds(&shuffled, PAPER_FOLDS);
    let c = confusion_matrix(&x, &labels, &folds, PAPER_SHRINK).unwrap();
    for k in 0..2 {
        for q in 0..2 {
            assert!((c[k][q] - GOLDEN_CONFUSION[k][q]).abs() < 1e-9, "{c:?}");
        }
    }
}

// Printed by GNU Octave 7.3 (`printf('%.17g')`, kept to 15 digits) running
// the reference code on `formula_data`; errp's agree to about 1e-15
// relative.
const GOLDEN_LOG_DENSITIES: [[f64; 2]; 3] = [
    [-112.778_478_397_26, -118.425_513_984_448],
    [-112.389_318_884_99, -120.661_937_753_968],
    [-113.280_461_833_603, -118.346_661_282_753],
];
const GOLDEN_POSTERIORS: [[f64; 2]; 3] = [
    [0.996_484_443_125_18, 0.003_515_556_874_820_71],
    [0.999_744_649_705_582, 0.000_255_350_294_416_307],
    [0.993_733_178_493_331, 0.006_266_821_506_670_35],
];
const GOLDEN_CONFUSION: [[f64; 2]; 2] = [
    [0.761_725_709_025_743, 0.522_771_643_949_885],
    [0.238_274_290_974_257, 0.477_228_356_050_115],
];

/// `n` trials of `d` features per class, the error class's mean moved by
/// `shift` on every feature, labelled 0.9 / 0.1 as a hypothesis does.
fn gaussian_classes(n: usize, d: usize, shift: f64, seed: u64) -> (Features, Vec<SoftLabel>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let x = Features::from_fn(2 * n, d, |r, _| {
        let z: f64 = StandardNormal.sample(&mut rng);
        z + if r >= n { shift } else { 0.0 }
    });
    let labels = (0..2 * n)
        .map(|r| if r >= n { [0.1, 0.9] } else { [0.9, 0.1] })
        .collect();
    (x, labels)
}

#[test]
fn two_separated_classes_are_told_apart() {
    // Means 0.5 apart on each of 10 features: d' = 1.58, 78 % by the
    // Bayes rule. A classifier that swapped or ignored the classes would
    // be at or below 50 %.
    let (x, labels) = gaussian_classes(200, 10, 0.5, 3);
    let model = GaussianClassifier::fit(&x, &labels, PAPER_SHRINK).unwrap();
    let (test, _) = gaussian_classes(500, 10, 0.5, 4);
    let right = (0..1000)
        .filter(|&i| {
            let p = model.posterior(&row(&test, i));
            assert!((p[0] + p[1] - 1.0).abs() < 1e-12);
            (p[1] > 0.5) == (i >= 500)
        })
        .count();
    let accuracy = right as f64 / 1000.0;
    assert!((0.72..0.84).contains(&accuracy), "{accuracy}");
    // Its confusion matrix, from its own soft labels: about 0.9 x 0.78 +
    // 0.1 x 0.22 = 0.72 of what it predicts correct is labelled correct.
    let shuffled: Vec<usize> = (0..400).map(|i| i * 7 % 400).collect();
    let folds = reference_folds(&shuffled, PAPER_FOLDS);
    let c = confusion_matrix(&x, &labels, &folds, PAPER_SHRINK).unwrap();
    assert!((0.62..0.8).contains(&c[0][0]), "{c:?}");
    assert!((0.62..0.8).contains(&c[1][1]), "{c:?}");
    for q in 0..2 {
        assert!((c[0][q] + c[1][q] - 1.0).abs() < 1e-12);
    }
}

#[test]
fn a_useless_classifier_is_flattened_by_its_confusion_correction() {
    // The same distribution under both labels, a quarter labelled errors:
    // whatever the classifier says of a trial, the corrected posterior is
    // near the label proportions (0.25 x 0.9 + 0.75 x 0.1 = 0.3 error).
    let (x, _) = gaussian_classes(150, 8, 0.0, 5);
    let labels: Vec<SoftLabel> = (0..300)
        .map(|r| if r % 4 == 0 { [0.1, 0.9] } else { [0.9, 0.1] })
        .collect();
    let shuffled: Vec<usize> = (0..300).map(|i| i * 7 % 300).collect();
    let c = confusion_matrix(&x, &labels, &reference_folds(&shuffled, 10), 0.5).unwrap();
    let model = GaussianClassifier::fit(&x, &labels, 0.5).unwrap();
    let (test, _) = gaussian_classes(50, 8, 0.0, 6);
    let mut raw_spread: f64 = 0.0;
    for i in 0..100 {
        let p = model.posterior(&row(&test, i));
        raw_spread = raw_spread.max((p[1] - 0.5).abs());
        let q = corrected(&c, p);
        assert!((q[1] - 0.3).abs() < 0.06, "{p:?} -> {q:?}");
    }
    // Uncorrected, it leans well away from even on some trials.
    assert!(raw_spread > 0.15, "{raw_spread}");
}

#[test]
fn too_few_trials_know_nothing_and_bad_labels_are_refused() {
    let (x, labels) = gaussian_classes(5, 10, 1.0, 7);
    let model = GaussianClassifier::fit(&x, &labels, PAPER_SHRINK).unwrap();
    assert_eq!(model.posterior(&row(&x, 0)), [0.5, 0.5]);
    assert!(model.log_densities(&row(&x, 0)).is_none());
    let (x, mut labels) = gaussian_classes(20, 3, 1.0, 7);
    for l in &mut labels {
        l[1] = 0.0;
    }
    let e = GaussianClassifier::fit(&x, &labels, PAPER_SHRINK)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("the error class has no weight in 40 trials"),
        "{e}"
    );
    let e = GaussianClassifier::fit(&x, &labels, 1.5)
        .unwrap_err()
        .to_string();
    assert!(e.contains("shrink") && e.contains("[0, 1]"), "{e}");
}

#[test]
fn folds_are_cut_as_the_reference_cuts_them() {
    // floor(linspace(1, 80, 11)) = 1 8 16 24 32 40 48 56 64 72 80: ten
    // folds of 8, in the order of `shuffled`.
    let shuffled: Vec<usize> = (0..80).rev().collect();
    let folds = reference_folds(&shuffled, 10);
    for (p, &trial) in shuffled.iter().enumerate() {
        assert_eq!(folds[trial], p / 8);
    }
    // 23 trials: floor(linspace(1, 23, 11)) = 1 3 5 7 9 12 14 16 18 20 23,
    // so the folds hold 3 2 2 2 3 2 2 2 2 3.
    let folds = reference_folds(&(0..23).collect::<Vec<_>>(), 10);
    let sizes: Vec<usize> = (0..10)
        .map(|f| folds.iter().filter(|&&g| g == f).count())
        .collect();
    assert_eq!(sizes, [3, 2, 2, 2, 3, 2, 2, 2, 2, 3]);
    // Fewer trials than folds: one each.
    assert_eq!(reference_folds(&[2, 0, 1], 10), [1, 2, 0]);
}

#[test]
fn sums_kept_up_to_date_give_the_classifier_a_pass_over_the_trials_gives() {
    // EEG-like features (a few uV, means of the same order as the spread),
    // 57 of them, soft labels of a hypothesis; the fold left out by
    // taking its sums away. Log densities equal to 1e-9 relative.
    let (mut x, labels) = gaussian_classes(60, 57, 0.8, 9);
    x.add_scalar_mut(2.0);
    let n = x.nrows();
    let mut all = [ClassMoments::new(57), ClassMoments::new(57)];
    let mut fold = [ClassMoments::new(57), ClassMoments::new(57)];
    let left_out: Vec<usize> = (0..n).filter(|i| i % 10 == 3).collect();
    for i in 0..n {
        for k in 0..2 {
            all[k].add(&row(&x, i), labels[i][k]);
            if left_out.contains(&i) {
                fold[k].add(&row(&x, i), labels[i][k]);
            }
        }
    }
    let kept: Vec<usize> = (0..n).filter(|i| !left_out.contains(i)).collect();
    let mut train = all.clone();
    for k in 0..2 {
        train[k].add_scaled(&fold[k], -1.0);
    }
    let pairs = [
        (
            GaussianClassifier::fit(&x, &labels, PAPER_SHRINK).unwrap(),
            GaussianClassifier::from_moments(&all, n, PAPER_SHRINK).unwrap(),
        ),
        (
            GaussianClassifier::fit_rows(&x, &kept, &labels, PAPER_SHRINK).unwrap(),
            GaussianClassifier::from_moments(&train, kept.len(), PAPER_SHRINK).unwrap(),
        ),
    ];
    for (one_pass, sums) in &pairs {
        for i in 0..n {
            let (a, b) = (
                one_pass.log_densities(&row(&x, i)).unwrap(),
                sums.log_densities(&row(&x, i)).unwrap(),
            );
            for k in 0..2 {
                assert!(close(b[k], a[k], 1e-9), "{i}: {a:?} {b:?}");
            }
        }
    }
    // A wrong sum (the fold's trials counted twice) is far off.
    let mut twice = all.clone();
    twice[1].add_scaled(&fold[1], 1.0);
    let wrong = GaussianClassifier::from_moments(&twice, n, PAPER_SHRINK).unwrap();
    let (a, b) = (
        pairs[0].0.log_densities(&row(&x, 3)).unwrap(),
        wrong.log_densities(&row(&x, 3)).unwrap(),
    );
    assert!(!close(b[1], a[1], 1e-6), "{a:?} {b:?}");
}
