//! The parameters of the continuous strategy and its likelihoods: eq. (6)
//! for turn steps and eq. (7) for linear steps (sec. 5.2 of the paper).

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use errp_valid::Check;

use crate::epuck::drive::EpuckParams;
use crate::epuck::pose::wrap_angle;
use crate::error::{Result, RobotError, check};
use crate::strategy::Strategy;

/// Parameters of the continuous strategy (sec. 5.2) and of the motion
/// (sec. 5.1), as a scenario file's `[control]` table holds them
/// (deserialized straight into this type; missing fields take the defaults,
/// unknown ones are refused). The controller's tuning below the paper's
/// level (alignment, heading gain, goal radius, the robot's constants) and
/// the assumed accuracy are not read from a file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EpuckControlParams {
    /// T_e: p(error) at or above it counts as a detected error; the paper:
    /// 0.8. In (0, 1].
    pub t_e: f64,
    /// k_n of eq. (6), the penalty of goals on the side the robot turns to;
    /// the paper: 0.2. In (0, 1).
    pub k_turn: f64,
    /// k_p of eq. (7), the reward of goals ahead after a correct window; the
    /// paper: 0.01. >= 0.
    pub k_p: f64,
    /// k_n of eq. (7), the penalty of goals ahead after an error; the paper:
    /// 0.7. 1 - k_n N(0; 0, sigma) must stay > 0.
    pub k_n: f64,
    /// sigma of eq. (7), the user's field of view; the paper: 20 deg. The
    /// normal pdf is taken in radians (peak 1.14 for 20 deg).
    pub sigma_deg: f64,
    /// Convergence: probability of the goal the robot is stopped on that
    /// ends the run; the paper: 0.4. In (0, 1).
    pub p_c: f64,
    /// Length of a stop, on a goal or after a detected error, s; the paper:
    /// "for a second". > 0.
    pub stop_secs: f64,
    /// Least length of a stop on a goal, s: the time the user's verdict on
    /// the arrival needs to reach the decoder (0: `stop_secs`, the paper's
    /// literal stop). In [0, 10]. `None`: left to whoever runs the
    /// controller (the testbed derives it from the detector's response
    /// span); the controller itself reads it as 0.
    pub goal_hold_secs: Option<f64>,
    /// After the robot leaves a goal, a detected error within this time is
    /// the user's late verdict on the stop (a veto of that goal), not on the
    /// new motion, s (0: none, the paper read literally). In [0, 10].
    /// `None`: as for `goal_hold_secs`.
    pub veto_window_secs: Option<f64>,
    /// Forward speed while driving, as a fraction of the top speed. In (0, 1].
    pub drive_speed_fraction: f64,
    /// Wheel speed while turning in place (one wheel forwards, one
    /// backwards), as a fraction of the top speed. In (0, 1].
    pub turn_speed_fraction: f64,
    /// A turn ends when the bearing to the target is below this, deg. In
    /// (0, 90).
    #[serde(skip)]
    pub align_tolerance_deg: f64,
    /// Proportional heading correction while driving, rad/s per rad of
    /// bearing. >= 0.
    #[serde(skip)]
    pub heading_gain: f64,
    /// The robot has reached (is "on") a goal within this distance, m. > 0,
    /// and less than half the distance between the two closest goals.
    #[serde(skip)]
    pub goal_radius_m: f64,
    /// The robot's constants (top speed, axle length).
    #[serde(skip)]
    pub epuck: EpuckParams,
    /// How the next goal to head for is chosen after a stop (the paper:
    /// greedy, the most probable goal). Greedy or info gain:
    /// [`Strategy::Thompson`] is grid-only (this controller draws no random
    /// numbers).
    pub strategy: Strategy,
    /// The decoder accuracy the device assumes when it predicts the
    /// decoder's outcomes for [`Strategy::InfoGain`]: the probability of a
    /// detection (p(error) >= T_e) when the user judges the motion wrong, and
    /// of none when the user judges it right. In (0.5, 1]. The device knows
    /// it from the calibration.
    #[serde(skip)]
    pub assumed_accuracy: f64,
}

