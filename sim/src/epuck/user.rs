//! The synthetic user of the continuous task: watches the tracked e-puck and
//! judges its motion all the time, as sec. 5.1 of the paper asks its subject
//! to do.
//!
//! Judgements (true goal g, bearing b of g relative to the heading):
//!
//! * **driving**: correct while |b| <= field of view (20 deg); error when the
//!   motion is not oriented to g, including driving past it (the bearing
//!   flips behind the robot: "overpassed the desired position");
//! * **turning in place**: correct when turning towards g, or away from it
//!   while still within the field of view; error when turning away beyond it
//!   ("overpassed the desired orientation");
//! * **stopped on a goal**: correct on g, error on any other goal;
//! * **on g** (within the goal radius): stopping or approaching is correct,
//!   turning or leaving is an error;
//! * **stopped elsewhere** (the stop after a detected error): no judgement;
//!   a robot halted mid-turn near a goal has not arrived there, so that is
//!   no judgement either (a stop counts as on a goal when the last motion
//!   seen before it was a drive);
//! * **before the first motion**: no judgement. The user placed the robot on
//!   its start; the paper times its runs "from the start of the movement".
//!
//! The user sees motion over a short window of tracked poses (0.5 s by
//! default), which is also part of the perception delay. An error onset
//! elicits an ErrP `reaction_latency_secs` later; an error that persists
//! re-elicits one every `reelicit_secs`; a correct onset (after an error or
//! no judgement) elicits the smaller correct-assessment potential.

use std::collections::VecDeque;

use errp_bci::AssessmentKind;
use errp_robot::{GoalLayout, Pose, wrap_angle};
use serde::{Deserialize, Serialize};

use crate::error::{Result, SimError};

/// The synthetic user's perception and timing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct UserParams {
    /// Half-angle within which a motion counts as oriented to the goal
    /// (rad); the paper's field of view of +-20 deg (sec. 5.2).
    pub fov_rad: f64,
    /// Delay from an error onset to the ErrP's time zero (s), on top of the
    /// motion window.
    pub reaction_latency_secs: f64,
    /// A persisting error re-elicits an ErrP this often (s).
    pub reelicit_secs: f64,
    /// Least time between two potentials of the same kind (s): a judgement
    /// that flickers at a boundary (the edge of the field of view) does not
    /// elicit a burst of ErrPs.
    pub min_gap_secs: f64,
    /// Span of tracked poses over which motion is seen (s). With the
    /// tracker's noise (2 mm, 1 deg per frame) 0.5 s keeps a still robot
    /// from ever looking as if it moved.
    pub motion_window_secs: f64,
    /// Speed above which the robot is seen driving (m/s); the e-puck drives
    /// at ~6.4 cm/s.
    pub driving_speed_m_per_s: f64,
    /// Turn rate above which the robot is seen turning (rad/s); the e-puck
    /// turns at ~70 deg/s.
    pub turning_rate_rad_per_s: f64,
    /// Distance within which the robot is seen on a goal (m): the city
    /// icons are about 10 cm wide.
    pub on_goal_radius_m: f64,
}

impl Default for UserParams {
    fn default() -> Self {
        Self {
            fov_rad: 20f64.to_radians(),
            reaction_latency_secs: 0.1,
            reelicit_secs: 1.5,
            min_gap_secs: 1.0,
            motion_window_secs: 0.5,
            driving_speed_m_per_s: 0.025,
            turning_rate_rad_per_s: 15f64.to_radians(),
            on_goal_radius_m: 0.05,
        }
    }
}

impl UserParams {
    /// Checks the ranges; errors name the scenario field (`user.<name>`).
    pub fn validate(&self) -> Result<()> {
        let check = |ok: bool, field: &str, v: f64, expected: &str| {
            if ok {
                Ok(())
            } else {
                Err(SimError::InvalidParameter {
                    name: format!("user.{field}"),
                    value: v.to_string(),
                    expected: expected.to_string(),
                })
            }
        };
        let deg = self.fov_rad.to_degrees();
        check(
            deg.is_finite() && deg > 0.0 && deg < 180.0,
            "fov_deg",
            deg,
            "an angle in (0, 180) degrees (the paper: 20)",
        )?;
        check(
            self.reaction_latency_secs.is_finite() && self.reaction_latency_secs >= 0.0,
            "reaction_latency_ms",
            self.reaction_latency_secs * 1000.0,
            "a delay >= 0 ms",
        )?;
        check(
            self.reelicit_secs.is_finite() && self.reelicit_secs >= 0.5,
            "reelicit_secs",
            self.reelicit_secs,
            "at least 0.5 s (an ErrP lasts about that long)",
        )?;
        check(
            self.min_gap_secs.is_finite() && self.min_gap_secs >= 0.0,
            "min_gap_secs",
            self.min_gap_secs,
            "a time >= 0 s",
        )?;
        check(
            self.motion_window_secs.is_finite() && self.motion_window_secs > 0.0,
            "motion_window_secs",
            self.motion_window_secs,
            "a span > 0 s",
        )?;
        check(
            self.on_goal_radius_m.is_finite() && self.on_goal_radius_m > 0.0,
            "on_goal_radius_cm",
            self.on_goal_radius_m * 100.0,
            "a radius > 0 cm",
        )?;
        check(
            self.driving_speed_m_per_s.is_finite() && self.driving_speed_m_per_s > 0.0,
            "driving_speed_cm_per_s",
            self.driving_speed_m_per_s * 100.0,
            "a speed > 0",
        )?;
        check(
            self.turning_rate_rad_per_s.is_finite() && self.turning_rate_rad_per_s > 0.0,
            "turning_rate_deg_per_s",
            self.turning_rate_rad_per_s.to_degrees(),
            "a rate > 0",
        )
    }
}

