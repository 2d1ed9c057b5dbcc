//! Reading scenario files: the text, TOML parsing with errors that name the
//! file and the field, and dotted-key overrides.

use std::path::Path;

use serde::de::DeserializeOwned;
use toml::Table;

use crate::error::{Result, SimError};

/// The largest scenario file read, in bytes: a scenario is a page of
/// TOML; anything far larger is not one.
pub const MAX_SCENARIO_BYTES: u64 = 1 << 20;

/// The deepest dotted key (`arena.obstacle.center_cm` has three parts) that
/// may be set in a scenario.
pub const MAX_KEY_PARTS: usize = 4;

/// The text of the scenario file at `path` (at most
/// [`MAX_SCENARIO_BYTES`]).
pub fn read_scenario(path: &Path) -> Result<String> {
    use std::io::Read;
    let cannot = |e: &dyn std::fmt::Display| {
        SimError::Scenario(format!("{}: cannot read the scenario: {e}", path.display()))
    };
    let file = crate::files::open_regular(path).map_err(|e| cannot(&e))?;
    let mut bytes = Vec::new();
    file.take(MAX_SCENARIO_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| cannot(&e))?;
    if bytes.len() as u64 > MAX_SCENARIO_BYTES {
        return Err(cannot(&format!(
            "it is over {} KiB; a scenario file is a page of TOML",
            MAX_SCENARIO_BYTES / 1024
        )));
    }
    String::from_utf8(bytes).map_err(|_| cannot(&"it is not UTF-8 text"))
}

/// Scenario text parsed as TOML into `T`; errors name `path`, the line, the
/// field (as a dotted key), the value and what is accepted.
pub fn parse_toml<T: DeserializeOwned>(text: &str, path: &Path) -> Result<T> {
    toml::from_str(text).map_err(|e| toml_error(path, Some(text), &e))
}

/// A scenario as a TOML table (a file's, with values set from the command
/// line or a sweep) into `T`. Errors name the field but no line: the table
/// is not the file as written.
pub fn table_into<T: DeserializeOwned>(table: &Table, path: &Path) -> Result<T> {
    table
        .clone()
        .try_into()
        .map_err(|e| toml_error(path, None, &e))
}

/// A TOML error of the scenario at `path` (`text`: the file as written, for
/// the line number) in the words of the scenario: the dotted field, its
/// value and what is accepted, not serde's Rust types.
fn toml_error(path: &Path, text: Option<&str>, e: &toml::de::Error) -> SimError {
    // Without its input, toml names the key path (`in `control.tau``)
    // instead of quoting the line.
    let mut bare = e.clone();
    bare.set_input(None);
    let shown = bare.to_string();
    let shown = shown.trim_end();
    let (message, key) = match shown.rsplit_once("\nin `") {
        Some((m, k)) => (m.trim_end(), Some(k.trim_end_matches('`'))),
        None => (shown, None),
    };
    let line = text.zip(e.span()).map(|(t, s)| {
        t.as_bytes()[..s.start.min(t.len())]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1
    });
    let at = match line {
        Some(l) => format!("{} line {l}", path.display()),
        None => path.display().to_string(),
    };
    let message = plain_types(message);
    // A syntax error: toml's own text, with the line quoted.
    if key.is_none()
        && !message.starts_with("unknown field")
        && !message.starts_with("missing field")
    {
        if text.is_some() && e.span().is_some() {
            return SimError::Scenario(format!("{}: {}", path.display(), e.to_string().trim_end()));
        }
        return SimError::Scenario(format!("{at}: {message}"));
    }
    let within = |name: &str| match key {
        Some(k) => format!("{k}.{name}"),
        None => name.to_string(),
    };
    if let Some(rest) = message.strip_prefix("unknown field `")
        && let Some((name, expected)) = rest.split_once('`')
    {
        let expected = expected.trim_start_matches(',').trim();
        return SimError::Scenario(format!(
            "{at}: unknown field `{}`; {expected}",
            within(name)
        ));
    }
    if let Some(rest) = message.strip_prefix("missing field `")
        && let Some((name, _)) = rest.split_once('`')
    {
        return SimError::Scenario(format!("{at}: missing field `{}`", within(name)));
    }
    let key = key.unwrap_or("?");
    // toml hands a date-time to serde as a table: say what it is.
    let written = text
        .zip(e.span())
        .and_then(|(t, s)| t.get(s))
        .map(str::trim)
        .filter(|v| v.parse::<toml::value::Datetime>().is_ok());
    match value_and_expected(&message) {
        Some((value, expected)) if value == "a table" && written.is_some() => SimError::Field {
            at,
            field: key.into(),
            value: format!("{} (a date-time)", written.unwrap_or_default()),
            expected,
        },
        Some((value, expected)) => SimError::Field {
            at,
            field: key.into(),
            value,
            expected,
        },
        None => SimError::Scenario(format!("{at}: field `{key}`: {message}")),
    }
}

/// serde's Rust type names in words.
fn plain_types(message: &str) -> String {
    let mut m = message.to_string();
    for (rust, words) in [
        ("expected usize", "expected a whole number >= 0"),
        ("expected u64", "expected a whole number >= 0"),
        ("expected u32", "expected a whole number >= 0"),
        ("expected i64", "expected a whole number"),
        ("expected f64", "expected a number"),
        ("expected a borrowed string", "expected a string"),
        ("expected a sequence", "expected an array"),
    ] {
        if let Some(rest) = m.strip_suffix(rust) {
            m = format!("{rest}{words}");
        }
    }
    m
}

