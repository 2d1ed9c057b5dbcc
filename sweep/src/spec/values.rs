//! A sweep's values as its inputs give them: lists and ranges
//! (`start:stop:step`), the accuracy levels, and how a value is written.

use errp_bci::RequestedAccuracy;
use errp_sim::task::format_number;
use errp_sim::{Names, Result, SimError};
use toml::Value;

/// A value as written in the CSV files and labels.
pub fn value_text(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Float(x) => format_number(*x),
        other => other.to_string(),
    }
}

/// The first value that appears twice in `values` (as the CSV writes it).
pub(super) fn repeated(values: &[Value]) -> Option<String> {
    let texts: Vec<String> = values.iter().map(value_text).collect();
    texts
        .iter()
        .enumerate()
        .find(|(i, t)| texts[..*i].contains(t))
        .map(|(_, t)| t.clone())
}

/// Rounds away the binary noise of `a + k * step` (`0.30000000000000004`).
pub(super) fn tidy(x: f64) -> f64 {
    let r = (x * 1e12).round() / 1e12;
    if r == 0.0 { 0.0 } else { r }
}

/// Parses `start:stop:step` (stop included), `a,b,c` or a single value.
/// Numbers stay numbers (integers if every part is one); anything else is a
/// string. `what` names the flag in errors.
pub fn parse_values(text: &str, what: &str) -> Result<Vec<Value>> {
    let bad = |why: &str| SimError::Sweep(format!("{what} {text:?} is invalid: {why}"));
    let text = text.trim();
    if text.is_empty() {
        return Err(bad("no values"));
    }
    let parts: Vec<&str> = text.split(':').map(str::trim).collect();
    if parts.len() == 3 {
        let ints: Option<Vec<i64>> = parts.iter().map(|p| p.parse::<i64>().ok()).collect();
        if let Some([a, b, step]) = ints.as_deref() {
            if *step <= 0 || b < a {
                return Err(bad(
                    "a range start:stop:step needs step > 0 and stop >= start",
                ));
            }
            let n = (i128::from(*b) - i128::from(*a)) / i128::from(*step) + 1;
            if n > 10_000 {
                return Err(bad(&format!("it gives {n} values, more than 10000")));
            }
            return Ok((0..n as i64)
                .map(|k| Value::Integer(a + k * step))
                .collect());
        }
        let nums: Option<Vec<f64>> = parts.iter().map(|p| p.parse::<f64>().ok()).collect();
        let Some([a, b, step]) = nums.as_deref() else {
            return Err(bad(
                "a range start:stop:step takes three numbers, e.g. 0.55:0.95:0.05",
            ));
        };
        if !(a.is_finite() && b.is_finite() && step.is_finite() && *step > 0.0 && b >= a) {
            return Err(bad(
                "a range start:stop:step needs finite numbers, step > 0 and stop >= start",
            ));
        }
        // Counted in floating point: a tiny step gives more values than an
        // integer holds.
        let count = ((b - a) / step + 1e-9).floor() + 1.0;
        if !count.is_finite() || count > 10_000.0 {
            return Err(bad(&format!(
                "it gives {count:.3e} values, more than 10000"
            )));
        }
        let n = count as usize;
        return Ok((0..n)
            .map(|k| Value::Float(tidy(a + k as f64 * step)))
            .collect());
    }
    if parts.len() != 1 {
        return Err(bad("expected start:stop:step, a list a,b,c or one value"));
    }
    text.split(',')
        .map(str::trim)
        .map(|s| {
            if s.is_empty() {
                Err(bad("an empty item in the list"))
            } else if let Ok(i) = s.parse::<i64>() {
                Ok(Value::Integer(i))
            } else if let Ok(x) = s.parse::<f64>() {
                if x.is_finite() {
                    Ok(Value::Float(x))
                } else {
                    Err(bad("values must be finite"))
                }
            } else if s == "true" || s == "false" {
                Ok(Value::Boolean(s == "true"))
            } else {
                Ok(Value::String(s.to_string()))
            }
        })
        .collect()
}

/// Parses the `--accuracy` levels: numbers in (0.5, 1), 1 allowed for the
/// grid's oracle decoder. Errors name the levels as `names` does.
pub fn parse_accuracies(text: &str, names: &Names) -> Result<Vec<f64>> {
    let flag = names.accuracy;
    let values = parse_values(text, flag)?;
    let mut out = Vec::with_capacity(values.len());
    for v in values {
        let a = match v {
            Value::Float(x) => x,
            Value::Integer(i) => i as f64,
            other => {
                return Err(SimError::Sweep(format!(
                    "{flag} {text:?} is invalid: {} is not a number",
                    value_text(&other)
                )));
            }
        };
        // 1 is for the oracle; a grid EEG or e-puck scenario refuses it.
        if RequestedAccuracy::new(a).is_err() {
            return Err(SimError::Sweep(format!(
                "{flag} {text:?} is invalid: {a} is not a mean accuracy in (0.5, 1) \
                 (e.g. 0.55:0.95:0.05)"
            )));
        }
        out.push(a);
    }
    Ok(out)
}
