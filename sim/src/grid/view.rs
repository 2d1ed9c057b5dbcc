//! What `errp run <grid scenario> --save` records.

use std::path::{Path, PathBuf};

use errp_robot::{Cell, Grid};
use rerun::blueprint::{Blueprint, Spatial2DView, TimeSeriesView};
use rerun::{Boxes2D, Color, Image, Points2D, RecordingStream, Scalars, SeriesLines, TextLog};

use crate::error::Result;
use crate::grid::run::GridRunReport;
use crate::grid::{GridEpisodeResult, GridStep};
use crate::record::data::Provenance;
use crate::record::schema::{Actions, Ends, GridRuns};
use crate::record::{
    RrdFile, SIM_TIME, eeg_channel, log_decoder_series, paths, record_error, task_blueprint,
};

/// Pause between episodes on the timeline (s).
const EPISODE_GAP_SECS: f64 = 2.0;

fn blueprint() -> Blueprint {
    task_blueprint(
        Spatial2DView::new("Grid: cursor, goal, posterior").with_origin(paths::GRID),
        vec![
            TimeSeriesView::new("p(error) per action")
                .with_origin(paths::DECODER)
                .into(),
            TimeSeriesView::new("Belief")
                .with_origin(paths::BELIEF)
                .into(),
            TimeSeriesView::new("EEG at FCz (uV, preprocessed)")
                .with_origin(paths::EEG)
                .into(),
            Spatial2DView::new("Visited states (Fig. 4)")
                .with_origin(paths::VISITS)
                .into(),
        ],
    )
}

/// Opens the `.rrd` of a grid run, with its layout, before the run.
pub fn grid_recording(path: &Path) -> Result<RrdFile> {
    RrdFile::create("errp_grid", path, blueprint())
}

/// Centre of a cell in view coordinates (row 0 at the bottom).
fn centre(grid: &Grid, c: Cell) -> [f32; 2] {
    [c.x as f32 + 0.5, (grid.height - 1 - c.y) as f32 + 0.5]
}

/// A heat map of per-cell values in [0, 1], one pixel per cell.
fn heat_map(grid: &Grid, values: &[f64]) -> Image {
    let mut rgb = Vec::with_capacity(grid.n_cells() * 3);
    for row in 0..grid.height {
        for x in 0..grid.width {
            let v = values[grid.index(Cell::new(x, grid.height - 1 - row))];
            let v = if v.is_finite() {
                v.clamp(0.0, 1.0)
            } else {
                0.0
            };
            // White (0) to dark blue (1).
            let shade = |lo: f64| (255.0 - v * (255.0 - lo)) as u8;
            rgb.extend_from_slice(&[shade(20.0), shade(60.0), shade(140.0)]);
        }
    }
    Image::from_rgb24(rgb, [grid.width as u32, grid.height as u32])
}

/// Writes every episode of `report` (run with `record_steps`) to `file`,
/// with `provenance` (its `runs` set here).
pub fn record_grid_run(
    file: RrdFile,
    report: &GridRunReport,
    provenance: &Provenance,
) -> Result<PathBuf> {
    let s = &report.scenario;
    let mut recorder = GridRecorder::new(file)?;
    for (k, ep) in report.episodes.iter().enumerate() {
        let seed = crate::grid::grid_episode_seed(s.seed, k);
        recorder.episode(seed, s.params.epoch_secs, ep)?;
    }
    recorder.finish(provenance)
}

/// A grid recording written one episode at a time (run with
/// `record_steps`), one after another on the timeline.
pub struct GridRecorder {
    file: RrdFile,
    grid: Grid,
    t0: f64,
    episodes: usize,
}

impl GridRecorder {
    /// Logs the static scene into `file`.
    pub fn new(file: RrdFile) -> Result<Self> {
        let grid = Grid::paper();
        let rec = file.stream();
        let err = record_error(file.path());
        let outline: Vec<([f32; 2], [f32; 2])> = grid
            .cells()
            .map(|c| (centre(&grid, c), [1.0, 1.0]))
            .collect();
        rec.log_static(
            paths::GRID_CELLS,
            &Boxes2D::from_centers_and_sizes(
                outline.iter().map(|o| o.0),
                outline.iter().map(|o| o.1),
            )
            .with_colors([Color::from_rgb(160, 160, 160)]),
        )
        .map_err(&err)?;
        log_decoder_series(rec, "0.5").map_err(&err)?;
        rec.log_static(
            paths::BELIEF_TRUE_GOAL,
            &SeriesLines::new().with_names(["p(true goal)"]),
        )
        .map_err(&err)?;
        rec.log_static(paths::BELIEF_MAX, &SeriesLines::new().with_names(["max p"]))
            .map_err(&err)?;
        drop(err);
        Ok(Self {
            file,
            grid,
            t0: 0.0,
            episodes: 0,
        })
    }

