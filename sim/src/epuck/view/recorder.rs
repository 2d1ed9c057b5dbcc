//! The e-puck recorder: the scene, the trajectory, the detections, the
//! belief, p(error) and the EEG of every run as it happens, and each run's
//! data tables ([`crate::record::schema`]), as an observer of the runs.

use std::path::PathBuf;

use errp_robot::{GoalLayout, LAYOUT_GRID_CELLS};
use rerun::{
    Arrows2D, Color, LineStrips2D, Points2D, RecordingStream, Scalars, SeriesLines, TextLog,
};

use crate::epuck::observer::{EpisodeStart, EpuckObserver, PhysicsFrame, WindowFrame};
use crate::epuck::run::EpuckRunsObserver;
use crate::epuck::world::{ArenaSpec, Obstacle};
use crate::error::{Result, SimError};
use crate::record::schema::{Ends, EpuckRuns, Errps, Events, Frames, Windows};
use crate::record::{RrdFile, SIM_TIME, eeg_channel, log_decoder_series, paths, record_error};

/// Pause between runs on the timeline (s).
pub const RUN_GAP_SECS: f64 = 2.0;
/// The trajectory is logged every this many physics steps (8 Hz).
const TRAJECTORY_EVERY: usize = 8;

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

// The recorder as an observer of runs and of each run's steps.

impl EpuckRunsObserver for EpuckRecorder {
    fn start_run(&mut self, k: usize, seed: u64) {
        let title = format!("run {}: {}", k + 1, self.run_title);
        self.next_run(&title, seed);
    }
}

impl EpuckObserver for EpuckRecorder {
    fn on_start(&mut self, start: &EpisodeStart) {
        self.tables.start = Some(*start);
    }

    fn on_errp(&mut self, time_secs: f64, onset_secs: f64, phase: usize) {
        let t = &mut self.tables;
        t.e_t.push(time_secs);
        t.e_onset.push(onset_secs);
        t.e_phase.push(phase as i64);
    }

    fn on_end(&mut self, time_secs: f64, committed: Option<usize>) {
        self.tables.end = Some((time_secs, committed));
    }

    fn on_physics(&mut self, f: &PhysicsFrame) {
        self.steps += 1;
        self.last_secs = f.time_secs;
        let t = &mut self.tables;
        t.f_t.push(f.time_secs);
        t.f_xy.push([f.pose.x_m, f.pose.y_m]);
        t.f_heading.push(f.pose.heading_rad.to_degrees());
        t.f_tracked.push([f.tracked.x_m, f.tracked.y_m]);
        t.f_phase.push(f.phase as i64);
        t.f_target.push(f.target as i64);
        if self.steps % TRAJECTORY_EVERY != 1 && self.steps > 1 {
            return;
        }
        self.at(f.time_secs);
        let p = f.pose;
        self.trajectory.push(cm(p.x_m, p.y_m));
        let r = self.rec.log(
            paths::ARENA_TRAJECTORY,
            &LineStrips2D::new([self.trajectory.clone()])
                .with_colors([Color::from_rgb(40, 90, 200)])
                .with_radii([0.6]),
        );
        self.keep(r);
        let r = self.rec.log(
            paths::ARENA_ROBOT,
            &Points2D::new([cm(p.x_m, p.y_m)])
                .with_radii([3.7])
                .with_colors([Color::from_rgb(30, 30, 30)]),
        );
        self.keep(r);
        let (s, c) = p.heading_rad.sin_cos();
        let r = self.rec.log(
            paths::ARENA_HEADING,
            &Arrows2D::from_vectors([[(8.0 * c) as f32, (8.0 * s) as f32]])
                .with_origins([cm(p.x_m, p.y_m)])
                .with_colors([Color::from_rgb(230, 120, 20)]),
        );
        self.keep(r);
    }

    fn on_window(&mut self, f: &WindowFrame) {
        let t = &mut self.tables;
        t.w_t.push(f.time_secs);
        t.w_p.push(f.p_error);
        t.w_evidence.push(f.evidence);
        t.w_detected.push(f.detected);
        t.w_step.push(f.step as i64);
        t.w_target.push(f.target as i64);
        let goals = self.layout.goals().len();
        // No belief (an agent drives): NaN in the table, the cities grey.
        if f.belief.len() == goals {
            t.w_belief.extend_from_slice(&f.belief);
        } else {
            t.w_belief.extend(std::iter::repeat_n(f64::NAN, goals));
        }
        self.at(f.time_secs);
        let colours: Vec<Color> = if f.belief.len() == goals {
            f.belief.iter().map(|&p| belief_colour(p)).collect()
        } else {
            vec![belief_colour(0.0); goals]
        };
        let r = self.rec.log(
            paths::ARENA_GOALS,
            &Points2D::new(self.layout.goals().iter().map(|g| cm(g.x_m, g.y_m)))
                .with_radii([5.0])
                .with_colors(colours),
        );
        self.keep(r);
        // The city the robot heads for: an orange ring.
        let t = &self.layout.goals()[f.target];
        let ring: Vec<[f32; 2]> = (0..=32)
            .map(|k| {
                let a = k as f64 / 32.0 * std::f64::consts::TAU;
                cm(t.x_m + 0.075 * a.cos(), t.y_m + 0.075 * a.sin())
            })
            .collect();
        let r = self.rec.log(
            paths::ARENA_TARGET,
            &LineStrips2D::new([ring])
                .with_colors([Color::from_rgb(230, 120, 20)])
                .with_radii([0.7]),
        );
        self.keep(r);
        for (i, &p) in f.belief.iter().enumerate() {
            let path = paths::belief_city(&self.layout.goals()[i].name);
            let r = self.rec.log(path, &Scalars::single(p));
            self.keep(r);
        }
        let r = self.rec.log(paths::P_ERROR, &Scalars::single(f.p_error));
        self.keep(r);
        // What the detector compared with T_e (the smoothed p(error)).
        let r = self.rec.log(paths::EVIDENCE, &Scalars::single(f.evidence));
        self.keep(r);
        let r = self.rec.log(paths::THRESHOLD, &Scalars::single(self.t_e));
        self.keep(r);
        if f.detected {
            self.detections.push(cm(f.tracked.x_m, f.tracked.y_m));
            let r = self.rec.log(
                paths::ARENA_DETECTIONS,
                &Points2D::new(self.detections.clone())
                    .with_radii([2.5])
                    .with_colors([Color::from_rgb(220, 30, 30)]),
            );
            self.keep(r);
        }
        // The EEG of the last 62.5 ms, sample by sample.
        let n = f.fcz_cz[0].len();
        let fs = n as f64 / crate::epuck::plant::WINDOW_STEP_SECS;
        for (name, samples) in ["FCz", "Cz"].iter().zip(&f.fcz_cz) {
            let path = eeg_channel(name);
            for (k, v) in samples.iter().enumerate() {
                self.at(f.time_secs - (n - 1 - k) as f64 / fs);
                let r = self.rec.log(path.as_str(), &Scalars::single(*v));
                self.keep(r);
            }
        }
    }

    fn on_event(&mut self, time_secs: f64, text: &str, warn: bool) {
        let t = &mut self.tables;
        t.v_t.push(time_secs);
        t.v_warn.push(warn);
        t.v_text.push(text.to_string());
        self.at(time_secs);
        let r = self.rec.log(
            paths::LOG,
            &TextLog::new(text).with_level(if warn { "WARN" } else { "INFO" }),
        );
        self.keep(r);
    }
}
