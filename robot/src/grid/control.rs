//! Shared control of the grid cursor: policy matching over Q-values from a
//! probability of error (sec. 4.2 of the paper).

use rand::Rng;
use serde::{Deserialize, Serialize};

use errp_valid::{Check, Valid};

use crate::belief::Belief;
use crate::error::{Result, RobotError, check};
use crate::grid::policy::{Policies, policy_likelihood};
use crate::grid::qvalues::{QParams, QTable};
use crate::grid::{Cell, Grid, GridAction};
use crate::strategy::{Strategy, gain_from_logs};

/// The Q-value scale of the shipped grid strategy (`goal_reward`, at the
/// paper's tau = 0.3), estimated from Table 1 by `errp fit grid`
/// (`fits/grid.json`, its `reached_estimate`): the goal reward of largest
/// likelihood for the four subjects' fixed-goal actions among those at
/// which the paper's 40 reached goals keep a probability of at least 5 %,
/// fitted jointly with the fixed pairs' total length (8).
pub const FITTED_GOAL_REWARD: f64 = 5.0;

/// Parameters of the grid strategy, as a scenario file's `[control]` table
/// holds them (deserialized straight into this type; missing fields take
/// the defaults, unknown ones are refused).
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
    /// Discount factor gamma of the Q-values' reward model ([`QParams`]), in
    /// [0, 1).
    pub discount: f64,
    /// Reward of goal-reached on the goal ([`QParams`]).
    pub goal_reward: f64,
    /// Reward of goal-reached anywhere else ([`QParams`]).
    pub wrong_goal_reward: f64,
    /// How the non-random actions are chosen (the paper: greedy).
    pub strategy: Strategy,
    /// The decoder accuracy the device assumes when it predicts the
    /// decoder's outcomes for [`Strategy::InfoGain`]. In (0.5, 1]. Not read
    /// from a file: the device knows it from the calibration.
    #[serde(skip)]
    pub assumed_accuracy: f64,
}

impl Default for GridControlParams {
    fn default() -> Self {
        Self {
            tau: 0.3,
            epsilon: 0.1,
            p_c: 0.9,
            discount: QParams::default().discount,
            goal_reward: FITTED_GOAL_REWARD,
            wrong_goal_reward: QParams::default().wrong_goal_reward,
            strategy: Strategy::Greedy,
            assumed_accuracy: 0.75,
        }
    }
}

/// Checked where a scenario enters (the reward model of the Q-values
/// with it); the controller takes it checked.
impl Check for GridControlParams {
    type Error = RobotError;

    fn check(&self) -> Result<()> {
        self.validate()
    }
}

impl GridControlParams {
    /// The reward model of the Q-values.
    pub fn q(&self) -> QParams {
        QParams {
            goal_reward: self.goal_reward,
            wrong_goal_reward: self.wrong_goal_reward,
            discount: self.discount,
        }
    }

    /// Checks every field; messages name the field and the accepted range.
    fn validate(&self) -> Result<()> {
        check(
            self.tau.is_finite() && self.tau > 0.0,
            "tau",
            self.tau,
            "a number > 0 (the paper: 0.3)",
        )?;
        check(
            self.epsilon.is_finite() && (0.0..=1.0).contains(&self.epsilon),
            "epsilon",
            self.epsilon,
            "a probability in [0, 1]",
        )?;
        check(
            self.p_c.is_finite() && self.p_c > 0.0 && self.p_c < 1.0,
            "p_c",
            self.p_c,
            "a probability in (0, 1) (the paper: 0.9)",
        )?;
        let a = self.assumed_accuracy;
        check(
            a.is_finite() && a > 0.5 && a <= 1.0,
            "assumed_accuracy",
            a,
            "a mean accuracy in (0.5, 1]",
        )?;
        self.q().validate()
    }
}

/// Thompson gives up its drawn goal when the decoder's p(error) for the
/// last action is at least this: the user objected.
const THOMPSON_OBJECTION: f64 = 0.5;

