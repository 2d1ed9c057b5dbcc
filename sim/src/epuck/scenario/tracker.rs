//! The ceiling camera of a scenario's `[tracker]` table, checked and in SI
//! units.

use std::path::Path;

use crate::epuck::schema::TrackerFile;
use crate::epuck::tracker::TrackerParams;
use crate::error::{Result, SimError};
use crate::scenario_file::field_error;

/// The ceiling camera of a `[tracker]` table, on the defaults.
pub(super) fn tracker_params(t: Option<&TrackerFile>, path: &Path) -> Result<TrackerParams> {
    let bad =
        |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
    let mut tracker = TrackerParams::default();
    if let Some(t) = t {
        if let Some(v) = t.rate_hz {
            if !(v.is_finite() && (1.0..=MAX_TRACKER_HZ).contains(&v)) {
                return Err(bad(
                    "tracker.rate_hz",
                    v.to_string(),
                    &format!("a frame rate from 1 to {MAX_TRACKER_HZ} Hz (default 30)"),
                ));
            }
            tracker.rate_hz = v;
        }
        if let Some(v) = t.position_noise_cm {
            if !(v.is_finite() && (0.0..=50.0).contains(&v)) {
                return Err(bad(
                    "tracker.position_noise_cm",
                    v.to_string(),
                    "a standard deviation from 0 to 50 cm (default 0.2)",
                ));
            }
            tracker.position_noise_m = v / 100.0;
        }
        if let Some(v) = t.heading_noise_deg {
            if !(v.is_finite() && (0.0..=180.0).contains(&v)) {
                return Err(bad(
                    "tracker.heading_noise_deg",
                    v.to_string(),
                    "a standard deviation from 0 to 180 degrees (default 1)",
                ));
            }
            tracker.heading_noise_rad = v.to_radians();
        }
    }
    tracker
        .validate()
        .map_err(|e| SimError::Scenario(format!("{}: {e}", path.display())))?;
    Ok(tracker)
}

/// The fastest overhead camera, frames per second.
pub const MAX_TRACKER_HZ: f64 = 1000.0;
