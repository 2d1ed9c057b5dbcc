//! What a live session's runs gave, as its front end and its recording
//! see them.

use crate::epuck::EpuckEpisodeResult;
use crate::grid::GridEpisodeResult;
use crate::live::LiveRunStats;

/// One run of a live grid session.
#[derive(Debug, Clone, PartialEq)]
pub struct GridLiveRun {
    /// The episode, as the task scores it.
    pub result: GridEpisodeResult,
    /// The decoder's timing.
    pub stats: LiveRunStats,
    /// Each action's decision as applied: p(error), or none (missed).
    pub decisions: Vec<Option<f64>>,
}

/// One run of a live e-puck session.
#[derive(Debug, Clone, PartialEq)]
pub struct EpuckLiveRun {
    /// The run, as the task scores it.
    pub result: EpuckEpisodeResult,
    /// The decoder's timing (missed: windows without a decision).
    pub stats: LiveRunStats,
    /// The p(error)s applied at each of the device's windows.
    pub decisions: Vec<Vec<f64>>,
}
