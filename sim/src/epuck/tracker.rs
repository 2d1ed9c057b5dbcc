//! The overhead camera: the paper tracked the e-puck "visually in real time
//! with a camera located on the ceiling" (sec. 5.1). The tracker samples the
//! true pose at its frame rate with Gaussian noise and holds the last frame
//! in between; the synthetic user and the controller both see this pose.

use errp_robot::{Pose, wrap_angle};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

use crate::error::{Result, SimError};

/// Camera tracker settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrackerParams {
    /// Frames per second.
    pub rate_hz: f64,
    /// Standard deviation of the position error, per axis (m).
    pub position_noise_m: f64,
    /// Standard deviation of the heading error (rad).
    pub heading_noise_rad: f64,
}

impl Default for TrackerParams {
    /// A 30 fps ceiling camera seeing a 2 m arena at ~1 mm per pixel: a few
    /// millimetres and about a degree of noise.
    fn default() -> Self {
        Self {
            rate_hz: 30.0,
            position_noise_m: 0.002,
            heading_noise_rad: 1f64.to_radians(),
        }
    }
}

impl TrackerParams {
    /// Checks the ranges.
    pub fn validate(&self) -> Result<()> {
        let bad = |field: &str, v: f64, expected: &str| {
            Err(SimError::InvalidParameter {
                name: format!("tracker.{field}"),
                value: v.to_string(),
                expected: expected.to_string(),
            })
        };
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0) {
            return bad("rate_hz", self.rate_hz, "a frame rate > 0");
        }
        if !(self.position_noise_m.is_finite() && self.position_noise_m >= 0.0) {
            return bad("position_noise_cm", self.position_noise_m * 100.0, ">= 0");
        }
        if !(self.heading_noise_rad.is_finite() && self.heading_noise_rad >= 0.0) {
            return bad(
                "heading_noise_deg",
                self.heading_noise_rad.to_degrees(),
                ">= 0",
            );
        }
        Ok(())
    }
}

/// The camera tracker of one episode.
#[derive(Debug, Clone)]
pub struct CameraTracker {
    params: TrackerParams,
    rng: ChaCha8Rng,
    next_frame_secs: f64,
    last: Option<Pose>,
}

impl CameraTracker {
    /// A tracker whose noise comes from `rng`.
    pub fn new(params: TrackerParams, rng: ChaCha8Rng) -> Self {
        Self {
            params,
            rng,
            next_frame_secs: 0.0,
            last: None,
        }
    }

    /// The tracked pose at `time_secs` given the true pose: a new noisy frame
    /// if one is due, else the last frame.
    pub fn observe(&mut self, time_secs: f64, truth: &Pose) -> Pose {
        if self.last.is_none() || time_secs + 1e-9 >= self.next_frame_secs {
            let p = &self.params;
            let mut n = || self.rng.sample::<f64, _>(StandardNormal);
            let (dx, dy, dh) = (n(), n(), n());
            self.last = Some(Pose {
                x_m: truth.x_m + p.position_noise_m * dx,
                y_m: truth.y_m + p.position_noise_m * dy,
                heading_rad: wrap_angle(truth.heading_rad + p.heading_noise_rad * dh),
            });
            // Frames on a fixed clock, whatever the caller's step.
            while self.next_frame_secs <= time_secs + 1e-9 {
                self.next_frame_secs += 1.0 / p.rate_hz;
            }
        }
        self.last.expect("a frame was taken")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use errp_bci::rng::labelled;

    #[test]
    fn frames_come_at_the_rate_with_the_stated_noise() {
        let params = TrackerParams::default();
        let mut t = CameraTracker::new(params, labelled(3, "tracker"));
        let truth = Pose {
            x_m: 1.0,
            y_m: 1.0,
            heading_rad: 0.0,
        };
        let mut frames = Vec::new();
        let mut last = None;
        for k in 0..64 * 100 {
            let p = t.observe(k as f64 / 64.0, &truth);
            if last != Some(p) {
                frames.push(p);
            }
            last = Some(p);
        }
        // 100 s at 30 fps.
        assert!((frames.len() as i64 - 3000).abs() <= 2, "{}", frames.len());
        let sd = (frames.iter().map(|p| (p.x_m - 1.0).powi(2)).sum::<f64>() / frames.len() as f64)
            .sqrt();
        assert!((sd - 0.002).abs() < 0.0002, "{sd}");
    }
}
