//! Every entity path the recordings use, in one place, so that the views
//! (their blueprints), the loggers and the readers (`errp inspect`, the
//! Python package) agree. Each path starts with `/`.

// What the task recordings share.

/// The decoder's output and threshold, under one time-series view.
pub const DECODER: &str = "/decoder";
/// p(error) of each decision.
pub const P_ERROR: &str = "/decoder/p_error";
/// The decision threshold (0.5, or T_e).
pub const THRESHOLD: &str = "/decoder/threshold";
/// E-puck: what the detector compared with T_e (p(error) or its moving
/// average).
pub const EVIDENCE: &str = "/decoder/evidence";
/// A few preprocessed EEG channels, each at [`eeg_channel`].
pub const EEG: &str = "/eeg";
/// The text log of events.
pub const LOG: &str = "/log";

/// The entity path of preprocessed EEG channel `name` (e.g. "FCz").
pub fn eeg_channel(name: &str) -> String {
    format!("{EEG}/{name}")
}

// The data tables every task recording carries (the `data` module).

/// The provenance document (static).
pub const PROVENANCE: &str = "/errp/provenance";
/// One row per run, at its start.
pub const RUNS: &str = "/errp/runs";
/// E-puck: one row per physics step.
pub const FRAMES: &str = "/errp/frames";
/// E-puck: one row per decoder window.
pub const WINDOWS: &str = "/errp/windows";
/// E-puck: one row per ErrP of the user.
pub const ERRPS: &str = "/errp/errps";
/// Grid: one row per action.
pub const ACTIONS: &str = "/errp/actions";
/// One row per run, at its end.
pub const ENDS: &str = "/errp/ends";
/// E-puck: the event log with run numbers.
pub const EVENTS: &str = "/errp/events";
/// A live session (`errp stream`): one row per decision received.
pub const DECISIONS: &str = "/errp/decisions";
/// The prefix of the data tables.
pub const TABLES: &str = "/errp/";

// The grid (Fig. 4).

/// The grid view's origin.
pub const GRID: &str = "/grid";
/// The 5x5 cells.
pub const GRID_CELLS: &str = "/grid/cells";
/// The user's goal.
pub const GRID_GOAL: &str = "/grid/goal";
/// The start cell.
pub const GRID_START: &str = "/grid/start";
/// The cursor.
pub const GRID_CURSOR: &str = "/grid/cursor";
/// The posterior over goals, as a heat map.
pub const GRID_POSTERIOR: &str = "/grid/posterior";
/// The belief's series.
pub const BELIEF: &str = "/belief";
/// Grid: the probability of the user's goal.
pub const BELIEF_TRUE_GOAL: &str = "/belief/true_goal";
/// Grid: the largest probability.
pub const BELIEF_MAX: &str = "/belief/max";
/// Grid: the cells visited so far.
pub const VISITS: &str = "/visits";
/// Grid: the visits as a heat map.
pub const VISITS_MAP: &str = "/visits/map";

// The e-puck (Fig. 5).

/// The arena view's origin (cm).
pub const ARENA: &str = "/arena";
/// The walls.
pub const ARENA_WALLS: &str = "/arena/walls";
/// The obstacles.
pub const ARENA_OBSTACLES: &str = "/arena/obstacles";
/// The 25 cities, with their names.
pub const ARENA_CITIES: &str = "/arena/cities";
/// The cities coloured by belief.
pub const ARENA_GOALS: &str = "/arena/goals";
/// The ring on the city the robot heads for.
pub const ARENA_TARGET: &str = "/arena/target";
/// Where errors were detected in the current run.
pub const ARENA_DETECTIONS: &str = "/arena/detections";
/// The current run's trajectory.
pub const ARENA_TRAJECTORY: &str = "/arena/trajectory";
/// The robot's body.
pub const ARENA_ROBOT: &str = "/arena/robot";
/// The robot's heading.
pub const ARENA_HEADING: &str = "/arena/heading";
/// Every run's trajectory, faint and static.
pub const ARENA_OVERVIEW_TRAJECTORIES: &str = "/arena/overview/trajectories";
/// Every run's detections, faint and static.
pub const ARENA_OVERVIEW_DETECTIONS: &str = "/arena/overview/detections";
/// The belief's series, one per city at [`belief_city`].
pub const BELIEF_CITY: &str = "/belief/city";

/// The belief series of city `name`.
pub fn belief_city(name: &str) -> String {
    format!("{BELIEF_CITY}/{name}")
}

// The calibration (`errp calibrate`).

/// The grand averages, one view per channel at [`grand_average`].
pub const GRAND_AVERAGE: &str = "/grand_average";
/// The scalp map of the difference wave.
pub const TOPOGRAPHY: &str = "/topography";
/// The map itself.
pub const TOPOGRAPHY_MAP: &str = "/topography/map";
/// The electrodes on it.
pub const TOPOGRAPHY_ELECTRODES: &str = "/topography/electrodes";
/// The head outline.
pub const TOPOGRAPHY_HEAD: &str = "/topography/head";
/// The calibration's summary in words.
pub const SUMMARY: &str = "/summary";

/// The grand averages of channel `name`.
pub fn grand_average(name: &str) -> String {
    format!("{GRAND_AVERAGE}/{name}")
}
