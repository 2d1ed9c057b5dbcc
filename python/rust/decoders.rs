//! The paper's decoders for `errp.decoders`: their features, fits and
//! decisions on numpy arrays, by the code the closed loop runs.

use errp_bci::{
    Classifier, ContinuousFeatures, EegBlock, EpochWindow, ErrorModel, LdaDecoder, PlattScaling,
    Shrinkage, SvmDecoder, SvmModel, SvmParts, calibrate_features,
};
use nalgebra::DMatrix;
use numpy::ndarray::{Array1, Array2};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{py_err, value_error};

/// The most trials the LDA trains on (its z-scored copy of a 100 000 x 312
/// set is 250 MB).
pub(crate) const MAX_LDA_TRIALS: usize = 100_000;
/// The most features the LDA takes: its PCA decomposes a d x d covariance
/// (4096: 128 MB and about a minute).
pub(crate) const MAX_LDA_FEATURES: usize = 4096;
/// The most trials the SVM trains on: its kernel matrix is n x n (10 000:
/// 800 MB, plus the folds of its Platt scaling).
pub(crate) const MAX_SVM_TRIALS: usize = 10_000;

/// One value per row, for Python.
type Column<'py> = Bound<'py, PyArray1<f64>>;

/// Which of the paper's two feature sets.
#[derive(Clone, Copy)]
enum Set {
    Temporal,
    Continuous,
}

/// Checks a sampling rate the paper's windows can be cut at: a multiple of
/// 64 Hz (the features are at 64 Hz) up to 4096 Hz.
fn check_sfreq(sfreq: f64) -> PyResult<()> {
    if sfreq.is_finite() && (64.0..=4096.0).contains(&sfreq) && sfreq % 64.0 == 0.0 {
        Ok(())
    } else {
        Err(value_error(
            "sfreq",
            sfreq,
            "a multiple of 64 Hz from 64 to 4096 (the features are taken at 64 Hz)",
        ))
    }
}

fn features(
    py: Python<'_>,
    x: &PyReadonlyArray3<'_, f64>,
    sfreq: f64,
    set: Set,
) -> PyResult<Array2<f64>> {
    check_sfreq(sfreq)?;
    let (temporal, continuous) = (EpochWindow::paper(sfreq), ContinuousFeatures::paper(sfreq));
    let (span, what) = match set {
        Set::Temporal => (temporal.span(), "the [200, 800] ms window"),
        Set::Continuous => (continuous.span(), "the 800 ms window"),
    };
    let (n, c, s) = x.as_array().dim();
    if c == 0 {
        return Err(value_error("X", "0 channels", "at least one channel"));
    }
    if s < span {
        return Err(value_error(
            "X",
            format!("{s} samples per epoch"),
            &format!("at least {span} ({what} at {sfreq} Hz, from the onset)"),
        ));
    }
    let data = x.as_slice()?;
    let width = match set {
        Set::Temporal => temporal.n_features(c),
        Set::Continuous => continuous.n_features(c),
    };
    let flat = py.detach(|| {
        let mut flat = Vec::with_capacity(n * width);
        for epoch in data.chunks_exact(c * s) {
            let block = EegBlock {
                n_channels: c,
                n_samples: s,
                data: epoch.to_vec(),
            };
            match set {
                Set::Temporal => temporal.extract_into(&block, 0, &mut flat),
                Set::Continuous => continuous.extract_into(&block, 0, &mut flat),
            }
        }
        flat
    });
    Ok(Array2::from_shape_vec((n, width), flat).expect("one row per epoch"))
}

/// The discrete decoder's features of epochs `(n_epochs, n_channels,
/// n_samples)` that start at the onset: each channel at [200, 800] ms,
/// 64 Hz (39 samples), channel by channel.
#[pyfunction]
pub(crate) fn temporal_features<'py>(
    py: Python<'py>,
    x: PyReadonlyArray3<'py, f64>,
    sfreq: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    Ok(features(py, &x, sfreq, Set::Temporal)?.into_pyarray(py))
}

/// The continuous decoder's features of 800 ms windows `(n_windows,
/// n_channels, n_samples)`: the temporal ones, then the log theta-band PSD
/// (3 to 9 Hz every 0.25 Hz) of each channel.
#[pyfunction]
pub(crate) fn continuous_features<'py>(
    py: Python<'py>,
    x: PyReadonlyArray3<'py, f64>,
    sfreq: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    Ok(features(py, &x, sfreq, Set::Continuous)?.into_pyarray(py))
}

/// A training set as the decoders take it, its size checked.
fn training_set(
    x: &PyReadonlyArray2<'_, f64>,
    y: &PyReadonlyArray1<'_, bool>,
    max_trials: usize,
    max_features: usize,
) -> PyResult<(DMatrix<f64>, Vec<bool>)> {
    let (n, d) = x.as_array().dim();
    if n > max_trials {
        return Err(value_error(
            "X",
            format!("{n} samples"),
            &format!("at most {max_trials}"),
        ));
    }
    if d == 0 || d > max_features {
        return Err(value_error(
            "X",
            format!("{d} features"),
            &format!("from 1 to {max_features}"),
        ));
    }
    let labels = y.as_slice()?.to_vec();
    Ok((DMatrix::from_row_slice(n, d, x.as_slice()?), labels))
}

