//! Candidate goals in the arena: the city icons of the continuous task.

use serde::{Deserialize, Serialize};

use crate::error::{Result, RobotError};

const CITIES_TOML: &str = include_str!("../../../assets/cities.toml");

/// Cells per side of the grid on which a layout file places its goals (the
/// paper's 5 x 5 discretisation of the arena, sec. 5.1).
pub const LAYOUT_GRID_CELLS: u32 = 5;

/// One candidate goal: a named point of the arena.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Goal {
    /// The city on its icon, e.g. "Pisa".
    pub name: String,
    /// Position along x, m (arena frame: origin bottom left, y up).
    pub x_m: f64,
    /// Position along y, m.
    pub y_m: f64,
}

/// A square arena and its candidate goals; validated, so the goals are at
/// least two, inside the arena, with distinct non-empty names. A goal's index
/// is its position in [`GoalLayout::goals`], and beliefs are indexed alike.
#[derive(Debug, Clone, PartialEq)]
pub struct GoalLayout {
    arena_size_m: f64,
    goals: Vec<Goal>,
}

/// The layout file as written: sizes in cm, goals on the 5 x 5 grid.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LayoutFile {
    arena_size_cm: f64,
    goal: Vec<GoalEntry>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct GoalEntry {
    name: String,
    column: u32,
    row: u32,
}

impl GoalLayout {
    /// A layout of `goals` in a square arena of side `arena_size_m`; checks
    /// that there are at least 2 goals, with unique non-empty names, strictly
    /// inside the arena.
    pub fn new(arena_size_m: f64, goals: Vec<Goal>) -> Result<Self> {
        let bad = |m: String| Err(RobotError::Parameter(m));
        if !(arena_size_m.is_finite() && arena_size_m > 0.0) {
            return bad(format!(
                "arena_size_m = {arena_size_m} must be a finite number > 0"
            ));
        }
        if goals.len() < 2 {
            return bad(format!("goals: {} given, at least 2 needed", goals.len()));
        }
        for (i, g) in goals.iter().enumerate() {
            if g.name.trim().is_empty() {
                return bad(format!("goals[{i}].name is empty"));
            }
            if goals[..i].iter().any(|other| other.name == g.name) {
                return bad(format!("goals[{i}].name = {:?} is not unique", g.name));
            }
            let inside = |v: f64| v.is_finite() && v > 0.0 && v < arena_size_m;
            if !(inside(g.x_m) && inside(g.y_m)) {
                return bad(format!(
                    "goal {:?} at ({}, {}) m is not inside the arena (0, {arena_size_m}) m",
                    g.name, g.x_m, g.y_m
                ));
            }
        }
        Ok(Self {
            arena_size_m,
            goals,
        })
    }

    /// The paper's arena (sec. 5.1): 200 x 200 cm with the 25 city icons of
    /// `assets/cities.toml` (Mexico bottom left, Pisa top right, ...).
    pub fn cities() -> Self {
        Self::from_grid_toml(CITIES_TOML).expect("assets/cities.toml is a valid layout")
    }

    /// Parses a layout file in the format of `assets/cities.toml`:
    /// `arena_size_cm` and `[[goal]]` tables with `name`, `column` and `row`
    /// (0 to 4, row 0 at the bottom) on the 5 x 5 grid; each goal is put at
    /// its cell's centre, x = (column + 0.5) size / 5, y = (row + 0.5) size / 5,
    /// in metres.
    pub fn from_grid_toml(text: &str) -> Result<Self> {
        let file: LayoutFile = toml::from_str(text)
            .map_err(|e| RobotError::Parameter(format!("goal layout file: {e}")))?;
        let size_m = file.arena_size_cm / 100.0;
        let cell_m = size_m / f64::from(LAYOUT_GRID_CELLS);
        let mut goals = Vec::with_capacity(file.goal.len());
        for g in file.goal {
            if g.column >= LAYOUT_GRID_CELLS || g.row >= LAYOUT_GRID_CELLS {
                return Err(RobotError::Parameter(format!(
                    "goal {:?}: column = {}, row = {} must be in 0..{LAYOUT_GRID_CELLS}",
                    g.name, g.column, g.row
                )));
            }
            goals.push(Goal {
                name: g.name,
                x_m: (f64::from(g.column) + 0.5) * cell_m,
                y_m: (f64::from(g.row) + 0.5) * cell_m,
            });
        }
        Self::new(size_m, goals)
    }

