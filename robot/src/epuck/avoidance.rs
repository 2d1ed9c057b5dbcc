//! The e-puck's obstacle reflex: a Braitenberg layer under the shared
//! control that reads the eight IR proximity sensors.

use serde::{Deserialize, Serialize};

use crate::epuck::drive::{EpuckParams, Twist, WheelSpeeds};

/// Obstacle avoidance from the proximity sensors, layered under the shared
/// control (a Braitenberg reflex, as classic e-puck controllers do): the
/// closer something is in front, the slower the robot drives and the harder
/// it turns away from the more obstructed side. Sweeps of the paper's empty
/// arena never trigger it: goals are 20 cm from the walls.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AvoidanceParams {
    /// Off: the robot drives into whatever is in front (for tests).
    pub enabled: bool,
    /// Front reading at which the robot starts slowing (~2.5 cm).
    pub react_reading: f64,
    /// Front reading at which forward motion stops (~1 cm).
    pub stop_reading: f64,
    /// Turn rate away from the obstruction at the stop reading (rad/s).
    pub turn_rate_rad_per_s: f64,
}

impl Default for AvoidanceParams {
    fn default() -> Self {
        Self {
            enabled: true,
            react_reading: 300.0,
            stop_reading: 1000.0,
            turn_rate_rad_per_s: 1.5,
        }
    }
}

impl AvoidanceParams {
    /// Blends the reflex into `wheels` given the eight readings ps0..ps7.
    pub fn apply(
        &self,
        readings: &[f64; 8],
        wheels: WheelSpeeds,
        epuck: &EpuckParams,
    ) -> WheelSpeeds {
        if !self.enabled {
            return wheels;
        }
        // ps0, ps1 on the right-front; ps6, ps7 on the left-front.
        let right = readings[0].max(readings[1]);
        let left = readings[7].max(readings[6]);
        let front = right.max(left);
        if front <= self.react_reading {
            return wheels;
        }
        let k = ((front - self.react_reading) / (self.stop_reading - self.react_reading))
            .clamp(0.0, 1.0);
        let twist = wheels.to_twist(epuck);
        let forward = twist.linear_m_per_s.max(0.0) * (1.0 - k);
        let away = if right >= left { 1.0 } else { -1.0 };
        let turn = (1.0 - k) * twist.angular_rad_per_s + k * away * self.turn_rate_rad_per_s;
        Twist {
            linear_m_per_s: forward,
            angular_rad_per_s: turn,
        }
        .to_wheels(epuck)
        .clamp(epuck)
    }
}