impl Default for EpuckControlParams {
    fn default() -> Self {
        Self {
            t_e: 0.8,
            k_turn: 0.2,
            k_p: 0.01,
            k_n: 0.7,
            sigma_deg: 20.0,
            p_c: 0.4,
            stop_secs: 1.0,
            goal_hold_secs: None,
            veto_window_secs: None,
            drive_speed_fraction: 0.5,
            turn_speed_fraction: 0.25,
            align_tolerance_deg: 3.0,
            heading_gain: 2.0,
            goal_radius_m: 0.02,
            epuck: EpuckParams::default(),
            strategy: Strategy::Greedy,
            assumed_accuracy: 0.75,
        }
    }
}

/// Checked where a scenario enters; the controller takes it checked.
impl Check for EpuckControlParams {
    type Error = RobotError;

    fn check(&self) -> Result<()> {
        self.validate()
    }
}

impl EpuckControlParams {
    /// Checks every field; messages name the field and the accepted range.
    fn validate(&self) -> Result<()> {
        let check = |ok: bool, name: &'static str, v: f64, range: &str| {
            check(ok && v.is_finite(), name, v, range)
        };
        let open01 = |v: f64| v > 0.0 && v < 1.0;
        let half_open01 = |v: f64| v > 0.0 && v <= 1.0;
        check(half_open01(self.t_e), "t_e", self.t_e, "in (0, 1]")?;
        check(open01(self.k_turn), "k_turn", self.k_turn, "in (0, 1)")?;
        check(self.k_p >= 0.0, "k_p", self.k_p, "a finite number >= 0")?;
        check(self.sigma_deg > 0.0, "sigma_deg", self.sigma_deg, "> 0")?;
        let floor = 1.0 - self.k_n * self.pdf_peak();
        check(
            self.k_n >= 0.0 && floor > 0.0,
            "k_n",
            self.k_n,
            &format!(
                ">= 0 with 1 - k_n N(0; 0, sigma) > 0, i.e. < {} for sigma_deg = {}",
                1.0 / self.pdf_peak(),
                self.sigma_deg
            ),
        )?;
        check(open01(self.p_c), "p_c", self.p_c, "in (0, 1)")?;
        check(
            self.stop_secs > 0.0 && self.stop_secs <= 10.0,
            "stop_secs",
            self.stop_secs,
            "in (0, 10] s (the paper: 1)",
        )?;
        let optional_secs = |name, v: Option<f64>| {
            v.map_or(Ok(()), |v| {
                check((0.0..=10.0).contains(&v), name, v, "a time in [0, 10] s")
            })
        };
        optional_secs("goal_hold_secs", self.goal_hold_secs)?;
        optional_secs("veto_window_secs", self.veto_window_secs)?;
        check(
            half_open01(self.drive_speed_fraction),
            "drive_speed_fraction",
            self.drive_speed_fraction,
            "in (0, 1]",
        )?;
        check(
            half_open01(self.turn_speed_fraction),
            "turn_speed_fraction",
            self.turn_speed_fraction,
            "in (0, 1]",
        )?;
        check(
            self.align_tolerance_deg > 0.0 && self.align_tolerance_deg < 90.0,
            "align_tolerance_deg",
            self.align_tolerance_deg,
            "in (0, 90)",
        )?;
        check(
            self.heading_gain >= 0.0,
            "heading_gain",
            self.heading_gain,
            "a finite number >= 0",
        )?;
        check(
            self.goal_radius_m > 0.0,
            "goal_radius_m",
            self.goal_radius_m,
            "> 0",
        )?;
        if self.strategy == Strategy::Thompson {
            return Err(RobotError::InvalidParameter {
                name: "strategy",
                value: format!("{:?}", self.strategy.name()),
                expected: "\"greedy\" or \"info_gain\": thompson is grid-only (the e-puck \
                           controller draws no random numbers)"
                    .into(),
            });
        }
        check(
            self.assumed_accuracy > 0.5 && self.assumed_accuracy <= 1.0,
            "assumed_accuracy",
            self.assumed_accuracy,
            "in (0.5, 1]",
        )?;
        self.epuck.validate()
    }

    /// sigma of eq. (7) in radians.
    pub fn sigma_rad(&self) -> f64 {
        self.sigma_deg.to_radians()
    }

    /// N(0; 0, sigma), the peak of eq. (7)'s normal pdf (1.1399 for 20 deg).
    pub fn pdf_peak(&self) -> f64 {
        normal_pdf(0.0, self.sigma_rad())
    }
}

