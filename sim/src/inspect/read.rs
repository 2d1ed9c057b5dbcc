//! Decoding an `.rrd` file into the data tables of
//! [`crate::record::data`], with the Rerun crates of the version that
//! writes them.

use std::collections::BTreeMap;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use re_log_encoding::DecoderApp;
use rerun::external::arrow::array::{
    Array, AsArray, BooleanArray, Float64Array, Int64Array, ListArray, StringArray,
};
use rerun::external::arrow::datatypes::DataType;
use rerun::log::{Chunk, LogMsg};

use crate::inspect::{InspectError, frames};
use crate::record::data::{Column, FORMAT, FORMAT_VERSION, Provenance, Table};
use crate::record::paths;

/// The largest recording read (bytes): more than 5000 grid episodes or 200
/// e-puck runs make.
pub const MAX_RECORDING_BYTES: u64 = 16 << 30;

/// The Rerun version whose files this build reads (and writes).
const RERUN_VERSION: [u8; 3] = [0, 36, 3];

/// What a file holds before it is checked as a recording of either task.
pub(crate) struct RawRecording {
    pub(crate) provenance: Option<String>,
    pub(crate) application: Option<String>,
    pub(crate) tables: BTreeMap<String, Table>,
}

/// Reads every message of `path`, keeping the provenance and the data
/// tables. Errors say what is wrong with the file.
pub(crate) fn read_raw(path: &Path) -> Result<RawRecording, InspectError> {
    let bad = |why: String| InspectError::Bad {
        path: path.to_path_buf(),
        why,
    };
    let mut file = crate::open_regular(path).map_err(|e| InspectError::Io {
        path: path.to_path_buf(),
        source: e,
    })?;
    let len = file
        .metadata()
        .map_err(|e| InspectError::Io {
            path: path.to_path_buf(),
            source: e,
        })?
        .len();
    if len == 0 {
        return Err(bad("the file is empty".into()));
    }
    if len > MAX_RECORDING_BYTES {
        return Err(bad(format!(
            "it is {:.1} GB, more than the {} GB a recording of errp can be",
            len as f64 / 1e9,
            MAX_RECORDING_BYTES >> 30
        )));
    }
    let mut head = [0u8; 8];
    let got = read_up_to(&mut file, &mut head).map_err(|e| InspectError::Io {
        path: path.to_path_buf(),
        source: e,
    })?;
    if got < 4 || &head[..4] != b"RRF2" {
        return Err(bad(
            "it is not a Rerun recording (an .rrd file begins with `RRF2`)".into(),
        ));
    }
    if got < 8 {
        return Err(bad("it is truncated: it ends inside its header".into()));
    }
    let version = [head[4], head[5], head[6]];
    if version > RERUN_VERSION {
        return Err(bad(format!(
            "it was written by Rerun {}.{}.{}, newer than the {}.{}.{} that this errp reads; \
             read it with the errp that wrote it",
            version[0],
            version[1],
            version[2],
            RERUN_VERSION[0],
            RERUN_VERSION[1],
            RERUN_VERSION[2]
        )));
    }
    // Every size the file states is checked before the decoder trusts it,
    // and a panic in the decoder is an error about the file.
    let mut file = BufReader::with_capacity(1 << 20, file);
    frames::check(&mut file, len).map_err(&bad)?;
    file.seek(SeekFrom::Start(0))
        .map_err(|e| InspectError::Io {
            path: path.to_path_buf(),
            source: e,
        })?;
    frames::guarded(|| decode(file, len))
        .map_err(|panic| {
            bad(format!(
                "it is corrupt: Rerun's decoder failed on it ({panic})"
            ))
        })?
        .map_err(bad)
}

/// Decodes every message of `file` (`len` bytes), keeping the provenance
/// and the data tables.
fn decode(file: BufReader<std::fs::File>, len: u64) -> Result<RawRecording, String> {
    let mut messages = DecoderApp::decode_lazy(file);
    let mut raw = RawRecording {
        provenance: None,
        application: None,
        tables: BTreeMap::new(),
    };
    for msg in messages.by_ref() {
        let msg = msg.map_err(|e| format!("it is corrupt: {e}"))?;
        match msg {
            LogMsg::SetStoreInfo(info) => {
                if info.info.store_id.is_recording() && raw.application.is_none() {
                    raw.application = Some(info.info.store_id.application_id().to_string());
                }
            }
            LogMsg::ArrowMsg(store, arrow) => {
                if !store.is_recording() {
                    continue;
                }
                let chunk =
                    Chunk::from_arrow_msg(&arrow).map_err(|e| format!("it is corrupt: {e}"))?;
                let entity = chunk.entity_path().to_string();
                if entity == paths::PROVENANCE {
                    raw.provenance = first_text(&chunk);
                } else if entity.starts_with(paths::TABLES) {
                    let table = raw.tables.entry(entity.clone()).or_default();
                    read_chunk(&chunk, table)
                        .map_err(|e| format!("its table {entity} is corrupt: {e}"))?;
                }
            }
            LogMsg::BlueprintActivationCommand(_) => {}
        }
    }
    let read = messages.num_bytes_processed();
    if read < len {
        return Err(format!(
            "it is truncated or corrupt: the last {} of its {len} bytes are not a whole message",
            len - read
        ));
    }
    Ok(raw)
}

