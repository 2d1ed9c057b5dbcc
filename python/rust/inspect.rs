//! `read_recording`: a recording's tidy tables (the ones `errp inspect
//! --csv` writes) as numpy arrays and lists, its provenance as JSON.

use std::path::PathBuf;

use errp_sim::inspect::{InspectError, Recording, csv_tables};
use errp_sim::record::data::Column;
use numpy::IntoPyArray;
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Reads `path`: `{"provenance": JSON text, "task": "epuck" | "grid",
/// "tables": {name: {column: values}}, "order": {name: [columns]}}`,
/// and for the e-puck `"cities"` (name, x, y in cm) and `"arena_cm"`.
#[pyfunction]
pub(crate) fn read_recording<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let rec = py.detach(|| Recording::open(&path)).map_err(|e| match e {
        InspectError::Io { ref source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(e.to_string())
        }
        InspectError::Io { .. } => PyOSError::new_err(e.to_string()),
        InspectError::Bad { .. } => PyValueError::new_err(e.to_string()),
    })?;
    let out = PyDict::new(py);
    let json =
        serde_json::to_string(&rec.provenance).map_err(|e| PyValueError::new_err(e.to_string()))?;
    out.set_item("provenance", json)?;
    out.set_item("task", rec.provenance.task.as_str())?;
    let tables = PyDict::new(py);
    let order = PyDict::new(py);
    for t in csv_tables(&rec) {
        let cols = PyDict::new(py);
        let mut names = Vec::new();
        for (name, c) in t.columns {
            names.push(name);
            match c {
                Column::F64(v) => cols.set_item(name, v.into_pyarray(py))?,
                Column::I64(v) => cols.set_item(name, v.into_pyarray(py))?,
                // Values and a mask of the missing ones: a pandas `Int64`
                // column (`read_recording`).
                Column::OptI64(v) => {
                    let mask: Vec<bool> = v.iter().map(Option::is_none).collect();
                    let values: Vec<i64> = v.into_iter().map(|x| x.unwrap_or(0)).collect();
                    cols.set_item(name, (values.into_pyarray(py), mask.into_pyarray(py)))?
                }
                Column::Bool(v) => cols.set_item(name, v.into_pyarray(py))?,
                Column::Str(v) => cols.set_item(name, v)?,
                Column::F64Rows(v, _) => cols.set_item(name, v.into_pyarray(py))?,
            }
        }
        tables.set_item(t.name, cols)?;
        order.set_item(t.name, names)?;
    }
    out.set_item("tables", tables)?;
    if let errp_sim::inspect::Runs::Epuck { scenario, .. } = &rec.runs {
        let cities: Vec<(String, f64, f64)> = scenario
            .layout
            .goals()
            .iter()
            .map(|g| (g.name.clone(), 100.0 * g.x_m, 100.0 * g.y_m))
            .collect();
        out.set_item("cities", cities)?;
        out.set_item("arena_cm", 100.0 * scenario.arena.size_m)?;
    }
    out.set_item("order", order)?;
    Ok(out)
}
