//! Shared control of the grid cursor: policy matching over Q-values from a
//! probability of error (sec. 4.2 of the paper).

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::belief::Belief;
use crate::error::{Result, RobotError};
use crate::grid::{Cell, Grid, GridAction};
use crate::qvalues::{QParams, QTable};

/// Parameters of the grid strategy.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GridControlParams {
    /// Soft-max temperature of eq. (3); the paper: 0.3.
    pub tau: f64,
    /// Probability of a uniformly random action instead of the greedy one
    /// (the paper uses epsilon-greedy without giving epsilon).
    pub epsilon: f64,
    /// Convergence: the run ends when one goal's probability reaches this;
    /// the paper: 0.9.
    pub p_c: f64,
    /// Reward model of the Q-values.
    pub q: QParams,
}

impl Default for GridControlParams {
    fn default() -> Self {
        Self {
            tau: 0.3,
            epsilon: 0.1,
            p_c: 0.9,
            q: QParams::default(),
        }
    }
}

impl GridControlParams {
    /// Checks every field; messages name the field and the accepted range.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(RobotError::Parameter(m));
        if !(self.tau.is_finite() && self.tau > 0.0) {
            return bad(format!("tau = {} must be a finite number > 0", self.tau));
        }
        if !(self.epsilon.is_finite() && (0.0..=1.0).contains(&self.epsilon)) {
            return bad(format!("epsilon = {} must be in [0, 1]", self.epsilon));
        }
        if !(self.p_c.is_finite() && self.p_c > 0.0 && self.p_c < 1.0) {
            return bad(format!("p_c = {} must be in (0, 1)", self.p_c));
        }
        self.q.validate()
    }
}

/// Eq. (4): the likelihood of policy i given the action and the decoder's
/// output, p(c=0|x) Q^_i(s,a) + p(c=1|x) (1 - Q^_i(s,a)).
pub fn policy_likelihood(q_hat: f64, p_error: f64) -> f64 {
    (1.0 - p_error) * q_hat + p_error * (1.0 - q_hat)
}

/// The device's side of the grid task: a belief over the 25 candidate goals
/// (every cell), updated after each action by eq. (4), and an epsilon-greedy
/// choice of the next action towards the most probable goal.
#[derive(Debug, Clone)]
pub struct GridController {
    params: GridControlParams,
    table: QTable,
    belief: Belief,
}

impl GridController {
    /// A controller with a uniform belief over every cell of `grid`.
    pub fn new(grid: Grid, params: GridControlParams) -> Result<Self> {
        params.validate()?;
        let table = QTable::compute(grid, &params.q)?;
        Ok(Self::with_table(table, params))
    }

    /// A controller reusing precomputed Q-values (they depend only on the
    /// grid and the reward model).
    pub fn with_table(table: QTable, params: GridControlParams) -> Self {
        let n = table.grid().n_cells();
        Self {
            params,
            table,
            belief: Belief::uniform(n),
        }
    }

    /// The parameters in force.
    pub fn params(&self) -> &GridControlParams {
        &self.params
    }

    /// The Q-values.
    pub fn table(&self) -> &QTable {
        &self.table
    }

    /// The belief over goals, indexed like the grid's cells.
    pub fn belief(&self) -> &Belief {
        &self.belief
    }

    /// The most probable goal and its probability.
    pub fn most_probable(&self) -> (Cell, f64) {
        let (i, p) = self.belief.most_probable();
        (self.table.grid().cell(i), p)
    }

    /// The goal the belief has converged to, if any (probability >= p_c).
    pub fn converged(&self) -> Option<Cell> {
        let (cell, p) = self.most_probable();
        (p >= self.params.p_c).then_some(cell)
    }

    /// Epsilon-greedy: with probability epsilon a uniformly random action,
    /// otherwise the optimal action for the most probable goal.
    pub fn choose(&self, cell: Cell, rng: &mut impl Rng) -> GridAction {
        if self.params.epsilon > 0.0 && rng.random::<f64>() < self.params.epsilon {
            GridAction::ALL[rng.random_range(0..GridAction::ALL.len())]
        } else {
            self.table.greedy(self.most_probable().0, cell)
        }
    }

    /// Updates the belief after `action` at `cell`, given the decoder's
    /// p(error) for it (eq. 4 for every goal, then Bayes' rule).
    pub fn observe(&mut self, cell: Cell, action: GridAction, p_error: f64) -> Result<()> {
        if !(p_error.is_finite() && (0.0..=1.0).contains(&p_error)) {
            return Err(RobotError::Likelihood(format!(
                "p(error) = {p_error} is not a probability"
            )));
        }
        let likelihoods = self.likelihoods(cell, action, p_error);
        self.belief.update(&likelihoods)
    }

