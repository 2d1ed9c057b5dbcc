//! Shared control of the e-puck from a probability of error: the likelihoods
//! of sec. 5.2 of the paper (eq. 6 and 7) and the motion of sec. 5.1.
//!
//! The robot turns in place towards the most probable goal, then drives
//! straight to it; it stops for `stop_secs` on reaching a goal (at least
//! `goal_hold_secs`, see below) or when the decoder reports an error, then
//! heads for the goal that
//! is most probable at that moment. Every decoder window (62.5 ms) updates
//! the belief over the goals with eq. (6) while turning and eq. (7) while
//! driving, and the run ends when a full stop on a goal ends with that
//! goal's probability at p_c or more (so the user always has the whole stop
//! to object to a wrong goal with an ErrP).
//!
//! What the paper leaves open, and our choices:
//! - **A stop on a goal waits for the user's verdict.** The user's ErrP for
//!   a wrong goal reaches a sliding-window decoder only after the user has
//!   seen the stop, reacted, and the potential has filled the window: more
//!   than the paper's 1 s. A stop on a goal therefore lasts
//!   `max(stop_secs, goal_hold_secs)`, so the veto reaches the belief
//!   before the run can converge; `goal_hold_secs = 0` is the paper's
//!   literal 1 s.
//! - **A late veto is charged to the stop.** A user who objects to a wrong
//!   goal until the robot leaves it produces ErrPs that the decoder reports
//!   after the robot has left. A detection within `veto_window_secs` of
//!   leaving a goal applies the stop's likelihood to that goal (a veto)
//!   and does not stop the new motion; 0 turns this off.
//! - **The stop on a goal is an action too.** The user judges a stop on the
//!   wrong goal as an error (sec. 5.1), but the paper gives no likelihood for
//!   it. While the robot is stopped on goal j after reaching it, each window
//!   applies eq. (7) with bearing 0 to goal j alone (the stop is an action
//!   aimed exactly at j): 1 + k_p N(0) if no error is detected, 1 - k_n N(0)
//!   (about 0.2) if one is; every other goal gets 1.
//! - **The stop after a detected error is not.** It is the system's reaction,
//!   not an action the user assesses, so windows during it do not update the
//!   belief (the caller still decodes them).
//! - **Goals under the robot.** A goal within `goal_radius_m` of the robot
//!   has no defined bearing; it gets likelihood 1 in turn and linear steps.
//! - **Goal choice** is greedy ([`Strategy::Greedy`]): the most probable
//!   goal, ties broken by the goal nearest the robot, then by the lowest
//!   index.
//! - **The run starts with the movement** (sec. 5.3 times "from the start
//!   of the movement"): the user placed the robot on its start, so the goal
//!   under it is not a target until the robot has left it, and the robot
//!   turns or drives at once. (Otherwise a detection during the first turn,
//!   which penalises the goals on one side and never the one under the
//!   robot, would make the start the most probable goal, and the robot
//!   would stop on it without having moved, a stop the user does not judge.)
//!   The start goal keeps its prior; the belief can bring the robot back to
//!   it later, like any other goal.
//! - **Goal choice by information gain** ([`Strategy::InfoGain`], not in the
//!   paper) heads for the goal whose heading the user's next assessment is
//!   expected to say most about; see
//!   [`next_target`](EpuckController::next_target).
//! - **No Thompson sampling** ([`Strategy::Thompson`]): the controller is
//!   deterministic (it has no random numbers), so
//!   [`EpuckControlParams::validate`] rejects that strategy.
//! - **The target is kept until the next stop**, as in sec. 5.1 ("the robot
//!   stopped ... Then, it moved towards a new goal"): the belief changes
//!   while the robot moves, the target does not.
//! - **Motion details**: turning ends when the bearing to the target is below
//!   `align_tolerance_deg`; while driving, a proportional heading correction
//!   (limited so that no wheel exceeds the top speed) keeps the robot on the
//!   target; if the target falls behind (|bearing| > 90 deg, e.g. after a
//!   collision) the robot turns in place again.

use std::f64::consts::FRAC_PI_2;

use serde::{Deserialize, Serialize};

use errp_valid::Valid;

use crate::belief::Belief;
use crate::epuck::drive::{Twist, WheelSpeeds};
use crate::epuck::layout::GoalLayout;
use crate::epuck::likelihood::{EpuckControlParams, linear_likelihood, turn_likelihood};
use crate::epuck::pose::{Pose, wrap_angle};
use crate::epuck::potential::QuadraticPotential;
use crate::error::{Result, RobotError};
use crate::strategy::{Strategy, expected_information_gain};

