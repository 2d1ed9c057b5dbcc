//! The e-puck: its constants, differential-drive kinematics and motor noise.
//!
//! A differential drive has no lateral velocity by construction: the two
//! wheels only push along the heading, so a [`Twist`] has a linear and an
//! angular part and nothing sideways (the non-holonomic constraint the
//! paper's potentials ignore, sec. 5.2).

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::epuck::pose::{Pose, wrap_angle};
use crate::error::{Result, check};

/// Physical constants of the e-puck (Mondada et al. 2009; GCtronic e-puck
/// documentation, <https://www.gctronic.com/doc/index.php/E-Puck>; e-puck.org
/// "Mechanics of the e-puck").
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EpuckParams {
    /// Wheel diameter, m: "about 41 mm" (e-puck.org mechanics; GCtronic).
    pub wheel_diameter_m: f64,
    /// Distance between the wheels, m: "about 53 mm" (e-puck.org mechanics;
    /// GCtronic).
    pub axle_length_m: f64,
    /// Motor steps per wheel revolution: 20-step steppers with a 50:1 gear,
    /// 1000 (GCtronic).
    pub steps_per_turn: u32,
    /// Top motor speed, steps/s: 1000, one wheel revolution per second
    /// (GCtronic), hence a top speed of pi x 0.041 = 0.1288 m/s.
    pub max_steps_per_sec: f64,
    /// Body diameter, m: 7.4 cm (GCtronic); used by the physics, not here.
    pub body_diameter_m: f64,
    /// Mass, kg: 150 g (GCtronic); used by the physics, not here.
    pub mass_kg: f64,
    /// Relative motor noise n: each wheel's speed is multiplied by a factor
    /// drawn from U[1 - n, 1 + n], as the Enki simulator does for its
    /// differential-wheeled robots (`DifferentialWheeled::step`, 0.05 for the
    /// e-puck). In [0, 1).
    pub wheel_speed_noise: f64,
}

impl Default for EpuckParams {
    fn default() -> Self {
        Self {
            wheel_diameter_m: 0.041,
            axle_length_m: 0.053,
            steps_per_turn: 1000,
            max_steps_per_sec: 1000.0,
            body_diameter_m: 0.074,
            mass_kg: 0.15,
            wheel_speed_noise: 0.05,
        }
    }
}

impl EpuckParams {
    /// Checks every field; messages name the field and the accepted range.
    pub fn validate(&self) -> Result<()> {
        let positive = |name: &'static str, v: f64| {
            check(v.is_finite() && v > 0.0, name, v, "a finite number > 0")
        };
        positive("wheel_diameter_m", self.wheel_diameter_m)?;
        positive("axle_length_m", self.axle_length_m)?;
        positive("max_steps_per_sec", self.max_steps_per_sec)?;
        positive("body_diameter_m", self.body_diameter_m)?;
        positive("mass_kg", self.mass_kg)?;
        check(
            self.steps_per_turn >= 1,
            "steps_per_turn",
            self.steps_per_turn,
            "at least 1",
        )?;
        let n = self.wheel_speed_noise;
        check(
            n.is_finite() && (0.0..1.0).contains(&n),
            "wheel_speed_noise",
            n,
            "a fraction in [0, 1)",
        )
    }

    /// Top wheel (and straight-line) speed, m/s: revolutions per second times
    /// the wheel's circumference.
    pub fn max_speed_m_per_s(&self) -> f64 {
        self.max_steps_per_sec / f64::from(self.steps_per_turn)
            * std::f64::consts::PI
            * self.wheel_diameter_m
    }
}

/// Ground speeds of the two wheels, m/s (> 0 forwards).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct WheelSpeeds {
    /// Left wheel, m/s.
    pub left_m_per_s: f64,
    /// Right wheel, m/s.
    pub right_m_per_s: f64,
}

impl WheelSpeeds {
    /// Both wheels still.
    pub const ZERO: Self = Self {
        left_m_per_s: 0.0,
        right_m_per_s: 0.0,
    };

    /// Limits both wheels to the top speed, scaling them together so that
    /// their ratio (hence the curvature of the path) is kept.
    pub fn clamp(&self, params: &EpuckParams) -> Self {
        let top = params.max_speed_m_per_s();
        let fastest = self.left_m_per_s.abs().max(self.right_m_per_s.abs());
        if fastest <= top {
            return *self;
        }
        let k = top / fastest;
        Self {
            left_m_per_s: self.left_m_per_s * k,
            right_m_per_s: self.right_m_per_s * k,
        }
    }