/// Thompson gives up its drawn goal when the goal's probability falls below
/// this fraction of the most probable goal's. Measured in the closed loop
/// (`tests/it/grid_strategies.rs`, 200 and 1000 episodes, decoder accuracy 0.8
/// and 0.65) against 0 (never), 1/25, 1/10, 1/4, 3/4 and 1: 1/2 and 3/4 were
/// best and close; 1 (give up as soon as another goal leads) is worse.
const THOMPSON_GIVE_UP_RATIO: f64 = 0.5;

/// The device's side of the grid task: a belief over the 25 candidate goals
/// (every cell), updated after each action by eq. (4), and an
/// epsilon-randomised choice of the next action by the [`Strategy`]: towards
/// the most probable goal (greedy), the most informative one (info gain), or
/// a goal drawn from the belief and kept until the user objects or the
/// belief moves away from it (Thompson; see
/// [`observe`](GridController::observe)).
#[derive(Debug, Clone)]
pub struct GridController {
    params: Valid<GridControlParams>,
    table: QTable,
    /// Every goal's policy (eq. 3) and its likelihood (eq. 4).
    policies: Policies,
    belief: Belief,
    /// For Thompson: the goal drawn and not yet given up (see
    /// [`choose`](Self::choose) and [`observe`](Self::observe)).
    draw: Option<Cell>,
}

impl GridController {
    /// A controller with a uniform belief over every cell of `grid`.
    pub fn new(grid: Grid, params: Valid<GridControlParams>) -> Result<Self> {
        // The control parameters' checks include the reward model's.
        let table = QTable::compute(grid, &params.part(GridControlParams::q))?;
        Ok(Self::with_table(table, params))
    }