/// Why the robot is stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum StopReason {
    /// It reached (or started on) this goal.
    OnGoal(usize),
    /// The decoder reported an error.
    ErrorDetected,
}

/// What the robot is doing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Phase {
    /// Turning in place towards the target.
    Turning,
    /// Driving straight to the target.
    Driving,
    /// Standing still until `until_secs` (simulated time).
    Stopped {
        /// When the stop ends, s.
        until_secs: f64,
        /// Why the robot stopped.
        reason: StopReason,
    },
}

/// The kind of action one decoder window assessed, which selects the
/// likelihood.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum StepKind {
    /// A turn step, eq. (6). `direction` is the heading change since the
    /// previous window, rad; only its sign counts (> 0 anticlockwise).
    Turn {
        /// Heading change since the previous window, rad.
        direction: f64,
    },
    /// A linear step, eq. (7).
    Linear,
    /// Stopped on this goal after reaching it: eq. (7) at bearing 0 for it.
    StopOnGoal(usize),
    /// Stopped after a detected error: no update.
    Idle,
}

/// What one decoder window did.
#[derive(Debug, Clone, PartialEq)]
pub struct Observation {
    /// The action the window assessed.
    pub step: StepKind,
    /// p(error) >= T_e while turning or driving: the robot has stopped
    /// (a detected error while stopped on a goal only shows in the
    /// likelihoods).
    pub detected: bool,
    /// The goal the robot converged on: a full stop on it ended with its
    /// probability at p_c or more. The run is over.
    pub converged: Option<usize>,
    /// The likelihood applied to each goal (all 1 for an idle window).
    pub likelihoods: Vec<f64>,
}

/// The device's side of the continuous task: a belief over the layout's
/// goals, the current target and the motion phase. Deterministic. Call
/// [`command`](Self::command) every physics step and
/// [`observe`](Self::observe) every decoder window, both with the tracked
/// pose and the simulated time (which starts at 0).
#[derive(Debug, Clone)]
pub struct EpuckController {
    params: Valid<EpuckControlParams>,
    layout: GoalLayout,
    potentials: Vec<QuadraticPotential>,
    belief: Belief,
    target: usize,
    phase: Phase,
    last_heading_rad: f64,
    converged: Option<usize>,
    /// The goal the robot last left, and until when a detection vetoes it.
    left_goal: Option<(usize, f64)>,
    /// The goal the robot started on, until it has left it: not a target.
    start_goal: Option<usize>,
}

impl EpuckController {
    /// A controller with a uniform belief, the robot at `start` at time 0.
    /// The first target is the strategy's choice among the goals the robot
    /// is not on (with the uniform belief, greedy takes the nearest): the
    /// robot moves at once, and the goal it starts on is no target until it
    /// has left it.
    pub fn new(params: Valid<EpuckControlParams>, layout: GoalLayout, start: Pose) -> Result<Self> {
        let goals = layout.goals();
        let mut closest = f64::INFINITY;
        for (i, a) in goals.iter().enumerate() {
            for b in &goals[..i] {
                closest = closest.min((a.x_m - b.x_m).hypot(a.y_m - b.y_m));
            }
        }
        if 2.0 * params.goal_radius_m >= closest {
            return Err(RobotError::Parameter(format!(
                "goal_radius_m = {} must be less than half the distance between the closest goals ({closest} m)",
                params.goal_radius_m
            )));
        }
        let potentials = goals
            .iter()
            .map(|g| QuadraticPotential::for_goal(g.x_m, g.y_m, layout.arena_size_m()))
            .collect();
        let mut c = Self {
            params,
            belief: Belief::uniform(layout.len()),
            layout,
            potentials,
            target: 0,
            phase: Phase::Turning,
            last_heading_rad: start.heading_rad,
            converged: None,
            left_goal: None,
            start_goal: None,
        };
        c.start_goal = (0..c.layout.len()).find(|&i| c.on_goal(&start, i));
        c.choose_next(&start, 0.0);
        Ok(c)
    }

    /// The parameters in force.
    pub fn params(&self) -> &EpuckControlParams {
        &self.params
    }

    /// The goals.
    pub fn layout(&self) -> &GoalLayout {
        &self.layout
    }

    /// The belief over goals, indexed like the layout.
    pub fn belief(&self) -> &Belief {
        &self.belief
    }