/// Reads into `buf` until it is full or the file ends; returns the bytes read.
fn read_up_to(file: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match file.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(got)
}

/// The first string of any text component of `chunk`.
fn first_text(chunk: &Chunk) -> Option<String> {
    let mut components: Vec<_> = chunk.components().iter().collect();
    components.sort_by_key(|(id, _)| id.as_str());
    for (_, column) in components {
        let list: &ListArray = &column.list_array;
        if let Some(s) = list.values().as_string_opt::<i32>()
            && !s.is_empty()
        {
            return Some(s.value(0).to_string());
        }
    }
    None
}

/// Appends the columns of `chunk` to `table`.
fn read_chunk(chunk: &Chunk, table: &mut Table) -> Result<(), String> {
    let rows = chunk.num_rows();
    // In name order, so that a table's columns do not depend on hashing.
    let mut components: Vec<_> = chunk.components().iter().collect();
    components.sort_by_key(|(id, _)| id.as_str());
    for (identifier, column) in components {
        let name = identifier.as_str();
        let list: &ListArray = &column.list_array;
        let values = list.values();
        let offsets = list.value_offsets();
        let widths: Vec<usize> = offsets
            .windows(2)
            .map(|w| (w[1] - w[0]).max(0) as usize)
            .collect();
        if widths.len() != rows {
            return Err(format!(
                "column `{name}` has {} rows, not {rows}",
                widths.len()
            ));
        }
        let start = offsets.first().copied().unwrap_or(0).max(0) as usize;
        let total: usize = widths.iter().sum();
        if start + total > values.len() {
            return Err(format!("column `{name}` is shorter than its offsets"));
        }
        let unit = widths.iter().all(|&w| w == 1);
        let column = match values.data_type() {
            DataType::Float64 => {
                let v: &Float64Array = values.as_primitive();
                let v = v.values()[start..start + total].to_vec();
                if unit {
                    Column::F64(v)
                } else {
                    let w = widths.first().copied().unwrap_or(0);
                    if widths.iter().any(|&x| x != w) {
                        return Err(format!("column `{name}` has rows of different lengths"));
                    }
                    Column::F64Rows(v, w)
                }
            }
            DataType::Int64 if unit => {
                let v: &Int64Array = values.as_primitive();
                Column::I64(v.values()[start..start + total].to_vec())
            }
            DataType::Boolean if unit => {
                let v: &BooleanArray = values.as_boolean();
                Column::Bool((start..start + total).map(|i| v.value(i)).collect())
            }
            DataType::Utf8 if unit => {
                let v: &StringArray = values.as_string();
                Column::Str(
                    (start..start + total)
                        .map(|i| v.value(i).to_string())
                        .collect(),
                )
            }
            other => {
                return Err(format!(
                    "column `{name}` holds {other}, which errp never writes"
                ));
            }
        };
        table.append(name, column)?;
    }
    Ok(())
}

/// Parses and checks the provenance document of `path`.
pub(crate) fn parse_provenance(
    path: &Path,
    raw: &RawRecording,
) -> Result<Provenance, InspectError> {
    let bad = |why: String| InspectError::Bad {
        path: path.to_path_buf(),
        why,
    };
    let Some(text) = &raw.provenance else {
        return Err(bad(match &raw.application {
            Some(app) if app == "errp_calibrate" => {
                "it is a calibration recording (`errp calibrate --save`): grand averages, no \
                 runs to inspect; open it with `rerun`"
                    .to_string()
            }
            Some(app) if app.starts_with("errp") => format!(
                "it is a recording of errp ({app}) made before recordings carried their \
                 provenance and data tables ({})); record it again with this errp",
                paths::PROVENANCE
            ),
            Some(app) => format!(
                "it is a Rerun recording of `{app}`, not of errp (it has no {})",
                paths::PROVENANCE
            ),
            None => format!("it holds no recording of errp (no {})", paths::PROVENANCE),
        }));
    };
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| bad(format!("its provenance is not JSON: {e}")))?;
    if value.get("format").and_then(|v| v.as_str()) != Some(FORMAT) {
        return Err(bad(format!(
            "its {} does not say `\"format\": \"{FORMAT}\"`",
            paths::PROVENANCE
        )));
    }
    let version = value
        .get("format_version")
        .and_then(serde_json::Value::as_u64)
        .unwrap_or(0);
    if version != u64::from(FORMAT_VERSION) {
        return Err(bad(format!(
            "it is recording format {version}{}; this errp reads format {FORMAT_VERSION}",
            if version > u64::from(FORMAT_VERSION) {
                ", from a newer errp"
            } else {
                ""
            }
        )));
    }
    serde_json::from_value(value).map_err(|e| bad(format!("its provenance is incomplete: {e}")))
}