    /// Differential-drive forward kinematics: v = (l + r) / 2,
    /// w = (r - l) / axle. There is no lateral term.
    pub fn to_twist(&self, params: &EpuckParams) -> Twist {
        Twist {
            linear_m_per_s: 0.5 * (self.left_m_per_s + self.right_m_per_s),
            angular_rad_per_s: (self.right_m_per_s - self.left_m_per_s) / params.axle_length_m,
        }
    }

    /// The speeds the motors actually deliver: each wheel's speed times an
    /// independent factor from U[1 - n, 1 + n], n = `wheel_speed_noise`
    /// (Enki's motor noise). Draws two numbers from `rng` whatever n is.
    pub fn apply_noise(&self, params: &EpuckParams, rng: &mut impl Rng) -> Self {
        let n = params.wheel_speed_noise;
        let mut factor = || 1.0 + n * (2.0 * rng.random::<f64>() - 1.0);
        let left = factor();
        let right = factor();
        Self {
            left_m_per_s: self.left_m_per_s * left,
            right_m_per_s: self.right_m_per_s * right,
        }
    }
}

/// Body velocity of a differential drive: forward and angular speed only;
/// the lateral velocity is zero by construction.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Twist {
    /// Speed along the heading, m/s.
    pub linear_m_per_s: f64,
    /// Rate of change of the heading, rad/s (> 0 counter-clockwise).
    pub angular_rad_per_s: f64,
}

impl Twist {
    /// Differential-drive inverse kinematics: l = v - w axle / 2,
    /// r = v + w axle / 2 (not clamped: see [`WheelSpeeds::clamp`]).
    pub fn to_wheels(&self, params: &EpuckParams) -> WheelSpeeds {
        let half = 0.5 * self.angular_rad_per_s * params.axle_length_m;
        WheelSpeeds {
            left_m_per_s: self.linear_m_per_s - half,
            right_m_per_s: self.linear_m_per_s + half,
        }
    }
}

