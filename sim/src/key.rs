//! Stable, versioned keys: the text that says what a cached targeting (on
//! disk) or a shared decoder (in memory) depends on, written out field by
//! field rather than taken from `{:?}`.
//!
//! A key is `KIND/vVERSION` followed by `;name=value` for each field the
//! caller names, in the caller's order. Numbers are written by rule, not
//! by `Display` or `Debug`: a float by its 64 bits (`f:3fe8000000000000`),
//! an integer in decimal, a string quoted; a parameter struct by its serde
//! form, with every float inside it by its bits as well, and its fields
//! sorted by name (whatever order serde_json's features keep). So two values that differ in the 17th digit never
//! share a key, and a change of how floats print changes nothing.
//!
//! What can change a key is a change of what it depends on: a field added,
//! removed or renamed in a parameter struct. That must not happen silently:
//! the tests pin the key of each kind's defaults, so a rename fails them
//! until the kind's version is raised on purpose (which also keeps old
//! cache entries from being read as new ones).

use serde::Serialize;
use serde_json::Value;

/// A key being written.
#[derive(Debug, Clone)]
pub struct StableKey {
    text: String,
}

impl StableKey {
    /// A key of `kind` (e.g. `targeting`) at `version`.
    pub fn new(kind: &str, version: u32) -> Self {
        Self {
            text: format!("{kind}/v{version}"),
        }
    }

    /// A float, by its bits.
    pub fn float(mut self, name: &str, x: f64) -> Self {
        self.push(name, &float_text(x));
        self
    }

    /// An integer.
    pub fn int(mut self, name: &str, n: u64) -> Self {
        self.push(name, &n.to_string());
        self
    }

    /// A word (an enum's name, say), quoted.
    pub fn text(mut self, name: &str, s: &str) -> Self {
        self.push(name, &Value::String(s.to_string()).to_string());
        self
    }

    /// A value with a serde form (a parameter struct, an option, a list):
    /// its fields sorted by name, every float by its bits.
    pub fn value(mut self, name: &str, v: &impl Serialize) -> Self {
        let mut text = String::new();
        match serde_json::to_value(v) {
            Ok(v) => write_canonical(&v, &mut text),
            // Only maps with non-string keys fail; no key holds one.
            Err(e) => text = format!("unserialisable({e})"),
        }
        self.push(name, &text);
        self
    }

    /// The simulated user's realism, unless ideal: an ideal user's key is
    /// the key from before realism existed, so caches stay valid.
    pub fn realism(self, realism: &errp_bci::Realism) -> Self {
        if realism.is_ideal() {
            self
        } else {
            self.value("realism", realism)
        }
    }

    /// The key.
    pub fn finish(self) -> String {
        self.text
    }

    fn push(&mut self, name: &str, value: &str) {
        self.text.push(';');
        self.text.push_str(name);
        self.text.push('=');
        self.text.push_str(value);
    }
}

fn float_text(x: f64) -> String {
    format!("f:{:016x}", x.to_bits())
}

/// `v` as JSON with every float by its bits and object keys sorted.
fn write_canonical(v: &Value, out: &mut String) {
    match v {
        Value::Number(n) if n.is_f64() => {
            out.push_str(&float_text(n.as_f64().unwrap_or(f64::NAN)));
        }
        Value::Array(items) => {
            out.push('[');
            for (i, item) in items.iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                write_canonical(item, out);
            }
            out.push(']');
        }
        Value::Object(map) => {
            let mut fields: Vec<_> = map.iter().collect();
            fields.sort_by(|a, b| a.0.cmp(b.0));
            out.push('{');
            for (i, (k, item)) in fields.into_iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                out.push_str(&Value::String(k.clone()).to_string());
                out.push(':');
                write_canonical(item, out);
            }
            out.push('}');
        }
        other => out.push_str(&other.to_string()),
    }
}

/// The field names of `v`'s serde form, dotted, sorted (with `[]` for
/// the items of a list): what a key holds of `v`, without the values. The
/// tests pin each key's, so that a field renamed, added or removed shows.
#[cfg(test)]
pub(crate) fn shape(v: &impl Serialize) -> Vec<String> {
    fn walk(v: &Value, at: &str, out: &mut Vec<String>) {
        match v {
            Value::Object(map) => {
                for (k, item) in map {
                    let path = if at.is_empty() {
                        k.clone()
                    } else {
                        format!("{at}.{k}")
                    };
                    out.push(path.clone());
                    walk(item, &path, out);
                }
            }
            Value::Array(items) => {
                if let Some(first) = items.first() {
                    walk(first, &format!("{at}[]"), out);
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    if let Ok(v) = serde_json::to_value(v) {
        walk(&v, "", &mut out);
    }
    out.sort();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize)]
    struct Inner {
        name: &'static str,
        gain: f64,
        n: u32,
    }

    #[test]
    fn floats_are_written_by_their_bits_and_fields_in_order() {
        let a = StableKey::new("test", 1)
            .float("x", 0.1)
            .int("seed", 7)
            .text("mode", "bank")
            .value(
                "inner",
                &Inner {
                    name: "a",
                    gain: 2.0,
                    n: 3,
                },
            )
            .value("none", &Option::<f64>::None)
            .finish();
        assert_eq!(
            a,
            "test/v1;x=f:3fb999999999999a;seed=7;mode=\"bank\";\
             inner={\"gain\":f:4000000000000000,\"n\":3,\"name\":\"a\"};none=null"
        );
        // The next float up is another key; -0 is not 0.
        let next = f64::from_bits(0.1f64.to_bits() + 1);
        assert_ne!(
            StableKey::new("t", 1).float("x", 0.1).finish(),
            StableKey::new("t", 1).float("x", next).finish()
        );
        assert_ne!(
            StableKey::new("t", 1).float("x", 0.0).finish(),
            StableKey::new("t", 1).float("x", -0.0).finish()
        );
        assert_ne!(
            StableKey::new("t", 1).finish(),
            StableKey::new("t", 2).finish()
        );
    }
}