    /// The goal the robot is heading for (or stopped on).
    pub fn target(&self) -> usize {
        self.target
    }

    /// The current motion phase.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// Goal `i`'s potential, eq. (5).
    pub fn potential(&self, i: usize) -> &QuadraticPotential {
        &self.potentials[i]
    }

    /// theta_i - theta_t: the greedy heading for goal `i` (eq. 5) relative to
    /// the robot's heading, wrapped to (-pi, pi].
    pub fn bearing_rad(&self, pose: &Pose, i: usize) -> f64 {
        let greedy = self.potentials[i].greedy_heading_rad(pose.x_m, pose.y_m);
        wrap_angle(greedy - pose.heading_rad)
    }

    fn on_goal(&self, pose: &Pose, i: usize) -> bool {
        let g = self.layout.goal(i);
        pose.distance_to(g.x_m, g.y_m) < self.params.goal_radius_m
    }

    /// The greedy goal choice: the most probable goal, ties broken by the
    /// nearest to `pose`, then by the lowest index.
    pub fn most_probable_goal(&self, pose: &Pose) -> usize {
        self.most_probable_of(pose, &self.belief.probabilities(), |_| true)
    }

    /// The most probable of the goals that `candidate` accepts (0 if none),
    /// ties broken by the nearest to `pose`, then by the lowest index.
    fn most_probable_of(&self, pose: &Pose, p: &[f64], candidate: impl Fn(usize) -> bool) -> usize {
        let top = (0..p.len())
            .filter(|&i| candidate(i))
            .map(|i| p[i])
            .fold(0.0, f64::max);
        let mut best: Option<(usize, f64)> = None;
        for (i, g) in self.layout.goals().iter().enumerate() {
            if !candidate(i) || p[i] < top * (1.0 - 1e-12) {
                continue;
            }
            let d = pose.distance_to(g.x_m, g.y_m);
            if best.is_none_or(|(_, bd)| d < bd - 1e-9) {
                best = Some((i, d));
            }
        }
        best.map_or(0, |(i, _)| i)
    }

    /// The goal to head for from `pose`, by the strategy.
    ///
    /// [`Strategy::Greedy`]: [`most_probable_goal`](Self::most_probable_goal).
    ///
    /// [`Strategy::InfoGain`]: if the most probable goal has probability
    /// p_c or more, that goal, as greedy: the run only ends after a full
    /// stop on a goal at p_c, so the robot has to go there and stop for the
    /// user to confirm or reject it; exploring elsewhere could only delay
    /// that. Otherwise the goal g of
    /// largest [`target_information_gain`](Self::target_information_gain):
    /// the one whose heading the next decoder window is expected to say
    /// most about; gains within 1e-12 of the largest tie, and ties go to the
    /// most probable goal, then to the nearest, then to the lowest index.
    ///
    /// [`Strategy::Thompson`] never gets here (the parameters' validation
    /// rejects it); it would be greedy.
    pub fn next_target(&self, pose: &Pose) -> usize {
        self.target_among(pose, |_| true)
    }

    /// [`next_target`](Self::next_target) among the goals that `candidate`
    /// accepts.
    fn target_among(&self, pose: &Pose, candidate: impl Fn(usize) -> bool) -> usize {
        let p = self.belief.probabilities();
        let greedy = self.most_probable_of(pose, &p, &candidate);
        if self.params.strategy != Strategy::InfoGain || p[greedy] >= self.params.p_c {
            return greedy;
        }
        let gains: Vec<f64> = (0..self.layout.len())
            .map(|g| {
                if candidate(g) {
                    self.gain(&p, pose, g)
                } else {
                    f64::NEG_INFINITY
                }
            })
            .collect();
        let best = gains.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        self.most_probable_of(pose, &p, |g| candidate(g) && gains[g] >= best - 1e-12)
    }

