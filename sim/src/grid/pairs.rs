//! The fixed goals' start/goal pairs as a family with one parameter, their
//! total Manhattan length, so that `errp fit grid` can estimate how hard the
//! paper's pairs were instead of choosing them.
//!
//! Fig. 4 of the paper marks each fixed run's start and goal, but its
//! positions cannot be read from the text. The one thing the text says of
//! them: "during run 3, mostly all the central states were visited, whereas
//! the peripheral states were not". A pair set of the family is five
//! distinct start/goal pairs (start and goal differ) whose third pair keeps
//! to the centre: the rectangle spanned by its start and goal holds the
//! centre cell, and every cell of it but the start and the goal is central
//! (not on the border). Within a total length, every such set is equally
//! likely: the family marginalises over what the text does not say.

use errp_robot::{Cell, Grid};
use rand::Rng;

/// The run (0-based) that keeps to the centre (the paper's run 3).
pub const CENTRAL_RUN: usize = 2;

/// Pairs per set (the paper's five fixed runs).
pub const PAIRS_PER_SET: usize = 5;

/// Manhattan length of a pair.
pub fn manhattan(start: Cell, goal: Cell) -> usize {
    start.x.abs_diff(goal.x) + start.y.abs_diff(goal.y)
}

/// The total Manhattan length of `pairs`.
pub fn total_length(pairs: &[(Cell, Cell)]) -> usize {
    pairs.iter().map(|&(s, g)| manhattan(s, g)).sum()
}

/// `pairs` as text: `(x,y)->(x,y)` each, space-separated.
pub fn pairs_text(pairs: &[(Cell, Cell)]) -> String {
    pairs
        .iter()
        .map(|(s, g)| format!("({},{})->({},{})", s.x, s.y, g.x, g.y))
        .collect::<Vec<_>>()
        .join(" ")
}

/// True if a run from `start` to `goal` keeps to the centre of `grid`: the
/// rectangle they span holds the centre cell, and all of its cells but
/// `start` and `goal` are off the border.
pub fn keeps_to_the_centre(grid: &Grid, start: Cell, goal: Cell) -> bool {
    let (w, h) = (grid.width, grid.height);
    let centre = Cell::new(w / 2, h / 2);
    let (x0, x1) = (start.x.min(goal.x), start.x.max(goal.x));
    let (y0, y1) = (start.y.min(goal.y), start.y.max(goal.y));
    if !((x0..=x1).contains(&centre.x) && (y0..=y1).contains(&centre.y)) {
        return false;
    }
    (x0..=x1).all(|x| {
        (y0..=y1).all(|y| {
            let c = Cell::new(x, y);
            c == start || c == goal || (x > 0 && y > 0 && x + 1 < w && y + 1 < h)
        })
    })
}

/// Every start/goal pair of `grid` a run of the set may have (run `k`,
/// 0-based), grouped by Manhattan length: `by_length[d]`.
fn candidates(grid: &Grid, k: usize) -> Vec<Vec<(Cell, Cell)>> {
    let n = grid.n_cells();
    let mut by_length = vec![Vec::new(); grid.width + grid.height];
    for i in 0..n {
        for j in 0..n {
            let (s, g) = (grid.cell(i), grid.cell(j));
            if s != g && (k != CENTRAL_RUN || keeps_to_the_centre(grid, s, g)) {
                by_length[manhattan(s, g)].push((s, g));
            }
        }
    }
    by_length
}

/// The fixed-goal pair sets of `grid`, by total length.
#[derive(Debug, Clone)]
pub struct PairFamily {
    grid: Grid,
    /// `candidates[k][d]`: run k's pairs of length d.
    candidates: Vec<Vec<Vec<(Cell, Cell)>>>,
    /// `ways[k][t]`: the number of choices of runs k.. (pairs not yet
    /// required distinct) of total length t.
    ways: Vec<Vec<f64>>,
}

impl PairFamily {
    /// The family on `grid`.
    pub fn new(grid: Grid) -> Self {
        let candidates: Vec<_> = (0..PAIRS_PER_SET).map(|k| candidates(&grid, k)).collect();
        let max = (grid.width + grid.height) * PAIRS_PER_SET;
        let mut ways = vec![vec![0.0; max + 1]; PAIRS_PER_SET + 1];
        ways[PAIRS_PER_SET][0] = 1.0;
        for k in (0..PAIRS_PER_SET).rev() {
            for t in 0..=max {
                ways[k][t] = candidates[k]
                    .iter()
                    .enumerate()
                    .filter(|(d, _)| *d <= t)
                    .map(|(d, c)| c.len() as f64 * ways[k + 1][t - d])
                    .sum();
            }
        }
        Self {
            grid,
            candidates,
            ways,
        }
    }

    /// The family on the paper's 5 x 5 grid.
    pub fn paper() -> Self {
        Self::new(Grid::paper())
    }

    /// The total lengths a set can have (5 to 36 on the paper's grid).
    pub fn lengths(&self) -> std::ops::RangeInclusive<usize> {
        let first = self.ways[0].iter().position(|&w| w > 0.0).unwrap_or(0);
        let last = self.ways[0].iter().rposition(|&w| w > 0.0).unwrap_or(0);
        first..=last
    }

