//! Eq. (3) and (4) of the paper: each candidate goal's policy over the five
//! actions (the soft-max of its Q-values) and the likelihood of that policy
//! given an action and the decoder's p(error), the one update the grid's
//! belief is made of.

use crate::grid::qvalues::QTable;

/// Eq. (4): the likelihood of policy i given the action and the decoder's
/// output, p(c=0|x) Q^_i(s,a) + p(c=1|x) (1 - Q^_i(s,a)).
pub fn policy_likelihood(q_hat: f64, p_error: f64) -> f64 {
    (1.0 - p_error) * q_hat + p_error * (1.0 - q_hat)
}

/// Every goal's policy at every cell (eq. 3, computed once from the
/// Q-values), with what eq. (4) gives of them.
#[derive(Debug, Clone)]
pub(crate) struct Policies {
    /// Cells of the grid.
    n_cells: usize,
    /// Eq. (3) at tau: `softmax[goal_index * n_cells + cell_index]`.
    softmax: Vec<[f64; 5]>,
    /// For information gain (empty otherwise), indexed like `softmax`: ln
    /// of eq. (4) for each action when the decoder says error (p(error) =
    /// alpha) and says correct (1 - alpha).
    ln_likelihood: Vec<[[f64; 2]; 5]>,
}

impl Policies {
    /// The policies of every goal of `table`'s grid at temperature `tau`;
    /// with `assumed` (the decoder's assumed accuracy alpha), also the log
    /// of eq. (4) when the decoder says error or correct.
    pub(crate) fn new(table: &QTable, tau: f64, assumed: Option<f64>) -> Self {
        let grid = *table.grid();
        let n_cells = grid.n_cells();
        let mut softmax = Vec::with_capacity(n_cells * n_cells);
        for goal in grid.cells() {
            for cell in grid.cells() {
                softmax.push(table.softmax(goal, cell, tau));
            }
        }
        let ln_likelihood = match assumed {
            None => Vec::new(),
            Some(alpha) => softmax
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
            n_cells,
            softmax,
            ln_likelihood,
        }
    }

    /// Eq. (3): Q^_goal(cell, .).
    pub(crate) fn q_hat(&self, goal_index: usize, cell_index: usize) -> &[f64; 5] {
        &self.softmax[goal_index * self.n_cells + cell_index]
    }

    /// Eq. (4) of `action` at `cell` for every goal, given `p_error`,
    /// indexed like the grid's cells.
    pub(crate) fn likelihoods(&self, cell_index: usize, action: usize, p_error: f64) -> Vec<f64> {
        (0..self.n_cells)
            .map(|goal| policy_likelihood(self.q_hat(goal, cell_index)[action], p_error))
            .collect()
    }

    /// The log of eq. (4) of goal `goal_index` for `action` at `cell_index`
    /// when the decoder says error (`says_error`: p(error) = alpha) or
    /// correct (1 - alpha): looked up when made with `assumed`.
    pub(crate) fn ln_likelihood(
        &self,
        (goal_index, cell_index, action): (usize, usize, usize),
        says_error: bool,
        alpha: f64,
    ) -> f64 {
        match self
            .ln_likelihood
            .get(goal_index * self.n_cells + cell_index)
        {
            Some(t) => t[action][usize::from(!says_error)],
            None => {
                let p = if says_error { alpha } else { 1.0 - alpha };
                policy_likelihood(self.q_hat(goal_index, cell_index)[action], p).ln()
            }
        }
    }
}