/// The normal pdf N(x; 0, sigma).
fn normal_pdf(x: f64, sigma: f64) -> f64 {
    (-0.5 * (x / sigma).powi(2)).exp() / (sigma * (2.0 * PI).sqrt())
}

/// Eq. (6) of the paper, the likelihood of a turn step for one goal: k_n
/// (`k_turn`) if an error is detected (`error`: the detector's verdict, the
/// paper's p(error) >= T_e, which the detector alone compares) while the robot turns
/// anticlockwise (`turn_direction` > 0, the sign of theta_t - theta_{t-1})
/// and the goal is to its left (bearing theta_i - theta_t in (0, pi]), or
/// while it turns clockwise and the goal is to its right (bearing in
/// (-pi, 0]); 1 otherwise, including when the robot is not turning. The
/// paper's "(theta_t - theta_t)" is read as (theta_i - theta_t), as its text
/// says. `bearing_rad` is wrapped here.
pub fn turn_likelihood(
    params: &EpuckControlParams,
    error: bool,
    turn_direction: f64,
    bearing_rad: f64,
) -> f64 {
    let b = wrap_angle(bearing_rad);
    let left = b > 0.0; // (0, pi]; wrapped, so b <= pi
    if error && ((turn_direction > 0.0 && left) || (turn_direction < 0.0 && !left)) {
        params.k_turn
    } else {
        1.0
    }
}