    /// The expected information gain, nats, of one decoder window spent
    /// heading for goal `g` from `pose`
    /// ([`expected_information_gain`](crate::expected_information_gain)).
    ///
    /// If the robot is not on g, the window is a linear step along g's
    /// greedy heading (eq. 5). For each goal i, with Delta_i the angle
    /// between the greedy headings to i and to g: the user judges the step
    /// an error with probability 1 - exp(-Delta_i^2 / (2 sigma^2)) (the
    /// Gaussian field of view of eq. 7) and the belief would be updated by
    /// eq. (7) at bearing Delta_i, as [`likelihoods`](Self::likelihoods)
    /// does for a linear step; a goal under the robot gets likelihood 1 and
    /// is always judged an error (the robot drives off it).
    ///
    /// If the robot is on g, heading for g is a stop on it: the user judges
    /// it an error unless g is the goal, and only g's probability changes
    /// (eq. 7 at bearing 0, as for [`StepKind::StopOnGoal`]).
    ///
    /// Outcomes: the decoder detects an error (p(error) >= T_e) with the
    /// assumed accuracy alpha if the user judges one, and with 1 - alpha if
    /// not. Eq. (7) depends on p(error) only through p(error) >= T_e, so a
    /// detection is evaluated at p(error) = 1 and no detection at 0 (taking
    /// alpha and 1 - alpha themselves would make both outcomes alike
    /// whenever alpha < T_e, as with the defaults 0.75 and 0.8).
    pub fn target_information_gain(&self, pose: &Pose, g: usize) -> f64 {
        self.gain(&self.belief.probabilities(), pose, g)
    }

    fn gain(&self, p: &[f64], pose: &Pose, g: usize) -> f64 {
        let alpha = self.params.assumed_accuracy;
        if self.on_goal(pose, g) {
            return expected_information_gain(
                p,
                alpha,
                |i| if i == g { 0.0 } else { 1.0 },
                |i, says_error| {
                    if i == g {
                        linear_likelihood(&self.params, says_error, 0.0)
                    } else {
                        1.0
                    }
                },
            );
        }
        let heading = |i: usize| self.potentials[i].greedy_heading_rad(pose.x_m, pose.y_m);
        let heading_g = heading(g);
        let delta = |i: usize| wrap_angle(heading(i) - heading_g);
        let two_var = 2.0 * self.params.sigma_rad().powi(2);
        expected_information_gain(
            p,
            alpha,
            |i| {
                if self.on_goal(pose, i) {
                    1.0
                } else {
                    1.0 - (-delta(i).powi(2) / two_var).exp()
                }
            },
            |i, says_error| {
                if self.on_goal(pose, i) {
                    1.0
                } else {
                    linear_likelihood(&self.params, says_error, delta(i))
                }
            },
        )
    }

    /// Picks the next target (never the start goal before the robot has
    /// left it) and starts towards it (or stays stopped on it).
    fn choose_next(&mut self, pose: &Pose, time_secs: f64) {
        let start = self.start_goal;
        self.target = self.target_among(pose, |i| Some(i) != start);
        self.phase = if self.on_goal(pose, self.target) {
            self.stop(time_secs, StopReason::OnGoal(self.target))
        } else {
            Phase::Turning
        };
    }

    fn stop(&self, time_secs: f64, reason: StopReason) -> Phase {
        let secs = match reason {
            StopReason::OnGoal(_) => {
                let hold = self.params.goal_hold_secs.unwrap_or(0.0);
                self.params.stop_secs.max(hold)
            }
            StopReason::ErrorDetected => self.params.stop_secs,
        };
        Phase::Stopped {
            until_secs: time_secs + secs,
            reason,
        }
    }