/// Fits the paper's discrete decoder (z-score, PCA keeping `pca_variance`
/// of the variance, shrinkage LDA; `shrinkage` None is Ledoit-Wolf) on
/// features `x` and labels `y` (True = error). With `platt_folds`, the
/// Platt scaling is fitted as the calibration fits it: on the out-of-fold
/// decisions of a stratified cross-validation drawn from `seed`, the class
/// prior removed. Returns the weights and bias of the decision (z-score
/// and PCA folded in) and the Platt scaling.
#[pyfunction]
#[pyo3(signature = (x, y, pca_variance, shrinkage, platt_folds, seed))]
pub(crate) fn lda_fit<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    y: PyReadonlyArray1<'py, bool>,
    pca_variance: f64,
    shrinkage: Option<f64>,
    platt_folds: Option<usize>,
    seed: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let (x, labels) = training_set(&x, &y, MAX_LDA_TRIALS, MAX_LDA_FEATURES)?;
    let decoder = LdaDecoder {
        pca_variance,
        shrinkage: shrinkage.map_or(Shrinkage::LedoitWolf, Shrinkage::Fixed),
    };
    let (model, platt) = py
        .detach(|| match platt_folds {
            Some(folds) => {
                calibrate_features(&decoder, &x, &labels, folds, seed).map(|c| (c.model, c.platt))
            }
            None => decoder
                .fit(&x, &labels, seed)
                .map(|m| (m, PlattScaling::IDENTITY)),
        })
        .map_err(|e| py_err(e.into()))?;
    let d = PyDict::new(py);
    d.set_item(
        "coef",
        Array1::from(model.weights().to_vec()).into_pyarray(py),
    )?;
    // The bias: the decision of an all-zero trial.
    d.set_item("intercept", model.decision(&vec![0.0; model.n_features()]))?;
    d.set_item("n_components", model.n_components())?;
    d.set_item("shrinkage", model.shrinkage())?;
    d.set_item("platt_a", platt.a)?;
    d.set_item("platt_b", platt.b)?;
    Ok(d)
}

/// Fits the continuous decoder's RBF-kernel SVM (z-scored features;
/// `gamma` None is 1 / n_features) on `x` and labels `y` (True = error),
/// with libsvm's Platt scaling on an internal 5-fold cross-validation drawn
/// from `seed`. Returns the model's parts.
#[pyfunction]
#[pyo3(signature = (x, y, c, gamma, tolerance, seed))]
pub(crate) fn svm_fit<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    y: PyReadonlyArray1<'py, bool>,
    c: f64,
    gamma: Option<f64>,
    tolerance: f64,
    seed: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let (x, labels) = training_set(&x, &y, MAX_SVM_TRIALS, usize::MAX)?;
    let decoder = SvmDecoder {
        c,
        gamma,
        tolerance,
    };
    let model = py
        .detach(|| decoder.fit(&x, &labels, seed))
        .map_err(|e| py_err(e.into()))?;
    let n_support = model.n_support();
    let d = PyDict::new(py);
    d.set_item(
        "mean",
        Array1::from(model.feature_means().to_vec()).into_pyarray(py),
    )?;
    d.set_item(
        "inv_sd",
        Array1::from(model.feature_inv_sds().to_vec()).into_pyarray(py),
    )?;
    d.set_item("gamma", model.gamma())?;
    d.set_item(
        "support",
        Array2::from_shape_vec((n_support, x.ncols()), model.support_vectors().to_vec())
            .expect("n_support x n_features")
            .into_pyarray(py),
    )?;
    d.set_item(
        "dual_coef",
        Array1::from(model.dual_coefficients().to_vec()).into_pyarray(py),
    )?;
    d.set_item("intercept", model.bias())?;
    d.set_item("platt_a", model.platt().a)?;
    d.set_item("platt_b", model.platt().b)?;
    d.set_item("n_iter", model.iterations())?;
    Ok(d)
}

/// The SVM's decision (`>= 0`: error) and Platt-scaled p(error) of each row
/// of `x`, by the model rebuilt from its parts.
#[pyfunction]
#[pyo3(signature = (model, x))]
pub(crate) fn svm_decision<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyDict>,
    x: PyReadonlyArray2<'py, f64>,
) -> PyResult<(Column<'py>, Column<'py>)> {
    let item = |k: &str| -> PyResult<Bound<'py, PyAny>> {
        model
            .get_item(k)?
            .ok_or_else(|| value_error("model", format!("no {k:?}"), "the parts svm_fit gives"))
    };
    let vec = |k: &str| -> PyResult<Vec<f64>> {
        Ok(item(k)?
            .extract::<PyReadonlyArray1<'py, f64>>()?
            .as_array()
            .to_vec())
    };
    let support = item("support")?.extract::<PyReadonlyArray2<'py, f32>>()?;
    let parts = SvmParts {
        mean: vec("mean")?,
        inv_sd: vec("inv_sd")?,
        gamma: item("gamma")?.extract()?,
        support: support.as_array().iter().copied().collect(),
        coef: vec("dual_coef")?,
        bias: item("intercept")?.extract()?,
        platt: PlattScaling {
            a: item("platt_a")?.extract()?,
            b: item("platt_b")?.extract()?,
        },
    };
    let m = SvmModel::from_parts(parts).map_err(|e| py_err(e.into()))?;
    let (n, d) = x.as_array().dim();
    if d != m.n_features() {
        return Err(value_error(
            "X",
            format!("{d} features"),
            &format!("the {} the model was fitted on", m.n_features()),
        ));
    }
    let data = x.as_slice()?;
    let (decision, p) = py.detach(|| {
        let decision: Vec<f64> = data.chunks_exact(d).map(|r| m.decision(r)).collect();
        let p = decision.iter().map(|&y| m.platt().p_error(y)).collect();
        (decision, p)
    });
    debug_assert_eq!(decision.len(), n);
    Ok((
        Array1::from(decision).into_pyarray(py),
        Array1::from_vec(p).into_pyarray(py),
    ))
}
