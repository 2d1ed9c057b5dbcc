//! Closed-loop runs of the grid controller with each strategy (no EEG): a
//! simulated user judges every action as sec. 4.1 says and an oracle decoder
//! reports the judgement with a fixed accuracy.

use errp_robot::{Cell, Grid, GridControlParams, GridController, QTable, Strategy, Valid};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const MAX_ACTIONS: usize = 300;

/// One seeded stream per consumer, derived from the episode's seed.
fn seeded(seed: u64, label: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(label);
    rng
}

/// How an episode ended.
struct Episode {
    /// The goal the belief converged to, if any.
    found: Option<Cell>,
    /// Actions taken.
    actions: usize,
    /// Of which not the greedy action for the most probable goal.
    not_greedy: usize,
}

/// Runs one episode.
fn episode(
    table: &QTable,
    params: GridControlParams,
    start: Cell,
    goal: Cell,
    accuracy: f64,
    seed: u64,
) -> Episode {
    let grid = *table.grid();
    let mut c = GridController::with_table(table.clone(), Valid::new(params).unwrap());
    let mut explore = seeded(seed, 1);
    let mut decoder = seeded(seed, 2);
    let mut cell = start;
    let mut not_greedy = 0;
    for n in 1..=MAX_ACTIONS {
        let action = c.choose(cell, &mut explore);
        not_greedy += usize::from(action != c.table().greedy(c.most_probable().0, cell));
        let error = !grid.is_correct(cell, action, goal);
        let says_error = if decoder.random::<f64>() < accuracy {
            error
        } else {
            !error
        };
        let p = if says_error { accuracy } else { 1.0 - accuracy };
        c.observe(cell, action, p).unwrap();
        cell = grid.step(cell, action);
        if let Some(found) = c.converged() {
            return Episode {
                found: Some(found),
                actions: n,
                not_greedy,
            };
        }
    }
    Episode {
        found: None,
        actions: MAX_ACTIONS,
        not_greedy,
    }
}

/// Over a set of episodes.
#[derive(Debug)]
struct Summary {
    /// Share of episodes converged on the true goal.
    success_rate: f64,
    /// Mean actions per episode (failures count their actions).
    mean_actions: f64,
    /// Share of actions that were not the greedy one.
    not_greedy_share: f64,
}

/// `n` episodes from random start and goal cells (the same for every
/// strategy).
fn measure(strategy: Strategy, accuracy: f64, n: u64) -> Summary {
    let grid = Grid::paper();
    let params = GridControlParams {
        strategy,
        ..GridControlParams::default()
    };
    let table = QTable::compute(grid, &Valid::new(params.q()).unwrap()).unwrap();
    let mut pairs = seeded(2013, 0);
    let (mut right, mut actions, mut not_greedy) = (0, 0, 0);
    for k in 0..n {
        let start = grid.cell(pairs.random_range(0..grid.n_cells()));
        let goal = grid.cell(pairs.random_range(0..grid.n_cells()));
        let e = episode(&table, params, start, goal, accuracy, 1000 + k);
        right += usize::from(e.found == Some(goal));
        actions += e.actions;
        not_greedy += e.not_greedy;
    }
    Summary {
        success_rate: right as f64 / n as f64,
        mean_actions: actions as f64 / n as f64,
        not_greedy_share: not_greedy as f64 / actions as f64,
    }
}

/// Measured (200 episodes): every strategy right in 200 of 200; greedy in
/// 37.5 actions on average, info gain in 42.5 (one-step information gain
/// ignores that the most telling action, goal-reached, needs the cursor on
/// the goal, which greedy heads for), Thompson in 55.1. Thompson keeps its
/// drawn goal until the user objects or the goal falls below half the
/// leader's probability; redrawing at every action made the cursor dither
/// between candidates and took 84.2 actions. It still loses to greedy: while
/// the belief is spread its draws send the cursor to goals that greedy,
/// heading for the leader, would not visit. The bounds leave about 20 %
/// margin (Thompson's excludes the per-action redraw).
/// `n` episodes of each strategy (greedy, info gain, Thompson) at
/// `accuracy`, printed.
fn measure_all(accuracy: f64, n: u64) -> [Summary; 3] {
    let all = Strategy::ALL.map(|s| measure(s, accuracy, n));
    eprintln!(
        "{n} episodes at accuracy {accuracy}:\n  greedy    {:?}\n  info_gain {:?}\n  \
         thompson  {:?}",
        all[0], all[1], all[2]
    );
    all
}

#[test]
fn every_strategy_finds_the_goal_with_an_80_percent_decoder() {
    let [greedy, info, thompson] = measure_all(0.8, 200);
    for s in [&greedy, &info, &thompson] {
        assert!(s.success_rate >= 0.85, "{s:?}");
    }
    assert!(greedy.mean_actions < 45.0, "{greedy:?}");
    assert!(info.mean_actions < 50.0, "{info:?}");
    assert!(thompson.mean_actions < 66.0, "{thompson:?}");
    // Greedy leaves its greedy action only on epsilon's random draws (0.1 x
    // 4/5 of them); info gain does so far more often, Thompson whenever its
    // drawn goal is not the most probable one and needs another action.
    assert!(greedy.not_greedy_share < 0.12, "{greedy:?}");
    assert!(
        info.not_greedy_share > greedy.not_greedy_share + 0.1,
        "{info:?}"
    );
    assert!(
        thompson.not_greedy_share > greedy.not_greedy_share + 0.1,
        "{thompson:?}"
    );
}

/// The same comparison with a weaker decoder. Measured (200 episodes):
/// greedy right in 90 % of episodes in 152.6 actions on average, info gain
/// 84 % in 175.1, Thompson 80.5 % in 223.9 (redrawing at every action:
/// 43.5 % in 280.3). Greedy is the best of the three here too. The bounds
/// leave about 10 points of success and 12 % of actions (Thompson's exclude
/// the per-action redraw).
#[test]
fn every_strategy_mostly_finds_the_goal_with_a_65_percent_decoder() {
    let [greedy, info, thompson] = measure_all(0.65, 200);
    assert!(greedy.success_rate >= 0.8, "{greedy:?}");
    assert!(info.success_rate >= 0.75, "{info:?}");
    assert!(thompson.success_rate >= 0.7, "{thompson:?}");
    assert!(greedy.mean_actions < 175.0, "{greedy:?}");
    assert!(info.mean_actions < 200.0, "{info:?}");
    assert!(thompson.mean_actions < 250.0, "{thompson:?}");
}