    /// The wheel speeds for this physics step (sec. 5.1: turn in place
    /// towards the target, then straight to it, stopping on it), given the
    /// tracked pose; also ends stops and switches between turning and
    /// driving. Zero while stopped. Never above the top speed.
    pub fn command(&mut self, pose: &Pose, time_secs: f64) -> WheelSpeeds {
        if let Some(s) = self.start_goal
            && !self.on_goal(pose, s)
        {
            self.start_goal = None;
        }
        let epuck = self.params.epuck;
        let top = epuck.max_speed_m_per_s();
        let align = self.params.align_tolerance_deg.to_radians();
        // Each transition moves forward (stop -> turn -> drive -> stop), so
        // this settles within a few passes.
        loop {
            match self.phase {
                Phase::Stopped { until_secs, reason } => {
                    if time_secs < until_secs || self.converged.is_some() {
                        return WheelSpeeds::ZERO;
                    }
                    // The run ends at the end of a full stop on a goal whose
                    // probability has reached p_c: the user had the whole
                    // stop to object with an ErrP.
                    if let StopReason::OnGoal(j) = reason
                        && self.belief.probability(j) >= self.params.p_c
                    {
                        self.converged = Some(j);
                        return WheelSpeeds::ZERO;
                    }
                    self.choose_next(pose, time_secs);
                    if let Phase::Stopped { .. } = self.phase {
                        return WheelSpeeds::ZERO;
                    }
                    if let StopReason::OnGoal(j) = reason {
                        let window = self.params.veto_window_secs.unwrap_or(0.0);
                        self.left_goal = Some((j, time_secs + window));
                    }
                }
                Phase::Turning => {
                    if self.on_goal(pose, self.target) {
                        self.phase = self.stop(time_secs, StopReason::OnGoal(self.target));
                        return WheelSpeeds::ZERO;
                    }
                    let b = self.bearing_rad(pose, self.target);
                    if b.abs() < align {
                        self.phase = Phase::Driving;
                        continue;
                    }
                    let s = b.signum() * self.params.turn_speed_fraction * top;
                    return WheelSpeeds {
                        left_m_per_s: -s,
                        right_m_per_s: s,
                    };
                }
                Phase::Driving => {
                    if self.on_goal(pose, self.target) {
                        self.phase = self.stop(time_secs, StopReason::OnGoal(self.target));
                        return WheelSpeeds::ZERO;
                    }
                    let b = self.bearing_rad(pose, self.target);
                    if b.abs() > FRAC_PI_2 {
                        self.phase = Phase::Turning;
                        continue;
                    }
                    let v = self.params.drive_speed_fraction * top;
                    let w_max = 2.0 * (top - v) / epuck.axle_length_m;
                    let w = (self.params.heading_gain * b).clamp(-w_max, w_max);
                    let twist = Twist {
                        linear_m_per_s: v,
                        angular_rad_per_s: w,
                    };
                    return twist.to_wheels(&epuck).clamp(&epuck);
                }
            }
        }
    }

    /// The likelihood of `step` for every goal, given the detector's verdict
    /// (`error`) and the pose:
    /// eq. (6) for a turn, eq. (7) for a linear step, eq. (7) at bearing 0
    /// for the goal the robot is stopped on, 1 elsewhere (see the module
    /// doc).
    pub fn likelihoods(&self, step: StepKind, error: bool, pose: &Pose) -> Vec<f64> {
        (0..self.layout.len())
            .map(|i| match step {
                StepKind::Turn { direction } if !self.on_goal(pose, i) => {
                    turn_likelihood(&self.params, error, direction, self.bearing_rad(pose, i))
                }
                StepKind::Linear if !self.on_goal(pose, i) => {
                    linear_likelihood(&self.params, error, self.bearing_rad(pose, i))
                }
                StepKind::StopOnGoal(j) if i == j => linear_likelihood(&self.params, error, 0.0),
                _ => 1.0,
            })
            .collect()
    }