/// What the user makes of the motion at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Judgement {
    /// The motion serves the goal.
    Correct,
    /// The motion is wrong.
    Error,
    /// Nothing to judge (stopped away from any goal).
    None,
}

/// How the robot is seen to move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SeenMotion {
    /// Translating (m/s along the heading).
    Driving,
    /// Turning in place; the sign is the sense (+ anticlockwise).
    Turning(f64),
    /// Not moving.
    Still,
}

/// An ErrP or correct potential the user's brain will produce.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elicited {
    /// Time zero of the potential (episode time, s).
    pub onset_secs: f64,
    /// Error or correct.
    pub kind: AssessmentKind,
}

/// The synthetic user of one continuous episode.
#[derive(Debug, Clone)]
pub struct SyntheticUser {
    params: UserParams,
    goals: Vec<(f64, f64)>,
    goal: usize,
    history: VecDeque<(f64, Pose)>,
    state: Judgement,
    last_error_secs: f64,
    last_correct_secs: f64,
    /// The robot's last seen motion before it stood still was a drive:
    /// standing on a goal is then an arrival there (never before the first
    /// motion).
    arrived: bool,
}

impl SyntheticUser {
    /// A user who wants goal `goal` of `layout`.
    pub fn new(params: UserParams, layout: &GoalLayout, goal: usize) -> Self {
        Self {
            params,
            goals: layout.goals().iter().map(|g| (g.x_m, g.y_m)).collect(),
            goal,
            history: VecDeque::new(),
            state: Judgement::None,
            last_error_secs: f64::NEG_INFINITY,
            last_correct_secs: f64::NEG_INFINITY,
            arrived: false,
        }
    }

    /// The current judgement.
    pub fn judgement(&self) -> Judgement {
        self.state
    }

    /// The goal the user wants.
    pub fn goal(&self) -> usize {
        self.goal
    }

    /// Sees the tracked pose at `time_secs`; returns the potential elicited
    /// by a change of judgement or a persisting error, if any.
    pub fn observe(&mut self, time_secs: f64, tracked: &Pose) -> Option<Elicited> {
        self.history.push_back((time_secs, *tracked));
        while self.history.len() > 2
            && self.history[1].0 <= time_secs - self.params.motion_window_secs
        {
            self.history.pop_front();
        }
        let (t0, p0) = self.history[0];
        let span = time_secs - t0;
        let motion = if span < 0.5 * self.params.motion_window_secs {
            SeenMotion::Still
        } else {
            let d = ((tracked.x_m - p0.x_m).powi(2) + (tracked.y_m - p0.y_m).powi(2)).sqrt();
            let turn = wrap_angle(tracked.heading_rad - p0.heading_rad);
            if d / span >= self.params.driving_speed_m_per_s {
                SeenMotion::Driving
            } else if turn.abs() / span >= self.params.turning_rate_rad_per_s {
                SeenMotion::Turning(turn.signum())
            } else {
                SeenMotion::Still
            }
        };
        let approaching = {
            let (gx, gy) = self.goals[self.goal];
            let now = tracked.distance_to(gx, gy);
            let before = p0.distance_to(gx, gy);
            now < before
        };
        match motion {
            SeenMotion::Driving => self.arrived = true,
            SeenMotion::Turning(_) => self.arrived = false,
            SeenMotion::Still => {}
        }
        let judgement = self.judge(motion, tracked, approaching);
        let previous = self.state;
        self.state = judgement;
        let p = &self.params;
        let since_error = time_secs - self.last_error_secs;
        let elicit = match (previous, judgement) {
            (Judgement::Error, Judgement::Error) => since_error >= p.reelicit_secs,
            (_, Judgement::Error) => since_error >= p.min_gap_secs,
            (Judgement::Error | Judgement::None, Judgement::Correct) => {
                time_secs - self.last_correct_secs >= p.min_gap_secs
            }
            _ => false,
        };
        if !elicit {
            return None;
        }
        if judgement == Judgement::Error {
            self.last_error_secs = time_secs;
        } else {
            self.last_correct_secs = time_secs;
        }
        Some(Elicited {
            onset_secs: time_secs + p.reaction_latency_secs,
            kind: if judgement == Judgement::Error {
                AssessmentKind::Error
            } else {
                AssessmentKind::Correct
            },
        })
    }

