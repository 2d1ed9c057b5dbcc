//! What the figure of a sweep shows: the success rate and the cost of the
//! successful episodes against the decoder's accuracy, one series per
//! setting, with the paper's results overlaid.

use errp_sim::task::PaperPoint;

/// One point of a sweep series: one level of decoder accuracy.
#[derive(Debug, Clone, PartialEq)]
pub struct LevelPoint {
    /// x: the decoder's mean accuracy at this level (0.5..1).
    pub accuracy: f64,
    /// Fraction of episodes that converged on the user's goal, 0..1.
    pub success_rate: f64,
    /// Lower end of the 95% Wilson interval of the success rate.
    pub success_lo: f64,
    /// Upper end of the 95% Wilson interval of the success rate.
    pub success_hi: f64,
    /// Mean cost (actions or seconds) over successful episodes; NaN if none,
    /// and the point is then left out of the cost panel.
    pub mean: f64,
    /// Standard deviation of the cost over successful episodes (NaN if none).
    pub sd: f64,
    /// Median cost over successful episodes (NaN if none).
    pub median: f64,
    /// Episodes at this level.
    pub n: usize,
}

/// A line: one combination of the swept parameters (e.g. "strategy=greedy",
/// "tau=0.3", or "" when only accuracy is swept).
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry; an empty label draws the series without a legend entry.
    pub label: String,
    /// The levels, in any order (they are drawn sorted by accuracy).
    pub points: Vec<LevelPoint>,
}

/// Everything one sweep figure shows.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepPlot {
    /// Title over the figure, e.g. "Grid task, 11 levels x 200 episodes,
    /// EEG decoder (bank), seed 1".
    pub title: String,
    /// What the cost is, e.g. "actions to convergence" or "time to
    /// convergence (s)": the right panel's y axis.
    pub cost_label: String,
    /// The lines, one per combination of the swept parameters.
    pub series: Vec<Series>,
    /// The paper's results, overlaid on the cost panel.
    pub paper: Vec<PaperPoint>,
    /// Legend entry of the paper's points, e.g. "paper, Table 1 (4 subjects x
    /// 2 goal sets)".
    pub paper_label: String,
}