    /// One decoder window, with the detector's verdict on it (`error`: an
    /// error is detected, the paper's p(error) >= T_e when each window is
    /// read on its own): classifies the step from the phase and the heading
    /// change since the previous call, updates the belief by Bayes' rule
    /// (eq. 2) with [`likelihoods`](Self::likelihoods), and on a detected
    /// error while turning or driving stops the robot until
    /// `time_secs + stop_secs`. Reports convergence when the robot is
    /// stopped on a goal whose probability is >= p_c.
    pub fn observe(&mut self, error: bool, pose: &Pose, time_secs: f64) -> Result<Observation> {
        let heading_change = wrap_angle(pose.heading_rad - self.last_heading_rad);
        self.last_heading_rad = pose.heading_rad;
        let moving = matches!(self.phase, Phase::Turning | Phase::Driving);
        let veto_of = match self.left_goal {
            Some((j, until)) if error && moving && time_secs <= until => Some(j),
            _ => None,
        };
        let step = match (veto_of, self.phase) {
            (Some(j), _) => StepKind::StopOnGoal(j),
            (None, Phase::Turning) => StepKind::Turn {
                direction: heading_change,
            },
            (None, Phase::Driving) => StepKind::Linear,
            (
                None,
                Phase::Stopped {
                    reason: StopReason::OnGoal(j),
                    ..
                },
            ) => StepKind::StopOnGoal(j),
            (
                None,
                Phase::Stopped {
                    reason: StopReason::ErrorDetected,
                    ..
                },
            ) => StepKind::Idle,
        };
        let likelihoods = self.likelihoods(step, error, pose);
        if step != StepKind::Idle {
            self.belief.update(&likelihoods)?;
        }
        let detected = error && moving && veto_of.is_none();
        if detected {
            self.phase = self.stop(time_secs, StopReason::ErrorDetected);
        }
        let converged = self.converged;
        Ok(Observation {
            step,
            detected,
            converged,
            likelihoods,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::epuck::drive::EpuckParams;
    use crate::strategy::Strategy;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::f64::consts::PI;

    fn params() -> EpuckControlParams {
        EpuckControlParams::default()
    }

    fn on(layout: &GoalLayout, name: &str, heading_rad: f64) -> Pose {
        let g = layout.goal(layout.index_of(name).unwrap());
        Pose::new(g.x_m, g.y_m, heading_rad)
    }

    #[test]
    fn the_robot_leaves_its_start_city_at_once() {
        let l = GoalLayout::cities();
        let start = on(&l, "Mexico", 0.0);
        let mut c = EpuckController::new(Valid::new(params()).unwrap(), l, start).unwrap();
        let mexico = 0;
        // The nearest goals other than Mexico, Havana and Bogota, tie at
        // 0.4 m; the lower index (Havana) wins. No stop on Mexico first.
        assert_eq!(c.target(), 1);
        assert_eq!(c.phase(), Phase::Turning);
        let w = c.command(&start, 0.0);
        assert_eq!(
            c.phase(),
            Phase::Driving,
            "Havana is straight ahead: no turn"
        );
        assert!(w.left_m_per_s > 0.0 && (w.left_m_per_s - w.right_m_per_s).abs() < 1e-12);
        // A window while driving off Mexico is a linear step; Mexico, under
        // the robot, has no bearing and keeps its probability.
        let o = c.observe(false, &start, 0.0625).unwrap();
        assert_eq!(o.step, StepKind::Linear);
        assert_eq!(o.likelihoods[mexico], 1.0);
        // A detection while still on Mexico penalises the goals ahead and
        // never Mexico; after the stop the robot still does not choose the
        // goal it has not left.
        let o = c.observe(true, &start, 0.125).unwrap();
        assert!(o.detected);
        assert_eq!(c.command(&start, 0.5), WheelSpeeds::ZERO);
        let mut c2 = c.clone();
        c.command(&start, 1.2);
        assert_ne!(c.target(), mexico);
        assert!(matches!(c.phase(), Phase::Turning | Phase::Driving));
        // Once it has left Mexico, Mexico is a goal like any other.
        let away = Pose::new(start.x_m, start.y_m + 0.2, 0.0);
        c2.command(&away, 1.2);
        assert!(c2.start_goal.is_none());
    }

    #[test]
    fn the_start_goal_is_avoided_by_info_gain_too() {
        let l = GoalLayout::cities();
        let start = on(&l, "Mexico", 0.0);
        let p = EpuckControlParams {
            strategy: Strategy::InfoGain,
            ..params()
        };
        let c = EpuckController::new(Valid::new(p).unwrap(), l, start).unwrap();
        assert_ne!(c.target(), 0);
        assert_eq!(c.phase(), Phase::Turning);
    }

    #[test]
    fn a_detected_error_stops_the_robot_and_freezes_the_belief() {
        let l = GoalLayout::cities();
        let start = Pose::new(1.0, 0.9, PI / 2.0); // just below Athens
        let mut c = EpuckController::new(Valid::new(params()).unwrap(), l, start).unwrap();
        let athens = c.layout().index_of("Athens").unwrap();
        assert_eq!(c.target(), athens);
        let w = c.command(&start, 0.0);
        assert_eq!(c.phase(), Phase::Driving);
        assert!(w.left_m_per_s > 0.0 && (w.left_m_per_s - w.right_m_per_s).abs() < 1e-12);
        let o = c.observe(true, &start, 0.0625).unwrap();
        assert_eq!(o.step, StepKind::Linear);
        assert!(o.detected);
        assert!(o.likelihoods[athens] < 0.21);
        let rome = c.layout().index_of("Rome").unwrap();
        assert!(o.likelihoods[rome] < 0.21, "Rome is straight ahead too");
        assert_eq!(
            c.phase(),
            Phase::Stopped {
                until_secs: 1.0625,
                reason: StopReason::ErrorDetected
            }
        );
        let before = c.belief().clone();
        let o = c.observe(true, &start, 0.125).unwrap();
        assert_eq!(o.step, StepKind::Idle);
        assert!(!o.detected && o.likelihoods.iter().all(|&v| v == 1.0));
        assert_eq!(c.belief(), &before);
        assert_eq!(c.command(&start, 1.0), WheelSpeeds::ZERO);
        c.command(&start, 1.0625);
        assert_ne!(c.target(), athens);
        assert_ne!(c.target(), rome);
        assert_eq!(c.phase(), Phase::Turning);
    }

    #[test]
    fn a_stop_on_a_goal_holds_for_the_verdict_and_a_late_veto_is_charged_to_it() {
        let l = GoalLayout::cities();
        // Just below Athens, facing it: the robot drives there first.
        let athens = l.index_of("Athens").unwrap();
        let start = Pose::new(1.0, 0.9, PI / 2.0);
        let held = EpuckControlParams {
            goal_hold_secs: Some(1.8),
            veto_window_secs: Some(1.2),
            ..params()
        };
        let mut c = EpuckController::new(Valid::new(held).unwrap(), l, start).unwrap();
        assert_eq!(c.target(), athens);
        let on_athens = on(c.layout(), "Athens", PI / 2.0);
        assert_eq!(c.command(&on_athens, 0.5), WheelSpeeds::ZERO, "arrived");
        assert_eq!(
            c.phase(),
            Phase::Stopped {
                until_secs: 2.3,
                reason: StopReason::OnGoal(athens)
            }
        );
        assert_eq!(c.command(&on_athens, 2.0), WheelSpeeds::ZERO, "still held");
        // The user's verdict on Athens arrives within the hold.
        let o = c.observe(true, &on_athens, 1.7).unwrap();
        assert_eq!(o.step, StepKind::StopOnGoal(athens));
        c.command(&on_athens, 2.3);
        assert!(
            matches!(c.phase(), Phase::Turning | Phase::Driving),
            "off to another goal"
        );
        let before = c.belief().probability(athens);
        // A detection 0.5 s after leaving is the verdict on Athens: it does
        // not stop the robot and only Athens is penalised.
        let o = c.observe(true, &on_athens, 2.8).unwrap();
        assert_eq!(o.step, StepKind::StopOnGoal(athens));
        assert!(!o.detected);
        assert!(matches!(c.phase(), Phase::Turning | Phase::Driving));
        assert!(c.belief().probability(athens) < 0.3 * before);
        // After the veto window, a detection stops the robot as usual.
        let o = c.observe(true, &on_athens, 3.6).unwrap();
        assert!(matches!(o.step, StepKind::Linear | StepKind::Turn { .. }));
        assert!(o.detected);
    }

    #[test]
    fn belief_stays_a_distribution_under_any_decoder_output() {
        let l = GoalLayout::cities();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut c =
            EpuckController::new(Valid::new(params()).unwrap(), l, Pose::new(0.9, 1.1, 0.0))
                .unwrap();
        for k in 0..5000 {
            let pose = Pose::new(
                rng.random_range(0.0..2.0),
                rng.random_range(0.0..2.0),
                rng.random_range(-PI..PI),
            );
            let t = k as f64 * 0.0625;
            c.command(&pose, t);
            let o = c.observe(rng.random_bool(0.2), &pose, t).unwrap();
            assert!(o.likelihoods.iter().all(|v| v.is_finite() && *v > 0.0));
            let probs = c.belief().probabilities();
            assert!(probs.iter().all(|v| v.is_finite() && *v >= 0.0));
            assert!((probs.iter().sum::<f64>() - 1.0).abs() < 1e-9);
        }
    }

    #[test]
    fn wheel_commands_respect_the_top_speed() {
        let l = GoalLayout::cities();
        let top = EpuckParams::default().max_speed_m_per_s();
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        for _ in 0..2000 {
            let pose = Pose::new(
                rng.random_range(0.0..2.0),
                rng.random_range(0.0..2.0),
                rng.random_range(-PI..PI),
            );
            let mut c =
                EpuckController::new(Valid::new(params()).unwrap(), l.clone(), pose).unwrap();
            let w = c.command(&pose, 0.0);
            assert!(w.left_m_per_s.abs() <= top + 1e-12 && w.right_m_per_s.abs() <= top + 1e-12);
        }
    }

    #[test]
    fn a_goal_radius_wider_than_half_the_goal_spacing_is_rejected() {
        let d = EpuckControlParams::default();
        let wide = EpuckControlParams {
            goal_radius_m: 0.2,
            ..d
        };
        let e = EpuckController::new(
            Valid::new(wide).unwrap(),
            GoalLayout::cities(),
            Pose::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("goal_radius_m"), "{e}");
    }

    /// A controller with the robot on Mexico (bottom left) and a belief of
    /// `mass[k]` on goal `goals[k]`, the rest spread evenly over the others.
    fn info_gain_on_mexico(goals: &[&str], mass: &[f64]) -> (EpuckController, Pose) {
        let l = GoalLayout::cities();
        let start = on(&l, "Mexico", 0.0);
        let params = EpuckControlParams {
            strategy: Strategy::InfoGain,
            ..params()
        };
        let mut c = EpuckController::new(Valid::new(params).unwrap(), l.clone(), start).unwrap();
        let idx: Vec<usize> = goals.iter().map(|g| l.index_of(g).unwrap()).collect();
        let rest = (1.0 - mass.iter().sum::<f64>()) / (l.len() - goals.len()) as f64;
        let w: Vec<f64> = (0..l.len())
            .map(|i| idx.iter().position(|&j| j == i).map_or(rest, |k| mass[k]))
            .collect();
        c.belief = Belief::uniform(l.len());
        c.belief.update(&w).unwrap();
        (c, start)
    }

    #[test]
    fn info_gain_heads_where_the_belief_splits_in_half() {
        // From Mexico: Bangkok due east is the most probable goal, but the
        // diagonal towards Pisa holds two modes (Athens, Pisa), and Lisbon is
        // due north. Heading for Bangkok asks "Bangkok or not?" (0.24 against
        // the rest); heading along the diagonal asks "the diagonal or not?"
        // (0.44 against the rest), which is closer to a half split.
        let (c, pose) = info_gain_on_mexico(
            &["Bangkok", "Athens", "Pisa", "Lisbon"],
            &[0.24, 0.22, 0.22, 0.22],
        );
        let l = c.layout();
        let bangkok = l.index_of("Bangkok").unwrap();
        assert_eq!(c.most_probable_goal(&pose), bangkok);
        let target = c.next_target(&pose);
        let diagonal = ["Lima", "Athens", "Berlin", "Pisa"].map(|n| l.index_of(n).unwrap());
        assert!(
            diagonal.contains(&target),
            "{}: gains {:?}",
            l.goal(target).name,
            (0..l.len())
                .map(|g| (l.goal(g).name.clone(), c.target_information_gain(&pose, g)))
                .collect::<Vec<_>>()
        );
        let gain = |n: &str| c.target_information_gain(&pose, l.index_of(n).unwrap());
        assert!(gain("Athens") > gain("Bangkok") && gain("Bangkok") > 0.0);
        // A heading between two modes (Rio de Janeiro, 63 deg, between the
        // diagonal and Lisbon) tells less than one through them.
        assert!(gain("Rio de Janeiro") < gain("Athens"));
        // Greedy with the same belief heads for Bangkok.
        let mut greedy = c.clone();
        greedy.params = greedy
            .params
            .with(|p| p.strategy = Strategy::Greedy)
            .unwrap();
        assert_eq!(greedy.next_target(&pose), bangkok);
    }

    #[test]
    fn info_gain_goes_for_a_goal_at_p_c_like_greedy() {
        // Bangkok above p_c = 0.4: the robot has to go and stop there, even
        // though the diagonal would split the belief better.
        let (c, pose) = info_gain_on_mexico(&["Bangkok", "Athens", "Pisa"], &[0.41, 0.2, 0.2]);
        let l = c.layout();
        let bangkok = l.index_of("Bangkok").unwrap();
        let athens = l.index_of("Athens").unwrap();
        assert!(
            c.target_information_gain(&pose, athens) > c.target_information_gain(&pose, bangkok)
        );
        assert_eq!(c.next_target(&pose), bangkok);
        let (c, pose) = info_gain_on_mexico(&["Bangkok", "Athens", "Pisa"], &[0.39, 0.2, 0.2]);
        assert_ne!(c.next_target(&pose), bangkok, "just below p_c it explores");
    }

    #[test]
    fn info_gain_with_a_certain_or_uniform_belief() {
        // Certain of Pisa (far above p_c): Pisa.
        let (c, pose) = info_gain_on_mexico(&["Pisa"], &[1.0]);
        let pisa = c.layout().index_of("Pisa").unwrap();
        assert_eq!(c.next_target(&pose), pisa);
        // Uniform: every gain is finite and >= 0 (no posterior has more
        // entropy), and the choice is some goal other than Mexico, or the
        // stop on it.
        let (c, pose) = info_gain_on_mexico(&[], &[]);
        for g in 0..c.layout().len() {
            let v = c.target_information_gain(&pose, g);
            assert!(v.is_finite() && v >= -1e-12, "{g}: {v}");
        }
        assert!(c.next_target(&pose) < c.layout().len());
    }
}