    /// Draws a set of total length `total` uniformly among the family's
    /// sets of that length (five distinct pairs, the third keeping to the
    /// centre); `None` if there is none.
    pub fn draw(&self, total: usize, rng: &mut impl Rng) -> Option<Vec<(Cell, Cell)>> {
        if !self.lengths().contains(&total) {
            return None;
        }
        // Distinct pairs by rejection: repeats are rare (at most a few in a
        // hundred draws at the extreme lengths, where few pairs fit).
        for _ in 0..10_000 {
            let mut left = total;
            let mut set = Vec::with_capacity(PAIRS_PER_SET);
            for k in 0..PAIRS_PER_SET {
                let weights: Vec<f64> = self.candidates[k]
                    .iter()
                    .enumerate()
                    .map(|(d, c)| {
                        if d <= left {
                            c.len() as f64 * self.ways[k + 1][left - d]
                        } else {
                            0.0
                        }
                    })
                    .collect();
                let sum: f64 = weights.iter().sum();
                let mut u = rng.random::<f64>() * sum;
                let d = weights
                    .iter()
                    .position(|&w| {
                        u -= w;
                        u < 0.0 && w > 0.0
                    })
                    .unwrap_or_else(|| weights.iter().rposition(|&w| w > 0.0).unwrap_or(0));
                let pool = &self.candidates[k][d];
                set.push(pool[rng.random_range(0..pool.len())]);
                left -= d;
            }
            let distinct = (0..set.len()).all(|i| (0..i).all(|j| set[i] != set[j]));
            if distinct {
                return Some(set);
            }
        }
        None
    }

    /// True if `pairs` is a set of the family (any length).
    pub fn contains(&self, pairs: &[(Cell, Cell)]) -> bool {
        pairs.len() == PAIRS_PER_SET
            && pairs
                .iter()
                .all(|&(s, g)| self.grid.contains(s) && self.grid.contains(g) && s != g)
            && keeps_to_the_centre(&self.grid, pairs[CENTRAL_RUN].0, pairs[CENTRAL_RUN].1)
            && (0..pairs.len()).all(|i| (0..i).all(|j| pairs[i] != pairs[j]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::{CORNER_PAIRS, FIXED_PAIRS};
    use errp_bci::rng::labelled;

    #[test]
    fn the_centre_rule_reads_as_the_paper_describes_run_3() {
        let g = Grid::paper();
        let c = Cell::new;
        // Across the middle row, and the central 3 x 3 block's diagonal.
        assert!(keeps_to_the_centre(&g, c(0, 2), c(4, 2)));
        assert!(keeps_to_the_centre(&g, c(1, 3), c(3, 1)));
        // Corner to corner crosses the border; a pair beside the centre
        // does not span it.
        assert!(!keeps_to_the_centre(&g, c(0, 0), c(4, 4)));
        assert!(!keeps_to_the_centre(&g, c(1, 1), c(1, 3)));
        assert!(!keeps_to_the_centre(&g, c(0, 2), c(3, 3)));
    }

    #[test]
    fn the_shipped_and_the_corner_pairs_are_sets_of_the_family() {
        let family = PairFamily::paper();
        assert!(family.contains(&FIXED_PAIRS));
        assert!(family.contains(&CORNER_PAIRS));
        assert_eq!(total_length(&CORNER_PAIRS), 28);
        assert_eq!(family.lengths(), 5..=36);
    }

    /// Every draw has the asked length and belongs to the family; the
    /// lengths per run spread (not one pattern per total).
    #[test]
    fn draws_have_the_asked_length_and_keep_run_3_central() {
        let family = PairFamily::paper();
        let mut rng = labelled(7, "test");
        for total in family.lengths() {
            let mut patterns = std::collections::BTreeSet::new();
            for _ in 0..40 {
                let set = family.draw(total, &mut rng).expect("a set of each length");
                assert_eq!(total_length(&set), total);
                assert!(family.contains(&set), "{set:?}");
                patterns.insert(
                    set.iter()
                        .map(|&(s, g)| manhattan(s, g))
                        .collect::<Vec<_>>(),
                );
            }
            if (8..=30).contains(&total) {
                assert!(patterns.len() > 5, "{total}: {patterns:?}");
            }
        }
        assert!(family.draw(4, &mut rng).is_none());
        assert!(family.draw(37, &mut rng).is_none());
    }

    /// Uniform over the sets of a length: run 3's length follows the
    /// count of sets with it (checked at total 16 against the exact
    /// shares, 4000 draws).
    #[test]
    fn draws_are_uniform_over_the_sets_of_a_length() {
        let family = PairFamily::paper();
        let total = 16;
        let mut rng = labelled(11, "test");
        let mut seen = [0.0f64; 5];
        let n = 4000;
        for _ in 0..n {
            let set = family.draw(total, &mut rng).expect("a set");
            let (s, g) = set[CENTRAL_RUN];
            seen[manhattan(s, g)] += 1.0 / n as f64;
        }
        for d in 1..=4 {
            let exact = family.candidates[CENTRAL_RUN][d].len() as f64
                * ways_without(&family, CENTRAL_RUN, total - d)
                / family.ways[0][total];
            assert!(
                (seen[d] - exact).abs() < 0.03,
                "{d}: {} against {exact}",
                seen[d]
            );
        }
    }

    /// The number of ways the runs other than `skip` make total `t`.
    fn ways_without(family: &PairFamily, skip: usize, t: usize) -> f64 {
        let mut ways = vec![0.0; t + 1];
        ways[0] = 1.0;
        for k in (0..PAIRS_PER_SET).filter(|&k| k != skip) {
            let mut next = vec![0.0; t + 1];
            for (s, w) in ways.iter().enumerate() {
                for (d, c) in family.candidates[k].iter().enumerate() {
                    if s + d <= t {
                        next[s + d] += w * c.len() as f64;
                    }
                }
            }
            ways = next;
        }
        ways[t]
    }
}
