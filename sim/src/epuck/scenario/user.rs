//! The synthetic user of a scenario's `[user]` table: how it judges the
//! robot (field of view, latency, re-elicitation), checked and in SI units.

use std::path::Path;

use crate::epuck::schema::UserFile;
use crate::epuck::user::UserParams;
use crate::error::{Result, SimError};
use crate::scenario_file::field_error;

/// The longest reaction latency of the synthetic user, ms.
pub const MAX_REACTION_LATENCY_MS: f64 = 2000.0;

/// The longest time before a persisting error elicits another ErrP, s.
pub const MAX_REELICIT_SECS: f64 = 60.0;

/// The synthetic user of a `[user]` table: field of view, reaction latency,
/// re-elicitation, on the defaults.
pub(super) fn user_params(u: &UserFile, path: &Path) -> Result<UserParams> {
    let bad =
        |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
    let mut user = UserParams::default();
    if let Some(v) = u.fov_deg {
        user.fov_rad = v.to_radians();
    }
    if let Some(v) = u.reaction_latency_ms {
        if !(v.is_finite() && (0.0..=MAX_REACTION_LATENCY_MS).contains(&v)) {
            return Err(bad(
                "user.reaction_latency_ms",
                v.to_string(),
                &format!(
                    "a delay from 0 to {MAX_REACTION_LATENCY_MS} ms (default {})",
                    user.reaction_latency_secs * 1000.0
                ),
            ));
        }
        user.reaction_latency_secs = v / 1000.0;
    }
    if let Some(v) = u.reelicit_secs {
        if !(v.is_finite() && (0.5..=MAX_REELICIT_SECS).contains(&v)) {
            return Err(bad(
                "user.reelicit_secs",
                v.to_string(),
                &format!(
                    "a time from 0.5 s (an ErrP lasts about that long) to \
                     {MAX_REELICIT_SECS} s (default {})",
                    user.reelicit_secs
                ),
            ));
        }
        user.reelicit_secs = v;
    }
    user.validate()
        .map_err(|e| SimError::Scenario(format!("{}: {e}", path.display())))?;
    Ok(user)
}
