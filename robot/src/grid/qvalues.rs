//! Optimal Q-values of the grid task and their soft-max (eq. 3).

use serde::{Deserialize, Serialize};

use errp_valid::{Check, Valid};

use crate::error::{Result, RobotError, check};
use crate::grid::{Cell, Grid, GridAction};

/// The reward model behind Q*_i. The paper says the Q-values come from
/// Q-learning but not with which rewards or discount; these are the open
/// parameters that set the Q-value scale the soft-max temperature acts on.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct QParams {
    /// Reward of goal-reached on the goal (ends the episode).
    pub goal_reward: f64,
    /// Reward of goal-reached anywhere else (also ends it).
    pub wrong_goal_reward: f64,
    /// Discount factor gamma in [0, 1).
    pub discount: f64,
}

impl Default for QParams {
    fn default() -> Self {
        Self {
            goal_reward: 1.0,
            wrong_goal_reward: 0.0,
            discount: 0.9,
        }
    }
}

/// The reward model, checked with the control parameters it is part of.
impl Check for QParams {
    type Error = RobotError;

    fn check(&self) -> Result<()> {
        self.validate()
    }
}

/// The largest |reward|: the Q-values over tau stay far from overflow.
const MAX_REWARD: f64 = 1000.0;

impl QParams {
    /// Checks every field.
    pub(crate) fn validate(&self) -> Result<()> {
        check(
            self.discount.is_finite() && (0.0..1.0).contains(&self.discount),
            "discount",
            self.discount,
            "a number in [0, 1)",
        )?;
        check(
            self.wrong_goal_reward.is_finite() && self.wrong_goal_reward.abs() <= MAX_REWARD,
            "wrong_goal_reward",
            self.wrong_goal_reward,
            &format!("a number in [-{MAX_REWARD}, {MAX_REWARD}]"),
        )?;
        check(
            self.goal_reward.is_finite()
                && self.goal_reward > self.wrong_goal_reward
                && self.goal_reward <= MAX_REWARD,
            "goal_reward",
            self.goal_reward,
            &format!(
                "a number above wrong_goal_reward ({}) and at most {MAX_REWARD}",
                errp_valid::shown(self.wrong_goal_reward)
            ),
        )
    }
}

/// Q*_i(s, a) for every goal i and cell s of a grid.
#[derive(Debug, Clone, PartialEq)]
pub struct QTable {
    grid: Grid,
    /// `values[goal_index * n_cells + cell_index][action_index]`.
    values: Vec<[f64; 5]>,
}

impl QTable {
    /// Solves the Bellman optimality equation by value iteration, for every
    /// cell as a goal. This is the fixed point Q-learning converges to
    /// (deterministic moves, goal-reached terminal), without its sampling
    /// noise: Q(s, move) = gamma V(s'), Q(s, goal-reached) = reward.
    pub fn compute(grid: Grid, params: &Valid<QParams>) -> Result<Self> {
        let n = grid.n_cells();
        let mut values = vec![[0.0; 5]; n * n];
        for goal in 0..n {
            let mut v = vec![0.0; n];
            loop {
                let mut change: f64 = 0.0;
                for s in 0..n {
                    let cell = grid.cell(s);
                    let mut q = [0.0; 5];
                    for a in GridAction::ALL {
                        q[a.index()] = match a {
                            GridAction::GoalReached if s == goal => params.goal_reward,
                            GridAction::GoalReached => params.wrong_goal_reward,
                            _ => params.discount * v[grid.index(grid.step(cell, a))],
                        };
                    }
                    let best = q.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                    change = change.max((best - v[s]).abs());
                    v[s] = best;
                    values[goal * n + s] = q;
                }
                if change < 1e-13 {
                    break;
                }
            }
        }
        Ok(Self { grid, values })
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// Q*_goal(cell, .) in [`GridAction::ALL`] order.
    pub fn q(&self, goal: Cell, cell: Cell) -> &[f64; 5] {
        &self.values[self.grid.index(goal) * self.grid.n_cells() + self.grid.index(cell)]
    }

    /// Eq. (3): soft-max of Q*_goal(cell, .) at temperature `tau`.
    pub fn softmax(&self, goal: Cell, cell: Cell, tau: f64) -> [f64; 5] {
        softmax(self.q(goal, cell), tau)
    }

    /// The best action for `goal` at `cell`, argmax_a Q*_i(s, a): the
    /// optimal policy of eq. (1) of the paper (first in [`GridAction::ALL`]
    /// order on ties).
    pub fn greedy(&self, goal: Cell, cell: Cell) -> GridAction {
        let q = self.q(goal, cell);
        let mut best = 0;
        for a in 1..5 {
            if q[a] > q[best] + 1e-12 {
                best = a;
            }
        }
        GridAction::ALL[best]
    }
}

/// Eq. (3): e^(q/tau) / sum e^(q/tau), computed stably.
pub fn softmax(q: &[f64; 5], tau: f64) -> [f64; 5] {
    let m = q.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut e = [0.0; 5];
    for (ei, qi) in e.iter_mut().zip(q) {
        *ei = ((qi - m) / tau).exp();
    }
    let sum: f64 = e.iter().sum();
    e.map(|v| v / sum)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn q_values_are_discounted_distances() {
        let g = Grid::paper();
        let t = QTable::compute(g, &Valid::default()).unwrap();
        let goal = Cell::new(2, 2);
        // From (0, 2), distance 2: moving right leads to distance 1, whose
        // value is gamma^1, so Q = gamma^2; moving left bumps the border.
        let q = t.q(goal, Cell::new(0, 2));
        let gamma: f64 = 0.9;
        assert!((q[GridAction::Right.index()] - gamma.powi(2)).abs() < 1e-12);
        assert!((q[GridAction::Left.index()] - gamma.powi(3)).abs() < 1e-12);
        assert!((q[GridAction::Up.index()] - gamma.powi(4)).abs() < 1e-12);
        assert_eq!(q[GridAction::GoalReached.index()], 0.0);
        assert_eq!(t.q(goal, goal)[GridAction::GoalReached.index()], 1.0);
        assert_eq!(t.greedy(goal, Cell::new(0, 2)), GridAction::Right);
        assert_eq!(t.greedy(goal, goal), GridAction::GoalReached);
    }

    #[test]
    fn greedy_actions_are_always_judged_correct() {
        let g = Grid::paper();
        let t = QTable::compute(g, &Valid::default()).unwrap();
        for goal in g.cells() {
            for cell in g.cells() {
                assert!(
                    g.is_correct(cell, t.greedy(goal, cell), goal),
                    "{goal} {cell}"
                );
            }
        }
    }

    #[test]
    fn softmax_sums_to_one_and_favours_the_best_action() {
        let p = softmax(&[0.81, 0.59, 0.73, 0.73, 0.0], 0.3);
        assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!(p[0] > p[2] && p[2] > p[1] && p[1] > p[4]);
        // Hand-computed: e^(0.81/0.3) / sum = 0.3636...
        let e = |q: f64| (q / 0.3f64).exp();
        let want = e(0.81) / (e(0.81) + e(0.59) + 2.0 * e(0.73) + e(0.0));
        assert!((p[0] - want).abs() < 1e-12);
        let huge = softmax(&[1e6, 0.0, 0.0, 0.0, 0.0], 1e-3);
        assert!(huge.iter().all(|v| v.is_finite()) && huge[0] == 1.0);
    }

    #[test]
    fn bad_reward_models_are_rejected() {
        let p = QParams {
            discount: 1.0,
            ..QParams::default()
        };
        assert!(p.validate().unwrap_err().to_string().contains("discount"));
    }
}