    /// Episodes recorded so far.
    pub fn episodes(&self) -> usize {
        self.episodes
    }

    /// The file.
    pub(crate) fn file(&self) -> &RrdFile {
        &self.file
    }

    /// Where the next episode starts on the timeline (s).
    pub(crate) fn next_t0(&self) -> f64 {
        self.t0
    }

    /// Records the next episode, run from `seed` with actions of
    /// `epoch_secs`. A step's belief of NaN (an agent chose the actions)
    /// leaves the posterior and the belief series out.
    pub fn episode(&mut self, seed: u64, epoch_secs: f64, ep: &GridEpisodeResult) -> Result<()> {
        let k = self.episodes;
        let grid = self.grid;
        let t0 = self.t0;
        let rec = self.file.stream();
        let err = record_error(self.file.path());
        send_episode_tables(rec, &grid, k, t0, seed, epoch_secs, ep).map_err(&err)?;
        rec.set_duration_secs(SIM_TIME, t0);
        rec.log(
            paths::LOG,
            &TextLog::new(format!(
                "episode {}: start {} goal {}",
                k + 1,
                ep.start,
                ep.goal
            )),
        )
        .map_err(&err)?;
        rec.log(
            paths::GRID_GOAL,
            &Boxes2D::from_centers_and_sizes([centre(&grid, ep.goal)], [[0.9, 0.9]])
                .with_colors([Color::from_rgb(220, 40, 40)])
                .with_labels(["G"]),
        )
        .map_err(&err)?;
        rec.log(
            paths::GRID_START,
            &Points2D::new([centre(&grid, ep.start)])
                .with_labels(["S"])
                .with_colors([Color::from_rgb(40, 160, 40)]),
        )
        .map_err(&err)?;
        rec.log(
            paths::GRID_CURSOR,
            &Points2D::new([centre(&grid, ep.start)])
                .with_radii([0.25])
                .with_colors([Color::from_rgb(30, 30, 30)]),
        )
        .map_err(&err)?;
        for step in &ep.steps {
            log_step(rec, &grid, ep.goal, t0, step).map_err(&err)?;
        }
        let end = t0 + ep.total_secs;
        rec.set_duration_secs(SIM_TIME, end);
        let most = ep.visits.iter().copied().max().unwrap_or(1).max(1) as f64;
        let visits: Vec<f64> = ep.visits.iter().map(|&v| f64::from(v) / most).collect();
        rec.log(paths::VISITS_MAP, &heat_map(&grid, &visits))
            .map_err(&err)?;
        let outcome = match ep.committed {
            Some(c) if c == ep.goal => format!("reached the goal {c}"),
            Some(c) => format!("committed to the wrong goal {c}"),
            None => "did not converge".to_string(),
        };
        rec.log(
            paths::LOG,
            &TextLog::new(format!(
                "episode {}: {outcome} after {} actions ({:.1} s net, {:.1} s total)",
                k + 1,
                ep.actions,
                ep.net_secs,
                ep.total_secs
            ))
            .with_level(if ep.reached() { "INFO" } else { "WARN" }),
        )
        .map_err(&err)?;
        self.t0 = end + EPISODE_GAP_SECS;
        self.episodes += 1;
        Ok(())
    }

    /// Logs `provenance` (its `runs` set to the episodes recorded), flushes
    /// the file and moves it into place.
    pub fn finish(self, provenance: &Provenance) -> Result<PathBuf> {
        provenance.write(&self.file, self.episodes)?;
        self.file.finish()
    }
}