    /// The judgement of `motion` at `pose` (see the module docs).
    pub fn judge(&self, motion: SeenMotion, pose: &Pose, approaching: bool) -> Judgement {
        let p = &self.params;
        let (gx, gy) = self.goals[self.goal];
        if pose.distance_to(gx, gy) <= p.on_goal_radius_m {
            return match motion {
                SeenMotion::Still => Judgement::Correct,
                SeenMotion::Driving if approaching => Judgement::Correct,
                _ => Judgement::Error,
            };
        }
        let bearing = pose.bearing_to(gx, gy);
        match motion {
            SeenMotion::Driving => {
                if bearing.abs() <= p.fov_rad {
                    Judgement::Correct
                } else {
                    Judgement::Error
                }
            }
            SeenMotion::Turning(sense) => {
                let towards = sense * bearing > 0.0;
                if towards || bearing.abs() <= p.fov_rad {
                    Judgement::Correct
                } else {
                    Judgement::Error
                }
            }
            SeenMotion::Still => {
                let on_other = self.arrived
                    && self.goals.iter().enumerate().any(|(i, &(x, y))| {
                        i != self.goal && pose.distance_to(x, y) <= p.on_goal_radius_m
                    });
                if on_other {
                    Judgement::Error
                } else {
                    Judgement::None
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(x: f64, y: f64, h: f64) -> Pose {
        Pose {
            x_m: x,
            y_m: y,
            heading_rad: h,
        }
    }

    fn user() -> (SyntheticUser, GoalLayout) {
        let layout = GoalLayout::cities();
        let pisa = layout.index_of("Pisa").unwrap();
        (
            SyntheticUser::new(UserParams::default(), &layout, pisa),
            layout,
        )
    }

    #[test]
    fn judgements_follow_section_5_1() {
        let (u, _) = user();
        // Pisa is at (1.8, 1.8); from (0.8, 0.8), between goals, it lies at
        // 45 degrees.
        let at = |h_deg: f64| pose(0.8, 0.8, h_deg.to_radians());
        assert_eq!(
            u.judge(SeenMotion::Driving, &at(45.0), false),
            Judgement::Correct
        );
        assert_eq!(
            u.judge(SeenMotion::Driving, &at(60.0), false),
            Judgement::Correct
        );
        assert_eq!(
            u.judge(SeenMotion::Driving, &at(70.0), false),
            Judgement::Error
        );
        assert_eq!(
            u.judge(SeenMotion::Turning(1.0), &at(0.0), false),
            Judgement::Correct
        );
        assert_eq!(
            u.judge(SeenMotion::Turning(-1.0), &at(0.0), false),
            Judgement::Error
        );
        assert_eq!(
            u.judge(SeenMotion::Turning(-1.0), &at(50.0), false),
            Judgement::Correct
        );
        assert_eq!(
            u.judge(SeenMotion::Turning(1.0), &at(70.0), false),
            Judgement::Error
        );
        assert_eq!(u.judge(SeenMotion::Still, &at(0.0), false), Judgement::None);
        // Before the first motion a stop on a goal is not judged: the user
        // put the robot there.
        let on_athens = pose(1.0, 1.0, 0.0);
        assert_eq!(
            u.judge(SeenMotion::Still, &on_athens, false),
            Judgement::None
        );
        // Arrived by driving, stopped on Athens (1.0, 1.0) is a wrong goal;
        // on Pisa it is right.
        let mut u = u;
        u.arrived = true;
        assert_eq!(
            u.judge(SeenMotion::Still, &on_athens, false),
            Judgement::Error
        );
        let on_pisa = pose(1.79, 1.8, 0.0);
        assert_eq!(
            u.judge(SeenMotion::Still, &on_pisa, false),
            Judgement::Correct
        );
        assert_eq!(
            u.judge(SeenMotion::Turning(1.0), &on_pisa, false),
            Judgement::Error
        );
        // Driving past Pisa: the goal is behind.
        let past = pose(1.7, 1.7, (-135f64).to_radians());
        assert_eq!(u.judge(SeenMotion::Driving, &past, false), Judgement::Error);
    }

    #[test]
    fn an_error_elicits_once_then_again_while_it_persists() {
        let (mut u, _) = user();
        let mut elicited = Vec::new();
        // Driving along +x from (0.6, 1.0): Pisa is 45+ degrees to the left.
        for k in 0..(64 * 4) {
            let t = k as f64 / 64.0;
            let p = pose(0.6 + 0.05 * t, 1.0, 0.0);
            if let Some(e) = u.observe(t, &p) {
                elicited.push(e);
            }
        }
        assert!(elicited.iter().all(|e| e.kind == AssessmentKind::Error));
        let onsets: Vec<f64> = elicited.iter().map(|e| e.onset_secs).collect();
        // First when the motion is first seen, then every 1.5 s.
        assert_eq!(onsets.len(), 3, "{onsets:?}");
        assert!((onsets[1] - onsets[0] - 1.5).abs() < 0.02, "{onsets:?}");
    }
}
