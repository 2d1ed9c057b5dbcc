//! Shared control of the grid cursor: policy matching over Q-values from a
//! probability of error (sec. 4.2 of the paper).

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::belief::Belief;
use crate::error::{Result, RobotError};
use crate::grid::{Cell, Grid, GridAction};
use crate::qvalues::{QParams, QTable};
use crate::strategy::{Strategy, gain_from_logs};

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
    /// How the non-random actions are chosen (the paper: greedy).
    pub strategy: Strategy,
    /// The decoder accuracy the device assumes when it predicts the
    /// decoder's outcomes for [`Strategy::InfoGain`]. In (0.5, 1].
    pub assumed_accuracy: f64,
}

impl Default for GridControlParams {
    fn default() -> Self {
        Self {
            tau: 0.3,
            epsilon: 0.1,
            p_c: 0.9,
            q: QParams::default(),
            strategy: Strategy::Greedy,
            assumed_accuracy: 0.75,
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
        let a = self.assumed_accuracy;
        if !(a.is_finite() && a > 0.5 && a <= 1.0) {
            return bad(format!("assumed_accuracy = {a} must be in (0.5, 1]"));
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
/// (every cell), updated after each action by eq. (4), and an
/// epsilon-randomised choice of the next action by the [`Strategy`]: towards
/// the most probable goal (greedy), or the most informative one.
#[derive(Debug, Clone)]
pub struct GridController {
    params: GridControlParams,
    table: QTable,
    /// Eq. (3) at `params.tau`: `softmax[goal_index * n_cells + cell_index]`.
    softmax: Vec<[f64; 5]>,
    /// For info gain (empty for greedy), indexed like `softmax`: ln of
    /// eq. (4) for each action when the decoder says error (p(error) =
    /// alpha) and says correct (1 - alpha).
    ln_likelihood: Vec<[[f64; 2]; 5]>,
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
    /// grid and the reward model). Computes the soft-max (eq. 3) of every
    /// goal and cell once.
    pub fn with_table(table: QTable, params: GridControlParams) -> Self {
        let grid = *table.grid();
        let n = grid.n_cells();
        let mut softmax = Vec::with_capacity(n * n);
        for goal in grid.cells() {
            for cell in grid.cells() {
                softmax.push(table.softmax(goal, cell, params.tau));
            }
        }
        let alpha = params.assumed_accuracy;
        let ln_likelihood = match params.strategy {
            Strategy::Greedy => Vec::new(),
            Strategy::InfoGain => softmax
                .iter()
                .map(|q| {
                    q.map(|q| {
                        [
                            policy_likelihood(q, alpha).ln(),
                            policy_likelihood(q, 1.0 - alpha).ln(),
                        ]
                    })
                })
                .collect(),
        };
        Self {
            params,
            table,
            softmax,
            ln_likelihood,
            belief: Belief::uniform(n),
        }
    }

    /// Eq. (3): Q^_goal(cell, .), from the table made at construction.
    fn q_hat(&self, goal_index: usize, cell_index: usize) -> &[f64; 5] {
        &self.softmax[goal_index * self.table.grid().n_cells() + cell_index]
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

    /// With probability epsilon a uniformly random action; otherwise, by
    /// the strategy, the optimal action for the most probable goal
    /// ([`Strategy::Greedy`], the paper's epsilon-greedy) or the action of
    /// largest [`information_gain`](Self::information_gain)
    /// ([`Strategy::InfoGain`]); gains within 1e-12 of the largest tie, and
    /// ties go to the greedy action, then to the first in
    /// [`GridAction::ALL`]. Both strategies draw the same random numbers.
    pub fn choose(&self, cell: Cell, rng: &mut impl Rng) -> GridAction {
        if self.params.epsilon > 0.0 && rng.random::<f64>() < self.params.epsilon {
            return GridAction::ALL[rng.random_range(0..GridAction::ALL.len())];
        }
        let greedy = self.table.greedy(self.most_probable().0, cell);
        match self.params.strategy {
            Strategy::Greedy => greedy,
            Strategy::InfoGain => {
                let b = self.belief.probabilities();
                let ln_b: Vec<f64> = b.iter().map(|v| v.ln()).collect();
                let gains = GridAction::ALL.map(|a| self.gain(&b, &ln_b, cell, a));
                let best = gains.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let tied = |a: GridAction| gains[a.index()] >= best - 1e-12;
                if tied(greedy) {
                    greedy
                } else {
                    GridAction::ALL
                        .into_iter()
                        .find(|&a| tied(a))
                        .unwrap_or(greedy)
                }
            }
        }
    }

    /// The expected information gain of `action` at `cell`, nats
    /// ([`expected_information_gain`](crate::expected_information_gain)): the
    /// user judges it an error for goal i iff `!grid.is_correct(cell, action,
    /// i)`, the decoder reports that judgement with the assumed accuracy
    /// alpha, as p(error) = alpha when it says error and 1 - alpha when it
    /// says correct, and the belief would be updated by eq. (4).
    pub fn information_gain(&self, cell: Cell, action: GridAction) -> f64 {
        let b = self.belief.probabilities();
        let ln_b: Vec<f64> = b.iter().map(|v| v.ln()).collect();
        self.gain(&b, &ln_b, cell, action)
    }

    /// [`expected_information_gain`](crate::expected_information_gain) with
    /// the logarithms looked up rather than computed (the same value within
    /// rounding).
    fn gain(&self, belief: &[f64], ln_belief: &[f64], cell: Cell, action: GridAction) -> f64 {
        let grid = self.table.grid();
        let n = grid.n_cells();
        let (c, a) = (grid.index(cell), action.index());
        let alpha = self.params.assumed_accuracy;
        let ln_l = |i: usize, says_error: bool| match self.ln_likelihood.get(i * n + c) {
            Some(t) => t[a][usize::from(!says_error)],
            None => {
                let p = if says_error { alpha } else { 1.0 - alpha };
                policy_likelihood(self.q_hat(i, c)[a], p).ln()
            }
        };
        gain_from_logs(
            belief,
            |i| ln_belief[i],
            alpha,
            |i| f64::from(u8::from(!grid.is_correct(cell, action, grid.cell(i)))),
            |i, says_error| {
                let p = if says_error { alpha } else { 1.0 - alpha };
                (
                    policy_likelihood(self.q_hat(i, c)[a], p),
                    ln_l(i, says_error),
                )
            },
        )
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
        let c = self.table.grid().index(cell);
        (0..self.table.grid().n_cells())
            .map(|goal| policy_likelihood(self.q_hat(goal, c)[action.index()], p_error))
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
            (
                GridControlParams {
                    assumed_accuracy: 0.5,
                    ..Default::default()
                },
                "assumed_accuracy",
            ),
            (
                GridControlParams {
                    assumed_accuracy: f64::NAN,
                    ..Default::default()
                },
                "assumed_accuracy",
            ),
        ] {
            let e = p.validate().unwrap_err().to_string();
            assert!(e.contains(field), "{e}");
        }
    }

    fn info_gain() -> GridControlParams {
        GridControlParams {
            strategy: Strategy::InfoGain,
            ..GridControlParams::default()
        }
    }

    /// A belief with `mass` spread evenly over `goals`, the rest over the
    /// other cells.
    fn set_belief(c: &mut GridController, goals: &[Cell], mass: f64) {
        let g = *c.table().grid();
        let rest = (1.0 - mass) / (g.n_cells() - goals.len()) as f64;
        let w: Vec<f64> = g
            .cells()
            .map(|cell| {
                if goals.contains(&cell) {
                    mass / goals.len() as f64
                } else {
                    rest
                }
            })
            .collect();
        c.belief = Belief::uniform(g.n_cells());
        c.belief.update(&w).unwrap();
    }

    #[test]
    fn info_gain_splits_two_goals_the_greedy_action_cannot_tell_apart() {
        // Goals (1, 4) and (3, 4) seen from (2, 2): up is right for both,
        // so it tells nothing; left and right each split them.
        let mut c = GridController::new(
            Grid::paper(),
            GridControlParams {
                epsilon: 0.0,
                ..info_gain()
            },
        )
        .unwrap();
        let (a, b) = (Cell::new(1, 4), Cell::new(3, 4));
        let here = Cell::new(2, 2);
        set_belief(&mut c, &[a, b], 1.0);
        assert_eq!(c.table().greedy(c.most_probable().0, here), GridAction::Up);
        assert!(c.information_gain(here, GridAction::Up).abs() < 1e-12);
        let left = c.information_gain(here, GridAction::Left);
        assert!(left > 1e-3, "{left}");
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        assert_eq!(
            c.choose(here, &mut rng),
            GridAction::Left,
            "tie: lower index"
        );
        // Certain: every gain is 0, the greedy action wins the tie.
        set_belief(&mut c, &[a], 1.0);
        assert_eq!(c.choose(here, &mut rng), GridAction::Up);
        // Uniform: no posterior has more entropy, so no gain is negative.
        c.belief = Belief::uniform(25);
        let gains = GridAction::ALL.map(|a| c.information_gain(here, a));
        assert!(
            gains.iter().all(|g| g.is_finite() && *g >= -1e-12),
            "{gains:?}"
        );
    }

    /// The epsilon-greedy choice as it was before strategies existed.
    fn old_choose(c: &GridController, cell: Cell, rng: &mut impl Rng) -> GridAction {
        let p = c.params();
        if p.epsilon > 0.0 && rng.random::<f64>() < p.epsilon {
            GridAction::ALL[rng.random_range(0..GridAction::ALL.len())]
        } else {
            c.table().greedy(c.most_probable().0, cell)
        }
    }

    /// Eq. (4) as it was computed before the soft-max table.
    fn old_likelihoods(c: &GridController, cell: Cell, action: GridAction, p: f64) -> Vec<f64> {
        let grid = *c.table().grid();
        grid.cells()
            .map(|goal| {
                let q_hat = c.table().softmax(goal, cell, c.params().tau)[action.index()];
                policy_likelihood(q_hat, p)
            })
            .collect()
    }

    #[test]
    fn greedy_is_unchanged_by_the_strategy_machinery() {
        let g = Grid::paper();
        for tau in [0.3, 0.05] {
            let params = GridControlParams {
                tau,
                ..GridControlParams::default()
            };
            let mut c = GridController::new(g, params).unwrap();
            let mut rng = ChaCha8Rng::seed_from_u64(21);
            let mut old_rng = rng.clone();
            let mut world = ChaCha8Rng::seed_from_u64(22);
            let mut cell = Cell::new(0, 0);
            for _ in 0..2000 {
                let a = c.choose(cell, &mut rng);
                assert_eq!(a, old_choose(&c, cell, &mut old_rng));
                let p = world.random::<f64>();
                let l = c.likelihoods(cell, a, p);
                let old = old_likelihoods(&c, cell, a, p);
                assert!(l.iter().zip(&old).all(|(x, y)| x.to_bits() == y.to_bits()));
                c.observe(cell, a, p).unwrap();
                cell = g.step(cell, a);
                if c.converged().is_some() {
                    c.belief = Belief::uniform(25);
                }
            }
            assert_eq!(rng, old_rng, "same draws");
        }
    }

    #[test]
    fn info_gain_draws_the_same_random_numbers_as_greedy() {
        let g = Grid::paper();
        let greedy = controller();
        let info = GridController::new(g, info_gain()).unwrap();
        let mut r1 = ChaCha8Rng::seed_from_u64(5);
        let mut r2 = r1.clone();
        for k in 0..500 {
            let cell = g.cell(k % 25);
            greedy.choose(cell, &mut r1);
            info.choose(cell, &mut r2);
        }
        assert_eq!(r1, r2);
    }

    #[test]
    fn the_precomputed_gain_is_the_formula() {
        // The table lookups agree with expected_information_gain on eq. (4)
        // computed afresh, for an info-gain controller (logarithm table) and
        // a greedy one (no table).
        let g = Grid::paper();
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let mut info = GridController::new(g, info_gain()).unwrap();
        let mut greedy = controller();
        let alpha = info.params().assumed_accuracy;
        for _ in 0..300 {
            let (cell, action) = (
                g.cell(rng.random_range(0..25)),
                GridAction::ALL[rng.random_range(0..5)],
            );
            let p = rng.random::<f64>();
            info.observe(cell, action, p).unwrap();
            greedy.observe(cell, action, p).unwrap();
            let b = info.belief().probabilities();
            for a in GridAction::ALL {
                let (le, lc) = (
                    info.likelihoods(cell, a, alpha),
                    info.likelihoods(cell, a, 1.0 - alpha),
                );
                let want = crate::strategy::expected_information_gain(
                    &b,
                    alpha,
                    |i| f64::from(u8::from(!g.is_correct(cell, a, g.cell(i)))),
                    |i, says_error| if says_error { le[i] } else { lc[i] },
                );
                let got = info.information_gain(cell, a);
                assert!((got - want).abs() < 1e-12, "{got} vs {want}");
                assert!((greedy.information_gain(cell, a) - want).abs() < 1e-12);
            }
        }
    }
}
