//! What `errp run <e-puck scenario> --save` records: the arena as seen from
//! the ceiling (walls, obstacles, the 25 cities coloured by belief, the
//! e-puck, its trajectory and red marks where errors were detected, as in
//! Fig. 5, with a ring on the city the robot heads for), the belief as one
//! series per city, p(error) against T_e, preprocessed EEG at FCz and Cz,
//! and a log of events, all on the `sim_time` timeline in seconds. Lengths
//! are in centimetres. A file opens at its end; every run's trajectory and
//! detections also stay as a faint static layer, so the whole batch shows
//! at a glance.

use std::path::{Path, PathBuf};

use errp_robot::{GoalLayout, LAYOUT_GRID_CELLS};
use rerun::blueprint::{Blueprint, Spatial2DView, TimeSeriesView};
use rerun::{
    Arrows2D, Color, LineStrips2D, Points2D, RecordingStream, Scalars, SeriesLines, TextLog,
};

use crate::epuck::decoder::ContinuousDecoder;
use crate::epuck::episode::EpuckEpisodeResult;
use crate::epuck::observer::{EpisodeStart, EpuckObserver, PhysicsFrame, WindowFrame};
use crate::epuck::plant::WindowDecoder;
use crate::epuck::run::{EpuckRunsObserver, run_epuck_runs};
use crate::epuck::scenario::EpuckScenario;
use crate::epuck::world::{ArenaSpec, Obstacle};
use crate::error::{Result, SimError};
use crate::record::data::Provenance;
use crate::record::schema::{Ends, EpuckRuns, Errps, Events, Frames, Windows};
use crate::record::{
    RrdFile, SIM_TIME, eeg_channel, log_decoder_series, paths, record_error, task_blueprint,
};

mod observe;

#[allow(unused_imports)]
pub use observe::*;

/// Pause between runs on the timeline (s).
pub const RUN_GAP_SECS: f64 = 2.0;
/// The trajectory is logged every this many physics steps (8 Hz).
const TRAJECTORY_EVERY: usize = 8;

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

fn cm(x: f64, y: f64) -> [f32; 2] {
    [(x * 100.0) as f32, (y * 100.0) as f32]
}

/// Polygon outline of an obstacle (cm).
fn outline(o: &Obstacle) -> Vec<[f32; 2]> {
    o.outline().into_iter().map(|(x, y)| cm(x, y)).collect()
}

/// Belief in [0, 1] as a colour: grey (0) to saturated green (1), on a
/// square-root scale so that small beliefs stay visible.
fn belief_colour(p: f64) -> Color {
    let v = p.clamp(0.0, 1.0).sqrt();
    let mix = |a: f64, b: f64| (a + (b - a) * v) as u8;
    Color::from_rgb(mix(170.0, 20.0), mix(170.0, 170.0), mix(170.0, 60.0))
}

/// Records one or more runs of an e-puck scenario as they happen.
pub struct EpuckRecorder {
    rec: RecordingStream,
    path: PathBuf,
    layout: GoalLayout,
    t_e: f64,
    offset_secs: f64,
    trajectory: Vec<[f32; 2]>,
    detections: Vec<[f32; 2]>,
    /// Every finished run's trajectory and detections, for the static layer.
    all_trajectories: Vec<Vec<[f32; 2]>>,
    all_detections: Vec<[f32; 2]>,
    steps: usize,
    last_secs: f64,
    error: Option<SimError>,
    /// The run being recorded (from 0) and its seed.
    run: usize,
    seed: u64,
    tables: RunTables,
    /// What the log says as each run of a batch starts, after its number
    /// (the user's goal and decoder).
    run_title: String,
}

/// One run's rows of the data tables ([`crate::record::data`]), sent when
/// the run ends.
#[derive(Default)]
struct RunTables {
    start: Option<EpisodeStart>,
    end: Option<(f64, Option<usize>)>,
    // Frames.
    f_t: Vec<f64>,
    f_xy: Vec<[f64; 2]>,
    f_heading: Vec<f64>,
    f_tracked: Vec<[f64; 2]>,
    f_phase: Vec<i64>,
    f_target: Vec<i64>,
    // Windows.
    w_t: Vec<f64>,
    w_p: Vec<f64>,
    w_evidence: Vec<f64>,
    w_detected: Vec<bool>,
    w_step: Vec<i64>,
    w_target: Vec<i64>,
    w_belief: Vec<f64>,
    // ErrPs.
    e_t: Vec<f64>,
    e_onset: Vec<f64>,
    e_phase: Vec<i64>,
    // Events.
    v_t: Vec<f64>,
    v_warn: Vec<bool>,
    v_text: Vec<String>,
}