    /// Eq. (4) for every goal, indexed like the grid's cells.
    pub fn likelihoods(&self, cell: Cell, action: GridAction, p_error: f64) -> Vec<f64> {
        let grid = *self.table.grid();
        grid.cells()
            .map(|goal| {
                let q_hat = self.table.softmax(goal, cell, self.params.tau)[action.index()];
                policy_likelihood(q_hat, p_error)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn controller() -> GridController {
        GridController::new(Grid::paper(), GridControlParams::default()).unwrap()
    }

    #[test]
    fn fig3_correct_move_favours_goals_ahead() {
        // (a) a correct move right from the centre, p(error) = 0.2.
        let c = controller();
        let l = c.likelihoods(Cell::new(2, 2), GridAction::Right, 0.2);
        let g = Grid::paper();
        let at = |x, y| l[g.index(Cell::new(x, y))];
        assert!(at(4, 2) > at(0, 2), "ahead beats behind");
        assert!(at(3, 2) > at(2, 4));
    }

    #[test]
    fn fig3_incorrect_move_penalises_goals_ahead() {
        // (b) the same move with p(error) = 0.8.
        let c = controller();
        let l = c.likelihoods(Cell::new(2, 2), GridAction::Right, 0.8);
        let g = Grid::paper();
        assert!(l[g.index(Cell::new(4, 2))] < l[g.index(Cell::new(0, 2))]);
    }

    #[test]
    fn fig3_goal_reached_favours_the_current_cell() {
        // (c) goal-reached at (1, 3) judged correct, p(error) = 0.2.
        let c = controller();
        let l = c.likelihoods(Cell::new(1, 3), GridAction::GoalReached, 0.2);
        let g = Grid::paper();
        let here = l[g.index(Cell::new(1, 3))];
        assert!(
            l.iter()
                .enumerate()
                .all(|(i, &v)| i == g.index(Cell::new(1, 3)) || v < here)
        );
    }

    #[test]
    fn belief_stays_a_distribution_under_any_decoder_output() {
        // Property: random cells, actions and p(error) in [0, 1] (including
        // the extremes) never give NaN, negatives or a sum other than 1.
        let g = Grid::paper();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for params in [
            GridControlParams::default(),
            GridControlParams {
                tau: 0.01,
                ..GridControlParams::default()
            },
        ] {
            let mut c = GridController::new(g, params).unwrap();
            for _ in 0..3000 {
                let cell = g.cell(rng.random_range(0..25));
                let action = GridAction::ALL[rng.random_range(0..5)];
                let p = match rng.random_range(0..4) {
                    0 => 0.0,
                    1 => 1.0,
                    _ => rng.random::<f64>(),
                };
                c.observe(cell, action, p).unwrap();
                let probs = c.belief().probabilities();
                assert!(probs.iter().all(|v| v.is_finite() && *v >= 0.0));
                assert!((probs.iter().sum::<f64>() - 1.0).abs() < 1e-9);
            }
        }
        assert!(
            controller()
                .observe(Cell::new(0, 0), GridAction::Up, 1.5)
                .is_err()
        );
        assert!(
            controller()
                .observe(Cell::new(0, 0), GridAction::Up, f64::NAN)
                .is_err()
        );
    }

    /// Runs one episode against a user whose assessments a decoder of
    /// `accuracy` reports (flipped with probability 1 - accuracy), returning
    /// the committed goal and the number of actions.
    fn oracle_episode(
        start: Cell,
        goal: Cell,
        accuracy: f64,
        rng: &mut ChaCha8Rng,
    ) -> (Option<Cell>, usize) {
        let g = Grid::paper();
        let mut c = controller();
        let mut cell = start;
        for n in 1..=300 {
            let action = c.choose(cell, rng);
            let error = !g.is_correct(cell, action, goal);
            let decoded = if rng.random::<f64>() < accuracy {
                error
            } else {
                !error
            };
            let p = if decoded { accuracy } else { 1.0 - accuracy };
            c.observe(cell, action, p).unwrap();
            cell = g.step(cell, action);
            if let Some(found) = c.converged() {
                return (Some(found), n);
            }
        }
        (None, 300)
    }

    #[test]
    fn a_90_percent_decoder_finds_the_goal() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut right = 0;
        let mut actions = 0;
        for k in 0..40 {
            let start = Cell::new(k % 5, (k / 5) % 5);
            let goal = Cell::new(4 - (k % 5), (k * 3 + 1) % 5);
            if start == goal {
                right += 1;
                continue;
            }
            let (found, n) = oracle_episode(start, goal, 0.9, &mut rng);
            right += usize::from(found == Some(goal));
            actions += n;
        }
        assert!(right >= 38, "{right}/40 right goals, {actions} actions");
    }

    #[test]
    fn a_chance_decoder_converges_to_the_right_goal_only_by_chance() {
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        let goal = Cell::new(4, 4);
        let mut right = 0;
        for _ in 0..100 {
            let (found, _) = oracle_episode(Cell::new(0, 0), goal, 0.5, &mut rng);
            right += usize::from(found == Some(goal));
        }
        // 1 in 25 by chance: 4 expected; 12 or more would be p < 0.001.
        assert!(right < 12, "{right}/100");
    }

    #[test]
    fn bad_parameters_name_the_field() {
        for (p, field) in [
            (
                GridControlParams {
                    tau: 0.0,
                    ..Default::default()
                },
                "tau",
            ),
            (
                GridControlParams {
                    epsilon: 1.5,
                    ..Default::default()
                },
                "epsilon",
            ),
            (
                GridControlParams {
                    p_c: 1.0,
                    ..Default::default()
                },
                "p_c",
            ),
        ] {
            let e = p.validate().unwrap_err().to_string();
            assert!(e.contains(field), "{e}");
        }
    }
}
