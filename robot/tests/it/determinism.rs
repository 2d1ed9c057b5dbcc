//! The determinism contracts of `errp_robot`: the controllers draw only from
//! the RNG they are given, so a seed gives the same actions and beliefs, and
//! the golden runs below pin the results themselves. Update them only for a
//! change meant to alter the numbers, and say so in the commit.

use errp_robot::{Cell, GoalLayout, Grid, GridControlParams, GridController, Strategy, Valid};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::epuck_closed_loop::{goal_pose, names, run};

/// 60 actions of the grid controller with `strategy` from (0, 0), driven by
/// seeded random p(error): the actions' initials, the most probable goal
/// and its probability. At goal reward 1 (the default before `errp fit
/// grid`), so that the golden runs pin the controller, not the fitted scale.
fn grid_trace(strategy: Strategy, seed: u64) -> (String, Cell, f64) {
    let params = GridControlParams {
        strategy,
        goal_reward: 1.0,
        ..GridControlParams::default()
    };
    let grid = Grid::paper();
    let mut c = GridController::new(grid, Valid::new(params).unwrap()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut cell = Cell::new(0, 0);
    let mut actions = String::new();
    for _ in 0..60 {
        let action = c.choose(cell, &mut rng);
        c.observe(cell, action, rng.random::<f64>()).unwrap();
        cell = grid.step(cell, action);
        actions.push_str(&action.name()[..1]);
    }
    let (goal, p) = c.most_probable();
    (actions, goal, p)
}

#[test]
fn a_seed_gives_the_same_grid_run_twice() {
    for strategy in Strategy::ALL {
        assert_eq!(
            grid_trace(strategy, 5),
            grid_trace(strategy, 5),
            "{strategy}"
        );
    }
}

/// Seed 5, where the three strategies act differently.
#[test]
fn the_grid_controller_gives_the_golden_runs() {
    let golden = [
        (
            Strategy::Greedy,
            "grulrlduggggdugggggggggggggggggggggggggggggggggggggggudggggg",
            Cell::new(0, 1),
            0.9999989739989263,
        ),
        (
            Strategy::InfoGain,
            "gruududuuggrdugggrgggggggggggggggggggggggggggggggggggudggggg",
            Cell::new(3, 3),
            0.9999990940508208,
        ),
        (
            Strategy::Thompson,
            "uugududrdduurgguuddgggggggdudruurddudullddrlguurdulgdrudulgd",
            Cell::new(2, 2),
            0.4899923355248912,
        ),
    ];
    for (strategy, actions, goal, p) in golden {
        let got = grid_trace(strategy, 5);

        assert_eq!(
            (got.0.as_str(), got.1),
            (actions, goal),
            "{strategy}: {got:?}"
        );
        assert!((got.2 - p).abs() < 1e-12, "{strategy}: {got:?}");
    }
}

/// The oracle closed loop from Mexico to Pisa (no RNG at all): the goals it
/// set off for, the time and the final pose.
#[test]
fn the_continuous_controller_gives_the_golden_run() {
    let pisa = GoalLayout::cities().index_of("Pisa").unwrap();
    let (start, _) = goal_pose("Mexico", 0.0);
    let r = run(start, Some(pisa), 300.0);
    let got = (names(&r.targets), r.secs, r.pose);
    // No stop on Mexico first: the run starts with the movement.
    let via = [
        "Havana",
        "Bogota",
        "Rio de Janeiro",
        "Beijing",
        "Cairo",
        "Berlin",
        "Pisa",
    ];
    assert_eq!(got.0, via, "{got:?}");
    assert_eq!(got.1, 44.5625, "{got:?}");
    let end = (got.2.x_m, got.2.y_m, got.2.heading_rad);
    let golden = (1.7864316376747638, 1.7862697106836318, 0.7913298063228643);
    assert!(
        (end.0 - golden.0).abs() < 1e-12
            && (end.1 - golden.1).abs() < 1e-12
            && (end.2 - golden.2).abs() < 1e-12,
        "{got:?}"
    );
}