/// The value and the expectation of serde's "invalid type: X, expected Y"
/// and "invalid value: X, expected Y" messages.
fn value_and_expected(message: &str) -> Option<(String, String)> {
    if let Some(rest) = message.strip_prefix("invalid length ") {
        let (n, expected) = rest.split_once(", expected ")?;
        return Some((format!("an array of {n}"), expected.to_string()));
    }
    let rest = message
        .strip_prefix("invalid type: ")
        .or_else(|| message.strip_prefix("invalid value: "))?;
    let (unexpected, expected) = rest.rsplit_once(", expected ")?;
    let value = match unexpected {
        "sequence" => "an array".to_string(),
        "map" => "a table".to_string(),
        u => [
            "integer ",
            "floating point ",
            "boolean ",
            "string ",
            "character ",
        ]
        .iter()
        .find_map(|p| u.strip_prefix(p))
        .unwrap_or(u)
        .trim_matches('`')
        .to_string(),
    };
    let expected = if expected.starts_with("struct ") || expected == "a map" {
        "a table".to_string()
    } else {
        expected.to_string()
    };
    Some((value, expected))
}

/// The parts of a dotted scenario field (`control.tau`): 1 to
/// [`MAX_KEY_PARTS`] non-empty ones, the last the field's own name.
pub fn key_parts(key: &str) -> std::result::Result<(Vec<&str>, &str), String> {
    let mut parts: Vec<&str> = key.split('.').collect();
    if parts.len() > MAX_KEY_PARTS || parts.iter().any(|p| p.is_empty()) {
        return Err(format!(
            "`{}` is not a scenario field: a field is a dotted key of 1 to {MAX_KEY_PARTS} \
             non-empty parts (e.g. control.tau)",
            truncate(key, 80)
        ));
    }
    // `split` yields at least one part, and none is empty.
    let last = parts.pop().unwrap_or(key);
    Ok((parts, last))
}

/// Two values `[x, y]`, exactly: an array of any other length is an error
/// (serde's fixed-size arrays ignore extra items).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Pair<T>(pub(crate) [T; 2]);

impl<'de, T: serde::Deserialize<'de>> serde::Deserialize<'de> for Pair<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        // A scenario file is at most 1 MiB, so the array is bounded.
        let items: Vec<T> = Vec::deserialize(d)?;
        let n = items.len();
        <[T; 2]>::try_from(items)
            .map(Pair)
            .map_err(|_| serde::de::Error::invalid_length(n, &"two values [x, y]"))
    }
}

/// A whole number in `[lo, hi]` from a TOML number (an integer, or a float
/// such as `1e3` with no fraction), or the error for `field`, whose range
/// text ends with `note` (e.g. " (default 1000)").
pub(crate) fn whole(
    path: &Path,
    field: &str,
    value: f64,
    lo: u64,
    hi: u64,
    note: &str,
) -> Result<usize> {
    if value.is_finite() && value.fract() == 0.0 && value >= lo as f64 && value <= hi as f64 {
        Ok(value as usize)
    } else {
        Err(field_error(
            path,
            field,
            value.to_string(),
            &format!("a whole number from {lo} to {hi}{note}"),
        ))
    }
}

/// At most `n` characters of `text`, marked when cut.
pub fn truncate(text: &str, n: usize) -> String {
    match text.char_indices().nth(n) {
        Some((i, _)) => format!("{}...", &text[..i]),
        None => text.to_string(),
    }
}

/// The error for a bad `field` of the scenario at `path`.
pub(crate) fn field_error(path: &Path, field: &str, value: String, expected: &str) -> SimError {
    SimError::Field {
        at: path.display().to_string(),
        field: field.into(),
        value: errp_bci::shown(value),
        expected: expected.into(),
    }
}

/// The `[realism]` table of a scenario, checked: the error names the field
/// (`realism.<name>`), its value and the accepted range.
pub(crate) fn checked_realism(
    realism: errp_bci::Realism,
    path: &Path,
) -> Result<errp_bci::Realism> {
    let params = errp_bci::GeneratorParams {
        realism,
        ..errp_bci::GeneratorParams::default()
    };
    match errp_bci::Valid::new(params) {
        Ok(p) => Ok(p.into_inner().realism),
        Err(errp_bci::BciError::InvalidParameter {
            name,
            value,
            expected,
        }) => Err(field_error(path, name, value, &expected)),
        Err(other) => Err(SimError::Scenario(format!(
            "{}: [realism] {other}",
            path.display()
        ))),
    }
}

/// The scenario's `name`, or its file name without the extension.
pub(crate) fn scenario_name(name: Option<String>, path: &Path) -> String {
    name.unwrap_or_else(|| {
        path.file_stem()
            .map_or("scenario".into(), |s| s.to_string_lossy().into())
    })
}

/// A robot parameter error of the scenario at `path`, named as the file
/// spells it: `control.tau` for `tau` under `[control]`.
pub(crate) fn robot_error(path: &Path, table: &str, e: errp_robot::RobotError) -> SimError {
    match e {
        errp_robot::RobotError::InvalidParameter {
            name,
            value,
            expected,
        } => field_error(path, &format!("{table}.{name}"), value, &expected),
        other => SimError::Scenario(format!("{}: [{table}] {other}", path.display())),
    }
}