impl EpuckRecorder {
    /// Logs the static scene (walls, obstacles, city labels, series styles).
    pub fn new(file: &RrdFile, arena: &ArenaSpec, layout: &GoalLayout, t_e: f64) -> Result<Self> {
        let rec = file.stream().clone();
        let path = file.path().to_path_buf();
        let err = record_error(file.path());
        let s = arena.size_m;
        rec.log_static(
            paths::ARENA_WALLS,
            &LineStrips2D::new([[cm(0.0, 0.0), cm(s, 0.0), cm(s, s), cm(0.0, s), cm(0.0, 0.0)]])
                .with_colors([Color::from_rgb(60, 60, 60)])
                .with_radii([1.0]),
        )
        .map_err(&err)?;
        if !arena.obstacles.is_empty() {
            rec.log_static(
                paths::ARENA_OBSTACLES,
                &LineStrips2D::new(arena.obstacles.iter().map(outline))
                    .with_colors([Color::from_rgb(110, 80, 50)])
                    .with_radii([0.8]),
            )
            .map_err(&err)?;
        }
        // City names beside the icons, alternately above and below by column
        // so that neighbours' long names do not run into each other.
        let cell_m = layout.arena_size_m() / f64::from(LAYOUT_GRID_CELLS);
        rec.log_static(
            paths::ARENA_CITIES,
            &Points2D::new(layout.goals().iter().map(|g| {
                let column = (g.x_m / cell_m).floor() as i64;
                let dy = if column % 2 == 0 { -0.13 } else { 0.13 };
                cm(g.x_m, g.y_m + dy)
            }))
            .with_radii([0.1])
            .with_colors([Color::from_rgb(90, 90, 90)])
            .with_labels(layout.goals().iter().map(|g| g.name.as_str())),
        )
        .map_err(&err)?;
        log_decoder_series(&rec, "T_e").map_err(&err)?;
        for g in layout.goals() {
            rec.log_static(
                paths::belief_city(&g.name),
                &SeriesLines::new().with_names([g.name.as_str()]),
            )
            .map_err(&err)?;
        }
        Ok(Self {
            rec,
            path,
            layout: layout.clone(),
            t_e,
            offset_secs: 0.0,
            trajectory: Vec::new(),
            detections: Vec::new(),
            all_trajectories: Vec::new(),
            all_detections: Vec::new(),
            steps: 0,
            last_secs: 0.0,
            error: None,
            run: 0,
            seed: 0,
            tables: RunTables::default(),
            run_title: String::new(),
        })
    }

    /// Starts the next run, with `seed`, after the previous one on the
    /// timeline; `start_goal_and_user` opens its log.
    pub fn next_run(&mut self, start_goal_and_user: &str, seed: u64) {
        if self.steps > 0 {
            self.send_tables();
            self.offset_secs += self.last_secs + RUN_GAP_SECS;
            self.log_overview();
            self.run += 1;
        }
        // What a run without a step left (an episode reset before any
        // action) belongs to no run.
        self.tables = RunTables::default();
        self.seed = seed;
        self.trajectory.clear();
        self.detections.clear();
        self.steps = 0;
        self.last_secs = 0.0;
        self.rec.set_duration_secs(SIM_TIME, self.offset_secs);
        let r = self.rec.log(paths::LOG, &TextLog::new(start_goal_and_user));
        self.keep(r);
        let r = self.rec.log(
            paths::ARENA_DETECTIONS,
            &Points2D::new(Vec::<[f32; 2]>::new()),
        );
        self.keep(r);
    }

    /// Names what each run's log opens with, after the run's number.
    pub(crate) fn set_run_title(&mut self, title: String) {
        self.run_title = title;
    }

    /// Where the current run starts on the timeline (s).
    pub(crate) fn run_offset_secs(&self) -> f64 {
        self.offset_secs
    }

    /// Logs the last run's overview; returns the first recording error, if
    /// any (logging goes on regardless).
    pub fn finish(mut self) -> Result<()> {
        if self.steps > 0 {
            self.send_tables();
            self.log_overview();
        }
        self.error.map_or(Ok(()), Err)
    }

