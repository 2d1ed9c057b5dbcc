//! The determinism contracts of `errp_robot`: the controllers draw only from
//! the RNG they are given, so a seed gives the same actions and beliefs, and
//! the golden digests below pin the numbers themselves. Update a digest only
//! for a change meant to alter them, and say so in the commit.

use errp_robot::{Cell, GoalLayout, Grid, GridAction, GridControlParams, GridController, Strategy};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::continuous_closed_loop::{goal_pose, run};

/// FNV-1a over the bit patterns of `values`: equal digests, equal bits.
fn digest(values: impl IntoIterator<Item = f64>) -> u64 {
    values.into_iter().fold(0xcbf2_9ce4_8422_2325, |h, v| {
        (h ^ v.to_bits()).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

#[track_caller]
fn assert_digest(what: &str, got: u64, golden: u64) {
    assert_eq!(
        got, golden,
        "{what}: digest {got:#018x}, golden {golden:#018x}"
    );
}

/// 60 actions of the grid controller with `strategy` from (0, 0), driven by
/// seeded random p(error): every action and the final belief.
fn grid_trace(strategy: Strategy, seed: u64) -> Vec<f64> {
    let params = GridControlParams {
        strategy,
        ..GridControlParams::default()
    };
    let grid = Grid::paper();
    let mut c = GridController::new(grid, params).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut cell = Cell::new(0, 0);
    let mut out = Vec::new();
    for _ in 0..60 {
        let action: GridAction = c.choose(cell, &mut rng);
        let p_error = rng.random::<f64>();
        c.observe(cell, action, p_error).unwrap();
        cell = grid.step(cell, action);
        out.push(action.index() as f64);
    }
    out.extend(c.belief().probabilities());
    out
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

#[test]
fn the_grid_controller_gives_the_golden_runs() {
    let got = Strategy::ALL.map(|s| format!("{:#018x}", digest(grid_trace(s, 5))));
    // Seed 5: the three strategies take different actions.
    let golden = [
        "0x5ad7365e483f9efe",
        "0x143c358284acaf6d",
        "0x275064bb120274d1",
    ];
    assert_eq!(got, golden, "greedy, info gain, Thompson");
}

/// The oracle closed loop from Mexico to Pisa (no RNG at all): the final
/// pose, the time and every goal it set off for.
#[test]
fn the_continuous_controller_gives_the_golden_run() {
    let pisa = GoalLayout::cities().index_of("Pisa").unwrap();
    let (start, _) = goal_pose("Mexico", 0.0);
    let r = run(start, Some(pisa), 300.0);
    let values = [r.pose.x_m, r.pose.y_m, r.pose.heading_rad, r.secs]
        .into_iter()
        .chain(r.targets.iter().map(|&t| t as f64));
    assert_digest(
        "Mexico to Pisa, oracle",
        digest(values),
        0x7c90_a5c7_6839_12e3,
    );
}