/// Sends episode `k`'s data tables ([`crate::record::data`]), run from
/// `seed`, starting at `t0` on the timeline.
fn send_episode_tables(
    rec: &rerun::RecordingStream,
    grid: &Grid,
    k: usize,
    t0: f64,
    seed: u64,
    epoch_secs: f64,
    ep: &GridEpisodeResult,
) -> std::result::Result<(), rerun::RecordingStreamError> {
    let run = k as i64;
    GridRuns {
        run: vec![run],
        seed: vec![seed as i64],
        goal: vec![grid.index(ep.goal) as i64],
        start_x: vec![ep.start.x as i64],
        start_y: vec![ep.start.y as i64],
        goal_x: vec![ep.goal.x as i64],
        goal_y: vec![ep.goal.y as i64],
        epoch_s: vec![epoch_secs],
    }
    .send(rec, &[t0])?;
    let steps = &ep.steps;
    let times: Vec<f64> = steps.iter().map(|s| t0 + s.onset_secs).collect();
    let int = |f: &dyn Fn(&crate::grid::GridStep) -> usize| {
        steps.iter().map(|s| f(s) as i64).collect::<Vec<_>>()
    };
    Actions {
        run: vec![run; steps.len()],
        t_s: steps.iter().map(|s| s.onset_secs).collect(),
        from_x: int(&|s| s.from.x),
        from_y: int(&|s| s.from.y),
        action: steps.iter().map(|s| s.action.name().to_string()).collect(),
        to_x: int(&|s| s.to.x),
        to_y: int(&|s| s.to.y),
        error: steps.iter().map(|s| s.error).collect(),
        p_error: steps.iter().map(|s| s.p_error).collect(),
        decoded_error: steps.iter().map(|s| s.decoded_error).collect(),
        belief: (
            steps
                .iter()
                .flat_map(|s| s.belief.iter().copied())
                .collect(),
            grid.n_cells(),
        ),
    }
    .send(rec, &times)?;
    Ends {
        run: vec![run],
        t_s: vec![ep.total_secs],
        committed: vec![ep.committed.map_or(-1, |c| grid.index(c) as i64)],
    }
    .send(rec, &[t0 + ep.total_secs])
}

/// One action of a grid episode that started at `t0` on the timeline: the
/// posterior, the cursor, p(error), the belief in the user's `goal`, the
/// action in words and the EEG at FCz.
fn log_step(
    rec: &RecordingStream,
    grid: &Grid,
    goal: Cell,
    t0: f64,
    step: &GridStep,
) -> rerun::RecordingStreamResult<()> {
    let fs = errp_bci::SFREQ_HZ;
    let t = t0 + step.onset_secs;
    rec.set_duration_secs(SIM_TIME, t);
    let has_belief = step.belief.iter().all(|p| p.is_finite());
    if has_belief {
        rec.log(paths::GRID_POSTERIOR, &heat_map(grid, &step.belief))?;
    }
    rec.log(
        paths::GRID_CURSOR,
        &Points2D::new([centre(grid, step.to)])
            .with_radii([0.25])
            .with_colors([Color::from_rgb(30, 30, 30)]),
    )?;
    rec.log(paths::P_ERROR, &Scalars::single(step.p_error))?;
    rec.log(paths::THRESHOLD, &Scalars::single(0.5))?;
    if has_belief {
        rec.log(
            paths::BELIEF_TRUE_GOAL,
            &Scalars::single(step.belief[grid.index(goal)]),
        )?;
        let max = step.belief.iter().copied().fold(0.0, f64::max);
        rec.log(paths::BELIEF_MAX, &Scalars::single(max))?;
    }
    let truth = if step.error { "error" } else { "correct" };
    // A live decoder's decision that did not come in time: no p(error).
    let (decoded, level) = if step.p_error.is_nan() {
        ("no decision in time (missed)".to_string(), "WARN")
    } else {
        let says = if step.p_error >= 0.5 {
            "error"
        } else {
            "correct"
        };
        let level = if (step.p_error >= 0.5) == step.error {
            "INFO"
        } else {
            "WARN"
        };
        (format!("decoded {says} (p = {:.2})", step.p_error), level)
    };
    rec.log(
        paths::LOG,
        &TextLog::new(format!(
            "{} {} -> {}: user {truth}, {decoded}",
            step.action.name(),
            step.from,
            step.to,
        ))
        .with_level(level),
    )?;
    for (i, v) in step.fcz.iter().enumerate() {
        rec.set_duration_secs(SIM_TIME, t + i as f64 / fs);
        rec.log(eeg_channel("FCz"), &Scalars::single(*v))?;
    }
    Ok(())
}