    /// Side of the square arena, m.
    pub fn arena_size_m(&self) -> f64 {
        self.arena_size_m
    }

    /// The goals, in index order.
    pub fn goals(&self) -> &[Goal] {
        &self.goals
    }

    /// Goal `i`.
    pub fn goal(&self, i: usize) -> &Goal {
        &self.goals[i]
    }

    /// Number of goals (at least 2).
    pub fn len(&self) -> usize {
        self.goals.len()
    }

    /// Always false: a layout has at least 2 goals.
    pub fn is_empty(&self) -> bool {
        self.goals.is_empty()
    }

    /// Index of the goal named `name` (exact match).
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.goals.iter().position(|g| g.name == name)
    }

    /// Every goal's name, in index order.
    pub fn names(&self) -> Vec<&str> {
        self.goals.iter().map(|g| g.name.as_str()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(layout: &GoalLayout, name: &str) -> (f64, f64) {
        let g = layout.goal(layout.index_of(name).unwrap());
        (g.x_m, g.y_m)
    }

    #[test]
    fn the_cities_sit_at_cell_centres_as_placed() {
        let l = GoalLayout::cities();
        assert_eq!(l.len(), 25);
        assert!((l.arena_size_m() - 2.0).abs() < 1e-12);
        let close = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).abs() + (a.1 - b.1).abs() < 1e-12;
        assert!(close(at(&l, "Mexico"), (0.2, 0.2)));
        assert!(close(at(&l, "Pisa"), (1.8, 1.8)));
        assert!(close(at(&l, "Lisbon"), (0.2, 1.8)));
        assert!(close(at(&l, "Tokyo"), (1.8, 0.6)));
        assert!(close(at(&l, "Las Vegas"), (0.6, 1.4)));
        assert!(close(at(&l, "Beijing"), (1.4, 1.0)));
        assert!(close(at(&l, "Cairo"), (1.0, 0.6)));
        assert!(close(at(&l, "Berlin"), (1.4, 1.4)));
        assert!(close(at(&l, "Rio de Janeiro"), (0.6, 1.0)));
        assert_eq!(l.index_of("Mexico"), Some(0));
        assert_eq!(l.index_of("Pisa"), Some(24));
        assert_eq!(l.index_of("Atlantis"), None);
        // Every cell centre holds exactly one goal: index = row * 5 + column.
        for (i, g) in l.goals().iter().enumerate() {
            let col = (i % 5) as f64;
            let row = (i / 5) as f64;
            assert!(
                close((g.x_m, g.y_m), (0.2 + 0.4 * col, 0.2 + 0.4 * row)),
                "{g:?}"
            );
        }
        assert_eq!(l.names().len(), 25);
    }

    #[test]
    fn invalid_layouts_are_rejected() {
        let g = |name: &str, x_m, y_m| Goal {
            name: name.into(),
            x_m,
            y_m,
        };
        assert!(GoalLayout::new(1.0, vec![g("a", 0.2, 0.2), g("b", 0.8, 0.8)]).is_ok());
        for (size, goals, word) in [
            (1.0, vec![g("a", 0.2, 0.2)], "at least 2"),
            (1.0, vec![g("a", 0.2, 0.2), g("a", 0.5, 0.5)], "unique"),
            (1.0, vec![g("a", 0.2, 0.2), g(" ", 0.5, 0.5)], "empty"),
            (1.0, vec![g("a", 0.2, 0.2), g("b", 1.5, 0.5)], "inside"),
            (1.0, vec![g("a", 0.2, 0.2), g("b", 0.5, f64::NAN)], "inside"),
            (
                0.0,
                vec![g("a", 0.2, 0.2), g("b", 0.5, 0.5)],
                "arena_size_m",
            ),
        ] {
            let e = GoalLayout::new(size, goals).unwrap_err().to_string();
            assert!(e.contains(word), "{e}");
        }
        let e = GoalLayout::from_grid_toml(
            "arena_size_cm = 100\n[[goal]]\nname = \"a\"\ncolumn = 5\nrow = 0\n",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("column"), "{e}");
        assert!(GoalLayout::from_grid_toml("arena_size_cm = 100\nfoo = 1\n").is_err());
    }
}