/// Moves `pose` by `twist` held for `dt_secs`, exactly: an arc of radius
/// v / w (a straight segment when w = 0), written as its chord, of length
/// v dt sin(dth / 2) / (dth / 2) along the mean heading theta + dth / 2, which
/// stays accurate for tiny turns. For tests and for callers without a
/// physics engine.
pub fn integrate(pose: &Pose, twist: &Twist, dt_secs: f64) -> Pose {
    let dth = twist.angular_rad_per_s * dt_secs;
    let half = 0.5 * dth;
    let sinc = if half.abs() < 1e-6 {
        1.0 - half * half / 6.0
    } else {
        half.sin() / half
    };
    let chord_m = twist.linear_m_per_s * dt_secs * sinc;
    let mean = pose.heading_rad + half;
    Pose {
        x_m: pose.x_m + chord_m * mean.cos(),
        y_m: pose.y_m + chord_m * mean.sin(),
        heading_rad: wrap_angle(pose.heading_rad + dth),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use std::f64::consts::PI;

    #[test]
    fn top_speed_is_one_wheel_turn_per_second() {
        let p = EpuckParams::default();
        p.validate().unwrap();
        assert!((p.max_speed_m_per_s() - PI * 0.041).abs() < 1e-12);
        assert!((p.max_speed_m_per_s() - 0.1288).abs() < 1e-4);
    }

    #[test]
    fn clamp_keeps_the_ratio() {
        let p = EpuckParams::default();
        let top = p.max_speed_m_per_s();
        let w = WheelSpeeds {
            left_m_per_s: -0.1,
            right_m_per_s: 0.4,
        }
        .clamp(&p);
        assert!((w.right_m_per_s - top).abs() < 1e-12);
        assert!((w.left_m_per_s / w.right_m_per_s + 0.25).abs() < 1e-12);
        let slow = WheelSpeeds {
            left_m_per_s: 0.01,
            right_m_per_s: -0.02,
        };
        assert_eq!(slow.clamp(&p), slow);
    }

    #[test]
    fn twist_and_wheels_are_inverse() {
        let p = EpuckParams::default();
        let t = Twist {
            linear_m_per_s: 0.05,
            angular_rad_per_s: -1.3,
        };
        let back = t.to_wheels(&p).to_twist(&p);
        assert!((back.linear_m_per_s - t.linear_m_per_s).abs() < 1e-12);
        assert!((back.angular_rad_per_s - t.angular_rad_per_s).abs() < 1e-12);
        // Turning in place: opposite wheels, no forward speed.
        let spin = WheelSpeeds {
            left_m_per_s: -0.03,
            right_m_per_s: 0.03,
        }
        .to_twist(&p);
        assert_eq!(spin.linear_m_per_s, 0.0);
        assert!((spin.angular_rad_per_s - 0.06 / 0.053).abs() < 1e-12);
    }

    #[test]
    fn noise_stays_within_its_band_and_is_seeded() {
        let p = EpuckParams::default();
        let w = WheelSpeeds {
            left_m_per_s: 0.1,
            right_m_per_s: -0.05,
        };
        let mut a = ChaCha8Rng::seed_from_u64(1);
        let mut b = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..1000 {
            let n = w.apply_noise(&p, &mut a);
            assert_eq!(n, w.apply_noise(&p, &mut b));
            assert!((n.left_m_per_s / 0.1 - 1.0).abs() <= 0.05 + 1e-12);
            assert!((n.right_m_per_s / -0.05 - 1.0).abs() <= 0.05 + 1e-12);
        }
        let quiet = EpuckParams {
            wheel_speed_noise: 0.0,
            ..p
        };
        assert_eq!(w.apply_noise(&quiet, &mut a), w);
    }

    #[test]
    fn integrate_moves_along_the_heading_only() {
        // No lateral velocity: a straight move goes exactly along the heading,
        // and an arc's chord points at heading + dtheta / 2 (the mean heading),
        // never sideways of the path the wheels roll.
        let p = EpuckParams::default();
        let start = Pose::new(0.5, 0.7, 0.9);
        let straight = WheelSpeeds {
            left_m_per_s: 0.08,
            right_m_per_s: 0.08,
        }
        .to_twist(&p);
        let end = integrate(&start, &straight, 2.0);
        assert!((end.x_m - (0.5 + 0.16 * 0.9f64.cos())).abs() < 1e-12);
        assert!((end.y_m - (0.7 + 0.16 * 0.9f64.sin())).abs() < 1e-12);
        assert_eq!(end.heading_rad, 0.9);
        for (l, r) in [(0.05, 0.09), (0.1, -0.02), (-0.04, -0.06)] {
            let t = WheelSpeeds {
                left_m_per_s: l,
                right_m_per_s: r,
            }
            .to_twist(&p);
            let dt = 0.1;
            let e = integrate(&start, &t, dt);
            let chord = (e.y_m - start.y_m).atan2(e.x_m - start.x_m);
            let mean = start.heading_rad + 0.5 * t.angular_rad_per_s * dt;
            let along = if t.linear_m_per_s >= 0.0 {
                mean
            } else {
                mean + PI
            };
            assert!(wrap_angle(chord - along).abs() < 1e-9, "{l} {r}");
            // The arc length equals |v| dt: chord = 2 R sin(dth / 2).
            let dth = t.angular_rad_per_s * dt;
            let chord_len = e.distance_to(start.x_m, start.y_m);
            let expected = (t.linear_m_per_s * dt).abs() * (dth / 2.0).sin() / (dth / 2.0);
            assert!((chord_len - expected).abs() < 1e-12);
        }
        // Turning in place does not move the centre.
        let spin = Twist {
            linear_m_per_s: 0.0,
            angular_rad_per_s: 1.0,
        };
        let s = integrate(&start, &spin, 0.5);
        assert_eq!((s.x_m, s.y_m), (start.x_m, start.y_m));
        assert!((s.heading_rad - 1.4).abs() < 1e-12);
    }

    #[test]
    fn bad_parameters_name_the_field() {
        for (p, field) in [
            (
                EpuckParams {
                    axle_length_m: 0.0,
                    ..Default::default()
                },
                "axle_length_m",
            ),
            (
                EpuckParams {
                    steps_per_turn: 0,
                    ..Default::default()
                },
                "steps_per_turn",
            ),
            (
                EpuckParams {
                    wheel_speed_noise: 1.0,
                    ..Default::default()
                },
                "wheel_speed_noise",
            ),
        ] {
            let e = p.validate().unwrap_err().to_string();
            assert!(e.contains(field), "{e}");
        }
    }
}
