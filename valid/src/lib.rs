//! Parse, don't validate: a parameter set is checked once, where it enters
//! (a scenario file, a command-line flag, a Python keyword), and is carried
//! from there as a [`Valid<T>`]. Only [`Valid::new`] makes one, its fields
//! can be read (through `Deref`) but not set, and a changed copy
//! ([`Valid::with`]) is checked again; so a function that takes a
//! `Valid<T>` (a controller, a detector) never checks it again.
//!
//! The parameter structs keep their public fields and their `Default`, for
//! building them; [`Check`] is what makes them valid.

//!
//! ```
//! use errp_valid::{Check, Valid};
//!
//! /// A probability, checked once.
//! #[derive(Debug, Clone, Copy, PartialEq)]
//! struct Rate(f64);
//!
//! impl Check for Rate {
//!     type Error = String;
//!     fn check(&self) -> Result<(), String> {
//!         if (0.0..=1.0).contains(&self.0) {
//!             Ok(())
//!         } else {
//!             Err(format!("rate = {} is invalid: expected 0 to 1", self.0))
//!         }
//!     }
//! }
//!
//! let rate = Valid::new(Rate(0.25)).unwrap();
//! assert_eq!(rate.0, 0.25);
//! assert!(Valid::new(Rate(1.5)).is_err());
//! // A changed copy is checked again.
//! assert!(rate.with(|r| r.0 = -1.0).is_err());
//! ```
#![forbid(unsafe_code)]
#![cfg_attr(not(test), warn(clippy::too_many_lines))]

use std::fmt;
use std::ops::Deref;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A value as an error message shows it: as `Display` gives it, but a
/// number whose plain form is long (`1e300` would print 301 digits, `1e-9`
/// eight zeros) in exponent form, as a user writes it. Integers
/// with more significant digits than a float holds stay whole.
pub fn shown(value: impl fmt::Display) -> String {
    let text = value.to_string();
    // A float's plain form has at most 17 significant digits; a longer
    // integer (a seed) is shown whole.
    let digits: String = text.chars().filter(char::is_ascii_digit).collect();
    let significant = digits.trim_start_matches('0').trim_end_matches('0').len();
    match text.parse::<f64>() {
        Ok(x)
            if x.is_finite()
                && significant <= 17
                && (x.abs() >= 1e16 || (x != 0.0 && x.abs() < 1e-4)) =>
        {
            format!("{x:e}")
        }
        _ => text,
    }
}

/// A parameter set that knows its own rules.
pub trait Check {
    /// What a broken rule is reported as (naming the field, the value and
    /// the accepted range).
    type Error;

    /// `Ok` if every field is within its rules.
    fn check(&self) -> Result<(), Self::Error>;
}

/// A `T` that passed [`Check::check`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Valid<T>(T);

impl<T: Check> Valid<T> {
    /// `value`, if it passes its checks.
    pub fn new(value: T) -> Result<Self, T::Error> {
        value.check()?;
        Ok(Self(value))
    }

    /// A copy with `change` made, checked again.
    pub fn with(&self, change: impl FnOnce(&mut T)) -> Result<Self, T::Error>
    where
        T: Clone,
    {
        let mut value = self.0.clone();
        change(&mut value);
        Self::new(value)
    }
}

impl<T> Valid<T> {
    /// A part of the checked value whose rules the value's own checks
    /// include (its [`Check::check`] checks the part), so the part needs no
    /// check of its own: `f` must only take the value apart.
    pub fn part<U>(&self, f: impl FnOnce(&T) -> U) -> Valid<U> {
        Valid(f(&self.0))
    }

    /// The checked value.
    pub fn get(&self) -> &T {
        &self.0
    }

    /// The value, to change and check again.
    pub fn into_inner(self) -> T {
        self.0
    }
}

impl<T> Deref for Valid<T> {
    type Target = T;

    fn deref(&self) -> &T {
        &self.0
    }
}

/// The defaults, which must pass their own checks (each crate's tests say
/// they do; a default that did not would be a bug, and panics here).
impl<T: Check + Default> Default for Valid<T>
where
    T::Error: fmt::Debug,
{
    fn default() -> Self {
        match Self::new(T::default()) {
            Ok(v) => v,
            Err(e) => panic!("the defaults break their own rules: {e:?}"),
        }
    }
}

impl<T: Serialize> Serialize for Valid<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.serialize(s)
    }
}

/// Read as a `T`, then checked: a file cannot hold an unchecked value.
impl<'de, T> Deserialize<'de> for Valid<T>
where
    T: Deserialize<'de> + Check,
    T::Error: fmt::Display,
{
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Self::new(T::deserialize(d)?).map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_shown_as_written() {
        assert_eq!(shown(1e300), "1e300");
        assert_eq!(shown(-2.5e-300), "-2.5e-300");
        assert_eq!(shown(0.3), "0.3");
        assert_eq!(shown(1e-9), "1e-9");
        assert_eq!(shown(0.001), "0.001");
        assert_eq!(shown(12345.0), "12345");
        assert_eq!(shown(u64::MAX), "18446744073709551615");
        assert_eq!(shown(1e20), "1e20");
        assert_eq!(shown("box"), "box");
        assert_eq!(shown(f64::NAN), "NaN");
    }

    #[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
    struct Gain {
        k: f64,
    }

    impl Check for Gain {
        type Error = String;
        fn check(&self) -> Result<(), String> {
            if (0.0..=1.0).contains(&self.k) {
                Ok(())
            } else {
                Err(format!("k: {} is out of range, expected 0 to 1", self.k))
            }
        }
    }

    #[test]
    fn only_checked_values_are_valid() {
        let v = Valid::new(Gain { k: 0.5 }).unwrap();
        assert_eq!(v.k, 0.5);
        assert_eq!(
            Valid::new(Gain { k: 2.0 }).unwrap_err(),
            "k: 2 is out of range, expected 0 to 1"
        );
        // A changed copy is checked again; the original is unchanged.
        assert!(v.with(|g| g.k = 3.0).is_err());
        assert_eq!(v.with(|g| g.k = 1.0).unwrap().k, 1.0);
        assert_eq!(v.k, 0.5);
        assert_eq!(Valid::<Gain>::default().k, 0.0);
    }

    #[test]
    fn a_file_cannot_hold_an_unchecked_value() {
        let v: Valid<Gain> = serde_json::from_str(r#"{"k": 0.25}"#).unwrap();
        assert_eq!(serde_json::to_string(&v).unwrap(), r#"{"k":0.25}"#);
        let e = serde_json::from_str::<Valid<Gain>>(r#"{"k": 7}"#).unwrap_err();
        assert!(e.to_string().contains("k: 7 is out of range"), "{e}");
    }
}
