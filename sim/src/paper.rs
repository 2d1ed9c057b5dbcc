//! Every number the paper reports that the testbed compares itself with:
//! Table 1 (sec. 4.3) and the two e-puck runs (sec. 5.3).

use errp_bci::GoalSet;

/// The paper's Table 1, for comparison: per subject and goal set, (actions
/// mean, sd, net s mean, sd, total s mean, sd, accuracy % mean, sd).
pub const PAPER: [(&str, GoalSet, [f64; 8]); 8] = [
    (
        "S1",
        GoalSet::Fixed,
        [16.0, 2.0, 12.96, 1.91, 52.65, 7.76, 83.14, 15.15],
    ),
    (
        "S1",
        GoalSet::Free,
        [23.0, 9.0, 18.08, 7.37, 73.45, 29.93, 78.75, 12.62],
    ),
    (
        "S2",
        GoalSet::Fixed,
        [43.0, 9.0, 34.56, 7.10, 140.40, 28.83, 69.49, 4.13],
    ),
    (
        "S2",
        GoalSet::Free,
        [21.0, 7.0, 16.48, 5.84, 66.95, 23.73, 82.48, 10.66],
    ),
    (
        "S3",
        GoalSet::Fixed,
        [23.0, 12.0, 18.40, 9.73, 74.75, 39.54, 72.49, 3.74],
    ),
    (
        "S3",
        GoalSet::Free,
        [16.0, 6.0, 12.96, 5.10, 52.65, 20.73, 88.18, 10.51],
    ),
    (
        "S4",
        GoalSet::Fixed,
        [17.0, 5.0, 13.60, 4.38, 55.25, 17.80, 76.35, 8.89],
    ),
    (
        "S4",
        GoalSet::Free,
        [23.0, 11.0, 18.08, 8.44, 73.45, 34.29, 78.66, 14.44],
    ),
];

/// The paper's pooled rows of Table 1 (mean +- sd over the 20 runs of a goal
/// set, same columns as [`PAPER`]) and its accuracy-vs-total-time
/// correlation r and p (sec. 4.3).
pub const PAPER_POOLED: [(GoalSet, [f64; 8], f64, f64); 2] = [
    (
        GoalSet::Fixed,
        [25.0, 13.0, 19.88, 10.75, 80.76, 73.68, 74.38, 4.66],
        -0.47,
        0.038,
    ),
    (
        GoalSet::Free,
        [21.0, 8.0, 16.40, 6.61, 66.63, 26.85, 77.67, 5.02],
        -0.79,
        3e-5,
    ),
];

/// The paper's two e-puck runs (sec. 5.3): (scenario name, seconds to the
/// goal, error events).
pub const PAPER_EPUCK: [(&str, f64, usize); 2] =
    [("Mexico to Pisa", 60.0, 11), ("Lisbon to Tokyo", 121.0, 26)];