    /// Sends the run's row of the runs table: how it started.
    fn send_start(&mut self, s: &EpisodeStart) {
        let cm = |v: f64| 100.0 * v;
        let row = EpuckRuns {
            run: vec![self.run as i64],
            seed: vec![self.seed as i64],
            goal: vec![s.goal as i64],
            start_x: vec![cm(s.pose.x_m)],
            start_y: vec![cm(s.pose.y_m)],
            start_heading_deg: vec![s.pose.heading_rad.to_degrees()],
            t_e: vec![s.t_e],
            detection_from_s: vec![s.detection_span.0],
            detection_to_s: vec![s.detection_span.1],
            window_from_s: vec![s.window_span.0],
            window_to_s: vec![s.window_span.1],
        };
        let r = row.send(&self.rec, &[self.offset_secs]);
        self.keep(r);
    }

    /// Sends the run's data tables, one chunk each.
    fn send_tables(&mut self) {
        let t = std::mem::take(&mut self.tables);
        let run = self.run as i64;
        let off = self.offset_secs;
        let on_timeline = |ts: &[f64]| ts.iter().map(|t| off + t).collect::<Vec<_>>();
        let cm = |v: f64| 100.0 * v;
        if let Some(s) = t.start {
            self.send_start(&s);
        }
        let times = on_timeline(&t.f_t);
        let frames = Frames {
            run: vec![run; t.f_t.len()],
            t_s: t.f_t,
            x_cm: t.f_xy.iter().map(|p| cm(p[0])).collect(),
            y_cm: t.f_xy.iter().map(|p| cm(p[1])).collect(),
            heading_deg: t.f_heading,
            tracked_x_cm: t.f_tracked.iter().map(|p| cm(p[0])).collect(),
            tracked_y_cm: t.f_tracked.iter().map(|p| cm(p[1])).collect(),
            phase: t.f_phase,
            target: t.f_target,
        };
        let r = frames.send(&self.rec, &times);
        self.keep(r);
        let times = on_timeline(&t.w_t);
        let windows = Windows {
            run: vec![run; t.w_t.len()],
            t_s: t.w_t,
            p_error: t.w_p,
            evidence: t.w_evidence,
            detected: t.w_detected,
            step: t.w_step,
            target: t.w_target,
            belief: (t.w_belief, self.layout.goals().len()),
        };
        let r = windows.send(&self.rec, &times);
        self.keep(r);
        let times = on_timeline(&t.e_t);
        let errps = Errps {
            run: vec![run; t.e_t.len()],
            t_s: t.e_t,
            onset_s: t.e_onset,
            phase: t.e_phase,
        };
        let r = errps.send(&self.rec, &times);
        self.keep(r);
        let times = on_timeline(&t.v_t);
        let events = Events {
            run: vec![run; t.v_t.len()],
            t_s: t.v_t,
            warn: t.v_warn,
            text: t.v_text,
        };
        let r = events.send(&self.rec, &times);
        self.keep(r);
        if let Some((end, committed)) = t.end {
            let ends = Ends {
                run: vec![run],
                t_s: vec![end],
                committed: vec![committed.map_or(-1, |c| c as i64)],
            };
            let r = ends.send(&self.rec, &[off + end]);
            self.keep(r);
        }
    }

    /// Adds the run that just ended to the static layer: its trajectory in
    /// faint blue, its detections in faint red, under the live ones.
    fn log_overview(&mut self) {
        self.all_trajectories.push(self.trajectory.clone());
        self.all_detections.extend_from_slice(&self.detections);
        let trajectories = LineStrips2D::new(self.all_trajectories.clone())
            .with_colors([Color::from_unmultiplied_rgba(40, 90, 200, 70)])
            .with_radii([0.5])
            .with_draw_order(-1.0);
        let detections = Points2D::new(self.all_detections.clone())
            .with_colors([Color::from_unmultiplied_rgba(220, 30, 30, 90)])
            .with_radii([2.0])
            .with_draw_order(-1.0);
        let layers: [(&str, &dyn rerun::AsComponents); 2] = [
            (paths::ARENA_OVERVIEW_TRAJECTORIES, &trajectories),
            (paths::ARENA_OVERVIEW_DETECTIONS, &detections),
        ];
        for (path, layer) in layers {
            let r = self.rec.log_static(path, layer);
            self.keep(r);
        }
    }

    fn keep(&mut self, r: std::result::Result<(), rerun::RecordingStreamError>) {
        if let Err(e) = r
            && self.error.is_none()
        {
            self.error = Some(record_error(&self.path)(e));
        }
    }

    fn at(&self, time_secs: f64) {
        self.rec
            .set_duration_secs(SIM_TIME, self.offset_secs + time_secs);
    }
}
