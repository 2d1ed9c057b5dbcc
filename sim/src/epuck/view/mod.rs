//! What `errp run <e-puck scenario> --save` records: the arena as seen from
//! the ceiling (walls, obstacles, the 25 cities coloured by belief, the
//! e-puck, its trajectory and red marks where errors were detected, as in
//! Fig. 5, with a ring on the city the robot heads for), the belief as one
//! series per city, p(error) against T_e, preprocessed EEG at FCz and Cz,
//! and a log of events, all on the `sim_time` timeline in seconds. Lengths
//! are in centimetres. A file opens at its end; every run's trajectory and
//! detections also stay as a faint static layer, so the whole batch shows
//! at a glance.

use std::path::Path;

use rerun::blueprint::{Blueprint, Spatial2DView, TimeSeriesView};

use crate::error::Result;
use crate::record::{RrdFile, paths, task_blueprint};

mod recorder;
mod runs;

pub use recorder::{EpuckRecorder, RUN_GAP_SECS};
pub use runs::{record_epuck_runs, record_epuck_runs_with};

/// The layout: the arena beside the belief (when the shared control
/// drives), p(error) and the EEG.
fn blueprint(belief: bool) -> Blueprint {
    let mut series = Vec::new();
    if belief {
        series.push(
            TimeSeriesView::new("Belief per city")
                .with_origin(paths::BELIEF_CITY)
                .into(),
        );
    }
    series.push(
        TimeSeriesView::new("p(error) and T_e")
            .with_origin(paths::DECODER)
            .into(),
    );
    series.push(
        TimeSeriesView::new("EEG (uV, preprocessed)")
            .with_origin(paths::EEG)
            .into(),
    );
    task_blueprint(
        Spatial2DView::new("Arena (cm): e-puck, trajectory, detected errors")
            .with_origin(paths::ARENA),
        series,
    )
}

/// Opens the `.rrd` of an e-puck run, with its layout, before the run.
pub fn epuck_recording(path: &Path) -> Result<RrdFile> {
    RrdFile::create("errp_epuck", path, blueprint(true))
}

/// Opens the `.rrd` of e-puck episodes driven by an agent of the caller's
/// own: the layout without the belief, which is the agent's.
pub fn epuck_agent_recording(path: &Path) -> Result<RrdFile> {
    RrdFile::create("errp_epuck", path, blueprint(false))
}
