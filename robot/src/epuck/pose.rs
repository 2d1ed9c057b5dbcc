//! The robot's pose in the arena frame and angle arithmetic.

use std::f64::consts::{PI, TAU};

use serde::{Deserialize, Serialize};

/// Wraps an angle to (-pi, pi], the range of the paper's relative angles
/// (theta_i - theta_t in eq. 6 and 7).
/// Angles already in range are returned unchanged (bit for bit).
pub fn wrap_angle(angle_rad: f64) -> f64 {
    if angle_rad > -PI && angle_rad <= PI {
        return angle_rad;
    }
    let r = angle_rad.rem_euclid(TAU);
    if r > PI { r - TAU } else { r }
}

/// Position and orientation of the robot, the state s = (u, v, theta) of
/// sec. 5.2: metres in the arena frame (origin at the bottom-left corner, x
/// to the right, y up) and the heading measured from +x, counter-clockwise.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose {
    /// Position along x, m.
    pub x_m: f64,
    /// Position along y (up), m.
    pub y_m: f64,
    /// Heading from +x, counter-clockwise, rad.
    pub heading_rad: f64,
}

impl Pose {
    /// A pose from its parts.
    pub fn new(x_m: f64, y_m: f64, heading_rad: f64) -> Self {
        Self {
            x_m,
            y_m,
            heading_rad,
        }
    }

    /// Angle of the point (x, y) relative to the heading, wrapped to
    /// (-pi, pi]: theta_i - theta_t of eq. (6) and (7) of the paper, > 0 when
    /// the point is to the robot's left. 0 - heading (wrapped) if the point
    /// is the robot's position.
    pub fn bearing_to(&self, x_m: f64, y_m: f64) -> f64 {
        let direction = (y_m - self.y_m).atan2(x_m - self.x_m);
        wrap_angle(direction - self.heading_rad)
    }

    /// Euclidean distance from the robot to the point (x, y), m.
    pub fn distance_to(&self, x_m: f64, y_m: f64) -> f64 {
        (x_m - self.x_m).hypot(y_m - self.y_m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_angle_lands_in_minus_pi_exclusive_pi_inclusive() {
        assert_eq!(wrap_angle(PI), PI);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(TAU + 0.5) - 0.5).abs() < 1e-12);
        assert!((wrap_angle(-TAU - 0.5) + 0.5).abs() < 1e-12);
        assert_eq!(wrap_angle(0.0), 0.0);
        assert_eq!(wrap_angle(-1e-300), -1e-300, "in range: unchanged");
        let tiny = wrap_angle(-TAU - 1e-17);
        assert!(tiny > -PI && tiny <= PI && tiny.abs() < 1e-15, "{tiny}");
        for k in -50..50 {
            let w = wrap_angle(k as f64 * 0.37);
            assert!(w > -PI && w <= PI, "{w}");
        }
    }

    #[test]
    fn bearing_is_positive_to_the_left() {
        let p = Pose::new(1.0, 1.0, PI / 2.0); // facing +y
        assert!((p.bearing_to(1.0, 2.0)).abs() < 1e-12, "ahead");
        assert!((p.bearing_to(0.0, 1.0) - PI / 2.0).abs() < 1e-12, "left");
        assert!((p.bearing_to(2.0, 1.0) + PI / 2.0).abs() < 1e-12, "right");
        assert!((p.bearing_to(1.0, 0.0) - PI).abs() < 1e-12, "behind");
        assert!((p.distance_to(4.0, 5.0) - 5.0).abs() < 1e-12);
    }
}