/// Eq. (7) of the paper, the likelihood of a linear step for one goal:
/// 1 + k_p N(bearing; 0, sigma) if no error is detected (`error` false: the
/// paper's p(error) < T_e), 1 - k_n N(bearing; 0, sigma) if one is, with the bearing
/// theta_i - theta_t in radians (N is even, so its sign does not matter).
pub fn linear_likelihood(params: &EpuckControlParams, error: bool, bearing_rad: f64) -> f64 {
    let n = normal_pdf(wrap_angle(bearing_rad), params.sigma_rad());
    if !error {
        1.0 + params.k_p * n
    } else {
        1.0 - params.k_n * n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::epuck::pose::Pose;

    fn params() -> EpuckControlParams {
        EpuckControlParams::default()
    }

    #[test]
    fn eq6_penalises_goals_on_the_side_of_the_turn() {
        let p = params();
        let (err, ok) = (true, false);
        let (acw, cw) = (0.05, -0.05);
        // Anticlockwise: goals to the left, bearing in (0, pi].
        assert_eq!(turn_likelihood(&p, err, acw, 0.5), 0.2);
        assert_eq!(turn_likelihood(&p, err, acw, PI), 0.2);
        assert_eq!(turn_likelihood(&p, err, acw, 0.0), 1.0);
        assert_eq!(turn_likelihood(&p, err, acw, -0.5), 1.0);
        // Clockwise: goals to the right, bearing in (-pi, 0].
        assert_eq!(turn_likelihood(&p, err, cw, -0.5), 0.2);
        assert_eq!(turn_likelihood(&p, err, cw, 0.0), 0.2);
        assert_eq!(turn_likelihood(&p, err, cw, 0.5), 1.0);
        assert_eq!(turn_likelihood(&p, err, cw, -PI), 1.0, "-pi wraps to pi");
        // No detected error, or no turn: no change.
        assert_eq!(turn_likelihood(&p, ok, acw, 0.5), 1.0);
        assert_eq!(turn_likelihood(&p, err, 0.0, 0.5), 1.0);
    }

    #[test]
    fn eq6_typo_is_read_as_the_goal_bearing() {
        // The paper prints (theta_t - theta_t), always 0; read as
        // theta_i - theta_t, the same turn and p(error) treat two goals on
        // opposite sides differently, and the robot's own heading alone
        // decides nothing.
        let p = params();
        let robot = Pose::new(1.0, 1.0, 0.3);
        let left = robot.bearing_to(0.6, 1.8);
        let right = robot.bearing_to(1.8, 0.6);
        assert!(left > 0.0 && right < 0.0);
        assert_eq!(turn_likelihood(&p, true, 0.02, left), 0.2);
        assert_eq!(turn_likelihood(&p, true, 0.02, right), 1.0);
        assert_eq!(turn_likelihood(&p, true, -0.02, left), 1.0);
        assert_eq!(turn_likelihood(&p, true, -0.02, right), 0.2);
    }

    #[test]
    fn eq7_peak_values() {
        let p = params();
        let peak = 1.0 / (20f64.to_radians() * (2.0 * PI).sqrt());
        assert!((p.pdf_peak() - peak).abs() < 1e-12);
        assert!((peak - 1.1429).abs() < 1e-4, "{peak}");
        assert!((linear_likelihood(&p, false, 0.0) - (1.0 + 0.01 * peak)).abs() < 1e-12);
        assert!((linear_likelihood(&p, true, 0.0) - (1.0 - 0.7 * peak)).abs() < 1e-12);
        assert!(linear_likelihood(&p, true, 0.0) > 0.19);
        // Even in the bearing, and flat far from the field of view.
        let b = 0.3;
        assert_eq!(
            linear_likelihood(&p, true, b),
            linear_likelihood(&p, true, -b)
        );
        assert!((linear_likelihood(&p, true, PI) - 1.0).abs() < 1e-8);
        assert!((linear_likelihood(&p, false, 2.0) - 1.0).abs() < 1e-5);
        // One sigma off the heading: N = peak * e^(-1/2).
        let one_sigma = linear_likelihood(&p, true, 20f64.to_radians());
        assert!((one_sigma - (1.0 - 0.7 * peak * (-0.5f64).exp())).abs() < 1e-12);
    }

    #[test]
    fn bad_parameters_name_the_field() {
        let d = EpuckControlParams::default();
        d.validate().unwrap();
        for (p, field) in [
            (
                EpuckControlParams {
                    t_e: 0.0,
                    ..d.clone()
                },
                "t_e",
            ),
            (
                EpuckControlParams {
                    k_turn: 1.0,
                    ..d.clone()
                },
                "k_turn",
            ),
            (
                EpuckControlParams {
                    k_p: -0.1,
                    ..d.clone()
                },
                "k_p",
            ),
            (
                EpuckControlParams {
                    k_n: 0.9,
                    ..d.clone()
                },
                "k_n",
            ),
            (
                EpuckControlParams {
                    sigma_deg: 0.0,
                    ..d.clone()
                },
                "sigma_deg",
            ),
            (
                EpuckControlParams {
                    p_c: 1.0,
                    ..d.clone()
                },
                "p_c",
            ),
            (
                EpuckControlParams {
                    stop_secs: 0.0,
                    ..d.clone()
                },
                "stop_secs",
            ),
            (
                EpuckControlParams {
                    drive_speed_fraction: 1.5,
                    ..d.clone()
                },
                "drive_speed_fraction",
            ),
            (
                EpuckControlParams {
                    turn_speed_fraction: 0.0,
                    ..d.clone()
                },
                "turn_speed_fraction",
            ),
            (
                EpuckControlParams {
                    align_tolerance_deg: 90.0,
                    ..d.clone()
                },
                "align_tolerance_deg",
            ),
            (
                EpuckControlParams {
                    heading_gain: f64::NAN,
                    ..d.clone()
                },
                "heading_gain",
            ),
            (
                EpuckControlParams {
                    goal_radius_m: 0.0,
                    ..d.clone()
                },
                "goal_radius_m",
            ),
            (
                EpuckControlParams {
                    assumed_accuracy: 0.5,
                    ..d.clone()
                },
                "assumed_accuracy",
            ),
            (
                EpuckControlParams {
                    assumed_accuracy: 1.01,
                    ..d.clone()
                },
                "assumed_accuracy",
            ),
            (
                EpuckControlParams {
                    strategy: Strategy::Thompson,
                    ..d.clone()
                },
                "strategy",
            ),
        ] {
            let e = p.validate().unwrap_err().to_string();
            assert!(e.contains(field), "{e}");
        }
        let e = EpuckControlParams {
            strategy: Strategy::Thompson,
            ..d.clone()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("grid-only") && e.contains("greedy") && e.contains("info_gain"),
            "{e}"
        );
        for strategy in [Strategy::Greedy, Strategy::InfoGain] {
            EpuckControlParams {
                strategy,
                ..d.clone()
            }
            .validate()
            .unwrap();
        }
    }
}