    /// A controller reusing precomputed Q-values (they depend only on the
    /// grid and the reward model). Computes the soft-max (eq. 3) of every
    /// goal and cell once.
    pub fn with_table(table: QTable, params: Valid<GridControlParams>) -> Self {
        let n = table.grid().n_cells();
        let assumed = match params.strategy {
            Strategy::Greedy | Strategy::Thompson => None,
            Strategy::InfoGain => Some(params.assumed_accuracy),
        };
        let policies = Policies::new(&table, params.tau, assumed);
        Self {
            params,
            table,
            policies,
            belief: Belief::uniform(n),
            draw: None,
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

    /// With probability epsilon a uniformly random action; otherwise, by
    /// the strategy:
    /// - [`Strategy::Greedy`] (the paper's epsilon-greedy): the optimal
    ///   action for the most probable goal;
    /// - [`Strategy::InfoGain`]: the action of largest
    ///   [`information_gain`](Self::information_gain); gains within 1e-12 of
    ///   the largest tie, and ties go to the greedy action, then to the first
    ///   in [`GridAction::ALL`];
    /// - [`Strategy::Thompson`]: the optimal action for the drawn goal
    ///   ([`drawn_goal`](Self::drawn_goal)); when there is none, a goal is
    ///   drawn from the belief ([`sample_goal`](Self::sample_goal)) and kept
    ///   until [`observe`](Self::observe) gives it up ("sticky" posterior
    ///   sampling, as in posterior sampling with episodes).
    ///
    /// The epsilon draw comes first for every strategy, and a random action
    /// leaves Thompson's draw in place. Greedy and info gain draw the same
    /// random numbers (one `f64` for epsilon, and an index when it hits);
    /// Thompson draws the same, plus one `f64` for the goal whenever epsilon
    /// misses and it holds no draw.
    pub fn choose(&mut self, cell: Cell, rng: &mut impl Rng) -> GridAction {
        if self.params.epsilon > 0.0 && rng.random::<f64>() < self.params.epsilon {
            return GridAction::ALL[rng.random_range(0..GridAction::ALL.len())];
        }
        match self.params.strategy {
            Strategy::Greedy => self.table.greedy(self.most_probable().0, cell),
            Strategy::InfoGain => self.most_informative(cell),
            Strategy::Thompson => {
                let goal = match self.draw {
                    Some(goal) => goal,
                    None => {
                        let goal = self.sample_goal(rng);
                        self.draw = Some(goal);
                        goal
                    }
                };
                self.table.greedy(goal, cell)
            }
        }
    }

    /// The goal [`Strategy::Thompson`] is heading for, if it holds a draw
    /// (always `None` for the other strategies).
    pub fn drawn_goal(&self) -> Option<Cell> {
        self.draw
    }

    /// The info-gain choice at `cell` (see [`choose`](Self::choose)).
    fn most_informative(&self, cell: Cell) -> GridAction {
        let greedy = self.table.greedy(self.most_probable().0, cell);
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

    /// A goal drawn from the belief, with one `rng.random::<f64>()` u: the
    /// first cell, in index order, at which the cumulative probability
    /// exceeds u times the total (the total is 1 up to rounding; a draw
    /// that rounding leaves past the end goes to the last goal of non-zero
    /// probability).
    pub fn sample_goal(&self, rng: &mut impl Rng) -> Cell {
        let b = self.belief.probabilities();
        let u = rng.random::<f64>() * b.iter().sum::<f64>();
        let mut cumulative = 0.0;
        let mut last = 0;
        for (i, &p) in b.iter().enumerate() {
            if p <= 0.0 {
                continue;
            }
            cumulative += p;
            last = i;
            if u < cumulative {
                break;
            }
        }
        self.table.grid().cell(last)
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

        let (c, a) = (grid.index(cell), action.index());
        let alpha = self.params.assumed_accuracy;
        let ln_l =
            |i: usize, says_error: bool| self.policies.ln_likelihood((i, c, a), says_error, alpha);
        gain_from_logs(
            belief,
            |i| ln_belief[i],
            alpha,
            |i| f64::from(u8::from(!grid.is_correct(cell, action, grid.cell(i)))),
            |i, says_error| {
                let p = if says_error { alpha } else { 1.0 - alpha };
                (
                    policy_likelihood(self.policies.q_hat(i, c)[a], p),
                    ln_l(i, says_error),
                )
            },
        )
    }

    /// Updates the belief after `action` at `cell`, given the decoder's
    /// p(error) for it (eq. 4 for every goal, then Bayes' rule).
    ///
    /// Thompson's drawn goal, if any, is then given up (the next
    /// [`choose`](Self::choose) that is not epsilon-random draws again) when
    /// either
    /// - p(error) >= 0.5: the user objected to the action (whichever action
    ///   it was, the drawn goal's goal-reached included), or
    /// - the drawn goal's probability is below 1/2 of the most probable
    ///   goal's: the evidence has moved on.
    ///
    /// A goal-reached judged correct does not give the draw up: the cursor
    /// stays and repeats it, which is how greedy converges too. Giving up
    /// after every goal-reached (the draw "has been tested") was measured
    /// worse (at decoder accuracy 0.65, 200 episodes: 72 % of goals found
    /// against 80.5 %), because one assessment of a 65-80 % decoder rarely
    /// settles a goal and redrawing walks the cursor away from it.
    pub fn observe(&mut self, cell: Cell, action: GridAction, p_error: f64) -> Result<()> {
        if !(p_error.is_finite() && (0.0..=1.0).contains(&p_error)) {
            return Err(RobotError::Likelihood(format!(
                "p(error) = {p_error} is not a probability"
            )));
        }
        let likelihoods = self.likelihoods(cell, action, p_error);
        self.belief.update(&likelihoods)?;
        if let Some(goal) = self.draw {
            let objected = p_error >= THOMPSON_OBJECTION;
            let overtaken = self.belief.probability(self.table.grid().index(goal))
                < THOMPSON_GIVE_UP_RATIO * self.most_probable().1;
            if objected || overtaken {
                self.draw = None;
            }
        }
        Ok(())
    }

    /// Eq. (4) for every goal, indexed like the grid's cells.
    pub fn likelihoods(&self, cell: Cell, action: GridAction, p_error: f64) -> Vec<f64> {
        let c = self.table.grid().index(cell);
        self.policies.likelihoods(c, action.index(), p_error)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn controller() -> GridController {
        GridController::new(
            Grid::paper(),
            Valid::new(GridControlParams::default()).unwrap(),
        )
        .unwrap()
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
            // A nearly hard soft-max: tau 0.01 at goal reward 2. (At the
            // shipped goal reward 5 and tau 0.01 a p(error) of exactly 0 or
            // 1 can leave every goal at likelihood 0, which `observe`
            // refuses with an error rather than a NaN belief.)
            GridControlParams {
                tau: 0.01,
                goal_reward: 2.0,
                ..GridControlParams::default()
            },
        ] {
            let mut c = GridController::new(g, Valid::new(params).unwrap()).unwrap();
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
            Valid::new(GridControlParams {
                epsilon: 0.0,
                ..info_gain()
            })
            .unwrap(),
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
            let mut c = GridController::new(g, Valid::new(params).unwrap()).unwrap();
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
        let mut greedy = controller();
        let mut info = GridController::new(g, Valid::new(info_gain()).unwrap()).unwrap();
        let mut r1 = ChaCha8Rng::seed_from_u64(5);
        let mut r2 = r1.clone();
        for k in 0..500 {
            let cell = g.cell(k % 25);
            greedy.choose(cell, &mut r1);
            info.choose(cell, &mut r2);
        }
        assert_eq!(r1, r2);
    }

    fn thompson(epsilon: f64) -> GridController {
        GridController::new(
            Grid::paper(),
            Valid::new(GridControlParams {
                strategy: Strategy::Thompson,
                epsilon,
                ..GridControlParams::default()
            })
            .unwrap(),
        )
        .unwrap()
    }

    /// A belief with probability `p[k]` on `goals[k]`, 0 elsewhere.
    fn set_weights(c: &mut GridController, goals: &[Cell], p: &[f64]) {
        let g = *c.table().grid();
        let w: Vec<f64> = g
            .cells()
            .map(|cell| goals.iter().position(|&x| x == cell).map_or(0.0, |k| p[k]))
            .collect();
        c.belief = Belief::uniform(g.n_cells());
        c.belief.update(&w).unwrap();
    }

    #[test]
    fn thompson_draws_goals_in_proportion_to_the_belief() {
        // Goals (0, 2) and (4, 2) seen from (2, 2): left for one, right for
        // the other; greedy would always go left.
        let mut c = thompson(0.0);
        let (a, b) = (Cell::new(0, 2), Cell::new(4, 2));
        let here = Cell::new(2, 2);
        set_weights(&mut c, &[a, b], &[0.7, 0.3]);
        assert_eq!(c.table().greedy(a, here), GridAction::Left);
        assert_eq!(c.table().greedy(b, here), GridAction::Right);
        let mut rng = ChaCha8Rng::seed_from_u64(31);
        let n = 2000;
        let mut left = 0;
        for _ in 0..n {
            // A fresh draw each time (no observation gives it up here).
            c.draw = None;
            match c.choose(here, &mut rng) {
                GridAction::Left => left += 1,
                GridAction::Right => {}
                other => panic!("{other:?} is greedy for neither goal"),
            }
        }
        let share = f64::from(left) / f64::from(n);
        assert!((share - 0.7).abs() < 0.04, "{share}");
        // A uniform belief: every cell gets drawn (25 x 80 expected each).
        c.belief = Belief::uniform(25);
        let mut seen = [0u32; 25];
        for _ in 0..n {
            seen[c.table().grid().index(c.sample_goal(&mut rng))] += 1;
        }
        assert!(seen.iter().all(|&k| (40..=130).contains(&k)), "{seen:?}");
    }

    #[test]
    fn thompson_keeps_its_draw_until_the_user_objects_or_it_falls_behind() {
        let g = Grid::paper();
        let (a, b) = (Cell::new(0, 2), Cell::new(4, 2));
        let here = Cell::new(2, 2);
        // Find a seed whose first draw is the less probable goal b.
        let mut c = thompson(0.0);
        let mut rng = (0..)
            .map(ChaCha8Rng::seed_from_u64)
            .find(|r| {
                set_weights(&mut c, &[a, b], &[0.6, 0.4]);
                c.draw = None;
                c.choose(here, &mut r.clone()) == GridAction::Right
            })
            .unwrap();
        set_weights(&mut c, &[a, b], &[0.6, 0.4]);
        c.draw = None;
        // Sticky: no further draws while it holds b, whatever the cell.
        assert_eq!(c.choose(here, &mut rng), GridAction::Right);
        assert_eq!(c.drawn_goal(), Some(b));
        let frozen = rng.clone();
        for k in 0..50 {
            let cell = g.cell(k % 25);
            assert_eq!(c.choose(cell, &mut rng), c.table().greedy(b, cell));
        }
        assert_eq!(rng, frozen, "no draw while one is held");
        // A correct assessment keeps it, and so does a goal-reached at b
        // judged correct (the cursor stays and tries again).
        c.observe(here, GridAction::Right, 0.2).unwrap();
        assert_eq!(c.drawn_goal(), Some(b));
        c.observe(b, GridAction::GoalReached, 0.2).unwrap();
        assert_eq!(c.drawn_goal(), Some(b));
        // An objection gives it up; the next choice draws again.
        c.observe(here, GridAction::Right, 0.5).unwrap();
        assert_eq!(c.drawn_goal(), None);
        c.choose(here, &mut rng);
        assert_ne!(rng, frozen);
        assert!(c.drawn_goal().is_some());
        // Falling below half the leader's probability gives it up too.
        c.draw = Some(b);
        set_weights(&mut c, &[a, b], &[0.6, 0.4]);
        c.observe(here, GridAction::Up, 0.2).unwrap();
        assert_eq!(c.drawn_goal(), Some(b), "0.4 > 0.6 / 2");
        set_weights(&mut c, &[a, b], &[0.7, 0.3]);
        c.observe(here, GridAction::Up, 0.2).unwrap();
        assert_eq!(c.drawn_goal(), None, "0.3 < 0.7 / 2");
        // Epsilon's random actions leave the draw in place.
        let mut c = thompson(1.0);
        c.draw = Some(b);
        for k in 0..50 {
            c.choose(g.cell(k % 25), &mut rng);
        }
        assert_eq!(c.drawn_goal(), Some(b));
        // The other strategies never hold a draw.
        for mut c in [
            controller(),
            GridController::new(g, Valid::new(info_gain()).unwrap()).unwrap(),
        ] {
            for k in 0..50 {
                c.choose(g.cell(k % 25), &mut rng);
                c.observe(g.cell(k % 25), GridAction::Up, 0.3).unwrap();
            }
            assert_eq!(c.drawn_goal(), None);
        }
    }

    #[test]
    fn thompson_keeps_epsilon_and_is_greedy_when_certain() {
        // Epsilon first, with the same draws as greedy: with epsilon = 1
        // both take the same random actions from the same stream.
        let g = Grid::paper();
        let mut greedy = GridController::new(
            g,
            Valid::new(GridControlParams {
                epsilon: 1.0,
                ..GridControlParams::default()
            })
            .unwrap(),
        )
        .unwrap();
        let mut th = thompson(1.0);
        let mut r1 = ChaCha8Rng::seed_from_u64(7);
        let mut r2 = r1.clone();
        for k in 0..500 {
            let cell = g.cell(k % 25);
            assert_eq!(greedy.choose(cell, &mut r1), th.choose(cell, &mut r2));
        }
        assert_eq!(r1, r2);
        // A certain belief: the drawn goal is the most probable one.
        let mut th = thompson(0.0);
        let goal = Cell::new(3, 1);
        set_weights(&mut th, &[goal], &[1.0]);
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        for k in 0..200 {
            let cell = g.cell(k % 25);
            assert_eq!(th.choose(cell, &mut rng), th.table().greedy(goal, cell));
        }
    }

    #[test]
    fn the_precomputed_gain_is_the_formula() {
        // The table lookups agree with expected_information_gain on eq. (4)
        // computed afresh, for an info-gain controller (logarithm table) and
        // a greedy one (no table).
        let g = Grid::paper();
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let mut info = GridController::new(g, Valid::new(info_gain()).unwrap()).unwrap();
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
