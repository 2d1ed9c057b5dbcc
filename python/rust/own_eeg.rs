//! A person's own EEG given from Python (`GridTask(eeg=...)`): the
//! channels, data, rate and events the Python layer took from an MNE
//! object, with its digest and the `[eeg]` options, as the scenario's
//! own EEG.

use std::path::Path;

use errp_bci::{Assessment, AssessmentKind, EegBlock, OwnEeg};
use errp_sim::TaskKind;
use errp_sim::own_eeg::{FileDigest, OwnEegSpec, SuppliedOwnEeg};
use numpy::PyReadonlyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::toml_value;

/// The most samples own EEG given from Python may hold (2^27, 1 GiB of
/// float64, as the largest EDF file read).
const MAX_SAMPLES: usize = 1 << 27;

fn item<'py>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<Bound<'py, PyAny>> {
    d.get_item(key)?
        .ok_or_else(|| PyValueError::new_err(format!("eeg: no {key:?}")))
}

/// The own EEG in `eeg` (keys `ch_names`, `data` `(n_channels,
/// n_samples)` in uV, `sfreq`, `onsets` s, `errors` (true for an error
/// event), `name`, `bytes`, `sha256`, `options`), checked and matched to the
/// montage, for the scenario of `task` at `who`.
pub(crate) fn supplied_own_eeg(
    eeg: &Bound<'_, PyDict>,
    who: &Path,
    task: TaskKind,
) -> PyResult<OwnEegSpec> {
    let names: Vec<String> = item(eeg, "ch_names")?.extract()?;
    let data: PyReadonlyArray2<'_, f64> = item(eeg, "data")?.extract()?;
    let sfreq: f64 = item(eeg, "sfreq")?.extract()?;
    let onsets: Vec<f64> = item(eeg, "onsets")?.extract()?;
    let errors: Vec<bool> = item(eeg, "errors")?.extract()?;
    let digest = FileDigest {
        name: item(eeg, "name")?.extract()?,
        bytes: item(eeg, "bytes")?.extract()?,
        sha256: item(eeg, "sha256")?.extract()?,
    };
    let view = data.as_array();
    let (n_channels, n_samples) = view.dim();
    if n_channels.saturating_mul(n_samples) > MAX_SAMPLES {
        return Err(PyValueError::new_err(format!(
            "eeg: {n_channels} channels x {n_samples} samples; a recording may hold at most \
             {MAX_SAMPLES} values (crop it, or pick the channels the decoder reads)"
        )));
    }
    if onsets.len() != errors.len() {
        return Err(PyValueError::new_err("eeg: one class per event onset"));
    }
    let mut block = EegBlock::zeros(n_channels, n_samples);
    for (ch, row) in view.rows().into_iter().enumerate() {
        for (out, x) in block.channel_mut(ch).iter_mut().zip(row) {
            *out = *x;
        }
    }
    let events = onsets
        .iter()
        .zip(&errors)
        .map(|(&onset_secs, &error)| Assessment {
            onset_secs,
            kind: if error {
                AssessmentKind::Error
            } else {
                AssessmentKind::Correct
            },
        })
        .collect();
    let labels: Vec<&str> = names.iter().map(String::as_str).collect();
    let recording = OwnEeg::new(&labels, &block, sfreq, events)
        .map_err(|e| PyValueError::new_err(format!("eeg: {}: {e}", digest.name)))?;
    let options = match eeg.get_item("options")? {
        Some(o) if !o.is_none() => match toml_value("eeg", &o)? {
            toml::Value::Table(t) => t,
            _ => return Err(PyValueError::new_err("eeg_options: a dict")),
        },
        _ => toml::Table::new(),
    };
    OwnEegSpec::supplied(
        &options,
        SuppliedOwnEeg {
            eeg: recording,
            digest,
        },
        who,
        task,
    )
    .map_err(crate::convert::py_err)
}
