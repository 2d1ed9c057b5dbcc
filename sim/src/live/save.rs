//! A live session recorded (`errp stream --save`): each run as the task's
//! own recording shows it (the grid's or the e-puck's tables and views),
//! and each run's decisions as received, in `/errp/decisions`
//! ([`crate::record::schema::LiveDecisions`]).

use std::path::{Path, PathBuf};

use crate::epuck::{EpuckObserver, EpuckRecorder, EpuckRunsObserver, EpuckScenario};
use crate::error::Result;
use crate::grid::{GridRecorder, GridScenario};
use crate::live::{EpuckLiveRun, Fate, GridLiveRun, LiveRunStats};
use crate::pace::Speed;
use crate::record::RrdFile;
use crate::record::data::{LiveProvenance, Provenance};
use crate::record::schema::LiveDecisions;

/// The task's recorder.
enum Task {
    /// With the scenario's seed and action length (s), which each
    /// episode's row records.
    Grid(GridRecorder, u64, f64),
    Epuck(Box<EpuckRecorder>, RrdFile),
}

/// A live session's `.rrd`, written run by run and moved into place by
/// [`LiveRecording::finish`] (nothing is left at its path before).
pub struct LiveRecording {
    task: Task,
    provenance: Provenance,
    /// Simulated seconds per second of the link's clock.
    speed: Speed,
    runs: usize,
}

impl LiveRecording {
    /// A grid session's recording of `scenario` at `path`, made as
    /// `provenance` says, live as `live` says.
    pub fn grid(
        path: &Path,
        scenario: &GridScenario,
        provenance: Provenance,
        live: LiveProvenance,
    ) -> Result<Self> {
        let file = crate::grid::grid_recording(path)?;
        let (seed, epoch_secs) = (scenario.seed, scenario.params.epoch_secs);
        let task = Task::Grid(GridRecorder::new(file)?, seed, epoch_secs);
        Ok(Self::new(task, provenance, live))
    }

    /// An e-puck session's recording of `scenario` at `path`, made as
    /// `provenance` says, live as `live` says.
    pub fn epuck(
        path: &Path,
        scenario: &EpuckScenario,
        provenance: Provenance,
        live: LiveProvenance,
    ) -> Result<Self> {
        let file = crate::epuck::epuck_recording(path)?;
        // The detector reads a decoder outside at the scenario's T_e.
        let t_e = scenario.params.control.t_e;
        let mut recorder = EpuckRecorder::new(&file, &scenario.arena, &scenario.layout, t_e)?;
        recorder.set_run_title(format!(
            "the user wants {} (your online decoder)",
            scenario.layout.goals()[scenario.episode.goal].name
        ));
        Ok(Self::new(
            Task::Epuck(Box::new(recorder), file),
            provenance,
            live,
        ))
    }

    fn new(task: Task, mut provenance: Provenance, live: LiveProvenance) -> Self {
        let speed = live.speed;
        provenance.live = Some(live);
        Self {
            task,
            provenance,
            speed,
            runs: 0,
        }
    }

    /// Records grid run `k` (run with its steps) and its decisions.
    pub fn grid_run(&mut self, k: usize, run: &GridLiveRun) -> Result<()> {
        let Task::Grid(recorder, scenario_seed, epoch_secs) = &mut self.task else {
            return Ok(());
        };
        let t0 = recorder.next_t0();
        let seed = crate::grid::grid_episode_seed(*scenario_seed, k);
        recorder.episode(seed, *epoch_secs, &run.result)?;
        self.runs = k + 1;
        let file = recorder.file();
        send_decisions(file, k, t0, self.speed, &run.stats)
    }

    /// What watches e-puck run `k` (seed `seed`) as it runs.
    pub fn epuck_watch(&mut self, k: usize, seed: u64) -> Option<&mut dyn EpuckObserver> {
        let Task::Epuck(recorder, _) = &mut self.task else {
            return None;
        };
        recorder.start_run(k, seed);
        Some(&mut **recorder)
    }

    /// Records e-puck run `k`'s decisions (its steps were watched).
    pub fn epuck_run(&mut self, k: usize, run: &EpuckLiveRun) -> Result<()> {
        let Task::Epuck(recorder, file) = &self.task else {
            return Ok(());
        };
        self.runs = k + 1;
        send_decisions(file, k, recorder.run_offset_secs(), self.speed, &run.stats)
    }

    /// Logs the provenance (with the runs recorded), flushes the file and
    /// moves it into place.
    pub fn finish(self) -> Result<PathBuf> {
        match self.task {
            Task::Grid(recorder, ..) => recorder.finish(&self.provenance),
            Task::Epuck(recorder, file) => {
                recorder.finish()?;
                self.provenance.write(&file, self.runs)?;
                file.finish()
            }
        }
    }
}

/// Sends run `k`'s decisions to `file`, the run starting at `t0` on the
/// timeline and its clock running `speed` times the link's.
fn send_decisions(
    file: &RrdFile,
    k: usize,
    t0: f64,
    speed: Speed,
    stats: &LiveRunStats,
) -> Result<()> {
    let d = &stats.decisions;
    let t_s: Vec<f64> = d
        .iter()
        .map(|d| speed.to_sim(d.received.arrived - stats.origin))
        .collect();
    let times: Vec<f64> = t_s.iter().map(|t| t0 + t).collect();
    LiveDecisions {
        run: vec![k as i64; d.len()],
        t_s,
        id: d.iter().map(|d| d.received.id).collect(),
        p_error: d.iter().map(|d| d.received.p_error).collect(),
        latency_s: d.iter().map(|d| d.latency_secs).collect(),
        fate: d.iter().map(|d| d.fate.name().to_string()).collect(),
        applied_to: d
            .iter()
            .map(|d| match d.fate {
                Fate::Applied(i) => i as i64,
                Fate::Late | Fate::Stray => -1,
            })
            .collect(),
    }
    .send(file.stream(), &times)
    .map_err(crate::record::record_error(file.path()))
}
