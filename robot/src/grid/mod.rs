//! The 5x5 grid world of the discrete task (sec. 4 of the paper).

pub(crate) mod control;
pub(crate) mod policy;
pub(crate) mod qvalues;

use serde::{Deserialize, Serialize};

use crate::error::{Result, RobotError};

/// A cell: column `x` (0 = left) and row `y` (0 = bottom).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Cell {
    /// Column, 0 on the left.
    pub x: usize,
    /// Row, 0 at the bottom.
    pub y: usize,
}

impl Cell {
    /// The cell at column `x`, row `y`.
    pub const fn new(x: usize, y: usize) -> Self {
        Self { x, y }
    }
}

impl std::fmt::Display for Cell {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "({}, {})", self.x, self.y)
    }
}

/// The five actions of the cursor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GridAction {
    /// One row up.
    Up,
    /// One row down.
    Down,
    /// One column left.
    Left,
    /// One column right.
    Right,
    /// "I am on the goal": stays in place.
    GoalReached,
}

impl GridAction {
    /// All actions, in the order used for Q-value arrays.
    pub const ALL: [GridAction; 5] = [
        GridAction::Up,
        GridAction::Down,
        GridAction::Left,
        GridAction::Right,
        GridAction::GoalReached,
    ];

    /// Position in [`GridAction::ALL`].
    pub fn index(self) -> usize {
        match self {
            GridAction::Up => 0,
            GridAction::Down => 1,
            GridAction::Left => 2,
            GridAction::Right => 3,
            GridAction::GoalReached => 4,
        }
    }

    /// Lower-case name, as in logs.
    pub fn name(self) -> &'static str {
        match self {
            GridAction::Up => "up",
            GridAction::Down => "down",
            GridAction::Left => "left",
            GridAction::Right => "right",
            GridAction::GoalReached => "goal-reached",
        }
    }
}

/// A rectangular grid; moves against a border leave the cursor in place.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Grid {
    /// Number of columns.
    pub width: usize,
    /// Number of rows.
    pub height: usize,
}

impl Grid {
    /// A `width` x `height` grid (each at least 1).
    pub fn new(width: usize, height: usize) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(RobotError::Parameter(format!(
                "a grid needs at least one column and one row, got {width} x {height}"
            )));
        }
        Ok(Self { width, height })
    }

    /// The paper's 5 x 5 grid.
    pub fn paper() -> Self {
        Self {
            width: 5,
            height: 5,
        }
    }

    /// Number of cells.
    pub fn n_cells(&self) -> usize {
        self.width * self.height
    }

    /// True if `cell` lies on the grid.
    pub fn contains(&self, cell: Cell) -> bool {
        cell.x < self.width && cell.y < self.height
    }

    /// Row-major index of a cell (bottom row first).
    pub fn index(&self, cell: Cell) -> usize {
        debug_assert!(self.contains(cell));
        cell.y * self.width + cell.x
    }

    /// The cell with row-major index `i`.
    pub fn cell(&self, i: usize) -> Cell {
        Cell::new(i % self.width, i / self.width)
    }

    /// Every cell, in index order.
    pub fn cells(&self) -> impl Iterator<Item = Cell> + '_ {
        (0..self.n_cells()).map(|i| self.cell(i))
    }

    /// Where `action` takes the cursor from `cell`.
    pub fn step(&self, cell: Cell, action: GridAction) -> Cell {
        let Cell { x, y } = cell;
        match action {
            GridAction::Up if y + 1 < self.height => Cell::new(x, y + 1),
            GridAction::Down if y > 0 => Cell::new(x, y - 1),
            GridAction::Left if x > 0 => Cell::new(x - 1, y),
            GridAction::Right if x + 1 < self.width => Cell::new(x + 1, y),
            _ => cell,
        }
    }

    /// Manhattan distance between two cells.
    pub fn distance(a: Cell, b: Cell) -> usize {
        a.x.abs_diff(b.x) + a.y.abs_diff(b.y)
    }

    /// The user's judgement (sec. 4.1): an action is correct if it moves the
    /// cursor closer to the goal, or is goal-reached on the goal; anything
    /// else (moving away, bumping a border, goal-reached elsewhere, moving
    /// off the goal) is an error.
    pub fn is_correct(&self, cell: Cell, action: GridAction, goal: Cell) -> bool {
        match action {
            GridAction::GoalReached => cell == goal,
            _ => Self::distance(self.step(cell, action), goal) < Self::distance(cell, goal),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moves_stop_at_the_borders() {
        let g = Grid::paper();
        assert_eq!(g.step(Cell::new(0, 0), GridAction::Down), Cell::new(0, 0));
        assert_eq!(g.step(Cell::new(0, 0), GridAction::Left), Cell::new(0, 0));
        assert_eq!(g.step(Cell::new(4, 4), GridAction::Up), Cell::new(4, 4));
        assert_eq!(g.step(Cell::new(2, 2), GridAction::Right), Cell::new(3, 2));
        assert_eq!(
            g.step(Cell::new(2, 2), GridAction::GoalReached),
            Cell::new(2, 2)
        );
        for i in 0..25 {
            assert_eq!(g.index(g.cell(i)), i);
        }
    }

    #[test]
    fn the_user_judges_as_section_4_1_says() {
        let g = Grid::paper();
        let goal = Cell::new(3, 1);
        assert!(g.is_correct(Cell::new(1, 1), GridAction::Right, goal));
        assert!(!g.is_correct(Cell::new(1, 1), GridAction::Left, goal));
        assert!(!g.is_correct(Cell::new(1, 1), GridAction::Up, goal));
        assert!(!g.is_correct(Cell::new(1, 1), GridAction::GoalReached, goal));
        assert!(g.is_correct(goal, GridAction::GoalReached, goal));
        assert!(!g.is_correct(goal, GridAction::Up, goal));
        // Bumping a border is an error even "towards" the goal's row.
        assert!(!g.is_correct(Cell::new(0, 0), GridAction::Down, Cell::new(0, 3)));
        assert!(Grid::new(0, 5).is_err());
    }
}
